//! The `digiteyes` command: help text, a render → track → eval round, and clear failures.

mod common;

use std::io::{BufRead, BufReader, Read, Write};
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use digiteyes_host::scenarios::NAMES;

fn digiteyes(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_digiteyes"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

#[test]
fn help_explains_every_command_and_scenario() {
    let dir = tempfile::tempdir().unwrap();
    let out = digiteyes(&["--help"], dir.path());
    assert!(out.status.success());
    let help = text(&out.stdout);
    for command in ["render", "track", "eval", "demo"] {
        assert!(help.contains(command), "{help}");
    }
    let out = digiteyes(&["render", "--help"], dir.path());
    let help = text(&out.stdout);
    for name in NAMES {
        assert!(help.contains(name), "{name} missing from\n{help}");
    }
    for option in [
        "--seed",
        "--frames",
        "--noise",
        "--blur",
        "--clutter",
        "grey levels",
        "px",
    ] {
        assert!(help.contains(option), "{option} missing from\n{help}");
    }
    let help = text(&digiteyes(&["track", "--help"], dir.path()).stdout);
    for option in ["--out", "--iterations", "--no-predict", "states.csv"] {
        assert!(help.contains(option), "{option} missing from\n{help}");
    }
    let help = text(&digiteyes(&["eval", "--help"], dir.path()).stdout);
    assert!(help.contains("--json") && help.contains("deg"), "{help}");
    let help = text(&digiteyes(&["demo", "--help"], dir.path()).stdout);
    assert!(
        help.contains("--keep") && help.contains("--frames"),
        "{help}"
    );
}

#[test]
fn render_track_and_evaluate_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = digiteyes(
        &[
            "render", "mouse", "seq", "--frames", "3", "--size", "320x240", "--seed", "4",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(dir.path().join("seq/cam0/000002.pgm").is_file());
    // Default output: states.csv in the current folder.
    let out = digiteyes(&["track", "seq"], dir.path());
    assert!(out.status.success(), "{}", text(&out.stderr));
    let summary = text(&out.stdout);
    assert!(
        summary.contains("tracked 3 frames") && summary.contains("frames/s"),
        "{summary}"
    );
    let states = std::fs::read_to_string(dir.path().join("states.csv")).unwrap();
    assert!(states.starts_with("frame,q0,"), "{states}");
    assert!(states
        .lines()
        .next()
        .unwrap()
        .ends_with("q27,rms_px,iterations,features_found,features_expected,lost,status"));
    assert_eq!(states.lines().count(), 4);
    let out = digiteyes(&["eval", "seq", "states.csv"], dir.path());
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("track life"));
    let out = digiteyes(&["eval", "seq", "states.csv", "--json"], dir.path());
    assert!(out.status.success(), "{}", text(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(json["frames"], 3);
    assert!(json["cameras"][0]["fingertip_mean_px"].is_number());
}

#[test]
fn bad_input_fails_with_one_clear_message() {
    let dir = tempfile::tempdir().unwrap();
    // No sequence there.
    let out = digiteyes(&["track", "nowhere", "--out", "s.csv"], dir.path());
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(
        err.starts_with("digiteyes: error:") && err.contains("nowhere/sequence.json"),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    // A frame of the wrong size.
    let seq = common::small_sequence(dir.path(), "mouse", 2);
    digiteyes_host::sequence::pgm::write_pgm(
        &seq.join("cam0/000001.pgm"),
        &image::GrayImage::new(8, 8),
    )
    .unwrap();
    let out = digiteyes(&["track", "mouse", "--out", "s.csv"], dir.path());
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(
        err.contains("cam0/000001.pgm") && err.contains("8x8"),
        "{err}"
    );
    // States that do not fit the sequence.
    std::fs::write(dir.path().join("bad.csv"), "frame,q0\n0,1\n").unwrap();
    let out = digiteyes(&["eval", "mouse", "bad.csv"], dir.path());
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(
        err.contains("bad.csv") && err.contains("state columns"),
        "{err}"
    );
    // An unknown scenario is a usage error.
    let out = digiteyes(&["render", "juggling", "x"], dir.path());
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out.stderr).contains("juggling"));
}

#[test]
fn demo_renders_tracks_and_evaluates() {
    let dir = tempfile::tempdir().unwrap();
    let keep = dir.path().join("kept");
    let out = digiteyes(
        &["demo", "--frames", "4", "--keep", keep.to_str().unwrap()],
        dir.path(),
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let report = text(&out.stdout);
    assert!(
        report.contains("streamed 4 frames: 4 tracked")
            && report.contains("track life")
            && report.contains("states/s")
            && report.contains("CRC errors"),
        "{report}"
    );
    assert!(keep.join("states.csv").is_file() && keep.join("cam0/000003.pgm").is_file());
    // It ends by saying where the report and the UI are; not in a terminal, it does not
    // serve the UI but prints the command that does.
    let report_html = keep.join("report.html");
    assert!(report_html.is_file(), "no report.html");
    let lines: Vec<&str> = report.lines().collect();
    let n = lines.len();
    assert!(
        n >= 2 && lines[n - 2] == format!("report: {}", report_html.display()),
        "{report}"
    );
    assert!(
        lines[n - 1].starts_with("UI: ")
            && lines[n - 1].contains(&format!(" ui --replay {}", keep.display()))
            && lines[n - 1].contains("http://127.0.0.1:"),
        "{report}"
    );
}

#[test]
fn link_commands_explain_their_options() {
    let dir = tempfile::tempdir().unwrap();
    let help = text(&digiteyes(&["--help"], dir.path()).stdout);
    for command in ["sim", "stream", "listen"] {
        assert!(help.contains(command), "{help}");
    }
    let help = text(&digiteyes(&["stream", "--help"], dir.path()).stdout);
    for option in [
        "--port",
        "--baud",
        "--seq",
        "--camera",
        "--setup",
        "--camera-index",
        "--reply-timeout",
        "--out",
        "dropped",
    ] {
        assert!(help.contains(option), "{option} missing from\n{help}");
    }
    let help = text(&digiteyes(&["listen", "--help"], dir.path()).stdout);
    for option in [
        "--port",
        "--json",
        "--forward",
        "udp://",
        "--setup",
        "--states",
    ] {
        assert!(help.contains(option), "{option} missing from\n{help}");
    }
    let help = text(&digiteyes(&["sim", "--help"], dir.path()).stdout);
    for option in ["--corrupt", "--corrupt-frames", "--restart-after", "Ctrl-C"] {
        assert!(help.contains(option), "{option} missing from\n{help}");
    }
}

#[test]
fn a_missing_serial_device_is_named() {
    let dir = tempfile::tempdir().unwrap();
    common::small_sequence(dir.path(), "mouse", 1);
    for args in [
        &["stream", "--port", "/nonexistent/ttyX", "--seq", "mouse"][..],
        &["listen", "--port", "/nonexistent/ttyX"][..],
    ] {
        let out = digiteyes(args, dir.path());
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = text(&out.stderr);
        assert!(
            err.starts_with("digiteyes: error:") && err.contains("/nonexistent/ttyX"),
            "{args:?}: {err}"
        );
        assert_eq!(err.lines().count(), 1, "{err}");
    }
}

/// Kills a child process (by its handle) unless it has already ended.
struct Reap(std::process::Child);

impl Drop for Reap {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Waits (at most `limit`) for `child` to end.
fn wait_for_exit(child: &mut std::process::Child, limit: Duration) -> std::process::ExitStatus {
    let deadline = Instant::now() + limit;
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status;
        }
        assert!(Instant::now() < deadline, "still running after {limit:?}");
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// The first line from `from` that contains `what` (failing after `limit`).
fn wait_for_line(from: impl std::io::Read + Send + 'static, what: &str, limit: Duration) -> String {
    let (tx, rx) = std::sync::mpsc::channel();
    let what = what.to_string();
    std::thread::spawn(move || {
        // Reads to the end, so the child never writes into a closed pipe.
        for line in BufReader::new(from).lines().map_while(Result::ok) {
            if line.contains(&what) {
                let _ = tx.send(line);
            }
        }
    });
    rx.recv_timeout(limit)
        .unwrap_or_else(|_| panic!("no line within {limit:?}"))
}

#[test]
fn sim_then_stream_then_eval_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    common::small_sequence(dir.path(), "mouse", 3);
    let mut sim = Reap(
        Command::new(env!("CARGO_BIN_EXE_digiteyes"))
            .arg("sim")
            .stdout(Stdio::piped())
            .spawn()
            .unwrap(),
    );
    let stdout = sim.0.stdout.take().unwrap();
    let line = wait_for_line(stdout, "simulated board on", Duration::from_secs(30));
    let port = line.rsplit(' ').next().unwrap().to_string();
    let out = digiteyes(
        &[
            "stream", "--port", &port, "--seq", "mouse", "--out", "s.csv",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let summary = text(&out.stdout);
    assert!(
        summary.contains("3 tracked") && summary.contains("states/s"),
        "{summary}"
    );
    let states = std::fs::read_to_string(dir.path().join("s.csv")).unwrap();
    assert!(
        states
            .lines()
            .next()
            .unwrap()
            .ends_with(",lost,dropped,status,board_ticks"),
        "{states}"
    );
    assert_eq!(states.lines().count(), 4);
    // Every tracked frame carries the board's own count of its work.
    for row in states.lines().skip(1) {
        let ticks: u64 = row.rsplit(',').next().unwrap().parse().expect(row);
        assert!(ticks > 0, "{row}");
    }
    let out = digiteyes(&["eval", "mouse", "s.csv"], dir.path());
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("track life"));
}

#[test]
fn listen_prints_and_forwards_json_lines_over_udp() {
    use digiteyes_core::protocol::{encode, BoardMessage, DropReason, Dropped, State, MAX_MESSAGE};
    use serialport::{SerialPort, TTYPort};

    let dir = tempfile::tempdir().unwrap();
    let (mut board, slave) = TTYPort::pair().unwrap();
    let path = slave.name().unwrap();
    let ui = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    ui.set_read_timeout(Some(Duration::from_secs(30))).unwrap();
    let forward = format!("udp://{}", ui.local_addr().unwrap());
    let mut listen = Reap(
        Command::new(env!("CARGO_BIN_EXE_digiteyes"))
            .args(["listen", "--port", &path, "--json", "--forward", &forward])
            .args(["--states", "2"])
            .current_dir(dir.path())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap(),
    );
    // It has opened (and flushed) the port once it says so; what is sent now arrives.
    let stderr = listen.0.stderr.take().unwrap();
    wait_for_line(stderr, "listening on", Duration::from_secs(30));
    let state = |frame| {
        BoardMessage::State(State {
            frame,
            timestamp: 1000 * u64::from(frame),
            q: [1.0, 0.0, 0.0, 0.0, 1.5, -2.0, 600.0].into_iter().collect(),
            rms_px: 0.5,
            lost: false,
            features_found: 20,
            features_expected: 24,
            iterations: 5,
            track_ticks: 1234,
            status: digiteyes_core::protocol::WireStatus::Tracking,
            search_evaluations: 0,
        })
    };
    let dropped = BoardMessage::Dropped(Dropped {
        frame: 8,
        reason: DropReason::Incomplete,
    });
    let mut bytes = vec![0x55, 0x13]; // line garbage first: skipped
    for message in [state(7), dropped, state(9)] {
        let mut buf = [0u8; MAX_MESSAGE];
        bytes.extend_from_slice(encode(&message, &mut buf).unwrap());
    }
    board.write_all(&bytes).unwrap();

    let mut lines = Vec::new();
    let mut buf = [0u8; 2048];
    while lines.len() < 3 {
        let n = ui.recv(&mut buf).expect("a datagram from listen");
        let line = std::str::from_utf8(&buf[..n]).unwrap();
        assert!(line.ends_with('\n'), "{line:?}");
        lines.push(serde_json::from_str::<serde_json::Value>(line.trim_end()).unwrap());
    }
    assert_eq!(lines[0]["State"]["frame"], 7);
    assert_eq!(lines[0]["State"]["q"][6], 600.0);
    assert_eq!(lines[1]["Dropped"]["frame"], 8);
    assert_eq!(lines[2]["State"]["frame"], 9);
    // Two states were asked for: it stops by itself, having printed the same lines.
    assert!(wait_for_exit(&mut listen.0, Duration::from_secs(30)).success());
    let mut printed = String::new();
    listen
        .0
        .stdout
        .take()
        .unwrap()
        .read_to_string(&mut printed)
        .unwrap();
    let printed: Vec<serde_json::Value> = printed
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(printed, lines);
    drop(slave);
}
