//! Helpers shared by the host's integration tests.
#![allow(dead_code)]

use std::io::{BufRead, BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use digiteyes_core::protocol::{encode, BoardMessage, MAX_MESSAGE};
use serialport::{SerialPort, TTYPort};

use digiteyes_host::scenarios::{render_scenario, RenderOptions};

/// `--port` twice, naming two boards that do not exist: for the refusals that must come
/// before any port is opened.
pub const TWO_ABSENT_BOARDS: [&str; 4] = ["--port", "/nonexistent/a", "--port", "/nonexistent/b"];

/// The conformance fixture from an independent renderer.
pub const FIXTURE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../fixtures/sample-mouse");

/// Renders `frames` frames of `scenario` at 160×120 into `dir/name` and returns that folder.
pub fn small_sequence(dir: &Path, scenario: &str, frames: usize) -> PathBuf {
    let seq = dir.join(scenario);
    let opts = RenderOptions {
        frames: Some(frames),
        size: Some((160, 120)),
        supersample: 2,
        ..RenderOptions::default()
    };
    render_scenario(scenario, &seq, &opts).unwrap();
    seq
}

/// The error's whole chain on one line.
pub fn message<T: std::fmt::Debug>(result: anyhow::Result<T>) -> String {
    format!("{:#}", result.unwrap_err())
}

/// Runs `digiteyes ARGS` in `dir`, asserts that it fails, and returns its stderr.
pub fn refused(dir: &Path, args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_digiteyes"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(
        !out.status.success(),
        "`{}` succeeded: {stderr}",
        args.join(" ")
    );
    stderr
}

/// A child process, killed and reaped when dropped: a failing test leaves nothing running.
pub struct Reap(pub std::process::Child);

impl Drop for Reap {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Runs `digiteyes listen --states STATES` on one end of a PTY pair, writes `messages` (as
/// a board would) to the other, and waits for listen to stop by itself after that many
/// states. Returns what it printed on stdout and its stderr lines after the first.
pub fn listen_to(messages: &[BoardMessage], states: usize) -> (String, Vec<String>) {
    let dir = tempfile::tempdir().unwrap();
    let (mut board, slave) = TTYPort::pair().unwrap();
    let path = slave.name().unwrap();
    let mut listen = Reap(
        Command::new(env!("CARGO_BIN_EXE_digiteyes"))
            .args(["listen", "--port", &path, "--states", &states.to_string()])
            .current_dir(dir.path())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap(),
    );
    // Every stderr line, as it comes: the first says the port is open.
    let (tx, rx) = mpsc::channel();
    let stderr = listen.0.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });
    let opened = rx.recv_timeout(Duration::from_secs(30)).unwrap();
    assert!(opened.contains("listening on"), "{opened}");

    let mut bytes = Vec::new();
    for message in messages {
        let mut buf = [0u8; MAX_MESSAGE];
        bytes.extend_from_slice(encode(message, &mut buf).unwrap());
    }
    board.write_all(&bytes).unwrap();

    let deadline = Instant::now() + Duration::from_secs(30);
    while listen.0.try_wait().unwrap().is_none() {
        assert!(
            Instant::now() < deadline,
            "listen did not stop after {states} states"
        );
        // Polling for the child's exit, which it reaches by itself after the states.
        std::thread::sleep(Duration::from_millis(10));
    }
    assert!(listen.0.wait().unwrap().success());
    let mut printed = String::new();
    listen
        .0
        .stdout
        .take()
        .unwrap()
        .read_to_string(&mut printed)
        .unwrap();
    reader.join().unwrap();
    (printed, rx.try_iter().collect())
}
