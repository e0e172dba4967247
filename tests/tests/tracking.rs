//! End to end: render a scenario with the project's renderer, track it with the core, and
//! hold the result to the accuracy bars of the tracking-core issue. Sequences are kept short
//! (the suite must stay quick on a 2-core machine); longer runs belong in the benchmarks.

use std::path::{Path, PathBuf};

use digiteyes_host::{
    evaluate, render_scenario, track_sequence, EvalReport, RenderOptions, TrackerConfig,
};

/// Renders `scenario` (`frames` frames), tracks it with the default tracker, and evaluates.
fn run(scenario: &str, frames: usize) -> EvalReport {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join(scenario);
    let options = RenderOptions {
        seed: 1,
        frames: Some(frames),
        ..RenderOptions::default()
    };
    render_scenario(scenario, &seq, &options).unwrap();
    let states = dir.path().join("states.csv");
    let summary = track_sequence(&seq, &states, TrackerConfig::default(), false).unwrap();
    assert_eq!(summary.frames, frames);
    let report = evaluate(&seq, &states).unwrap();
    println!("{scenario}: {report:#?}");
    report
}

/// Fails with the figure and its unit when `value` is not below `bar`.
fn below(value: f64, bar: f64, what: &str) {
    assert!(value < bar, "{what}: {value} is not below {bar}");
}

fn fingertip_mean(report: &EvalReport) -> f64 {
    report
        .cameras
        .iter()
        .map(|c| c.fingertip_mean_px)
        .fold(0.0, f64::max)
}

#[test]
fn mouse_tracks_to_a_pixel_and_a_few_degrees() {
    let r = run("mouse", 30);
    below(fingertip_mean(&r), 1.5, "fingertip error (px)");
    below(r.joint_rms_deg, 3.0, "free-joint RMS (deg)");
    assert_eq!(r.track_life, 1.0);
}

#[test]
fn rigid_palm_pose() {
    let r = run("rigid", 30);
    below(r.palm_rotation_deg, 1.5, "palm rotation error (deg)");
    below(r.palm_translation_mm, 3.0, "palm translation error (mm)");
}

#[test]
fn fullhand_stereo() {
    let r = run("fullhand-stereo", 20);
    below(fingertip_mean(&r), 2.0, "fingertip error (px)");
    below(r.joint_rms_deg, 5.0, "free-joint RMS (deg)");
    assert_eq!(r.track_life, 1.0);
}

#[test]
fn fast_motion_keeps_track() {
    let r = run("fast", 30);
    assert_eq!(
        r.track_life,
        1.0,
        "fingertip error {} px",
        fingertip_mean(&r)
    );
}

#[test]
fn clutter_keeps_track() {
    let r = run("clutter", 30);
    assert_eq!(
        r.track_life,
        1.0,
        "fingertip error {} px",
        fingertip_mean(&r)
    );
}

/// The conformance sample from an independent renderer: if we read the contract (PGM, camera
/// convention, pixel centres, quaternion and state order, `free`) as its authors did, the
/// tracker follows it to about a pixel.
#[test]
fn the_independent_sample_mouse_fixture_tracks_to_a_pixel() {
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fixtures/sample-mouse");
    if !fixture.exists() {
        panic!(
            "fixture missing at {}: it ships with the repository (fixtures/sample-mouse)",
            fixture.display()
        );
    }
    let dir = tempfile::tempdir().unwrap();
    let states: PathBuf = dir.path().join("states.csv");
    let summary = track_sequence(&fixture, &states, TrackerConfig::default(), false).unwrap();
    assert_eq!(summary.frames, 12);
    let r = evaluate(&fixture, &states).unwrap();
    println!("sample-mouse: {r:#?}");
    below(fingertip_mean(&r), 1.0, "fingertip error (px)");
    below(r.joint_rms_deg, 3.0, "free-joint RMS (deg)");
    assert_eq!(r.track_life, 1.0);
}
