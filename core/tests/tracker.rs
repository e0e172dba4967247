//! The tracker's error paths and its behaviour on frames with nothing to track.

use digiteyes_core::camera::{Camera, CameraError};
use digiteyes_core::estimator::FreeMask;
use digiteyes_core::frame::{FrameError, FrameView};
use digiteyes_core::kinematics::KinematicsError;
use digiteyes_core::model::Model;
use digiteyes_core::tracker::{Tracker, TrackerConfig, TrackerError};
use nalgebra::{Matrix3, Vector3};

fn camera() -> Camera {
    Camera {
        width: 64,
        height: 48,
        fx: 100.0,
        fy: 100.0,
        cx: 31.5,
        cy: 23.5,
        r: Matrix3::identity(),
        t: Vector3::new(0.0, 0.0, 600.0),
    }
}

fn initial() -> Vec<f32> {
    let mut q = vec![0.0f32; 28];
    q[0] = 1.0;
    q
}

fn tracker(free: FreeMask) -> Result<Tracker, TrackerError> {
    Tracker::new(
        Model::hand().unwrap(),
        &[camera()],
        &initial(),
        free,
        TrackerConfig::default(),
    )
}

#[test]
fn a_frame_of_the_wrong_size_is_rejected_and_the_state_kept() {
    let mut t = tracker(FreeMask::all(28)).unwrap();
    let data = vec![0u8; 32 * 48];
    let frame = FrameView::packed(&data, 32, 48).unwrap();
    let before = t.state().to_vec();
    assert_eq!(
        t.track(&[frame]),
        Err(TrackerError::Frame(FrameError::WrongSize {
            expected_width: 64,
            expected_height: 48
        }))
    );
    assert_eq!(t.state(), &before[..]);
}

#[test]
fn the_number_of_frames_must_match_the_cameras() {
    let mut t = tracker(FreeMask::all(28)).unwrap();
    let data = vec![0u8; 64 * 48];
    let frame = FrameView::packed(&data, 64, 48).unwrap();
    assert_eq!(t.track(&[]), Err(TrackerError::FrameCount));
    assert_eq!(t.track(&[frame, frame]), Err(TrackerError::FrameCount));
}

#[test]
fn set_up_errors() {
    assert_eq!(
        tracker(FreeMask::from_states(&[4, 28]).unwrap()).err(),
        Some(TrackerError::BadFreeState(28))
    );
    let mut nan = initial();
    nan[9] = f32::NAN;
    let r = Tracker::new(
        Model::hand().unwrap(),
        &[camera()],
        &nan,
        FreeMask::all(28),
        TrackerConfig::default(),
    );
    assert_eq!(
        r.err(),
        Some(TrackerError::State(KinematicsError::NotFinite { state: 9 }))
    );
    let r = Tracker::new(
        Model::hand().unwrap(),
        &[camera()],
        &initial()[..20],
        FreeMask::all(28),
        TrackerConfig::default(),
    );
    assert!(matches!(
        r.err(),
        Some(TrackerError::State(KinematicsError::WrongStateCount { .. }))
    ));
    let r = Tracker::new(
        Model::hand().unwrap(),
        &[],
        &initial(),
        FreeMask::all(28),
        TrackerConfig::default(),
    );
    assert_eq!(r.err(), Some(TrackerError::CameraCount));
    let mut bad = camera();
    bad.fx = -1.0;
    let r = Tracker::new(
        Model::hand().unwrap(),
        &[bad],
        &initial(),
        FreeMask::all(28),
        TrackerConfig::default(),
    );
    assert_eq!(
        r.err(),
        Some(TrackerError::Camera(CameraError::BadFocalLength))
    );
    let five = [camera(); 5];
    let r = Tracker::new(
        Model::hand().unwrap(),
        &five,
        &initial(),
        FreeMask::all(28),
        TrackerConfig::default(),
    );
    assert_eq!(r.err(), Some(TrackerError::CameraCount));
}

#[test]
fn naming_one_quaternion_state_frees_all_four() {
    let t = tracker(FreeMask::from_states(&[2, 8]).unwrap()).unwrap();
    for i in 0..4 {
        assert!(t.free().contains(i));
    }
    assert!(t.free().contains(8) && !t.free().contains(4));
}

#[test]
fn a_black_frame_is_lost_and_leaves_a_finite_state() {
    let mut t = tracker(FreeMask::all(28)).unwrap();
    let data = vec![0u8; 64 * 48];
    let frame = FrameView::packed(&data, 64, 48).unwrap();
    let report = t.track(&[frame]).unwrap();
    assert!(report.lost);
    assert_eq!(report.features_found, 0);
    assert!(t.state().iter().all(|v| v.is_finite()));
}

#[test]
fn reset_rejects_a_nan_state_and_keeps_the_old_one() {
    let mut t = tracker(FreeMask::all(28)).unwrap();
    let mut bad = initial();
    bad[0] = f32::NAN;
    assert!(t.reset(&bad).is_err());
    assert_eq!(t.state(), &initial()[..]);
}

#[test]
fn track_under_puts_the_trackers_own_settings_back_error_or_not() {
    use digiteyes_core::estimator::Robust;
    use digiteyes_core::motion::PriorWeights;
    use digiteyes_core::tracker::RefineOverrides;
    let mut t = tracker(FreeMask::all(28)).unwrap();
    let own = *t.config();
    assert!(!own.estimator.bounded_step, "the plain step by default");
    let data = vec![0u8; 64 * 48];
    let frame = FrameView::packed(&data, 64, 48).unwrap();
    let overrides = RefineOverrides {
        robust: Robust::Tukey(9.0),
        max_edge_angle_rad: 1.5,
        bounded_step: true,
        prior: PriorWeights::OFF,
        iterations: own.iterations + 3,
    };
    assert_ne!(
        overrides.prior, own.motion.prior,
        "the prior is overridden too"
    );
    let report = t.track_under(&overrides, &[frame]).unwrap();
    assert!(report.lost);
    assert_eq!(*t.config(), own);
    let small = vec![0u8; 32 * 48];
    let wrong = FrameView::packed(&small, 32, 48).unwrap();
    let overrides = RefineOverrides {
        robust: Robust::None,
        max_edge_angle_rad: 0.1,
        ..overrides
    };
    assert!(t.track_under(&overrides, &[wrong]).is_err());
    assert_eq!(*t.config(), own);
}

#[test]
fn a_leafs_refinement_keeps_the_share_of_the_prior_its_rig_is_given() {
    use digiteyes_core::acquire::FinderConfig;
    use digiteyes_core::motion::PriorWeights;
    let own = TrackerConfig::default();
    assert!(own.motion.prior.joint > 0.0 && own.motion.prior.translation > 0.0);
    let finder = FinderConfig {
        leaf_prior_share: [0.25, 1.0],
        local_prior_share: 0.0,
        ..FinderConfig::default()
    };
    assert_eq!(finder.leaf_overrides(&own, 1).prior, own.motion.prior);
    let stereo = finder.leaf_overrides(&own, 2);
    assert_eq!(stereo.prior.joint, own.motion.prior.joint * 0.25);
    assert_eq!(
        stereo.prior.translation,
        own.motion.prior.translation * 0.25
    );
    assert_eq!(stereo.robust, finder.leaf_robust);
    assert_eq!(stereo.max_edge_angle_rad, finder.leaf_max_edge_angle_rad);
    assert_eq!(stereo.bounded_step, finder.leaf_bounded_step);
    assert_eq!(stereo.iterations, finder.refine_iterations);
    assert_eq!(finder.local_overrides(&own).prior, PriorWeights::OFF);
    // A share that is not one: not a number keeps the tracker's own, beyond 1 is 1.
    let odd = FinderConfig {
        leaf_prior_share: [f32::NAN, 3.0],
        ..FinderConfig::default()
    };
    assert_eq!(odd.leaf_overrides(&own, 2).prior, own.motion.prior);
    assert_eq!(odd.leaf_overrides(&own, 1).prior, own.motion.prior);
    // The defaults: the tracker's own prior in every rig.
    let default = FinderConfig::default();
    for n in 1..=2 {
        assert_eq!(default.leaf_overrides(&own, n).prior, own.motion.prior);
    }
    assert_eq!(default.local_overrides(&own).prior, own.motion.prior);
}

#[test]
fn set_prior_takes_valid_weights_and_refuses_others() {
    use digiteyes_core::motion::PriorWeights;
    let mut t = tracker(FreeMask::all(28)).unwrap();
    let own = t.config().motion.prior;
    let free_position = PriorWeights {
        translation: 0.0,
        ..own
    };
    assert!(t.set_prior(free_position));
    assert_eq!(t.config().motion.prior, free_position);
    for bad in [f32::NAN, -1.0, f32::INFINITY] {
        let refused = PriorWeights { joint: bad, ..own };
        assert!(!t.set_prior(refused), "joint weight {bad} refused");
        assert_eq!(t.config().motion.prior, free_position, "nothing changed");
    }
    assert!(t.set_prior(own));
    assert_eq!(*t.config(), TrackerConfig::default());
}
