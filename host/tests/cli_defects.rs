//! Defects a tester found in the `digiteyes` command, each pinned: option values that
//! panicked or hung, outputs a failure destroyed, and messages that named the wrong thing or
//! echoed too much.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn digiteyes(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_digiteyes"))
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .output()
        .unwrap()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// The command refused the arguments with a message naming `option`, without panicking.
#[track_caller]
fn refused_naming(args: &[&str], option: &str) {
    let dir = tempfile::tempdir().unwrap();
    let out = digiteyes(args, dir.path());
    let err = stderr(&out);
    assert!(!out.status.success(), "{args:?} was accepted");
    assert_ne!(out.status.code(), Some(101), "{args:?} panicked:\n{err}");
    assert!(!err.contains("panicked"), "{args:?} panicked:\n{err}");
    assert!(
        err.contains(option),
        "{args:?}: message does not name {option}:\n{err}"
    );
}

#[test]
fn durations_and_rates_that_panicked_are_refused_naming_their_option() {
    refused_naming(&["ui", "--replay", "x", "--fps", "1e-30"], "--fps");
    refused_naming(&["ui", "--replay", "x", "--seconds", "1e30"], "--seconds");
    refused_naming(&["ui", "--replay", "x", "--seconds=-1"], "--seconds");
    refused_naming(
        &[
            "stream",
            "--port",
            "/nonexistent",
            "--seq",
            "x",
            "--reply-timeout",
            "1e30",
        ],
        "--reply-timeout",
    );
    refused_naming(
        &["listen", "--port", "/nonexistent", "--seconds", "1e30"],
        "--seconds",
    );
    refused_naming(
        &["listen", "--port", "/nonexistent", "--seconds=-1"],
        "--seconds",
    );
    refused_naming(&["sim", "--report-every", "1e30"], "--report-every");
    refused_naming(&["demo", "--ui-seconds", "1e30"], "--ui-seconds");
    refused_naming(&["demo", "--frames", "0"], "--frames");
}

#[test]
fn render_levels_are_bounded() {
    for (option, value) in [
        ("--blur", "1e6"),
        ("--blur", "inf"),
        ("--blur=-1", ""),
        ("--noise", "NaN"),
        ("--noise", "1000"),
    ] {
        let mut args = vec!["render", "mouse", "out", "--frames", "2"];
        args.push(option);
        if !value.is_empty() {
            args.push(value);
        }
        refused_naming(&args, option.split('=').next().unwrap());
    }
}

/// A small rendered mouse sequence in `dir/mouse`.
fn sequence(dir: &Path, frames: usize) -> PathBuf {
    common::small_sequence(dir, "mouse", frames)
}

#[test]
fn a_failed_track_leaves_an_existing_output_whole() {
    let dir = tempfile::tempdir().unwrap();
    let seq = sequence(dir.path(), 6);
    let out = dir.path().join("states.csv");
    let ok = digiteyes(
        &["track", seq.to_str().unwrap(), "-o", "states.csv", "-q"],
        dir.path(),
    );
    assert!(ok.status.success(), "{}", stderr(&ok));
    let good = std::fs::read_to_string(&out).unwrap();
    assert_eq!(good.lines().count(), 7);
    // Truncate frame 3: the next run fails there.
    let frame = seq.join("cam0/000003.pgm");
    let bytes = std::fs::read(&frame).unwrap();
    std::fs::write(&frame, &bytes[..bytes.len() / 2]).unwrap();
    let failed = digiteyes(
        &["track", seq.to_str().unwrap(), "-o", "states.csv", "-q"],
        dir.path(),
    );
    assert!(!failed.status.success());
    assert!(
        stderr(&failed).contains("000003.pgm"),
        "{}",
        stderr(&failed)
    );
    assert_eq!(
        std::fs::read_to_string(&out).unwrap(),
        good,
        "the good file was replaced"
    );
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().contains("partial"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}

/// A states file for `seq` (from `track`), returned as text.
fn tracked(dir: &Path, seq: &Path) -> String {
    let out = digiteyes(&["track", seq.to_str().unwrap(), "-o", "t.csv", "-q"], dir);
    assert!(out.status.success(), "{}", stderr(&out));
    std::fs::read_to_string(dir.join("t.csv")).unwrap()
}

#[test]
fn a_huge_csv_cell_is_quoted_short() {
    let dir = tempfile::tempdir().unwrap();
    let seq = sequence(dir.path(), 3);
    let text = tracked(dir.path(), &seq);
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let mut fields: Vec<String> = lines[2].split(',').map(String::from).collect();
    fields[5] = "9".repeat(10_000_000) + "x";
    lines[2] = fields.join(",");
    std::fs::write(dir.path().join("big.csv"), lines.join("\n")).unwrap();
    let out = digiteyes(&["eval", seq.to_str().unwrap(), "big.csv"], dir.path());
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.len() < 1_000, "{} bytes of error", err.len());
    assert!(err.contains("big.csv") && err.contains("q4"), "{err}");
}

#[test]
fn a_value_past_f32_in_truth_is_blamed_on_truth_csv() {
    let dir = tempfile::tempdir().unwrap();
    let seq = sequence(dir.path(), 3);
    tracked(dir.path(), &seq);
    let truth = std::fs::read_to_string(seq.join("truth.csv")).unwrap();
    let mut lines: Vec<String> = truth.lines().map(String::from).collect();
    let mut fields: Vec<String> = lines[2].split(',').map(String::from).collect();
    fields[5] = "1e39".into();
    lines[2] = fields.join(",");
    std::fs::write(seq.join("truth.csv"), lines.join("\n") + "\n").unwrap();
    let out = digiteyes(&["eval", seq.to_str().unwrap(), "t.csv"], dir.path());
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.contains("truth.csv") && err.contains("line 3"), "{err}");
    assert!(!err.contains("t.csv:"), "blamed the states file: {err}");
}

#[test]
fn a_frame_that_is_a_folder_or_a_pipe_is_named_as_such() {
    let dir = tempfile::tempdir().unwrap();
    let seq = sequence(dir.path(), 3);
    let frame = seq.join("cam0/000001.pgm");
    std::fs::remove_file(&frame).unwrap();
    std::fs::create_dir(&frame).unwrap();
    let out = digiteyes(&["track", seq.to_str().unwrap(), "-q"], dir.path());
    assert!(
        stderr(&out).contains("000001.pgm: is a folder"),
        "{}",
        stderr(&out)
    );
    std::fs::remove_dir(&frame).unwrap();
    let made = Command::new("mkfifo").arg(&frame).status().unwrap();
    assert!(made.success());
    let out = digiteyes(&["track", seq.to_str().unwrap(), "-q"], dir.path());
    assert!(
        stderr(&out).contains("000001.pgm: is not a regular file"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn nan_in_sequence_json_names_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let seq = sequence(dir.path(), 2);
    let json = std::fs::read_to_string(seq.join("sequence.json")).unwrap();
    let bad = json.replacen("\"fx\": ", "\"fx\": NaN, \"was\": ", 1);
    std::fs::write(seq.join("sequence.json"), bad).unwrap();
    let out = digiteyes(&["track", seq.to_str().unwrap(), "-q"], dir.path());
    let err = stderr(&out);
    assert!(
        err.contains("cameras[0].fx") && err.contains("NaN"),
        "{err}"
    );
}

#[test]
fn a_missing_initial_state_says_what_to_do() {
    let dir = tempfile::tempdir().unwrap();
    let seq = sequence(dir.path(), 2);
    let json = std::fs::read_to_string(seq.join("sequence.json")).unwrap();
    let mut value: serde_json::Value = serde_json::from_str(&json).unwrap();
    value.as_object_mut().unwrap().remove("initial_state");
    std::fs::write(seq.join("sequence.json"), value.to_string()).unwrap();
    let out = digiteyes(&["track", seq.to_str().unwrap(), "-q"], dir.path());
    let err = stderr(&out);
    assert!(!out.status.success());
    // Without an initial state every state must be free; this sequence fixes some.
    assert!(
        err.contains("`initial_state` is absent") && err.contains("`free` lists"),
        "{err}"
    );
}

#[test]
fn a_pgm_error_is_said_once() {
    let dir = tempfile::tempdir().unwrap();
    let seq = sequence(dir.path(), 2);
    std::fs::write(seq.join("cam0/000001.pgm"), b"xx").unwrap();
    let out = digiteyes(&["track", seq.to_str().unwrap(), "-q"], dir.path());
    let err = stderr(&out);
    assert!(err.contains("000001.pgm"), "{err}");
    assert_eq!(err.matches("Expected magic constant").count(), 1, "{err}");
}

#[test]
fn replay_refuses_a_short_states_file_as_eval_and_report_do() {
    let dir = tempfile::tempdir().unwrap();
    let seq = sequence(dir.path(), 4);
    let text = tracked(dir.path(), &seq);
    let short: Vec<&str> = text.lines().take(3).collect();
    std::fs::write(dir.path().join("short.csv"), short.join("\n") + "\n").unwrap();
    let s = seq.to_str().unwrap();
    let eval = digiteyes(&["eval", s, "short.csv"], dir.path());
    let report = digiteyes(&["report", s, "short.csv", "-o", "r.html"], dir.path());
    let replay = digiteyes(
        &[
            "ui",
            "--replay",
            s,
            "--states",
            "short.csv",
            "--bind",
            "127.0.0.1:0",
            "--seconds",
            "1",
        ],
        dir.path(),
    );
    for (name, out) in [
        ("eval", &eval),
        ("report", &report),
        ("ui --replay", &replay),
    ] {
        assert!(!out.status.success(), "{name} accepted a short states file");
        let err = stderr(out);
        assert!(
            err.contains("2 frames of states") && err.contains("has 4"),
            "{name}: {err}"
        );
    }
}

#[test]
fn a_camera_that_cannot_see_the_hand_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let seq = sequence(dir.path(), 2);
    let json = std::fs::read_to_string(seq.join("sequence.json")).unwrap();
    let original: serde_json::Value = serde_json::from_str(&json).unwrap();
    let mut absurd = original.clone();
    absurd["cameras"][0]["fx"] = serde_json::json!(1e30);
    let mut behind = original.clone();
    // The camera looks down at the table from above: put the hand far above the camera.
    behind["initial_state"][6] = serde_json::json!(1e4);
    for (what, value) in [("fx = 1e30", absurd), ("hand behind", behind)] {
        std::fs::write(seq.join("sequence.json"), value.to_string()).unwrap();
        let out = digiteyes(&["track", seq.to_str().unwrap(), "-q"], dir.path());
        let err = stderr(&out);
        assert!(!out.status.success(), "{what}: accepted");
        assert!(
            err.contains("camera 0") && err.contains("cannot see the hand"),
            "{what}: {err}"
        );
    }
}

/// `digiteyes ... | head`: a reader that goes away ends the command quietly, not in a panic.
#[test]
fn a_closed_stdout_pipe_is_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_digiteyes"))
        .args(["render", "mouse", "out", "--frames", "1", "--size", "32x24"])
        .args(["--supersample", "1"])
        .current_dir(dir.path())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take()); // the reader is gone before the first line
    let out = child.wait_with_output().unwrap();
    let err = stderr(&out);
    assert!(!err.contains("panicked"), "{err}");
    assert_ne!(out.status.code(), Some(101), "{err}");
}

#[test]
fn one_board_per_camera_needs_as_many_ports_as_cameras_and_a_sequence() {
    let dir = tempfile::tempdir().unwrap();
    let seq = sequence(dir.path(), 2);
    let seq = seq.to_str().unwrap();
    // A one-camera sequence and two ports: refused before any port is opened.
    let ports = &common::TWO_ABSENT_BOARDS[..];
    let out = digiteyes(&[&["stream"], ports, &["--seq", seq]].concat(), dir.path());
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(
        err.contains("1 camera(s) and 2 --port(s)") && err.contains("one board per camera"),
        "{err}"
    );
    // Two ports without a sequence.
    let out = digiteyes(
        &[
            &["stream"],
            ports,
            &["--camera", "/dev/null", "--setup", seq],
        ]
        .concat(),
        dir.path(),
    );
    assert!(!out.status.success());
    assert!(stderr(&out).contains("needs --seq DIR"), "{}", stderr(&out));
}
