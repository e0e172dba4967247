//! A region's shading residual with one finger free (`likelihood::shading_cache`): the fixed
//! part of the hand found once gives the sums the slow way gives (`shading::residual_in`),
//! pixel for pixel, on rigs nobody tuned it for (random-mono and random-stereo seeds
//! 401..=407, odd); a region too large for the cache is refused; and the refinement moves
//! every finger the same with the cache as without it.

use digiteyes_core::hypotheses::fingers::Fingers;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::likelihood::shading::{fit, residual_in, PixelCost, RegionScoring};
use digiteyes_core::likelihood::shading_cache::{moving_frames, ShadingCache, MAX_CACHED_PIXELS};
use digiteyes_core::likelihood::shading_refine::{refine_finger, ShadingRefineConfig};
use digiteyes_core::nalgebra::Vector2;
use digiteyes_core::projection::{Bounds, ProjectedModel};
use digiteyes_core::silhouette::hand_bounds;
use digiteyes_host::sequence::Sequence;

mod common;

use common::shading::scored;

use common::frames;

/// Seeds, each rendered 6 frames at 320×240.
fn seeds() -> impl Iterator<Item = u64> {
    (0..4).map(|i| 401 + 2 * i)
}

/// Camera `c`'s view of state `q`, every link in it however short.
fn view_of(sequence: &Sequence, c: usize, q: &[f32]) -> ProjectedModel {
    let poses = Poses::compute(&sequence.model, q).unwrap();
    let mut view = ProjectedModel::new();
    view.update(&sequence.model, &poses, &sequence.cameras[c], 0.0);
    view
}

/// Finger `f`'s joint states.
fn joints_of(sequence: &Sequence, fingers: &Fingers, f: usize) -> Vec<usize> {
    (0..sequence.model.n_states())
        .filter(|&s| fingers.contains(f, s))
        .collect()
}

/// `q` with joint `s` moved `rad`, within its range.
fn moved(sequence: &Sequence, q: &[f32], s: usize, rad: f32) -> Vec<f32> {
    let limit = sequence.model.limit(s).unwrap();
    let mut out = q.to_vec();
    out[s] = (out[s] + rad).clamp(limit.lo, limit.hi);
    out
}

#[test]
fn the_cache_gives_the_slow_sums_pixel_for_pixel() {
    let dir = tempfile::tempdir().unwrap();
    let mut compared = 0;
    for scenario in ["random-mono", "random-stereo"] {
        for seed in seeds() {
            let sequence = common::seeded(dir.path(), scenario, seed, 6);
            let fingers = Fingers::of(&sequence.model);
            let truth = frames::truth_states(&sequence);
            for k in [0, 5] {
                let images = frames::images(&sequence, k);
                let views = frames::views(&images);
                for (c, (camera, frame)) in sequence.cameras.iter().zip(&views).enumerate() {
                    let start = view_of(&sequence, c, &truth[k]);
                    let Some(found) = fit(&start, camera, frame, 64) else {
                        continue;
                    };
                    // The whole hand, widened: a region the fingers' moves stay inside.
                    let hand = hand_bounds(&start).unwrap();
                    let pad = Vector2::new(15.0, 15.0);
                    let region = Bounds {
                        min: hand.min - pad,
                        max: hand.max + pad,
                    };
                    for f in 0..fingers.count() {
                        let joints = joints_of(&sequence, &fingers, f);
                        let moving = moving_frames(&sequence.model, &joints);
                        // Capped residuals on every other finger: the same sums either way.
                        let cost = if f % 2 == 0 {
                            PixelCost::SQUARE
                        } else {
                            PixelCost::capped_at(30.0)
                        };
                        // The light's term clamped on fingers 2 and 3: the same sums too.
                        let scoring = RegionScoring {
                            clamp_light: (2..4).contains(&f),
                            ..scored(&found.terms, &region, 2.0, cost)
                        };
                        let mut cache = ShadingCache::default();
                        let kept = cache
                            .fill(&start, camera, frame, &scoring, &moving)
                            .expect("the hand's region fits at 320 x 240");
                        for &s in &joints {
                            for rad in [-0.3, 0.05, 0.4] {
                                let trial =
                                    view_of(&sequence, c, &moved(&sequence, &truth[k], s, rad));
                                let fast = cache
                                    .residual(&kept, &trial, camera, frame, &moving)
                                    .unwrap();
                                let slow = residual_in(&trial, camera, frame, &scoring).unwrap();
                                assert_eq!(
                                    fast, slow,
                                    "{scenario} {seed} frame {k} finger {f} state {s} {rad}"
                                );
                                compared += 1;
                            }
                        }
                    }
                }
            }
        }
    }
    println!("{compared} trials summed both ways, bit for bit");
    assert!(compared > 300, "{compared}");
}

#[test]
fn a_region_beyond_the_room_left_is_refused_and_clear_makes_room() {
    let dir = tempfile::tempdir().unwrap();
    let sequence = common::seeded(dir.path(), "random-mono", 401, 1);
    let q = &frames::truth_states(&sequence)[0];
    let images = frames::images(&sequence, 0);
    let views = frames::views(&images);
    let (camera, frame) = (&sequence.cameras[0], &views[0]);
    let view = view_of(&sequence, 0, q);
    let terms = fit(&view, camera, frame, 64).unwrap().terms;
    let moving = moving_frames(&sequence.model, &[]);
    // 96 × 64 pixels at step 1: 6,144, of which the cache holds one region but not two.
    let region = Bounds {
        min: Vector2::new(100.0, 100.0),
        max: Vector2::new(195.0, 163.0),
    };
    let scoring = scored(&terms, &region, 1.0, PixelCost::SQUARE);
    let mut cache = ShadingCache::default();
    const { assert!(6144 <= MAX_CACHED_PIXELS && MAX_CACHED_PIXELS < 2 * 6144) };
    let first = cache.fill(&view, camera, frame, &scoring, &moving);
    assert!(first.is_some());
    assert_eq!(
        cache.fill(&view, camera, frame, &scoring, &moving),
        None,
        "a second region of that size does not fit"
    );
    // The first is still there and sums what the slow way sums (nothing moves).
    let slow = residual_in(&view, camera, frame, &scoring).unwrap();
    assert_eq!(slow.points, 6144);
    assert_eq!(
        cache.residual(first.as_ref().unwrap(), &view, camera, frame, &moving),
        Some(slow)
    );
    let first = first.unwrap();
    cache.clear();
    assert_eq!(
        cache.residual(&first, &view, camera, frame, &moving),
        None,
        "a region kept before a clear is gone"
    );
    let again = cache.fill(&view, camera, frame, &scoring, &moving);
    assert_eq!(
        cache.residual(&again.unwrap(), &view, camera, frame, &moving),
        Some(slow)
    );
    // A cache with no room keeps nothing; a region outside the frame is none at all.
    let mut none = ShadingCache::with_room(0);
    assert_eq!(none.fill(&view, camera, frame, &scoring, &moving), None);
    let outside = Bounds {
        min: Vector2::new(500.0, 10.0),
        max: Vector2::new(600.0, 20.0),
    };
    assert_eq!(
        cache.fill(
            &view,
            camera,
            frame,
            &scored(&terms, &outside, 1.0, PixelCost::SQUARE),
            &moving
        ),
        None
    );
}

#[test]
fn the_refinement_moves_every_finger_the_same_with_the_cache_as_without() {
    let dir = tempfile::tempdir().unwrap();
    let mut refined = 0;
    for scenario in ["random-mono", "random-stereo"] {
        for seed in seeds() {
            let sequence = common::seeded(dir.path(), scenario, seed, 6);
            let fingers = Fingers::of(&sequence.model);
            let k = 5;
            let images = frames::images(&sequence, k);
            let views = frames::views(&images);
            let truth = &frames::truth_states(&sequence)[k];
            for f in 0..fingers.count() {
                // Capped residuals on every other finger: the same moves either way.
                let config = ShadingRefineConfig {
                    residual_cap_grey: if f % 2 == 0 { 0.0 } else { 30.0 },
                    ..ShadingRefineConfig::default()
                };
                // The finger's flexions bent 0.12 rad off, as the refinement's tests do.
                let mut off = truth.clone();
                for &s in joints_of(&sequence, &fingers, f).iter().skip(1) {
                    off = moved(&sequence, &off, s, 0.12);
                }
                let run = |mut cache: ShadingCache| {
                    let mut q = off.clone();
                    let mut poses = Poses::compute(&sequence.model, &q).unwrap();
                    let mut view = ProjectedModel::new();
                    let outcome = refine_finger(
                        &sequence.model,
                        &sequence.cameras,
                        &views,
                        &fingers,
                        f,
                        &mut q,
                        &mut poses,
                        &mut view,
                        &mut cache,
                        &config,
                    );
                    (q, outcome)
                };
                let (fast, with) = run(ShadingCache::default());
                let (slow, without) = run(ShadingCache::with_room(0));
                assert_eq!(fast, slow, "{scenario} {seed} finger {f}");
                assert_eq!((with.moves, with.trials), (without.moves, without.trials));
                assert_eq!(with.uncached_cameras, 0, "{scenario} {seed} finger {f}");
                assert_eq!(
                    usize::from(without.uncached_cameras),
                    sequence.cameras.len()
                );
                refined += usize::from(with.moves > 0);
            }
        }
    }
    println!("{refined} fingers moved, the same with the cache as without");
    assert!(refined >= 10, "{refined}");
}
