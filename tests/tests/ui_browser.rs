//! The UI page in a real browser: `digiteyes ui`'s server fed with states (as JSON lines over
//! UDP, the way `listen --forward udp://` sends them) and with a replayed sequence, loaded in
//! headless Chromium. The DOM it ends with must show the streamed values, and its screenshot
//! a drawn hand.
//!
//! Needs Debian's `chromium` (scripts/test installs it; `DIGITEYES_CHROMIUM` names another
//! binary). Without it each test prints `SKIPPED: ...` to stderr and passes (under `CI=true` it fails).

mod common;

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream, UdpSocket};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use digiteyes_host::scenarios::{render_scenario, scenario, RenderOptions};
use digiteyes_host::ui::{RunningUi, UiOptions, UiSource};
use digiteyes_host::{track_sequence, TrackerConfig};

/// The 3D canvas's background (`#e9edf2` in style.css and app.js).
const CANVAS_BACKGROUND: [u8; 3] = [0xe9, 0xed, 0xf2];

fn skip(test: &str, reason: &str) {
    common::skip(
        &format!("UI browser test `{test}` (tests/tests/ui_browser.rs)"),
        reason,
    );
}

/// How long each page runs (ms of its own time).
const PAGE_BUDGET_MS: u32 = 4_000;

fn dump_dom(exe: &Path, url: &str) -> String {
    common::browser::dump_dom(exe, url, PAGE_BUDGET_MS)
}

fn screenshot(exe: &Path, url: &str, dir: &Path) -> image::RgbImage {
    let png = dir.join("page.png");
    common::browser::chromium_run(
        exe,
        url,
        PAGE_BUDGET_MS,
        &[format!("--screenshot={}", png.display())],
    );
    image::open(&png).expect("a PNG screenshot").to_rgb8()
}

/// The 3D view in a screenshot: the bounding box of the canvas's background colour, and the
/// fraction of the pixels inside it that are the hand (skin-toned: red above green above
/// blue, as app.js shades the model).
fn hand_coverage(shot: &image::RgbImage) -> (u32, u32, f64) {
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    for (x, y, p) in shot.enumerate_pixels() {
        if p.0 == CANVAS_BACKGROUND {
            (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
        }
    }
    assert!(x1 > x0 && y1 > y0, "no 3D canvas in the screenshot");
    let mut skin = 0u64;
    for y in y0..=y1 {
        for x in x0..=x1 {
            let [r, g, b] = shot.get_pixel(x, y).0.map(u16::from);
            if r > 150 && r > g + 20 && g > b {
                skin += 1;
            }
        }
    }
    let area = u64::from(x1 - x0 + 1) * u64::from(y1 - y0 + 1);
    (x1 - x0 + 1, y1 - y0 + 1, skin as f64 / area as f64)
}

/// A plain HTTP GET on loopback: (status, body).
fn http_get(addr: &str, path: &str) -> (u16, Vec<u8>) {
    let mut stream = TcpStream::connect(addr).unwrap();
    write!(
        stream,
        "GET {path} HTTP/1.1\r\nHost: {addr}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut response = Vec::new();
    stream.read_to_end(&mut response).unwrap();
    let split = response
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .expect("an HTTP header");
    let head = String::from_utf8_lossy(&response[..split]);
    let status = head.split_whitespace().nth(1).unwrap().parse().unwrap();
    let body = response[split + 4..].to_vec();
    // tiny_http may send the body chunked; the tests only read small fixed bodies and PNGs
    // it sends with a Content-Length.
    (status, body)
}

fn start_ui(source: UiSource) -> RunningUi {
    let options = UiOptions {
        bind: "127.0.0.1:0".parse().unwrap(),
        source,
        duration: None,
    };
    RunningUi::start(&options, &mut std::io::sink()).expect("the UI starts")
}

fn host_port(url: &str) -> String {
    url.trim_start_matches("http://")
        .trim_end_matches('/')
        .to_string()
}

fn state_message(frame: u32, q: &[f32]) -> String {
    common::browser::state_line(frame, q)
}

/// Sends states to `to` every 40 ms until dropped, as `listen --forward udp://` would: the
/// page must see a live signal however long the browser takes to start.
struct Streamer {
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<u32>>,
}

impl Streamer {
    fn start(to: SocketAddr, q: Vec<f32>) -> Streamer {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        let thread = std::thread::spawn(move || {
            let socket = UdpSocket::bind("127.0.0.1:0").unwrap();
            let mut frame = 0;
            while !flag.load(Ordering::Relaxed) {
                socket
                    .send_to(state_message(frame, &q).as_bytes(), to)
                    .unwrap();
                frame += 1;
                // The board's frame period: pacing the stream, not waiting for anything.
                std::thread::sleep(Duration::from_millis(40));
            }
            frame
        });
        Streamer {
            stop,
            thread: Some(thread),
        }
    }
}

impl Drop for Streamer {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

#[test]
fn streamed_states_show_in_the_page_and_draw_a_hand() {
    let exe = match common::browser::chromium() {
        Ok(exe) => exe,
        Err(reason) => return skip("streamed states", &reason),
    };
    let mut q: Vec<f32> = scenario("mouse")
        .unwrap()
        .base
        .iter()
        .map(|&v| v as f32)
        .collect();
    q[4] = 23.456;
    q[9] = 0.777;
    let ui = start_ui(UiSource::Udp("127.0.0.1:0".parse().unwrap()));
    let _streamer = Streamer::start(ui.udp_addr().unwrap(), q.clone());
    let deadline = Instant::now() + Duration::from_secs(10);
    while ui.hub().snapshot().link.states < 5 {
        assert!(
            Instant::now() < deadline,
            "no state reached the UI over UDP"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let addr = host_port(&ui.url());
    let (status, _) = http_get(&addr, "/frame.png");
    assert_eq!(status, 404, "a UDP source has no camera frames");

    let dom = dump_dom(&exe, &ui.url());
    assert!(dom.contains(">TRACKING<"), "no TRACKING badge:\n{dom}");
    for (label, value) in [
        ("q4 palm x (mm)", "23.456"),
        ("q9 finger 1 PIP flexion (rad)", "0.777"),
        ("q6 palm z (mm)", "45.000"),
    ] {
        let row = dom
            .split("<tr")
            .find(|row| row.contains(label))
            .unwrap_or_else(|| panic!("no row for {label}"));
        assert!(row.contains(value), "{label} does not show {value}: {row}");
    }
    assert!(
        dom.contains(r#"data-shapes-drawn="16""#),
        "the page did not draw the 16 shapes of the hand"
    );
    assert!(dom.contains("base (23.5, "), "no 3D mouse reading");

    let dir = tempfile::tempdir().unwrap();
    let shot = screenshot(&exe, &ui.url(), dir.path());
    let (w, h, hand) = hand_coverage(&shot);
    println!("3D view: {w}x{h} px, {:.1}% hand", hand * 100.0);
    assert_eq!(
        (w, h),
        (640, 480),
        "the 3D canvas is not where it should be"
    );
    assert!(
        hand > 0.02,
        "the 3D view is blank: {:.2}% of it is hand",
        hand * 100.0
    );
    ui.stop().unwrap();
}

#[test]
fn a_replay_shows_the_camera_frame_with_the_model() {
    let exe = match common::browser::chromium() {
        Ok(exe) => exe,
        Err(reason) => return skip("replay", &reason),
    };
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("mouse");
    let render = RenderOptions {
        frames: Some(8),
        size: Some((160, 120)),
        supersample: 1,
        ..RenderOptions::default()
    };
    render_scenario("mouse", &seq, &render).unwrap();
    let states = seq.join("states.csv");
    track_sequence(&seq, &states, TrackerConfig::default(), false).unwrap();
    let ui = start_ui(UiSource::Replay {
        seqdir: seq.clone(),
        states,
        hypotheses: None,
        camera: 0,
        fps: Some(20.0),
    });
    let deadline = Instant::now() + Duration::from_secs(10);
    while ui.hub().snapshot().camera_frame.is_none() {
        assert!(Instant::now() < deadline, "the replay sent no frame");
        std::thread::sleep(Duration::from_millis(20));
    }
    let (status, png) = http_get(&host_port(&ui.url()), "/frame.png");
    assert_eq!(status, 200);
    let frame = image::load_from_memory(&png).expect("/frame.png is a PNG");
    assert_eq!((frame.width(), frame.height()), (160, 120));

    let dom = dump_dom(&exe, &ui.url());
    let img = dom
        .split("<img")
        .nth(1)
        .and_then(|s| s.split('>').next())
        .expect("the camera <img>");
    assert!(
        img.contains("/frame.png?frame=") && !img.contains("hidden"),
        "the camera view is not showing frames: <img{img}>"
    );
    assert!(dom.contains("replay of"), "the source is not named");
    assert!(dom.contains("base ("), "no 3D mouse reading");
    ui.stop().unwrap();
}
