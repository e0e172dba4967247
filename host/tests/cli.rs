//! The `digiteyes` command: help text, a render → track → eval round, and clear failures.

mod common;

use std::path::Path;
use std::process::{Command, Output};

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
        .ends_with("q27,rms_px,iterations,features_found,features_expected,lost"));
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
        report.contains("tracked 4 frames") && report.contains("track life"),
        "{report}"
    );
    assert!(keep.join("states.csv").is_file() && keep.join("cam0/000003.pgm").is_file());
}
