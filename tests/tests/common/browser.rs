//! Headless Chromium for the UI tests: finding it, and loading a page for a budget of its
//! (virtual) time.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The browser (`DIGITEYES_CHROMIUM`, else `chromium`, `chromium-browser` or
/// `google-chrome`), or why a test must be skipped.
pub fn chromium() -> Result<PathBuf, String> {
    let candidates: Vec<PathBuf> = match std::env::var_os("DIGITEYES_CHROMIUM") {
        Some(path) => vec![PathBuf::from(path)],
        None => ["chromium", "chromium-browser", "google-chrome"]
            .iter()
            .map(PathBuf::from)
            .collect(),
    };
    for exe in candidates {
        let works = Command::new(&exe)
            .arg("--version")
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        if works {
            return Ok(exe);
        }
    }
    Err("no chromium found (apt-get install -y chromium, or set DIGITEYES_CHROMIUM)".into())
}

/// Loads `url` in headless Chromium with a fresh profile, lets the page run for
/// `budget_ms` of its time, and returns what Chromium printed (the DOM with `--dump-dom`).
pub fn chromium_run(exe: &Path, url: &str, budget_ms: u32, extra: &[String]) -> String {
    let profile = tempfile::tempdir().unwrap();
    let output = Command::new(exe)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
            "--window-size=1340,1100",
        ])
        .arg(format!("--virtual-time-budget={budget_ms}"))
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .args(extra)
        .arg(url)
        .stdin(Stdio::null())
        .output()
        .expect("chromium runs");
    assert!(
        output.status.success(),
        "chromium failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// The DOM `url` ends with after `budget_ms` of the page's time.
pub fn dump_dom(exe: &Path, url: &str, budget_ms: u32) -> String {
    chromium_run(exe, url, budget_ms, &["--dump-dom".to_string()])
}

/// A board's `State` for `q` at `frame` as one JSON line, as `listen --forward udp://` sends
/// it (tracked, with plausible figures).
pub fn state_line(frame: u32, q: &[f32]) -> String {
    use digiteyes_core::protocol::{BoardMessage, State};
    let message = BoardMessage::State(State {
        frame,
        timestamp: u64::from(frame) * 1000,
        q: heapless::Vec::from_slice(q).unwrap(),
        rms_px: 0.75,
        lost: false,
        features_found: 40,
        features_expected: 42,
        iterations: 3,
        track_ticks: 5000,
        status: digiteyes_core::protocol::WireStatus::Tracking,
        search_evaluations: 0,
    });
    format!("{}\n", serde_json::to_string(&message).unwrap())
}
