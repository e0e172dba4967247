//! The image's check on the track (`core/src/watch.rs`, issue 9): a track the likelihood no
//! longer supports is flagged lost even while its features and residual look healthy, and a
//! right track is never flagged — also on the independent renderer's fixture, whose right
//! track scores lower than ours (an absolute bar flagged its frames 3–6).

use std::path::Path;

use digiteyes_core::fill::FillConfig;
use digiteyes_core::watch::WatchConfig;
use digiteyes_host::render::Lighting;
use digiteyes_host::sequence::read_states;
use digiteyes_host::track::{track_sequence_opts, TrackOptions};
use digiteyes_host::{evaluate, render_scenario, RenderOptions, TrackerConfig};

fn never() -> WatchConfig {
    WatchConfig {
        every_frames: 0,
        ..WatchConfig::default()
    }
}

/// Tracks `seq` with `watch`; returns each frame's `lost` and mean fingertip error (px).
fn track(seq: &Path, out: &Path, watch: WatchConfig) -> (Vec<bool>, Vec<f64>) {
    track_with(seq, out, watch, TrackerConfig::default())
}

/// [`track`] with the tracker's parameters.
fn track_with(
    seq: &Path,
    out: &Path,
    watch: WatchConfig,
    config: TrackerConfig,
) -> (Vec<bool>, Vec<f64>) {
    let options = TrackOptions {
        watch,
        ..TrackOptions::default()
    };
    track_sequence_opts(seq, out, config, false, None, &options).unwrap();
    let report = evaluate(seq, out).unwrap();
    let states = read_states(out, 28).unwrap();
    let lost = states
        .extra("lost")
        .unwrap()
        .iter()
        .map(|&v| v != 0.0)
        .collect();
    (lost, report.fingertip_mean_by_frame)
}

#[test]
fn a_right_track_of_another_renderer_is_never_flagged() {
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fixtures/sample-mouse");
    let dir = tempfile::tempdir().unwrap();
    let (lost, tips) = track(&fixture, &dir.path().join("a.csv"), WatchConfig::default());
    let (plain, _) = track(&fixture, &dir.path().join("b.csv"), never());
    assert!(
        tips.iter().all(|&t| t < 3.0),
        "the fixture is tracked: {tips:?}"
    );
    assert_eq!(lost, plain);
    assert!(lost.iter().all(|&l| !l), "right frames flagged: {lost:?}");
}

#[test]
fn a_track_the_image_no_longer_supports_is_flagged() {
    // Seed 76 (a stereo rig of the robustness sweep, 640x480), tracked without the palm's
    // outline edges: from frame ~59 the track settles on wrong fingers while the tracker's
    // own flag stays down. The watch removes a third or more of those frames (measured:
    // 32 -> 17, whether a check falls due every 32 frames, as at 640x480 before stop 61, or
    // every 8, as at every size since), not all. (With the palm edges,
    // the default, this seed is tracked right to frame 90 and no sweep seed offers a wrong
    // track the watch catches: docs/robustness.md.) Rendered under the fixed light this case
    // was found under, not the lighting the sweep now draws for the seed.
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("seq");
    let options = RenderOptions {
        seed: 76,
        frames: Some(90),
        supersample: 2,
        lighting: Some(Lighting::default()),
        ..RenderOptions::default()
    };
    render_scenario("random-stereo", &seq, &options).unwrap();
    let wrong = 20.0; // px at 640 wide: the sweep's "truly lost"
    let mut config = TrackerConfig::default();
    config.features.palm_edges = false;
    // With the edge-direction test this seed is tracked right: off, to have a wrong track.
    config.features.max_edge_angle_rad = core::f32::consts::FRAC_PI_2;
    // And so with the outermost edge (0 wrong frames claimed with it): off too.
    config.features.outermost_share = 0.0;
    // And so with the knuckle tips (on by default since; 0 wrong frames claimed with them):
    // off too.
    config.features.knuckle_tips = false;
    // And so with the region rows (on by default since; 0 wrong frames claimed with them):
    // off too.
    config.fill = FillConfig::OFF;
    let a = dir.path().join("a.csv");
    let (watched, tips) = track_with(&seq, &a, WatchConfig::default(), config);
    let b = dir.path().join("b.csv");
    let (plain, plain_tips) = track_with(&seq, &b, never(), config);
    let claimed_wrong = |lost: &[bool], tips: &[f64]| {
        lost.iter()
            .zip(tips)
            .filter(|(l, t)| !**l && **t > wrong)
            .count()
    };
    let right_flagged = |lost: &[bool], tips: &[f64]| {
        lost.iter()
            .zip(tips)
            .filter(|(l, t)| **l && **t <= wrong)
            .count()
    };
    let (with, without) = (
        claimed_wrong(&watched, &tips),
        claimed_wrong(&plain, &plain_tips),
    );
    assert!(
        without >= 10,
        "the plain track is claimed while wrong: {without} frames"
    );
    assert!(
        with * 3 <= without * 2,
        "frames claimed while wrong: {with} with the watch, {without} without"
    );
    assert_eq!(
        right_flagged(&watched, &tips),
        right_flagged(&plain, &plain_tips),
        "the watch flagged right frames"
    );
}
