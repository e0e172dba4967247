//! With one camera, a hand lost for longer than the local re-acquisition looks is taken back
//! by the global search, whose leaf's depth is read from the hand's size: a guess one camera
//! cannot check (a hand 8–11 % nearer or farther, its fingers bent to match, scores as well).
//! The confirm phase therefore also carries the accepted state moved to the depth the hand was
//! last claimed at, and ranks every hypothesis a little lower the farther its palm lies from
//! that depth (`FinderConfig::confirm_held_weight`, up to `confirm_held_band`). On these mono
//! seeds, after a blackout of 90 frames, without it the re-acquisition is claimed with the palm
//! over 100 mm from the truth along the camera's ray, frame after frame; with it, never.

use std::path::Path;

use digiteyes_core::acquire::{AcquireConfig, FinderConfig};
use digiteyes_core::auto_tracker::{AutoTracker, Status};
use digiteyes_core::estimator::FreeMask;
use digiteyes_core::tracker::TrackerConfig;
use digiteyes_host::sequence::Sequence;
use digiteyes_host::{render_scenario, RenderOptions};

mod common;
use common::frames::{images, truth_states, views};
use common::search::{buffers, palm_error_mm, tip_error_px, HELD_FRAMES, ON_HAND_PX};

/// Frames without the hand: longer than the lost frames and the local re-acquisition's 60
/// frames together, so the global search takes the hand back.
const DARK: std::ops::Range<usize> = 40..130;
/// Frames rendered.
const FRAMES: usize = 200;
/// Issue 9's bar: no frame claimed with the palm this far (mm) from the truth.
const FAR_MM: f32 = 100.0;

/// What one run claimed after the hand's return.
struct Return {
    /// Claimed frames with the palm over [`FAR_MM`] from the truth.
    far: usize,
    /// The first frame after the return from which [`HELD_FRAMES`] claimed frames in a row
    /// lie within [`ON_HAND_PX`], if one does within 30 frames.
    back_after: Option<usize>,
}

/// `random-mono` `seed` (320×240, [`FRAMES`] frames, [`DARK`] without the hand) tracked from
/// its initial state under `finder`.
fn run(dir: &Path, seed: u64, finder: FinderConfig) -> Return {
    let seq = dir.join(format!("random-mono-{seed}"));
    let options = RenderOptions {
        seed,
        frames: Some(FRAMES),
        size: Some((320, 240)),
        blackout: Some(DARK),
        ..RenderOptions::default()
    };
    render_scenario("random-mono", &seq, &options).unwrap();
    let sequence = Sequence::open(&seq).unwrap();
    let truth = truth_states(&sequence);
    let initial: Vec<f32> = sequence.initial_state.iter().map(|&v| v as f32).collect();
    let acquire = AcquireConfig::default();
    let mut auto = AutoTracker::tracking(
        sequence.model.clone(),
        &sequence.cameras,
        &initial,
        FreeMask::all(sequence.n_states()),
        TrackerConfig::default(),
        acquire,
    )
    .unwrap();
    auto.set_finder(finder);
    let mut bufs = buffers(&sequence.cameras, acquire.likelihood.stride_px);
    let (mut far, mut good) = (0, Vec::new());
    for (k, truth_k) in truth.iter().enumerate() {
        let frame = images(&sequence, k);
        let mut b: Vec<&mut [u8]> = bufs.iter_mut().map(|b| b.as_mut_slice()).collect();
        let r = auto.step(&views(&frame), &mut b).unwrap();
        let claimed = r.status == Status::Tracking && !r.report.lost;
        let state = auto.state();
        if claimed && k >= DARK.end && palm_error_mm(state, truth_k) > FAR_MM {
            far += 1;
        }
        let tips = tip_error_px(&sequence.model, &sequence.cameras, state, truth_k);
        good.push(claimed && tips <= ON_HAND_PX);
    }
    let back_after = (DARK.end..DARK.end + 30)
        .filter(|&k| k + HELD_FRAMES <= good.len())
        .find(|&k| good[k..k + HELD_FRAMES].iter().all(|&g| g))
        .map(|k| k - DARK.end);
    Return { far, back_after }
}

#[test]
fn one_cameras_search_takes_the_hand_back_at_the_depth_it_was_last_claimed_at() {
    let with = FinderConfig::default();
    assert!(
        with.confirm_held_weight > 0.0 && with.confirm_depth_share[1] > 0.0,
        "one camera's confirm phase is drawn to the last claimed depth by default"
    );
    let without = FinderConfig {
        confirm_held_weight: 0.0,
        ..with
    };
    let dir = tempfile::tempdir().unwrap();
    // Seeds of the blackout sweep the weight was chosen on (32501–32580; `docs/recovery.md`,
    // "The depth the hand was last claimed at"), with far frames without it: the two with
    // the most.
    for seed in [32530, 32535] {
        let on = run(dir.path(), seed, with);
        let off = run(dir.path(), seed, without);
        eprintln!(
            "seed {seed}: far frames {} with, {} without; back after {:?} / {:?} frames",
            on.far, off.far, on.back_after, off.back_after
        );
        assert!(
            off.far >= 20,
            "seed {seed}: without the last claimed depth, claimed far off the hand"
        );
        assert_eq!(
            on.far, 0,
            "seed {seed}: with it, no frame claimed over {FAR_MM} mm off"
        );
        assert!(
            on.back_after.is_some(),
            "seed {seed}: with it, the hand is taken back within 30 frames"
        );
    }
}
