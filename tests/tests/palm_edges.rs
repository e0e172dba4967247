//! The palm's own outline edges (issue 9) on the sequence that showed the defect: the
//! robustness sweep's mono seed 39, whose curled fingers lie over the palm. Tracked from the
//! true state, the palm turns away within a frame (every Gauss–Newton iteration turns it
//! further) while the joints stay right. The palm's outline edges hold it back, but do NOT keep
//! it within a few degrees (measured, 5 frames from the truth: at most 22.5° with them, 36.5°
//! without; frame 0 alone 14.1° vs 15.4°; weighting the palm rows ×3, ×10, ×30 left frame 0 at
//! 16.0°, 16.8°, 12.4°): the two outline edges the fingers leave visible meet at one corner,
//! and out-of-plane tilt of a flat box seen nearly face-on barely moves its outline.
//!
//! The seed is rendered under the fixed light it was found under: with the lighting the sweep
//! now draws for it, the defect is milder (28° without the palm edges, 21° with them).

use digiteyes_core::fill::FillConfig;
use digiteyes_core::tracker::TrackerConfig;
use digiteyes_host::render::Lighting;
use digiteyes_host::scenarios::{render_scenario, RenderOptions};
use digiteyes_host::sequence::Sequence;

mod common;
use common::frames;

/// Angle between the palm rotations of two states (deg), by their quaternions `q0..q3`.
fn palm_rotation_deg(a: &[f32], b: &[f32]) -> f32 {
    let norm = |q: &[f32]| q[..4].iter().map(|v| v * v).sum::<f32>().sqrt();
    let dot: f32 = a[..4].iter().zip(&b[..4]).map(|(x, y)| x * y).sum();
    let cos = (dot.abs() / (norm(a) * norm(b))).min(1.0);
    2.0 * cos.acos().to_degrees()
}

/// Tracks the first `n` frames of `seq` from the true first state with `config`, never
/// recovering; returns the largest palm rotation error (deg) over them.
fn worst_palm_deg(seq: &Sequence, n: usize, config: TrackerConfig) -> f32 {
    let truth = frames::truth_states(seq);
    let mut tracker = frames::tracker_at(seq, &truth[0], config);
    let mut worst = 0.0f32;
    for (k, state) in truth.iter().enumerate().take(n) {
        let images = frames::images(seq, k);
        tracker.track(&frames::views(&images)).unwrap();
        worst = worst.max(palm_rotation_deg(tracker.state(), state));
    }
    worst
}

#[test]
fn the_palm_outline_keeps_seed_39s_palm_where_the_fingers_lie_across_it() {
    let dir = tempfile::tempdir().unwrap();
    let seq_dir = dir.path().join("seed39");
    const FRAMES: usize = 5;
    let options = RenderOptions {
        seed: 39,
        frames: Some(FRAMES),
        supersample: 2,
        lighting: Some(Lighting::default()),
        ..RenderOptions::default()
    };
    render_scenario("random-mono", &seq_dir, &options).unwrap();
    let seq = Sequence::open(&seq_dir).unwrap();
    let mut with = TrackerConfig::default();
    assert!(with.features.palm_edges, "on by default");
    // The edge-direction test (on by default since) also keeps this palm from turning as
    // far (26 deg without the palm edges); off here, to judge the palm edges alone.
    with.features.max_edge_angle_rad = core::f32::consts::FRAC_PI_2;
    // So do the knuckle tips (on by default since: 2.7 deg at most without the palm edges);
    // off here too.
    with.features.knuckle_tips = false;
    // And so do the region rows (on by default since: 26.8 deg at most without the palm
    // edges); off here too.
    with.fill = FillConfig::OFF;
    let mut without = with;
    without.features.palm_edges = false;
    let (on, off) = (
        worst_palm_deg(&seq, FRAMES, with),
        worst_palm_deg(&seq, FRAMES, without),
    );
    eprintln!("seed 39, {FRAMES} frames from the truth: palm rotation error at most {on:.2} deg with palm edges, {off:.2} deg without");
    assert!(
        off > 30.0,
        "without them the palm turns away (the defect): {off} deg"
    );
    assert!(
        on + 10.0 < off,
        "with them it turns at least 10 deg less: {on} deg vs {off} deg"
    );
}
