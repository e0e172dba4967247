//! With one camera the local re-acquisition does not move the last good palm in depth
//! (`FinderConfig::local_depth_share`): a single view sees the hand's depth only through its
//! size, and bent fingers make a nearer hand look like a farther one. On the robustness
//! sweep's mono seed 1 the variant moved 15 % nearer was once refined, accepted and held about
//! 90 mm nearer the camera than the hand to the end, without the lost flag. (Since sines and
//! cosines are computed in single precision, stop 54, no run of mono seeds 1-41 takes that
//! variant back: the hazard is shown here on the state itself, a hand moved nearer along the
//! ray and refined on the frame.)

use digiteyes_core::acquire::{AcquireConfig, LeafScore};
use digiteyes_core::frame::FrameView;
use digiteyes_core::likelihood::{EdgeMap, Scene, StateScorer};
use digiteyes_core::state::TRANSLATION;
use digiteyes_core::tracker::Tracker;
use digiteyes_host::bench::robustness::count_run;
use digiteyes_host::evaluate;
use digiteyes_host::track::{track_sequence_opts, TrackOptions};
use digiteyes_host::{render_scenario, RenderOptions, TrackerConfig};

mod common;

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

/// A hand moved 15 % nearer the one camera along its ray and refined there by the tracker
/// stays far from the hand: the view does not pull the depth back. And the acceptance would
/// take such a hand (3 passes the one-camera bars of the search's likelihood; 5 passes the
/// score bar and only the reverse term's 3.5 px bar refuses it, at 3.9 px; 1 scores under
/// them): one view cannot be trusted to tell which depth is right, so one camera's
/// local re-acquisition does not offer the nearer start (its depth share is 0 by default).
/// On random-mono seeds 1, 3 and 5, frame 0, at 320×240.
#[test]
fn one_view_cannot_tell_a_hand_moved_along_its_ray() {
    assert_eq!(TrackOptions::default().finder.local_depth_share[1], 0.0);
    let dir = tempfile::tempdir().unwrap();
    let config = AcquireConfig::default().likelihood;
    let accept = TrackOptions::default().finder.accept;
    let mut accepted = 0;
    for seed in [1, 3, 5] {
        let sequence = common::seeded(dir.path(), "random-mono", seed, 1);
        let truth = sequence.read_truth().unwrap();
        let q: Vec<f32> = truth.rows[0].iter().map(|&v| v as f32).collect();
        let camera = sequence.cameras[0];
        let palm = |q: &[f32]| {
            digiteyes_core::nalgebra::Vector3::new(
                q[TRANSLATION][0],
                q[TRANSLATION][1],
                q[TRANSLATION][2],
            )
        };
        let nearer = camera.centre() + (palm(&q) - camera.centre()) * 0.85;
        let mut moved = q.clone();
        moved[TRANSLATION].copy_from_slice(nearer.as_slice());
        let image = sequence.read_frame(0, 0).unwrap();
        let frame = FrameView::packed(
            image.as_raw(),
            image.width() as usize,
            image.height() as usize,
        )
        .unwrap();
        let mut tracker_config = TrackerConfig::default();
        tracker_config.predict = false;
        let mut tracker = Tracker::new(
            sequence.model.clone(),
            &sequence.cameras,
            &moved,
            sequence.free_mask(),
            tracker_config,
        )
        .unwrap();
        for _ in 0..10 {
            tracker.track(&[frame]).unwrap();
        }
        let refined = tracker.state().to_vec();
        let off_mm = (palm(&refined) - palm(&q)).norm();
        let mut buffer =
            vec![0u8; EdgeMap::bytes_needed(frame.width(), frame.height(), config.stride_px)];
        let edges = [EdgeMap::build(&mut buffer, &frame, &config).unwrap()];
        let frames = [frame];
        let scene = Scene::new(&sequence.model, &sequence.cameras, &frames, &edges);
        let mut scorer = StateScorer::new();
        let (score, worst_camera, reverse_px) =
            scorer.score_cameras_and_reverse(&scene, &refined, &config);
        let true_score = scorer.score(&scene, &q, &config);
        let moved_mm = (nearer - palm(&q)).norm();
        println!(
            "seed {seed}: moved {moved_mm:.0} mm, refined {off_mm:.0} mm from the hand; \
             score {score:.3} (the truth {true_score:.3}), reverse {reverse_px:?} px"
        );
        assert!(refined.iter().all(|v| v.is_finite()));
        assert!(
            off_mm > 0.5 * moved_mm,
            "seed {seed}: the view pulled the depth back ({off_mm:.0} of {moved_mm:.0} mm)"
        );
        let leaf = LeafScore {
            score,
            worst_camera,
            reverse_px,
        };
        accepted += usize::from(accept.judge(1, leaf, false).accepted);
    }
    assert!(
        accepted >= 1,
        "no hand moved along its ray passed the acceptance"
    );
}

/// The run the hazard was first seen on, under the defaults: no frame far from the hand
/// without the lost flag.
#[test]
fn one_cameras_run_keeps_no_frame_far_from_the_hand_unflagged() {
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
    let (far_default, _) = far_frames(&seq, TrackerConfig::default(), &TrackOptions::default());
    assert_eq!(
        far_default, 0,
        "the defaults: no frame far without the lost flag"
    );
}
