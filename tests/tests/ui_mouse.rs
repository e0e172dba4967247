//! The UI's 3D mouse in a real browser: `digiteyes ui` fed over UDP (as `listen --forward
//! udp://` sends) with states of the thesis' mouse trial, loaded in headless Chromium. A thumb
//! click with the cursor (the pole's top) inside a sphere selects it; a thumb click with the
//! cursor elsewhere, or a finger-4 click, drops the selection; resting inside a sphere selects
//! nothing.
//!
//! Needs Debian's `chromium` (scripts/test installs it; `DIGITEYES_CHROMIUM` names another
//! binary). Without it the test prints `SKIPPED: ...` to stderr and passes (under `CI=true` it
//! fails).

mod common;

use std::net::{SocketAddr, UdpSocket};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use digiteyes_host::scenarios::{mouse_thesis, scenario};
use digiteyes_host::ui::hub::Hub;
use digiteyes_host::ui::{RunningUi, UiOptions, UiSource};

/// Sphere A of app.js: where the trial's raised finger holds the cursor, (0, 0, 48) mm.
const SPHERE_A: &str = "A";
/// How long the page runs (ms of its time): the script needs about three polls of 50 ms per
/// step; the rest is slack for a slow start.
const PAGE_BUDGET_MS: u32 = 7_000;
/// How long a step may wait for the UI to take a state in, or for the page to poll it.
const STEP_DEADLINE: Duration = Duration::from_secs(10);
/// Polls the page must make after the hub holds a state before the next one is sent: the
/// first may have been answered from the previous state, the second cannot have been.
const POLLS_PER_STEP: u64 = 2;

/// The value of `data-NAME` on the page's `<body>`.
fn body_data<'a>(dom: &'a str, name: &str) -> &'a str {
    let body = &dom[dom.find("<body").expect("a <body>")..];
    let tag = &body[..body.find('>').unwrap()];
    let key = format!(r#"data-{name}=""#);
    let start = tag
        .find(&key)
        .unwrap_or_else(|| panic!("no data-{name} on <body>: {tag}"))
        + key.len();
    &tag[start..start + tag[start..].find('"').unwrap()]
}

fn state_message(frame: u32, q: &[f32]) -> String {
    common::browser::state_line(frame, q)
}

/// Plays `script` to the page one state at a time, as `listen --forward udp://` would send
/// them: each state is sent, and the next one only once the page has polled the UI after the
/// UI took this one in. So the page sees every step, however fast or slow it runs.
struct Player {
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<usize>>,
}

/// Waits until `done` or the step's deadline; false if the deadline passed or `stop` was set.
fn wait_for(stop: &AtomicBool, mut done: impl FnMut() -> bool) -> bool {
    let deadline = Instant::now() + STEP_DEADLINE;
    while !done() {
        if stop.load(Ordering::Relaxed) || Instant::now() > deadline {
            return false;
        }
        // Polling a condition another thread makes true, not waiting out a guess.
        std::thread::sleep(Duration::from_millis(2));
    }
    true
}

impl Player {
    fn start(hub: Arc<Hub>, to: SocketAddr, script: Vec<Vec<f32>>) -> Player {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        let thread = std::thread::spawn(move || {
            let socket = UdpSocket::bind("127.0.0.1:0").unwrap();
            let shown = |frame: u32| {
                let snapshot = hub.snapshot();
                snapshot.state.is_some_and(|s| s.frame == frame)
            };
            // The page has loaded and polls.
            if !wait_for(&flag, || hub.polls_served() > 0) {
                return 0;
            }
            let mut steps_seen = 0;
            for (step, q) in script.iter().enumerate() {
                let frame = FIRST_SCRIPT_FRAME + step as u32;
                socket
                    .send_to(state_message(frame, q).as_bytes(), to)
                    .unwrap();
                if !wait_for(&flag, || shown(frame)) {
                    break;
                }
                let polls = hub.polls_served();
                if !wait_for(&flag, || hub.polls_served() >= polls + POLLS_PER_STEP) {
                    break;
                }
                steps_seen += 1;
            }
            steps_seen
        });
        Player {
            stop,
            thread: Some(thread),
        }
    }

    /// Stops the player; how many steps of the script the page saw.
    fn finish(mut self) -> usize {
        self.stop.store(true, Ordering::Relaxed);
        self.thread.take().map_or(0, |t| t.join().unwrap())
    }
}

impl Drop for Player {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The frame number of the script's first state (`first` is frame 0).
const FIRST_SCRIPT_FRAME: u32 = 1;

/// The trial's state with the finger held up over the palm's rest position (the cursor at
/// about (0, 0, 48) mm, inside sphere A), both buttons at rest.
fn finger_up() -> Vec<f32> {
    let base = scenario(mouse_thesis::NAME).unwrap().base;
    let q = mouse_thesis::state_at(&base, 170.0);
    q.iter().map(|&v| v as f32).collect()
}

/// Serves the UI from UDP, sends it `first`, loads the page in Chromium for
/// [`PAGE_BUDGET_MS`] while playing `script` to it step by step, and returns the DOM it ends
/// with.
fn run_page(exe: &Path, first: &[f32], script: Vec<Vec<f32>>) -> String {
    let options = UiOptions {
        bind: "127.0.0.1:0".parse().unwrap(),
        source: UiSource::Udp("127.0.0.1:0".parse().unwrap()),
        duration: None,
    };
    let ui = RunningUi::start(&options, &mut std::io::sink()).expect("the UI starts");
    let to = ui.udp_addr().unwrap();
    let socket = UdpSocket::bind("127.0.0.1:0").unwrap();
    socket
        .send_to(state_message(0, first).as_bytes(), to)
        .unwrap();
    let deadline = Instant::now() + STEP_DEADLINE;
    while ui.hub().snapshot().state.is_none() {
        assert!(
            Instant::now() < deadline,
            "no state reached the UI over UDP"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
    let steps = script.len();
    let player = Player::start(Arc::clone(ui.hub()), to, script);
    let started = Instant::now();
    let dom = common::browser::dump_dom(exe, &ui.url(), PAGE_BUDGET_MS);
    println!("the page ran {:.1} s", started.elapsed().as_secs_f64());
    let seen = player.finish();
    ui.stop().unwrap();
    assert_eq!(
        seen, steps,
        "the page stopped polling after {seen} of the script's {steps} steps"
    );
    dom
}

/// `q` with state `s` moved by `d`.
fn with(q: &[f32], s: usize, d: f32) -> Vec<f32> {
    let mut q = q.to_vec();
    q[s] += d;
    q
}

/// The thumb's abduction (a button).
const THUMB: usize = 24;
/// Finger 4's abduction (a button).
const FINGER4: usize = 19;
/// The palm's x on the table.
const PALM_X: usize = 4;

fn chromium_or_skip(test: &str) -> Option<PathBuf> {
    match common::browser::chromium() {
        Ok(exe) => Some(exe),
        Err(reason) => {
            common::skip(
                &format!("UI mouse test `{test}` (tests/tests/ui_mouse.rs)"),
                &reason,
            );
            None
        }
    }
}

#[test]
fn a_thumb_click_inside_a_sphere_selects_it_and_nothing_else_does() {
    let Some(exe) = chromium_or_skip("select") else {
        return;
    };
    let on_a = finger_up();
    let click = mouse_thesis::CLICK_RAD as f32;
    let thumb = |q: &[f32]| with(q, THUMB, click);
    let finger4 = |q: &[f32]| with(q, FINGER4, click);
    // 40 mm along x: inside no sphere.
    let away = with(&on_a, PALM_X, 40.0);
    let script = vec![
        on_a.clone(),
        thumb(&on_a), // select A
        on_a.clone(),
        away.clone(),
        thumb(&away), // a click off every sphere drops it
        away.clone(),
        on_a.clone(), // resting inside A selects nothing
        thumb(&on_a), // select A again
        on_a.clone(),
        finger4(&on_a), // finger 4 drops it
        on_a.clone(),
    ];
    let dom = run_page(&exe, &on_a, script);
    let events = body_data(&dom, "mouse-events");
    println!("selection events: {events}");
    let thumb_presses: usize = body_data(&dom, "thumb-presses").parse().unwrap();
    let finger4_presses: usize = body_data(&dom, "finger4-presses").parse().unwrap();
    assert!(
        thumb_presses >= 2 && finger4_presses >= 1,
        "the page did not see the script's clicks: {thumb_presses} thumb, {finger4_presses} finger 4"
    );
    let events: Vec<&str> = events.split_whitespace().collect();
    // Only A is ever selected; each kind of drop happened.
    for kind in [
        format!("select:{SPHERE_A}"),
        "drop:thumb".to_string(),
        "drop:finger4".to_string(),
    ] {
        assert!(events.contains(&kind.as_str()), "no {kind} in {events:?}");
    }
    assert!(
        events
            .iter()
            .all(|e| e.starts_with("drop:") || *e == format!("select:{SPHERE_A}")),
        "{events:?}"
    );
}

#[test]
fn resting_inside_a_sphere_or_clicking_outside_selects_nothing() {
    let Some(exe) = chromium_or_skip("no selection") else {
        return;
    };
    let on_a = finger_up();
    let away = with(&on_a, PALM_X, 40.0);
    let thumb_away = with(&away, THUMB, mouse_thesis::CLICK_RAD as f32);
    let dom = run_page(
        &exe,
        &on_a,
        vec![on_a.clone(), away.clone(), thumb_away, away],
    );
    let hovered: usize = body_data(&dom, "mouse-hovered").parse().unwrap();
    let thumb_presses: usize = body_data(&dom, "thumb-presses").parse().unwrap();
    // The page saw the cursor inside A and saw the thumb click, never together.
    assert!(
        hovered >= 1 && thumb_presses >= 1,
        "hovered {hovered}, thumb presses {thumb_presses}"
    );
    assert_eq!(body_data(&dom, "mouse-events"), "");
    assert_eq!(body_data(&dom, "mouse-selected"), "");
    assert!(dom.contains("nothing selected") || dom.contains("cursor inside sphere A"));
}
