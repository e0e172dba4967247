//! The image likelihood (issue 10) orders hypotheses: on frames from our renderer, on rigs
//! nobody tuned for (random-mono seeds 201..=215; the parameters were chosen on 101..=105),
//! the true state scores better than the same state perturbed — always for a palm moved
//! 30 mm or turned 40°, in at least 39 of 40 cases for smaller perturbations — and a frame
//! without the hand scores the true state poorly. Its reverse chamfer term rises when a
//! finger is bent off its edges.

use digiteyes_core::frame::FrameView;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::likelihood::{evaluate, EdgeMap, Likelihood, LikelihoodConfig, Scene};
use digiteyes_core::projection::ProjectedModel;
use digiteyes_host::sequence::Sequence;

mod common;

fn score(sequence: &Sequence, k: usize, q: &[f32], blank: bool) -> Likelihood {
    score_under(sequence, k, q, blank, &LikelihoodConfig::default())
}

/// The likelihood of `q` at frame `k` of camera 0 under `config`; with `blank`, of the
/// background alone (the first pixel's grey everywhere).
fn score_under(
    sequence: &Sequence,
    k: usize,
    q: &[f32],
    blank: bool,
    config: &LikelihoodConfig,
) -> Likelihood {
    let mut image = sequence.read_frame(0, k).unwrap();
    if blank {
        let grey = image.as_raw()[0];
        image.as_mut().fill(grey);
    }
    let frame = FrameView::packed(
        image.as_raw(),
        image.width() as usize,
        image.height() as usize,
    )
    .unwrap();
    let mut buffer =
        vec![0u8; EdgeMap::bytes_needed(frame.width(), frame.height(), config.stride_px)];
    let edges = EdgeMap::build(&mut buffer, &frame, config).unwrap();
    let camera = &sequence.cameras[0];
    let poses = Poses::compute(&sequence.model, q).unwrap();
    let mut view = ProjectedModel::new();
    view.update(&sequence.model, &poses, camera, 4.0);
    evaluate(&view, camera, &frame, &edges, config)
}

/// The true state of `sequence`'s first frame.
fn first_true_state(sequence: &Sequence) -> Vec<f32> {
    let truth = sequence.read_truth().unwrap();
    truth.rows[0].iter().map(|&v| v as f32).collect()
}

/// `q` with the palm moved `dx` mm along x, turned `angle` rad about its z axis, and every
/// finger joint flexed by `bend` rad.
fn perturbed(q: &[f32], dx: f32, angle: f32, bend: f32) -> Vec<f32> {
    let mut p = q.to_vec();
    p[4] += dx;
    let (c, s) = ((angle / 2.0).cos(), (angle / 2.0).sin());
    let (w, x, y, z) = (q[0], q[1], q[2], q[3]);
    // q ⊗ (c, 0, 0, s)
    p[0] = w * c - z * s;
    p[1] = x * c + y * s;
    p[2] = y * c - x * s;
    p[3] = z * c + w * s;
    for v in p.iter_mut().skip(7) {
        *v += bend;
    }
    p
}

#[test]
fn the_true_state_scores_better_than_perturbed_ones() {
    let dir = tempfile::tempdir().unwrap();
    let mut worse = 0;
    let mut cases = 0;
    let mut margins = Vec::new();
    let randoms = (0..8).map(|i| ("random-mono", 201 + 2 * i));
    for (scenario, seed) in [("fullhand-mono", 1)].into_iter().chain(randoms) {
        let sequence = common::seeded(dir.path(), scenario, seed, 20);
        let truth = sequence.read_truth().unwrap();
        for k in [0, 10, 19] {
            let q: Vec<f32> = truth.rows[k].iter().map(|&v| v as f32).collect();
            let at_truth = score(&sequence, k, &q, false);
            assert!(
                at_truth.score > 0.5,
                "{scenario} {seed} frame {k}: {at_truth:?}"
            );
            for (dx, angle, bend) in [
                (15.0, 0.0, 0.0),
                (-30.0, 0.0, 0.0),
                (0.0, 0.35, 0.0),
                (0.0, -0.7, 0.0),
                (0.0, 0.0, 0.4),
                (10.0, 0.2, -0.3),
            ] {
                let other = score(&sequence, k, &perturbed(&q, dx, angle, bend), false);
                cases += 1;
                margins.push(at_truth.score - other.score);
                let large = dx.abs() >= 30.0 || angle.abs() >= 0.7;
                assert!(
                    !large || other.score < at_truth.score,
                    "{scenario} {seed} frame {k}: a large perturbation ({dx} mm, {angle} rad) \
                     scores {:.3} >= the truth's {:.3}",
                    other.score,
                    at_truth.score
                );
                if other.score >= at_truth.score {
                    worse += 1;
                    println!(
                        "{scenario} {seed} frame {k}: ({dx}, {angle}, {bend}) scores {:.3} >= truth {:.3} ({other:?} vs {at_truth:?})",
                        other.score, at_truth.score
                    );
                }
            }
            let blank = score(&sequence, k, &q, true);
            assert!(
                blank.score < at_truth.score - 0.3,
                "{scenario} {seed} frame {k}: no hand {:.3}, hand {:.3}",
                blank.score,
                at_truth.score
            );
        }
    }
    margins.sort_by(f32::total_cmp);
    println!(
        "{cases} perturbations: truth better in {}; margin min {:.3}, median {:.3}",
        cases - worse,
        margins[0],
        margins[margins.len() / 2]
    );
    // Small perturbations of curled fingers can hide as much of the silhouette as the truth
    // does: measured on these seeds, 1 in 162 ties within 0.003 (docs/recovery.md).
    assert!(
        worse * 40 <= cases,
        "the truth scored best in only {} of {cases}",
        cases - worse
    );
}

/// `evaluate` sums the chamfer term point by point as `likelihood::visit` makes the points,
/// with no buffer: the same figures, bit for bit, as `Samples::of` and `Samples::chamfer`
/// over the same points, on the truth and on perturbed states (some points hidden, some
/// outside the frame).
#[test]
fn the_chamfer_summed_as_points_are_made_is_the_buffered_samples() {
    use digiteyes_core::likelihood::Samples;
    use digiteyes_core::nalgebra::Vector2;
    let dir = tempfile::tempdir().unwrap();
    let config = LikelihoodConfig::default();
    let mut compared = 0;
    let mut with_hidden = 0;
    let mut with_outside = 0;
    for (scenario, seed) in [("fullhand-mono", 1), ("random-mono", 203)] {
        let sequence = common::seeded(dir.path(), scenario, seed, 1);
        let q = first_true_state(&sequence);
        let image = sequence.read_frame(0, 0).unwrap();
        let (w, h) = (image.width() as usize, image.height() as usize);
        let frame = FrameView::packed(image.as_raw(), w, h).unwrap();
        let mut buffer = vec![0u8; EdgeMap::bytes_needed(w, h, config.stride_px)];
        let edges = EdgeMap::build(&mut buffer, &frame, &config).unwrap();
        let camera = &sequence.cameras[0];
        for (dx, angle, bend) in [(0.0, 0.0, 0.0), (40.0, 0.5, 0.6), (-400.0, 0.0, -0.2)] {
            let p = perturbed(&q, dx, angle, bend);
            let poses = Poses::compute(&sequence.model, &p).unwrap();
            let mut view = ProjectedModel::new();
            view.update(&sequence.model, &poses, camera, 4.0);
            let streamed = evaluate(&view, camera, &frame, &edges, &config);
            let samples = Samples::of(&view, camera, &config);
            let (chamfer, inside) =
                samples.chamfer(&edges, Vector2::zeros(), config.chamfer_cap_px);
            let label = format!("{scenario} {seed} ({dx}, {angle}, {bend})");
            assert_eq!(streamed.points_hidden, samples.hidden, "{label}");
            assert_eq!(streamed.points, inside, "{label}");
            assert_eq!(
                streamed.points_outside as usize,
                samples.points.len() - usize::from(inside),
                "{label}"
            );
            if inside > 0 {
                assert_eq!(streamed.chamfer_px.to_bits(), chamfer.to_bits(), "{label}");
            }
            compared += 1;
            with_hidden += usize::from(samples.hidden > 0);
            with_outside += usize::from(streamed.points_outside > 0);
        }
    }
    assert_eq!(compared, 6);
    assert!(with_hidden > 0, "no view had hidden points");
    assert!(with_outside > 0, "no view had points outside the frame");
}

/// The states the bound and silhouette tests score: the truth and perturbations of it, near
/// and far, so that some score high and some low.
fn scored_states(q: &[f32]) -> Vec<Vec<f32>> {
    let mut states = Vec::new();
    for dx in [0.0, 8.0, -25.0, 60.0] {
        for angle in [0.0, 0.3, -0.9] {
            for bend in [0.0, 0.4, -0.3] {
                states.push(perturbed(q, dx, angle, bend));
            }
        }
    }
    states
}

/// `StateScorer::score_above` gives `score`'s mean bit for bit whenever it gives a score,
/// and gives none only when that mean is at or under the bar: it skips only terms that
/// could not lift the score over. On the truth and 35 perturbations of it, in one camera
/// and two, against bars below, at and above each state's score.
#[test]
fn the_bounded_score_is_the_score_or_proves_it_is_under_the_bar() {
    use digiteyes_core::likelihood::StateScorer;
    let dir = tempfile::tempdir().unwrap();
    let config = LikelihoodConfig::default();
    let (mut scored, mut refused, mut silhouettes_skipped, mut cameras_skipped) = (0, 0, 0, 0);
    for (scenario, seed) in [("random-mono", 203), ("random-stereo", 204)] {
        let sequence = common::seeded(dir.path(), scenario, seed, 1);
        let q = first_true_state(&sequence);
        let images: Vec<_> = (0..sequence.cameras.len())
            .map(|k| sequence.read_frame(k, 0).unwrap())
            .collect();
        let frames: Vec<FrameView> = images
            .iter()
            .map(|i| FrameView::packed(i.as_raw(), i.width() as usize, i.height() as usize))
            .collect::<Result<_, _>>()
            .unwrap();
        let mut buffers: Vec<Vec<u8>> = frames
            .iter()
            .map(|f| vec![0u8; EdgeMap::bytes_needed(f.width(), f.height(), config.stride_px)])
            .collect();
        let edges: Vec<EdgeMap> = buffers
            .iter_mut()
            .zip(&frames)
            .map(|(b, f)| EdgeMap::build(b, f, &config).unwrap())
            .collect();
        let cameras = &sequence.cameras;
        let mut scorer = StateScorer::new();
        for p in scored_states(&q) {
            let scene = Scene::new(&sequence.model, cameras, &frames, &edges);
            let score = scorer.score(&scene, &p, &config);
            // A judged leaf's score and reverse term, posed once, are the two computed apart,
            // whether the likelihood weighs the term or not.
            for weight in [0.0, 0.8] {
                let weighed = LikelihoodConfig {
                    reverse_weight: weight,
                    ..config
                };
                let (mean, worst) = scorer.score_cameras(&scene, &p, &weighed);
                let reverse = scorer.worst_reverse_px(&scene, &p, &weighed);
                let (m, w, r) = scorer.score_cameras_and_reverse(&scene, &p, &weighed);
                assert_eq!(
                    (m.to_bits(), w.to_bits(), r.map(f32::to_bits)),
                    (mean.to_bits(), worst.to_bits(), reverse.map(f32::to_bits)),
                    "{scenario} {seed}, reverse weight {weight}"
                );
            }
            for bar in [
                f32::NEG_INFINITY,
                score - 0.05,
                score - 1e-6,
                score,
                score + 0.02,
                0.6,
                0.85,
            ] {
                let bounded = scorer.score_above(&scene, &p, &config, bar);
                let label = format!("{scenario} {seed}: score {score}, bar {bar}");
                match bounded.score {
                    Some(s) => {
                        assert_eq!(s.to_bits(), score.to_bits(), "{label}");
                        assert_eq!(bounded.edge_terms as usize, cameras.len(), "{label}");
                        scored += 1;
                    }
                    None => {
                        assert!(score <= bar, "{label}: refused a score over its bar");
                        refused += 1;
                        silhouettes_skipped +=
                            usize::from(bounded.silhouette_terms < bounded.edge_terms);
                        cameras_skipped +=
                            usize::from((bounded.edge_terms as usize) < cameras.len());
                    }
                }
                if bar < score {
                    assert!(
                        bounded.score.is_some(),
                        "{label}: refused a score over its bar"
                    );
                }
            }
        }
    }
    assert!(
        scored > 0 && refused > 0,
        "scored {scored}, refused {refused}"
    );
    assert!(silhouettes_skipped > 0, "no silhouette term was skipped");
    assert!(cameras_skipped > 0, "no camera was skipped");
}

/// The silhouette score counts each class's grey levels in histograms and tests only the
/// parts whose bounds span a grid row; a plain per-point count over every part (the score
/// as first written) gives the same figures, bit for bit, at the search's grids.
#[test]
fn the_silhouette_score_is_the_plain_per_point_count() {
    use digiteyes_core::nalgebra::Vector2;
    use digiteyes_core::silhouette::{self, covers, hand_bounds, MARGIN, MIN_CLASS_SAMPLES};
    let dir = tempfile::tempdir().unwrap();
    let mut compared = 0;
    for (scenario, seed) in [
        ("fullhand-mono", 1),
        ("random-mono", 203),
        ("random-mono", 205),
    ] {
        let sequence = common::seeded(dir.path(), scenario, seed, 1);
        let q = first_true_state(&sequence);
        let image = sequence.read_frame(0, 0).unwrap();
        let (w, h) = (image.width() as usize, image.height() as usize);
        let frame = FrameView::packed(image.as_raw(), w, h).unwrap();
        let camera = &sequence.cameras[0];
        for p in scored_states(&q) {
            let poses = Poses::compute(&sequence.model, &p).unwrap();
            let mut view = ProjectedModel::new();
            view.update(&sequence.model, &poses, camera, 4.0);
            for grid in [10usize, 16, 24] {
                let fast = silhouette::score(&view, camera, &frame, grid);
                // The plain count.
                let plain = hand_bounds(&view).and_then(|bounds| {
                    let size = bounds.max - bounds.min;
                    let min = bounds.min - size * MARGIN;
                    let step = size * (1.0 + 2.0 * MARGIN) / (grid - 1) as f32;
                    let mut samples = Vec::new();
                    let (mut sum, mut sum_sq, mut count) = ([0.0f32; 2], [0.0f32; 2], [0u32; 2]);
                    for j in 0..grid {
                        for i in 0..grid {
                            let x = min.x + step.x * i as f32;
                            let y = min.y + step.y * j as f32;
                            let Some(v) = frame.sample(x, y) else {
                                continue;
                            };
                            let k = usize::from(covers(&view, camera, &Vector2::new(x, y)));
                            samples.push(((v + 0.5) as u8, k));
                            sum[k] += v;
                            sum_sq[k] += v * v;
                            count[k] += 1;
                        }
                    }
                    if count[0] < MIN_CLASS_SAMPLES || count[1] < MIN_CLASS_SAMPLES {
                        return None;
                    }
                    let mean = [sum[0] / count[0] as f32, sum[1] / count[1] as f32];
                    let var = [
                        (sum_sq[0] / count[0] as f32 - mean[0] * mean[0]).max(0.0),
                        (sum_sq[1] / count[1] as f32 - mean[1] * mean[1]).max(0.0),
                    ];
                    let contrast = mean[1] - mean[0];
                    let threshold = 0.5 * (mean[0] + mean[1]);
                    let agree = samples
                        .iter()
                        .filter(|(v, k)| (f32::from(*v) > threshold) == (*k == 1))
                        .count() as u32;
                    Some(silhouette::SilhouetteScore {
                        contrast,
                        separation: contrast * contrast / (var[0] + var[1]).max(1.0),
                        agreement: agree as f32 / (count[0] + count[1]) as f32,
                        inside: count[1],
                        outside: count[0],
                    })
                });
                assert_eq!(fast, plain, "{scenario} {seed}, grid {grid}");
                compared += usize::from(plain.is_some());
            }
        }
    }
    assert!(compared > 200, "only {compared} scores compared");
}

/// Each finger of `sequence`'s model: its joint states (all past the palm's 7) and its tip.
fn fingers(sequence: &Sequence) -> Vec<(Vec<usize>, usize)> {
    let model = &sequence.model;
    ["finger1", "finger2", "finger3", "finger4", "thumb"]
        .iter()
        .map(|name| {
            let tip = model.find(&format!("{name}.tip")).unwrap();
            let joints = model
                .chain(tip)
                .unwrap()
                .iter()
                .map(|&s| usize::from(s))
                .filter(|&s| s >= digiteyes_core::model::BASE_STATES)
                .collect();
            (joints, tip)
        })
        .collect()
}

#[test]
fn a_finger_bent_off_its_edges_leaves_them_unexplained() {
    // The reverse chamfer term: edges near the hand that no model line explains. One finger
    // bent 0.6 rad further at each joint (within its range) leaves its true edges without a
    // line, so the term rises, wherever the bent finger's own lines happen to find edges;
    // and the score with the term orders the truth above the bent finger at least as often
    // as without it. Judged where the bend moves the fingertip over 10 px in the image.
    let dir = tempfile::tempdir().unwrap();
    let config = LikelihoodConfig {
        reverse_weight: 1.0,
        ..LikelihoodConfig::default()
    };
    let plain = LikelihoodConfig::default();
    let (mut cases, mut higher, mut score_lower, mut plain_lower) = (0, 0, 0, 0);
    for seed in (0..8).map(|i| 201 + 2 * i) {
        let sequence = common::seeded(dir.path(), "random-mono", seed, 20);
        let truth = sequence.read_truth().unwrap();
        let camera = &sequence.cameras[0];
        for k in [0, 10, 19] {
            let q: Vec<f32> = truth.rows[k].iter().map(|&v| v as f32).collect();
            let at_truth = score_under(&sequence, k, &q, false, &config);
            let plain_truth = score_under(&sequence, k, &q, false, &plain).score;
            let truth_poses = Poses::compute(&sequence.model, &q).unwrap();
            for (joints, tip) in fingers(&sequence) {
                let mut bent = q.clone();
                for &j in &joints {
                    let limit = sequence.model.limit(j).unwrap();
                    bent[j] = (bent[j] + 0.6).clamp(limit.lo, limit.hi);
                }
                let poses = Poses::compute(&sequence.model, &bent).unwrap();
                let moved = match (
                    truth_poses.origin(tip).and_then(|p| camera.project(&p)),
                    poses.origin(tip).and_then(|p| camera.project(&p)),
                ) {
                    (Some(a), Some(b)) => (a - b).norm(),
                    _ => continue,
                };
                if moved <= 10.0 {
                    continue;
                }
                let other = score_under(&sequence, k, &bent, false, &config);
                let (Some(t), Some(o)) = (at_truth.reverse_px, other.reverse_px) else {
                    continue;
                };
                cases += 1;
                higher += usize::from(o > t);
                score_lower += usize::from(other.score < at_truth.score);
                plain_lower += usize::from(
                    score_under(&sequence, k, &bent, false, &plain).score < plain_truth,
                );
            }
        }
    }
    println!(
        "{cases} fingers bent: the reverse term higher on {higher}, the score lower on \
         {score_lower} with it, {plain_lower} without"
    );
    // Measured: 113 fingers, the term higher on 102, the score lower on 111 with it and 109
    // without.
    assert!(cases >= 60, "{cases}");
    assert!(
        higher * 100 >= cases * 85,
        "higher on only {higher} of {cases}"
    );
    assert!(
        score_lower >= plain_lower && score_lower * 100 >= cases * 95,
        "lower on {score_lower} of {cases} with the term, {plain_lower} without"
    );
}
