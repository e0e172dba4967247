//! The slice search's outermost edge (issue 9, `FeatureConfig::outermost_share`) on a
//! sequence that shows it: the robustness sweep's stereo seed 4128 (fresh when the change was
//! judged), which the strongest-edge search lost within the first quarter of its 200 frames
//! (track life 12 %) and the outermost edge tracked to the end (100 %) when the sweep judged
//! it (`docs/robustness.md`, "The outermost edge"). Tracked here by the plain tracker from the
//! true first state, so the feature search alone makes the difference.

use digiteyes_core::fill::FillConfig;
use digiteyes_core::tracker::TrackerConfig;
use digiteyes_host::scenarios::{render_scenario, RenderOptions};
use digiteyes_host::sequence::Sequence;

mod common;
use common::{frames, search};

/// Mean fingertip error (px, every camera) of each of the first `n` frames of `seq`, tracked
/// from the true first state with `config`.
fn tip_errors_px(seq: &Sequence, n: usize, config: TrackerConfig) -> Vec<f32> {
    let truth = frames::truth_states(seq);
    let mut tracker = frames::tracker_at(seq, &truth[0], config);
    (0..n)
        .map(|k| {
            let images = frames::images(seq, k);
            tracker.track(&frames::views(&images)).unwrap();
            search::tip_error_px(&seq.model, &seq.cameras, tracker.state(), &truth[k])
        })
        .collect()
}

#[test]
fn the_outermost_edge_holds_a_hand_the_strongest_edge_loses() {
    const SEED: u64 = 4128;
    const FRAMES: usize = 60;
    let dir = tempfile::tempdir().unwrap();
    let seq_dir = dir.path().join("seq");
    let options = RenderOptions {
        seed: SEED,
        frames: Some(FRAMES),
        supersample: 2,
        ..RenderOptions::default()
    };
    render_scenario("random-stereo", &seq_dir, &options).unwrap();
    let seq = Sequence::open(&seq_dir).unwrap();
    let mut with = TrackerConfig::default();
    assert!(with.features.outermost_share > 0.0, "on by default");
    // The region rows (on by default since) are off, to judge the outermost edge alone.
    // With them the outermost edge's track reaches 11 px over frames 21-25 on this seed (its
    // life ends there) and is back under 10 px from frame 26; the strongest edge's is at
    // 10-12 px over frames 10-30.
    with.fill = FillConfig::OFF;
    let mut without = with;
    without.features.outermost_share = 0.0;
    let (on, off) = (
        tip_errors_px(&seq, FRAMES, with),
        tip_errors_px(&seq, FRAMES, without),
    );
    let show = |e: &[f32]| {
        e.iter()
            .map(|v| format!("{v:.0}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    eprintln!("seed {SEED} tip px, outermost: {}", show(&on));
    eprintln!("seed {SEED} tip px, strongest: {}", show(&off));
    // The track life's end: over 10 px (at 640 wide) for 5 frames. Measured: the outermost
    // edge stays within 6 px over the 60 frames; the strongest edge drifts past 10 px from
    // frame 14 and ends at 9-15 px.
    let life_ends = |e: &[f32]| e.windows(5).any(|w| w.iter().all(|&v| v > 10.0));
    assert!(life_ends(&off), "the strongest edge loses the hand");
    assert!(!life_ends(&on), "the outermost edge holds it");
    let worst = on.iter().fold(0.0f32, |a, &b| a.max(b));
    assert!(worst < 8.0, "the outermost edge stays within 8 px: {worst}");
}
