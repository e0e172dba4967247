//! Acquisition that lands in the basin (issue 10's targets): the search's leaves re-placed on
//! the frame they are refined on, several leaves carried as hypotheses after one is accepted
//! (`MultiTracker::seed`, the confirming frames) and an acquisition the confirming frames
//! refute given up; the local re-acquisition's variants of the last good state.

mod common;
use common::frames::{images, views};
use common::search;

use digiteyes_core::acquire::{AcquireConfig, FinderConfig, LOCAL_VARIANTS};
use digiteyes_core::auto_tracker::{AutoReport, AutoTracker, Status};
use digiteyes_core::config::MAX_STATES;
use digiteyes_core::estimator::FreeMask;
use digiteyes_core::fill::FillConfig;
use digiteyes_core::hypotheses::{HypothesesConfig, MultiTracker};
use digiteyes_core::tracker::{Tracker, TrackerConfig};
use digiteyes_host::sequence::Sequence;

fn whole(q: &[f32]) -> [f32; MAX_STATES] {
    let mut out = [0.0f32; MAX_STATES];
    out[..q.len()].copy_from_slice(q);
    out
}

fn palm_error_mm(a: &[f32], b: &[f32]) -> f32 {
    (0..3)
        .map(|i| (a[4 + i] - b[4 + i]).powi(2))
        .sum::<f32>()
        .sqrt()
}

#[test]
fn seeded_hypotheses_start_fresh_are_capped_at_the_count_and_the_right_one_is_kept() {
    let dir = tempfile::tempdir().unwrap();
    let seq = Sequence::open(&common::mouse(dir.path(), 8)).unwrap();
    let truth = seq.read_truth().unwrap();
    let initial: Vec<f32> = seq.initial_state.iter().map(|&v| v as f32).collect();
    let tracker = Tracker::new(
        seq.model.clone(),
        &seq.cameras,
        &initial,
        FreeMask::all(seq.n_states()),
        TrackerConfig::default(),
    )
    .unwrap();
    let config = HypothesesConfig {
        count: 3,
        ..HypothesesConfig::default()
    };
    let mut multi = MultiTracker::new(tracker, config);
    let mut bufs = search::buffers(&seq.cameras, config.likelihood.stride_px);
    let mut step = |multi: &mut MultiTracker, k: usize| {
        let images = images(&seq, k);
        let mut b: Vec<&mut [u8]> = bufs.iter_mut().map(|b| b.as_mut_slice()).collect();
        multi.track(&views(&images), &mut b).unwrap()
    };
    step(&mut multi, 0);
    let first = multi.tracker().memory();
    let n = first.state.len();
    // Three wrong readings of the same frame: the palm 30 mm off along each axis.
    let others: Vec<[f32; MAX_STATES]> = (0..3)
        .map(|axis| {
            let mut q = whole(&first.state);
            q[4 + axis] += 30.0;
            q
        })
        .collect();
    multi.seed(&others).unwrap();
    let h = multi.hypotheses();
    assert_eq!(h.len(), 3, "capped at the count: the first and two others");
    assert_eq!(
        h[0].memory, first,
        "the tracker's own memory comes first, kept"
    );
    assert_eq!(
        multi.tracker().memory(),
        first,
        "the tracker still holds the first"
    );
    for (h, q) in h[1..].iter().zip(&others) {
        // The state as given (its quaternion renormalised).
        let near = h
            .memory
            .state
            .iter()
            .zip(&q[..n])
            .all(|(a, b)| (a - b).abs() < 1e-5);
        assert!(near, "{:?} vs {:?}", &h.memory.state[..], &q[..n]);
        assert_eq!(h.memory.velocity, None, "fresh: no motion");
        assert_eq!(
            h.memory.silhouette_reference, None,
            "fresh: no silhouette reference"
        );
    }
    for k in 1..seq.frames {
        step(&mut multi, k);
    }
    let t: Vec<f32> = truth.rows[seq.frames - 1]
        .iter()
        .map(|&v| v as f32)
        .collect();
    let e = palm_error_mm(multi.state(), &t);
    // The wrong readings are 30 mm off; the tracker's own error here is a few mm.
    assert!(e < 10.0, "the right reading is kept: palm {e:.1} mm off");
}

#[test]
fn a_leaf_from_an_earlier_frame_is_placed_where_the_hand_is_now() {
    let dir = tempfile::tempdir().unwrap();
    for (rig, seed) in [("random-stereo", 101), ("random-mono", 102)] {
        let sequence = common::seeded(dir.path(), rig, seed, 1);
        let truth: Vec<f32> = sequence.read_truth().unwrap().rows[0]
            .iter()
            .map(|&v| v as f32)
            .collect();
        let acquire = AcquireConfig::default();
        let images = images(&sequence, 0);
        let views = views(&images);
        let mut bufs = search::buffers(&sequence.cameras, acquire.likelihood.stride_px);
        let maps = search::edge_maps(&mut bufs, &views, &acquire.likelihood);
        let mut acquirer = search::acquirer(&sequence, acquire);
        // Where the hand was some frames ago: 50 mm across the first camera's view.
        let c0 = &sequence.cameras[0];
        let across = c0.r.transpose() * digiteyes_core::nalgebra::Vector3::new(50.0, 0.0, 0.0);
        let mut q = whole(&truth);
        for i in 0..3 {
            q[4 + i] += across[i];
        }
        let before = palm_error_mm(&q, &truth);
        assert!(acquirer.replace(&sequence.model, &sequence.cameras, &maps, &mut q));
        let after = palm_error_mm(&q, &truth);
        println!("{rig} {seed}: palm {before:.1} mm off, re-placed {after:.1} mm off");
        assert!(after < 0.4 * before, "{rig}: {before:.1} → {after:.1} mm");
    }
}

#[test]
fn the_local_variants_turn_and_move_the_last_good_state() {
    let dir = tempfile::tempdir().unwrap();
    let sequence = common::seeded(dir.path(), "random-mono", 103, 1);
    let q: Vec<f32> = sequence.read_truth().unwrap().rows[0]
        .iter()
        .map(|&v| v as f32)
        .collect();
    let q = whole(&q);
    let acquirer = search::acquirer(&sequence, AcquireConfig::default());
    let eye = sequence.cameras[0].centre();
    let distance = |v: &[f32; MAX_STATES]| {
        (digiteyes_core::nalgebra::Vector3::new(v[4], v[5], v[6]) - eye).norm()
    };
    for k in 0..LOCAL_VARIANTS {
        let v = acquirer.variant(&sequence.cameras, &q, k, 0.3, 0.15);
        // The angle between the two rotations: 2·acos|⟨q, v⟩|.
        let dot: f32 = (0..4).map(|i| q[i] * v[i]).sum();
        let angle = 2.0 * dot.abs().min(1.0).acos();
        let depth = distance(&v) / distance(&q);
        assert_eq!(&v[7..], &q[7..], "variant {k}: the fingers are kept");
        match k {
            0 => assert_eq!(v, q),
            1..=6 => {
                assert!((angle - 0.3).abs() < 1e-3, "variant {k}: turned {angle}");
                assert_eq!(&v[4..7], &q[4..7]);
            }
            _ => {
                assert!(angle < 1e-6);
                assert!(
                    (depth - 1.0).abs() > 0.14 && (depth - 1.0).abs() < 0.16,
                    "{depth}"
                );
            }
        }
    }
}

/// Searches `sequence` from nothing under `finder` for its first `frames` frames, handing
/// each frame's number, report and tracker to `each`.
fn search_frames(
    sequence: &Sequence,
    finder: FinderConfig,
    frames: usize,
    mut each: impl FnMut(usize, &AutoReport, &AutoTracker),
) {
    // With the knuckle tips or the region rows (both on by default since), seed 1751 is held
    // right however the confirm phase ranks (about 3 px and 2.5 px on frames 12-15) and seed
    // 113 carries a single leaf: both off here, to show the confirm phase choosing.
    let mut tracker = TrackerConfig::default();
    tracker.features.knuckle_tips = false;
    tracker.fill = FillConfig::OFF;
    let (mut auto, mut bufs) = search::searching_with(sequence, AcquireConfig::default(), tracker);
    auto.set_finder(finder);
    for k in 0..frames.min(sequence.frames) {
        let images = images(sequence, k);
        let mut b: Vec<&mut [u8]> = bufs.iter_mut().map(|b| b.as_mut_slice()).collect();
        let r = auto.step(&views(&images), &mut b).unwrap();
        each(k, &r, &auto);
    }
}

/// The first frame of `sequence` the auto tracker accepts the hand on (claimed on the next,
/// once confirmed: `FinderConfig::probation_max_drop`), and the status and hypotheses of the
/// next `frames` frames.
fn acquire(sequence: &Sequence, finder: FinderConfig, frames: usize) -> (usize, Vec<(Status, u8)>) {
    let mut found = None;
    let mut after = Vec::new();
    search_frames(sequence, finder, sequence.frames, |k, r, auto| {
        if found.is_none() && r.accepted {
            found = Some(k);
        } else if found.is_some() && after.len() < frames {
            after.push((r.status, auto.hypotheses().len() as u8));
        }
    });
    (found.expect("the hand is acquired"), after)
}

#[test]
fn an_accepted_leaf_is_confirmed_among_the_others_and_a_refuted_one_given_up() {
    let dir = tempfile::tempdir().unwrap();
    // A tuning seed the probe acquires.
    let sequence = common::seeded(dir.path(), "random-stereo", 113, 24);
    // The confirm phase alone: the finger polish at its end would carry a polished state
    // for another phase (`tests/tests/polish.rs`).
    let confirm = FinderConfig {
        confirm_frames: 5,
        confirm_hypotheses: 4,
        confirm_min_score: 0.0,
        polish_margin: [-1.0, -1.0],
        ..FinderConfig::default()
    };
    let (k, after) = acquire(&sequence, confirm, 6);
    println!("acquired at {k}: {after:?}");
    assert!(
        after[..4].iter().any(|&(_, n)| n > 1),
        "several leaves carried while confirming: {after:?}"
    );
    assert!(
        after.iter().all(|&(s, _)| s == Status::Tracking),
        "{after:?}"
    );
    assert_eq!(
        after[4].1, 1,
        "back to one hypothesis after 5 frames: {after:?}"
    );
    // A bar no hand reaches: the acquisition is refuted after the confirming frames.
    let refuting = FinderConfig {
        confirm_min_score: 1.5,
        ..confirm
    };
    let (k2, after) = acquire(&sequence, refuting, 6);
    assert_eq!(k2, k);
    assert!(
        after[..4].iter().all(|&(s, _)| s == Status::Tracking),
        "{after:?}"
    );
    assert_eq!(after[4].0, Status::Searching, "refuted: {after:?}");
    assert_eq!(after[5].0, Status::Searching, "searching again: {after:?}");
}

/// The mean fingertip error (px) of the state claimed on each of frames `frames` of
/// `sequence`, searched for from nothing under `finder` (infinite where no hand is claimed).
fn claimed_tip_errors(
    sequence: &Sequence,
    finder: FinderConfig,
    frames: std::ops::Range<usize>,
) -> Vec<f32> {
    let truth = sequence.read_truth().unwrap();
    let mut errors = Vec::new();
    search_frames(sequence, finder, frames.end, |k, r, auto| {
        if frames.contains(&k) {
            let t: Vec<f32> = truth.rows[k].iter().map(|&v| v as f32).collect();
            errors.push(if r.status == Status::Tracking && !r.report.lost {
                search::tip_error_px(&sequence.model, &sequence.cameras, auto.state(), &t)
            } else {
                f32::INFINITY
            });
        }
    });
    errors
}

#[test]
fn the_confirm_phase_keeps_the_leaf_better_over_its_frames_not_on_the_last() {
    let dir = tempfile::tempdir().unwrap();
    // A seed of the sweep this shows on: after the acquisition, ranked by the frame under the
    // switch margin of 0.01 the output stays on a leaf 15-17 px off through frame 15; ranked
    // by the running mean it is 6.6-7.0 px off. Found by `scan_seeds_for_the_confirm_phase_
    // ranking` below under stop 72's defaults (the slice window at 16 px): of seeds
    // 2432-3300, 2716, 2787, 2870 and 3130 pass this test's bars; 3130 by the widest margin.
    // (Seed 2046, found among the even seeds 2032-2430 under the search's budget of 100 a
    // frame and a 20 px window, is held right when ranked by the frame too since, 1.1-1.8
    // px; before it, 1751.)
    let sequence = common::seeded(dir.path(), "random-stereo", 3130, 16);
    let ranked_by_the_frame = FinderConfig {
        confirm_switch_margin: 0.01,
        confirm_score_memory: 0.0,
        ..FinderConfig::default()
    };
    let before = claimed_tip_errors(&sequence, ranked_by_the_frame, 12..16);
    let now = claimed_tip_errors(&sequence, FinderConfig::default(), 12..16);
    println!("frames 12-15, tip px: by the frame {before:?}, by the running mean {now:?}");
    assert!(before.iter().all(|&e| e > 10.0), "{before:?}");
    assert!(now.iter().all(|&e| e < 10.0), "{now:?}");
}

/// A scan for the seed of the test above, by its own bars, for when a default changes
/// (`docs/mechanism-seeds.md`): `DIGITEYES_SCAN_SEEDS=2032..=2430 cargo test --release -p
/// digiteyes-tests --test acquire_multi scan -- --ignored --nocapture` prints each seed's
/// claimed tip errors on frames 12-15 under both rankings and the seeds that pass.
#[test]
#[ignore = "a scan of minutes: DIGITEYES_SCAN_SEEDS=A..=B"]
fn scan_seeds_for_the_confirm_phase_ranking() {
    let ranked_by_the_frame = FinderConfig {
        confirm_switch_margin: 0.01,
        confirm_score_memory: 0.0,
        ..FinderConfig::default()
    };
    let mut passing = Vec::new();
    for seed in common::seeds_to_scan() {
        let dir = tempfile::tempdir().unwrap();
        let sequence = common::seeded(dir.path(), "random-stereo", seed, 16);
        let before = claimed_tip_errors(&sequence, ranked_by_the_frame, 12..16);
        let now = claimed_tip_errors(&sequence, FinderConfig::default(), 12..16);
        let shows = before.iter().all(|&e| e > 10.0) && now.iter().all(|&e| e < 10.0);
        println!(
            "seed {seed}: by the frame {before:?}, by the running mean {now:?}, shows {shows}"
        );
        if shows {
            passing.push(seed);
        }
    }
    println!("{} seeds pass: {passing:?}", passing.len());
}
