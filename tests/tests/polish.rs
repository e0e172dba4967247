//! `Acquirer::polish_fingers`: each finger in turn given the library's pose that scores best
//! with the others as they are. A track that holds the palm with a finger or two wrong sits
//! in a minimum of Gauss–Newton's edge residuals, not of the likelihood, which still prefers
//! the truth (`docs/recovery.md`, "The fingers polished after a confirm phase").

use digiteyes_core::acquire::{FinderConfig, FingerPose, POSE_COUNT};
use digiteyes_core::config::MAX_STATES;

mod common;
use common::search::{self, TrueFrame};

/// First state of fingers 1–4 and the thumb in the whole-hand model.
const FINGER_STARTS: [usize; 5] = [7, 11, 15, 19, 23];

#[test]
fn a_finger_curled_wrong_under_the_true_palm_is_polished_toward_the_truth() {
    // `fullhand-stereo`'s first frame: a relaxed, slightly spread hand. Under the true palm,
    // with the index (finger 1) curled into a fist and the others true, the polish keeps the
    // palm, scores no less than its start, and brings the index nearer the truth than the
    // fist it started from.
    search::on_the_true_first_frame(|f| {
        let TrueFrame {
            truth,
            mut acquirer,
            scene,
            ..
        } = f;
        let fist = acquirer.with_pose(&truth, FingerPose::Fist as usize);
        let mut start = truth;
        start[7..11].copy_from_slice(&fist[7..11]);

        let (polished, score, before) = acquirer.polish_fingers(&scene, &start);

        assert_eq!(before, acquirer.score(&scene, &start));
        assert_eq!(score, acquirer.score(&scene, &polished));
        assert!(score > before, "polished {score} against {before}");
        assert_eq!(polished[..7], start[..7], "the palm is kept");
        let index_error = |p: &[f32; MAX_STATES]| -> f32 {
            (FINGER_STARTS[0]..FINGER_STARTS[1])
                .map(|i| (p[i] - truth[i]).powi(2))
                .sum::<f32>()
                .sqrt()
        };
        println!(
            "index: {:.2} rad from the truth curled, {:.2} polished; score {before:.3} -> {score:.3}",
            index_error(&start),
            index_error(&polished)
        );
        assert!(
            index_error(&polished) < 0.5 * index_error(&start),
            "the index polished toward the truth"
        );
    });
}

#[test]
fn a_polished_state_is_never_worse_and_each_finger_ends_at_its_best_library_pose() {
    // Whatever the start, the result never scores less than the start, and no library pose
    // of the thumb (polished last) scores more than the result with the rest kept: from
    // every library pose under the true palm of `fullhand-stereo`'s first frame.
    search::on_the_true_first_frame(|f| {
        let TrueFrame {
            truth,
            mut acquirer,
            scene,
            ..
        } = f;
        for pose in 0..POSE_COUNT {
            let start = acquirer.with_pose(&truth, pose);
            let (polished, score, before) = acquirer.polish_fingers(&scene, &start);
            assert!(score >= before, "pose {pose}: {score} under {before}");
            for other in 0..POSE_COUNT {
                let mut thumb = acquirer.with_pose(&polished, other);
                thumb[..FINGER_STARTS[4]].copy_from_slice(&polished[..FINGER_STARTS[4]]);
                let s = acquirer.score(&scene, &thumb);
                assert!(
                    s <= score,
                    "pose {pose}: the thumb in pose {other} scores {s} over {score}"
                );
            }
        }
    });
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
