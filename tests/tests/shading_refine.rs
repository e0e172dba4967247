//! A finger moved where the hand's shading says it lies (`likelihood::shading_refine`,
//! `Tracker::refine_shading`), on frames from our renderer and rigs nobody tuned it for
//! (random-mono seeds 301..=315, odd): a finger bent off comes back toward the truth, a finger
//! at the truth stays there, the tracker does nothing unless asked, and a frame of the wrong
//! size moves nothing.

use digiteyes_core::frame::FrameView;
use digiteyes_core::hypotheses::fingers::Fingers;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::likelihood::shading_cache::ShadingCache;
use digiteyes_core::likelihood::shading_refine::{refine_finger, ShadingRefineConfig};
use digiteyes_core::projection::ProjectedModel;
use digiteyes_core::tracker::{TrackerConfig, TrackerError};
use digiteyes_host::sequence::Sequence;
use digiteyes_host::sequence_tracker;

mod common;
use common::{frames, search};

/// Seeds, each rendered 12 frames at 320×240.
fn seeds() -> impl Iterator<Item = u64> {
    (0..8).map(|i| 301 + 2 * i)
}

/// Mean fingertip distance (px) between states `a` and `b`.
fn tip_distance_px(sequence: &Sequence, a: &[f32], b: &[f32]) -> f32 {
    search::tip_error_px(&sequence.model, &sequence.cameras, a, b)
}

/// Refines finger `f` of `q` on camera 0's frame `k` with `config`, `passes` times.
fn refined(
    sequence: &Sequence,
    k: usize,
    q: &[f32],
    f: usize,
    passes: usize,
    config: &ShadingRefineConfig,
) -> Vec<f32> {
    let images = frames::images(sequence, k);
    let views = frames::views(&images);
    let fingers = Fingers::of(&sequence.model);
    let mut poses = Poses::compute(&sequence.model, q).unwrap();
    let mut view = ProjectedModel::new();
    let mut cache = ShadingCache::default();
    let mut out = q.to_vec();
    for _ in 0..passes {
        refine_finger(
            &sequence.model,
            &sequence.cameras,
            &views,
            &fingers,
            f,
            &mut out,
            &mut poses,
            &mut view,
            &mut cache,
            config,
        );
    }
    out
}

/// Each seed's true state at frame `k`.
fn truth_at(sequence: &Sequence, k: usize) -> Vec<f32> {
    frames::truth_states(sequence).swap_remove(k)
}

#[test]
fn a_finger_bent_off_comes_back_toward_the_truth() {
    let dir = tempfile::tempdir().unwrap();
    let config = ShadingRefineConfig::default();
    let (mut cases, mut nearer, mut before_sum, mut after_sum) = (0, 0, 0.0, 0.0);
    for seed in seeds() {
        let sequence = common::seeded(dir.path(), "random-mono", seed, 12);
        let fingers = Fingers::of(&sequence.model);
        for k in [0, 11] {
            let q = truth_at(&sequence, k);
            for f in 0..fingers.count() {
                // The finger's flexions (all its states but the first) bent 0.12 rad further,
                // within their ranges.
                let mut off = q.clone();
                let states: Vec<usize> = (0..q.len()).filter(|&s| fingers.contains(f, s)).collect();
                for &s in states.iter().skip(1) {
                    let limit = sequence.model.limit(s).unwrap();
                    off[s] = (off[s] + 0.12).clamp(limit.lo, limit.hi);
                }
                let before = tip_distance_px(&sequence, &off, &q);
                if before < 1.0 {
                    continue; // a finger at its limit, or seen end-on: nothing to pull back
                }
                let after =
                    tip_distance_px(&sequence, &refined(&sequence, k, &off, f, 3, &config), &q);
                cases += 1;
                nearer += usize::from(after < before);
                before_sum += before;
                after_sum += after;
            }
        }
    }
    println!(
        "{cases} fingers: nearer the truth after in {nearer}; mean tip error {:.2} -> {:.2} px",
        before_sum / cases as f32,
        after_sum / cases as f32
    );
    assert!(cases >= 40, "{cases} cases");
    assert!(
        nearer * 10 >= cases * 7,
        "nearer in only {nearer} of {cases}"
    );
    assert!(after_sum < 0.7 * before_sum, "{before_sum} -> {after_sum}");
}

#[test]
fn a_finger_at_the_truth_stays_near_it() {
    let dir = tempfile::tempdir().unwrap();
    let config = ShadingRefineConfig::default();
    let mut moved = Vec::new();
    for seed in seeds() {
        let sequence = common::seeded(dir.path(), "random-mono", seed, 1);
        let fingers = Fingers::of(&sequence.model);
        let q = truth_at(&sequence, 0);
        for f in 0..fingers.count() {
            let after = refined(&sequence, 0, &q, f, 1, &config);
            moved.push(tip_distance_px(&sequence, &after, &q));
        }
    }
    moved.sort_by(f32::total_cmp);
    let median = moved[moved.len() / 2];
    println!(
        "tip moved from the truth: median {median:.2} px, most {:.2}",
        moved[moved.len() - 1]
    );
    assert!(median < 1.0, "{moved:?}");
}

#[test]
fn the_tracker_refines_only_when_asked_and_refuses_a_wrong_frame() {
    let dir = tempfile::tempdir().unwrap();
    let sequence = common::seeded(dir.path(), "random-mono", 301, 2);
    let images = frames::images(&sequence, 1);
    let frame = frames::views(&images)[0];
    // Off by default: nothing moves, nothing is counted.
    let mut tracker = sequence_tracker(&sequence, TrackerConfig::default()).unwrap();
    tracker.track(&[frame]).unwrap();
    let before = tracker.memory();
    let outcome = tracker.refine_shading(&[frame]).unwrap();
    assert_eq!(outcome.trials, 0);
    assert_eq!(tracker.memory(), before);
    // Asked, from a finger bent off: it moves, and keeps the velocity. With no margin, so
    // that any try leaving less moves it (the default's 0.5 % over capped residuals holds
    // this finger still; what the margin and the cap do is measured on the sweep).
    let mut config = TrackerConfig::default();
    config.shading_refine.every_frames = 1;
    config.shading_refine.margin = 0.0;
    let mut tracker = sequence_tracker(&sequence, config).unwrap();
    tracker.track(&[frame]).unwrap();
    let mut memory = tracker.memory();
    let fingers = Fingers::of(&sequence.model);
    // The first call refines finger 1.
    for s in (0..memory.state.len())
        .filter(|&s| fingers.contains(1, s))
        .skip(1)
    {
        memory.state[s] += 0.15;
    }
    tracker.restore(&memory).unwrap();
    let outcome = tracker.refine_shading(&[frame]).unwrap();
    assert!(outcome.trials > 0 && outcome.moves > 0, "{outcome:?}");
    assert_ne!(tracker.state(), &memory.state[..]);
    assert_eq!(tracker.memory().velocity, memory.velocity);
    // A frame of the wrong size: an error, and nothing moves.
    let small = vec![0u8; 16 * 16];
    let wrong = FrameView::packed(&small, 16, 16).unwrap();
    let kept = tracker.memory();
    assert!(matches!(
        tracker.refine_shading(&[wrong]),
        Err(TrackerError::Frame(_))
    ));
    assert_eq!(tracker.memory(), kept);
}

#[test]
fn several_fingers_a_call_are_the_fingers_in_turn_one_after_another() {
    // Three fingers a call from the tracker: the same state as refining those three in turn,
    // each from the one before. Call n takes fingers 3n, 3n + 1, 3n + 2 (mod 5), so the
    // first (n = 1, as one finger a call takes finger 1 first) takes 3, 4 and 0.
    let dir = tempfile::tempdir().unwrap();
    let sequence = common::seeded(dir.path(), "random-mono", 303, 2);
    let images = frames::images(&sequence, 1);
    let views = frames::views(&images);
    let fingers = Fingers::of(&sequence.model);
    let mut config = TrackerConfig::default();
    config.shading_refine.every_frames = 1;
    config.shading_refine.fingers_per_call = 3;
    let mut tracker = sequence_tracker(&sequence, config).unwrap();
    tracker.track(&views).unwrap();
    let mut memory = tracker.memory();
    for f in 0..fingers.count() {
        for s in (0..memory.state.len())
            .filter(|&s| fingers.contains(f, s))
            .skip(1)
        {
            memory.state[s] += 0.15;
        }
    }
    tracker.restore(&memory).unwrap();
    let outcome = tracker.refine_shading(&views).unwrap();
    let mut expected = memory.state.to_vec();
    let mut trials = 0;
    for f in [3, 4, 0] {
        let mut poses = Poses::compute(&sequence.model, &expected).unwrap();
        let mut view = ProjectedModel::new();
        let one = refine_finger(
            &sequence.model,
            &sequence.cameras,
            &views,
            &fingers,
            f,
            &mut expected,
            &mut poses,
            &mut view,
            &mut ShadingCache::default(),
            &config.shading_refine,
        );
        trials += one.trials;
    }
    assert_eq!(outcome.trials, trials);
    assert!(outcome.moves > 0, "{outcome:?}");
    assert_eq!(tracker.state(), &expected[..]);
}

#[test]
fn the_whole_pipeline_with_the_refinement_tracks_a_friendly_hand_as_well() {
    // `fullhand-stereo` (seed 1, 20 frames at 640×480) through `track_sequence`, the status
    // machine and all, with a finger refined after every frame: it runs (the states differ
    // from the default's) and holds the same bar as the default in `tracking.rs`.
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("fullhand-stereo");
    let options = digiteyes_host::RenderOptions {
        seed: 1,
        frames: Some(20),
        ..digiteyes_host::RenderOptions::default()
    };
    digiteyes_host::render_scenario("fullhand-stereo", &seq, &options).unwrap();
    let run = |every: u8, name: &str| {
        let mut config = TrackerConfig::default();
        config.shading_refine.every_frames = every;
        let states = dir.path().join(name);
        digiteyes_host::track_sequence(&seq, &states, config, false).unwrap();
        let report = digiteyes_host::evaluate(&seq, &states).unwrap();
        let tips = report
            .cameras
            .iter()
            .map(|c| c.fingertip_mean_px)
            .fold(0.0, f64::max);
        (std::fs::read(&states).unwrap(), tips, report.track_life)
    };
    let (plain, plain_tips, _) = run(0, "plain.csv");
    let (refined, refined_tips, life) = run(1, "refined.csv");
    println!("fingertips: {plain_tips:.2} px plain, {refined_tips:.2} px refined");
    assert_ne!(plain, refined, "the refinement ran");
    assert!(refined_tips < 2.0, "fingertip error {refined_tips} px");
    assert_eq!(life, 1.0);
}
