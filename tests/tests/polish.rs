//! `Acquirer::polish_fingers`: each finger in turn given the library's pose that scores best
//! with the others as they are. A track that holds the palm with a finger or two wrong sits
//! in a minimum of Gauss–Newton's edge residuals, not of the likelihood, which still prefers
//! the truth (`docs/recovery.md`, "The fingers polished after a confirm phase").

use digiteyes_core::acquire::{AcquireConfig, FinderConfig, FingerPose};
use digiteyes_core::config::MAX_STATES;

mod common;
use common::{frames, search};

/// First state of fingers 1–4 and the thumb in the whole-hand model.
const FINGER_STARTS: [usize; 5] = [7, 11, 15, 19, 23];

#[test]
fn a_finger_curled_wrong_under_the_true_palm_is_polished_toward_the_truth() {
    // `fullhand-stereo`'s first frame: a relaxed, slightly spread hand. Under the true palm,
    // with the index (finger 1) curled into a fist and the others true, the polish keeps the
    // palm, scores no less than its start, and brings the index nearer the truth than the
    // fist it started from.
    let dir = tempfile::tempdir().unwrap();
    let sequence = common::seeded(dir.path(), "fullhand-stereo", 0, 1);
    let n = sequence.n_states();
    let truth: Vec<f32> = sequence.read_truth().unwrap().rows[0]
        .iter()
        .map(|&v| v as f32)
        .collect();
    let acquire = AcquireConfig::default();
    let mut acquirer = search::acquirer(&sequence, acquire);
    let images = frames::images(&sequence, 0);
    let views = frames::views(&images);
    let mut bufs = search::buffers(&sequence.cameras, acquire.likelihood.stride_px);
    let maps = search::edge_maps(&mut bufs, &views, &acquire.likelihood);
    let mut q = [0.0f32; MAX_STATES];
    q[..n].copy_from_slice(&truth);
    let fist = acquirer.with_pose(&q, FingerPose::Fist as usize);
    let mut start = q;
    start[7..11].copy_from_slice(&fist[7..11]);

    let (polished, score, before) =
        acquirer.polish_fingers(&sequence.model, &sequence.cameras, &views, &maps, &start);

    let scored = |a: &mut digiteyes_core::acquire::Acquirer, p: &[f32; MAX_STATES]| {
        a.score(&sequence.model, &sequence.cameras, &views, &maps, p)
    };
    assert_eq!(
        before,
        scored(&mut acquirer, &start),
        "the start's own score"
    );
    assert_eq!(
        score,
        scored(&mut acquirer, &polished),
        "the polished state's own score"
    );
    assert!(score > before, "polished {score} against {before}");
    assert_eq!(polished[..7], start[..7], "the palm is kept");
    let finger_error = |p: &[f32; MAX_STATES], f: usize| -> f32 {
        let range = FINGER_STARTS[f]..FINGER_STARTS.get(f + 1).copied().unwrap_or(n);
        range.map(|i| (p[i] - truth[i]).powi(2)).sum::<f32>().sqrt()
    };
    println!(
        "index: {:.2} rad from the truth curled, {:.2} polished; score {before:.3} -> {score:.3}",
        finger_error(&start, 0),
        finger_error(&polished, 0)
    );
    assert!(
        finger_error(&polished, 0) < 0.5 * finger_error(&start, 0),
        "the index polished toward the truth"
    );
}

#[test]
fn a_polished_state_is_never_worse_and_each_finger_ends_at_its_best_library_pose() {
    // Whatever the start, no single finger given any library pose afterwards scores more
    // than the polish's result on the finger it last polished, and the result never scores
    // less than the start: from every library pose under the true palm of
    // `fullhand-stereo`'s first frame.
    let dir = tempfile::tempdir().unwrap();
    let sequence = common::seeded(dir.path(), "fullhand-stereo", 0, 1);
    let n = sequence.n_states();
    let truth: Vec<f32> = sequence.read_truth().unwrap().rows[0]
        .iter()
        .map(|&v| v as f32)
        .collect();
    let acquire = AcquireConfig::default();
    let mut acquirer = search::acquirer(&sequence, acquire);
    let images = frames::images(&sequence, 0);
    let views = frames::views(&images);
    let mut bufs = search::buffers(&sequence.cameras, acquire.likelihood.stride_px);
    let maps = search::edge_maps(&mut bufs, &views, &acquire.likelihood);
    let mut q = [0.0f32; MAX_STATES];
    q[..n].copy_from_slice(&truth);
    for pose in 0..digiteyes_core::acquire::POSE_COUNT {
        let start = acquirer.with_pose(&q, pose);
        let (polished, score, before) =
            acquirer.polish_fingers(&sequence.model, &sequence.cameras, &views, &maps, &start);
        assert!(score >= before, "pose {pose}: {score} under {before}");
        // The thumb is polished last: every library pose of it, the rest kept, scores no more.
        for other in 0..digiteyes_core::acquire::POSE_COUNT {
            let mut thumb = acquirer.with_pose(&polished, other);
            thumb[..FINGER_STARTS[4]].copy_from_slice(&polished[..FINGER_STARTS[4]]);
            let s = acquirer.score(&sequence.model, &sequence.cameras, &views, &maps, &thumb);
            assert!(
                s <= score,
                "pose {pose}: the thumb in pose {other} scores {s} over {score}"
            );
        }
    }
}

#[test]
fn the_polish_is_off_unless_a_margin_of_zero_or_more_is_set() {
    let mut finder = FinderConfig {
        polish_margin: [-1.0, f32::NAN],
        ..FinderConfig::default()
    };
    assert_eq!(finder.polish(2), None);
    assert_eq!(finder.polish(1), None);
    finder.polish_margin = [0.0, 0.01];
    assert_eq!(finder.polish(2), Some(0.0));
    assert_eq!(finder.polish(1), Some(0.01));
    assert_eq!(
        finder.polish(3),
        Some(0.0),
        "three cameras are polished as two"
    );
}
