//! With one camera the local re-acquisition does not move the last good palm in depth
//! (`FinderConfig::local_depth_share`): a single view sees the hand's depth only through its
//! size, and bent fingers make a nearer hand look like a farther one. On the robustness
//! sweep's mono seed 1 the variant moved 15 % nearer was refined, accepted and held about
//! 90 mm nearer the camera than the hand to the end, without the lost flag.

use digiteyes_core::fill::FillConfig;
use digiteyes_host::bench::robustness::count_run;
use digiteyes_host::evaluate;
use digiteyes_host::track::{track_sequence_opts, TrackOptions};
use digiteyes_host::{render_scenario, RenderOptions, TrackerConfig};

/// Frames of `random-mono` seed 1 (as the sweep renders it) tracked with `config` under
/// `options` whose
/// palm is more than `FAR_PALM_MM` from the truth while not flagged lost (counted as the
/// benchmark counts them), and the frames
/// the local re-acquisition took the hand back on.
fn far_frames(
    seq: &std::path::Path,
    config: TrackerConfig,
    options: &TrackOptions,
) -> (usize, Vec<usize>) {
    let out = seq.join("states.csv");
    let summary = track_sequence_opts(seq, &out, config, false, None, options).unwrap();
    let report = evaluate(seq, &out).unwrap();
    let far = count_run(seq, &out, &report).unwrap().far_unflagged;
    (far, summary.status.reacquired)
}

#[test]
fn one_cameras_local_re_acquisition_keeps_the_palms_depth() {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("mono1");
    let options = RenderOptions {
        seed: 1,
        frames: Some(200),
        size: Some((640, 480)),
        supersample: 2,
        ..RenderOptions::default()
    };
    render_scenario("random-mono", &seq, &options).unwrap();
    let defaults = TrackOptions::default();
    assert_eq!(defaults.finder.local_depth_share[1], 0.0);
    // With the knuckle tips (on by default since) this seed's track is not lost, so no
    // re-acquisition runs to be judged: off here, where it is.
    let mut config = TrackerConfig::default();
    config.features.knuckle_tips = false;
    // And with the region rows (on by default since) the variant moved in depth is taken
    // back to the hand (0 far frames): off too.
    config.fill = FillConfig::OFF;
    // And the local starts turned 0.3 rad, as when this was shown: at 0.7 rad (the default
    // since) the variant moved in depth is not the one taken back.
    let mut kept = TrackOptions::default();
    kept.finder.local_turn_rad = 0.3;
    // And without one camera's bar on the reverse chamfer term (3.5 px by default since),
    // under which neither variant's re-acquisition is accepted on this seed: off too.
    kept.finder.accept.one_camera_max_reverse_px = f32::INFINITY;
    let (far, reacquired) = far_frames(&seq, config, &kept);
    let mut moved = kept;
    moved.finder.local_depth_share[1] = 0.15;
    let (far_moved, reacquired_moved) = far_frames(&seq, config, &moved);
    println!(
        "depth kept: {far} far frames, re-acquired at {reacquired:?}; moved ±15 %: \
         {far_moved} far frames, re-acquired at {reacquired_moved:?}"
    );
    assert!(
        !reacquired_moved.is_empty() && far_moved >= 20,
        "moved in depth, the hand is taken back far from the truth and held there"
    );
    assert_eq!(far, 0, "no frame far from the hand without the lost flag");
    let (far_default, _) = far_frames(&seq, TrackerConfig::default(), &defaults);
    assert_eq!(
        far_default, 0,
        "the defaults: no frame far without the lost flag"
    );
}
