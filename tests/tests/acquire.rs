//! The search that finds the hand without help (issue 10): it keeps within its per-frame
//! budget and picks up where it left off; hand-free frames — plain, noisy, cluttered — are
//! never claimed, even when the whole search and every leaf's refinement run on every frame;
//! and, from no initial state, the status machine acquires the hand on random rigs the sweep
//! says it acquires (docs/recovery.md: `acquire_probe --seeds 101..=140`).

use digiteyes_core::acquire::{
    AcceptConfig, AcquireConfig, Finder, FinderConfig, FinderStep, FingerPose, Progress, POSE_COUNT,
};
use digiteyes_core::auto_tracker::Status;
use digiteyes_core::config::MAX_STATES;
use digiteyes_core::estimator::{FreeMask, Robust};
use digiteyes_core::fill::FillConfig;
use digiteyes_core::frame::FrameView;
use digiteyes_core::likelihood::Scene;
use digiteyes_core::tracker::Tracker;
use digiteyes_host::sequence::Sequence;
use digiteyes_host::TrackerConfig;

mod common;
use common::search::TrueFrame;
use common::{frames, search};
use digiteyes_host::render::hand_free::hand_free;

/// A tracker and a finder for `sequence` from nothing: every state free, the base the
/// identity palm at the origin.
fn finder(sequence: &Sequence, acquire: AcquireConfig, config: FinderConfig) -> (Tracker, Finder) {
    let tracker = Tracker::new(
        sequence.model.clone(),
        &sequence.cameras,
        &search::base(sequence.n_states()),
        FreeMask::all(sequence.n_states()),
        TrackerConfig::default(),
    )
    .unwrap();
    (
        tracker,
        Finder::new(search::acquirer(sequence, acquire), config),
    )
}

#[test]
fn hand_free_frames_are_never_claimed() {
    let dir = tempfile::tempdir().unwrap();
    for (rig, seed) in [("random-mono", 101), ("random-stereo", 102)] {
        let sequence = common::seeded(dir.path(), rig, seed, 1);
        // The whole search, to the end, on every frame, and every leaf refined and judged by
        // the acceptance the finder uses.
        let acquire = AcquireConfig {
            evaluations_per_frame: u16::MAX,
            ..AcquireConfig::default()
        };
        let config = FinderConfig {
            leaves_per_frame: 8,
            leaves: 8,
            ..FinderConfig::default()
        };
        let (mut tracker, mut finder) = finder(&sequence, acquire, config);
        // A tracker weighting its residuals otherwise than the search refines leaves.
        let mut tukey = TrackerConfig::default();
        tukey.estimator.robust = Robust::Tukey(5.0);
        tracker.reconfigure(&sequence.cameras, tukey).unwrap();
        let mut bufs = search::buffers(&sequence.cameras, acquire.likelihood.stride_px);
        let (mut leaves, mut best) = (0u32, 0.0f32);
        for (k, (noise, clutter)) in [(0, false), (8, false), (8, true), (0, true)]
            .into_iter()
            .cycle()
            .take(20)
            .enumerate()
        {
            let pixels: Vec<Vec<u8>> = sequence
                .cameras
                .iter()
                .enumerate()
                .map(|(c, cam)| {
                    let (w, h) = (cam.width as usize, cam.height as usize);
                    hand_free(
                        w,
                        h,
                        40 + (k * 7 % 40) as u8,
                        noise,
                        clutter,
                        (4 * k + c) as u64,
                    )
                })
                .collect();
            let views: Vec<FrameView<'_>> = pixels
                .iter()
                .zip(&sequence.cameras)
                .map(|(p, c)| FrameView::packed(p, c.width as usize, c.height as usize).unwrap())
                .collect();
            // The search on this frame to its end, then its leaves on the same frame.
            for _ in 0..2 {
                let maps = search::edge_maps(&mut bufs, &views, &acquire.likelihood);
                match finder.step(&mut tracker, &views, &maps).unwrap() {
                    FinderStep::Found { verdict, .. } => {
                        panic!("{rig}: hand-free frame {k} claimed a hand: {verdict:?}")
                    }
                    FinderStep::Searching {
                        refined, best_leaf, ..
                    } => {
                        leaves += u32::from(refined);
                        if let Some(v) = best_leaf {
                            best = best.max(v.score);
                        }
                    }
                }
            }
            finder.restart();
        }
        println!("{rig}: 20 hand-free frames, {leaves} leaves refined and refused, best {best:.3}");
        assert!(
            leaves >= 20 * 8,
            "{rig}: the search must have reached its leaves on every frame: {leaves}"
        );
        // The leaves were refined under the search's robust weight; the tracker keeps its own.
        assert_eq!(
            tracker.config().estimator.robust,
            Robust::Tukey(5.0),
            "{rig}: refining leaves must leave the tracker's robust weight as it was"
        );
    }
}

/// `test` on the first frame of `random-mono` 101 and `random-stereo` 102 (320×240), with
/// its edge maps built as the search's defaults build them.
fn on_first_frames(mut test: impl FnMut(&str, &Sequence, &Scene<'_>)) {
    let dir = tempfile::tempdir().unwrap();
    for (rig, seed) in [("random-mono", 101), ("random-stereo", 102)] {
        let sequence = common::seeded(dir.path(), rig, seed, 1);
        let images = frames::images(&sequence, 0);
        let views = frames::views(&images);
        let likelihood = AcquireConfig::default().likelihood;
        let mut bufs = search::buffers(&sequence.cameras, likelihood.stride_px);
        let maps = search::edge_maps(&mut bufs, &views, &likelihood);
        let scene = Scene::new(&sequence.model, &sequence.cameras, &views, &maps);
        test(rig, &sequence, &scene);
    }
}

#[test]
fn the_search_keeps_its_budget_and_goes_on_where_it_left_off() {
    on_first_frames(|rig, sequence, scene| {
        let config = AcquireConfig::default();
        let mut acquirer = search::acquirer(sequence, config);
        // The budget is per camera: a stereo step scores as many hypotheses as a mono one.
        let budget = acquirer.budget(sequence.cameras.len());
        assert_eq!(
            usize::from(budget),
            usize::from(config.evaluations_per_frame) * sequence.cameras.len(),
            "{rig}"
        );
        let (mut steps, mut last) = (0, 0);
        let found = loop {
            match acquirer.step(scene) {
                Progress::Searching { evaluated } => {
                    // The item under way is finished: a step overruns by less than one item,
                    // and an item is one hypothesis scored in every camera.
                    assert!(
                        evaluated < budget + acquirer.largest_item_cost,
                        "{rig} step {steps}: {evaluated}, largest item {}",
                        acquirer.largest_item_cost
                    );
                    assert!(
                        usize::from(acquirer.largest_item_cost) <= sequence.cameras.len(),
                        "{}",
                        acquirer.largest_item_cost
                    );
                    assert!(
                        acquirer.evaluations > last,
                        "{rig} step {steps} did nothing"
                    );
                    last = acquirer.evaluations;
                }
                Progress::Found(leaf) => break leaf,
            }
            steps += 1;
            assert!(steps < 10_000, "the search never ends");
        };
        println!(
            "{rig}: found after {steps} steps, {} hypotheses, score {:.2}",
            acquirer.evaluations, found.score
        );
        // Measured: 6 steps in mono, 5 in stereo (a per-camera budget).
        assert!(
            steps > 3,
            "a {budget}-evaluation budget spreads the search over frames: {steps} steps"
        );
        // The coarse level's cheaper evaluations charged at half, the library's poses tried on
        // the first tree level only: 6 frames in mono, 11 in stereo (10 and 20 before).
        let most = if sequence.cameras.len() == 1 { 7 } else { 12 };
        assert!(steps <= most, "{rig}: the search took {steps} frames");
        assert!(found.score > 0.5 && acquirer.best().len() > 1);
    });
}

#[test]
fn a_step_after_evaluations_spent_elsewhere_spends_only_what_is_left() {
    on_first_frames(|rig, sequence, scene| {
        let config = AcquireConfig::default();
        let budget = search::acquirer(sequence, config).budget(sequence.cameras.len());
        for spent in [0, budget / 3, budget - 1, budget, budget.saturating_mul(4)] {
            let mut acquirer = search::acquirer(sequence, config);
            let Progress::Searching { evaluated } = acquirer.step_after(scene, spent) else {
                panic!("{rig}: one step found the hand");
            };
            let left = budget.saturating_sub(spent).max(1);
            assert!(
                evaluated < left + acquirer.largest_item_cost,
                "{rig}, {spent} spent: {evaluated} evaluated, {left} left"
            );
            assert!(
                acquirer.evaluations > 0,
                "{rig}, {spent} spent: the search still moves on"
            );
            if spent == 0 {
                let mut plain = search::acquirer(sequence, config);
                assert_eq!(
                    plain.step(scene),
                    Progress::Searching { evaluated },
                    "{rig}: nothing spent elsewhere is the plain step"
                );
            }
        }
    });
}

#[test]
fn a_frame_of_leaves_after_work_elsewhere_refines_one_leaf_fewer() {
    on_first_frames(|rig, sequence, scene| {
        // The whole search on the first step; no leaf ever accepted, so each is counted.
        let acquire = AcquireConfig {
            evaluations_per_frame: u16::MAX,
            ..AcquireConfig::default()
        };
        let config = FinderConfig {
            accept: AcceptConfig {
                min_score: 2.0,
                min_camera_score: 2.0,
                one_camera_score: 2.0,
                ..AcceptConfig::default()
            },
            ..FinderConfig::default()
        };
        let refined_after = |spent: u16| {
            let (mut tracker, mut finder) = finder(sequence, acquire, config);
            let (views, maps) = (scene.frames, scene.edges);
            let mut refined = Vec::new();
            for _ in 0..3 {
                match finder.step_after(&mut tracker, views, maps, spent).unwrap() {
                    FinderStep::Searching { refined: n, .. } => refined.push(n),
                    FinderStep::Found { .. } => panic!("{rig}: a leaf accepted over the bar"),
                }
            }
            refined
        };
        let per_frame = config.leaves_per_frame;
        assert_eq!(
            refined_after(0),
            vec![0, per_frame, per_frame],
            "{rig}: the search, then its leaves"
        );
        assert_eq!(
            refined_after(20),
            vec![0, per_frame - 1, per_frame - 1],
            "{rig}: work spent elsewhere takes one leaf's place"
        );
    });
}

/// `rig` at `seed` (34 frames, 320×240) searched from nothing by the status machine under
/// `tracker`: per frame, whether a hand was claimed within 5 px of the truth, and the line
/// `y` (claimed, right) / `n` (claimed, wrong) / `.` (none).
fn acquisition(
    dir: &std::path::Path,
    rig: &str,
    seed: u64,
    tracker: TrackerConfig,
    finder: FinderConfig,
) -> (Vec<bool>, String) {
    let sequence = common::seeded(dir, rig, seed, 34);
    let truth = sequence.read_truth().unwrap();
    let (mut auto, mut bufs) = search::searching_with(&sequence, AcquireConfig::default(), tracker);
    auto.set_finder(finder);
    let (mut good, mut line) = (Vec::new(), String::new());
    for k in 0..sequence.frames {
        let images = frames::images(&sequence, k);
        let views = frames::views(&images);
        let mut b: Vec<&mut [u8]> = bufs.iter_mut().map(|b| b.as_mut_slice()).collect();
        let r = auto.step(&views, &mut b).unwrap();
        let claimed = r.status == Status::Tracking && !r.report.lost;
        let t: Vec<f32> = truth.rows[k].iter().map(|&v| v as f32).collect();
        let ok = claimed
            && search::tip_error_px(&sequence.model, &sequence.cameras, auto.state(), &t) <= 5.0;
        line.push(if ok {
            'y'
        } else if claimed {
            'n'
        } else {
            '.'
        });
        good.push(ok);
    }
    (good, line)
}

/// The first frame before `before` from which the hand is held right for 5 frames.
fn acquired_before(good: &[bool], before: usize) -> Option<usize> {
    (0..before).find(|&k| good[k..k + 5].iter().all(|&g| g))
}

#[test]
fn the_hand_is_acquired_from_nothing_on_rigs_the_sweep_acquires() {
    // Tuning seeds the probe acquires with the defaults (docs/recovery.md), through the
    // status machine `track` and the board run; 10 px at 640 wide is 5 px here, held 5
    // frames, starting before frame 30 — and in stereo before frame 10, which a search
    // whose budget is not per camera (it ended on frame 12) cannot. (With the per-camera
    // budget, 21 of the 40 stereo tuning seeds 101–140 are acquired before frame 15, 17 of
    // them on frame 6 or 7. Under the sweep's varied lighting mono 133 and stereo 139 are no
    // longer acquired at 5 px, and 134 and 108 took their places. Under the region rows at
    // weight 1 with the class margin, 9 of the 40 mono tuning seeds are acquired at 5 px as
    // before, but 134 is no longer one of them, and 136, acquired either way, takes its place;
    // 22 of the 40 stereo ones before frame 10 as before, but not 107 and 108, and 111 and
    // 112 take their places. Since one camera's acceptance bars a reverse chamfer term over
    // 3.5 px, 136's leaves, 4.8 px off, leave 4.0 px of the image's edges unexplained and
    // are refused; 104 takes its place.)
    let dir = tempfile::tempdir().unwrap();
    for (rig, seed, before) in [
        ("random-mono", 113, 30),
        ("random-mono", 104, 30),
        ("random-stereo", 111, 10),
        ("random-stereo", 113, 10),
        ("random-stereo", 104, 10),
        ("random-stereo", 112, 10),
    ] {
        let (good, line) = acquisition(
            dir.path(),
            rig,
            seed,
            TrackerConfig::default(),
            FinderConfig::default(),
        );
        println!("{rig} {seed}: {line}");
        assert!(
            acquired_before(&good, before).is_some(),
            "{rig} {seed} was not acquired before frame {before}: {line}"
        );
    }
}

#[test]
fn leaves_are_refined_under_the_searchs_robust_weight_not_the_trackers() {
    // Under Tukey's weight at 5 px an edge farther than 5 px from its prediction pulls
    // nothing, and a search leaf starts farther than that: when the leaves were refined
    // under the tracker's own weight, a tracker configured with it no longer acquired
    // `random-mono` seed 133 (docs/robustness.md). Leaves are refined under
    // `FinderConfig::leaf_robust` (Huber 2 px), so a Tukey tracker still acquires. (Since the
    // sweep's lighting is varied, 133 is not acquired at 5 px under either weight; 134 was,
    // until the region rows' weight 1; 136 was, until one camera's acceptance barred a
    // reverse chamfer term over 3.5 px; with that bar 134 is again, and is not with its
    // leaves refined under Tukey 5 px, checked by hand: `acquire_probe --seeds 134..=134
    // --rigs mono --limit-px 10 --leaf-robust tukey=5`.)
    let dir = tempfile::tempdir().unwrap();
    let mut tukey = TrackerConfig::default();
    tukey.estimator.robust = Robust::Tukey(5.0);
    assert_ne!(FinderConfig::default().leaf_robust, tukey.estimator.robust);
    let (good, line) = acquisition(
        dir.path(),
        "random-mono",
        134,
        tukey,
        FinderConfig::default(),
    );
    println!("random-mono 134 under Tukey 5 px: {line}");
    assert!(
        acquired_before(&good, 30).is_some(),
        "random-mono 134 was not acquired before frame 30 under Tukey: {line}"
    );
}

#[test]
fn leaves_are_refined_without_the_trackers_edge_direction_test() {
    // A leaf starts turned from the hand, so the image's edges run at an angle to the ones
    // it predicts: under the tracker's edge-direction test (30 degrees by default) its
    // refinement refuses the edges that would pull it in, and `random-stereo` seed 112 is
    // not acquired. Leaves are refined with the test off
    // (`FinderConfig::leaf_max_edge_angle_rad`). (A seed that shows it, not a sweep's
    // verdict: at 5 px, with the tracker's outermost edge, 23 of the 40 stereo seeds 101-140
    // are acquired with the leaves' test off and 20 with it on, but 16 and 20 of 801-830;
    // docs/recovery.md. The seed was 817 before the lighting was varied, 803 before the
    // outermost edge, 108 until the search's budget of 100 a frame, under which 108 is
    // acquired either way, and 124 until sines and cosines were computed in single precision
    // (stop 54), which moved its run by rounding. Of the even seeds 102-160, 142 and 146 were
    // then acquired only with the leaves' test off, 116 and 138 only with it on, 18 either
    // way. Since the slice window narrowed to 16 px (stop 72) 142 is acquired with neither;
    // of the stereo seeds 101-500 (`acquire_probe --seeds 101..=500 --rigs stereo
    // --limit-px 10 --fill-weight 0 --settle-frames 0`, with and without
    // `--leaf-angle-deg 30`) 25 are acquired only with the leaves' test off, 112 among them,
    // 21 only with it on, 250 either way: a mechanism shown on one seed, not a verdict.)
    // The tracker runs without its region rows here, and without the free settling after
    // an acquisition (`settle_frames` 0): both pull the strict leaves in as well, which
    // hides the edge test's effect.
    let dir = tempfile::tempdir().unwrap();
    let mut tracker = TrackerConfig::default();
    tracker.fill = FillConfig::OFF;
    let angle = tracker.features.max_edge_angle_rad;
    let finder = FinderConfig {
        settle_frames: 0,
        ..FinderConfig::default()
    };
    assert!(
        angle < finder.leaf_max_edge_angle_rad,
        "the test is on by default"
    );
    let (good, line) = acquisition(dir.path(), "random-stereo", 112, tracker, finder);
    println!("random-stereo 112, leaves without the test: {line}");
    assert!(
        acquired_before(&good, 30).is_some(),
        "random-stereo 112 not acquired before frame 30: {line}"
    );
    let strict = FinderConfig {
        leaf_max_edge_angle_rad: angle,
        ..finder
    };
    let (good, line) = acquisition(dir.path(), "random-stereo", 112, tracker, strict);
    println!("random-stereo 112, leaves under the tracker's test: {line}");
    assert!(
        acquired_before(&good, 30).is_none(),
        "random-stereo 112 acquired with leaves under the tracker's edge test: {line}"
    );
}

#[test]
fn the_library_pose_that_scores_best_is_the_nearest_the_hand() {
    // `Acquirer::best_pose` (the local re-acquisition's extra start) chooses among the
    // library's finger poses by the likelihood. Under the true palm on `fullhand-stereo`'s
    // first frame (a relaxed, slightly spread hand), started from a fist, it keeps the palm,
    // scores best of all the poses, and is nearer the true fingers than most of them. (Not
    // the nearest: the likelihood scores the open hand 0.909 here, the relaxed one, nearest
    // the truth, 0.877; the fist and the pointing hand score lowest. Gauss-Newton refines
    // the chosen start before the acceptance judges it.)
    search::on_the_true_first_frame(|f| {
        let TrueFrame {
            sequence,
            truth,
            mut acquirer,
            scene,
        } = f;
        let n = sequence.n_states();
        let fist = acquirer.with_pose(&truth, FingerPose::Fist as usize);
        let (chosen, score) = acquirer.best_pose(&scene, &fist);
        assert_eq!(chosen[..7], truth[..7], "the palm is kept");
        let distance = |p: &[f32; MAX_STATES]| -> f32 {
            (7..n)
                .map(|i| (p[i] - truth[i]).powi(2))
                .sum::<f32>()
                .sqrt()
        };
        let poses: Vec<[f32; MAX_STATES]> = (0..POSE_COUNT)
            .map(|p| acquirer.with_pose(&truth, p))
            .collect();
        for (p, posed) in poses.iter().enumerate() {
            let s = acquirer.score(&scene, posed);
            println!(
                "pose {p}: {:.2} rad from the fingers, score {s:.3}",
                distance(posed)
            );
            assert!(s <= score, "pose {p} scores {s} over the chosen {score}");
        }
        let mut distances: Vec<f32> = poses.iter().map(&distance).collect();
        distances.sort_by(f32::total_cmp);
        let median = distances[POSE_COUNT / 2];
        assert!(
            distance(&chosen) < median && distance(&chosen) < distance(&fist),
            "chose a pose {:.2} rad from the fingers; the library's median is {median:.2}, the \
             fist {:.2}",
            distance(&chosen),
            distance(&fist)
        );
    });
}
