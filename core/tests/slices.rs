//! The 1-D slice search on synthetic profiles with known sub-pixel edge positions.

use digiteyes_core::features::{
    edge_runs_along, find_edge, find_outermost_edge, find_valley, FeatureConfig, Polarity,
};
use digiteyes_core::frame::FrameView;
use nalgebra::Vector2;

/// A box-filtered step from `hi` (inside) to `lo` (outside) at sub-pixel position `edge`,
/// sampled at pixel centres 0..n: what a pixel sees of an ideal edge.
fn step_profile(n: usize, edge: f32, hi: f32, lo: f32) -> Vec<f32> {
    (0..n)
        .map(|k| {
            let covered = (edge - (k as f32 - 0.5)).clamp(0.0, 1.0);
            lo + (hi - lo) * covered
        })
        .collect()
}

/// Deterministic Gaussian-ish noise (sum of uniforms) so the tests are repeatable.
fn noise(seed: &mut u64, sigma: f32) -> f32 {
    let mut sum = 0.0;
    for _ in 0..12 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        sum += (*seed >> 40) as f32 / (1u64 << 24) as f32;
    }
    (sum - 6.0) * sigma
}

#[test]
fn step_edges_are_found_to_a_tenth_of_a_pixel() {
    let mut worst = 0.0f32;
    for i in 0..=70 {
        let edge = 6.0 + i as f32 * 0.1;
        let p = step_profile(20, edge, 160.0, 25.0);
        let found = find_edge(&p, Polarity::DarkOutside, 4.0).expect("edge");
        worst = worst.max((found.position - edge).abs());
    }
    assert!(worst < 0.1, "worst sub-pixel error {worst} px");
}

#[test]
fn noisy_step_edges_stay_within_a_third_of_a_pixel() {
    let mut seed = 7u64;
    let (mut sum, mut worst, mut n) = (0.0f32, 0.0f32, 0);
    for i in 0..200 {
        let edge = 6.0 + (i % 70) as f32 * 0.1;
        let mut p = step_profile(20, edge, 140.0, 30.0);
        for v in &mut p {
            *v += noise(&mut seed, 4.0);
        }
        let found = find_edge(&p, Polarity::DarkOutside, 4.0).expect("edge");
        let e = (found.position - edge).abs();
        sum += e;
        worst = worst.max(e);
        n += 1;
    }
    let mean = sum / n as f32;
    assert!(mean < 0.15, "mean error {mean} px with noise σ 4");
    assert!(worst < 0.6, "worst error {worst} px with noise σ 4");
}

#[test]
fn the_wrong_sign_is_not_an_edge_unless_any_sign_is_asked() {
    let p = step_profile(20, 9.3, 25.0, 160.0); // dark inside, bright outside
    assert!(find_edge(&p, Polarity::DarkOutside, 4.0).is_none());
    let found = find_edge(&p, Polarity::Any, 4.0).expect("edge of either sign");
    assert!((found.position - 9.3).abs() < 0.1);
}

#[test]
fn the_strongest_of_two_edges_wins() {
    let mut p = step_profile(24, 15.2, 160.0, 25.0);
    for (k, v) in p.iter_mut().enumerate() {
        if k < 5 {
            *v += 20.0; // a weaker step further inside
        }
    }
    let found = find_edge(&p, Polarity::DarkOutside, 4.0).expect("edge");
    assert!((found.position - 15.2).abs() < 0.1, "{}", found.position);
}

/// Two steps down: an inner one from `hi` to `mid` at `inner`, an outer one from `mid` to
/// `lo` at `outer`: a hand-bright surface, a darker one beside it, then the background.
fn two_steps(n: usize, inner: f32, outer: f32, [hi, mid, lo]: [f32; 3]) -> Vec<f32> {
    let a = step_profile(n, inner, hi, mid);
    let b = step_profile(n, outer, mid, lo);
    a.iter().zip(&b).map(|(x, y)| x + y - mid).collect()
}

#[test]
fn the_outermost_edge_at_least_a_share_of_the_strongest_wins() {
    // The inner step drops 80 grey levels, the outer 55 (0.69 of it).
    let p = two_steps(24, 6.2, 15.2, [160.0, 80.0, 25.0]);
    let strongest = find_edge(&p, Polarity::DarkOutside, 4.0).expect("edge");
    assert!(
        (strongest.position - 6.2).abs() < 0.1,
        "{}",
        strongest.position
    );
    let outer = find_outermost_edge(&p, Polarity::DarkOutside, 4.0, 0.5).expect("edge");
    assert!((outer.position - 15.2).abs() < 0.1, "{}", outer.position);
    // Asked for 0.8 of the strongest, the outer step is too weak: the strongest stays.
    let inner = find_outermost_edge(&p, Polarity::DarkOutside, 4.0, 0.8).expect("edge");
    assert!((inner.position - 6.2).abs() < 0.1, "{}", inner.position);
    // A share above 1, or NaN, is taken as 1: the strongest, never nothing.
    for share in [1.5, f32::NAN] {
        let e = find_outermost_edge(&p, Polarity::DarkOutside, 4.0, share).expect("edge");
        assert!(
            (e.position - 6.2).abs() < 0.1,
            "share {share}: {}",
            e.position
        );
    }
}

#[test]
fn with_one_edge_the_outermost_is_the_strongest() {
    for i in 0..=40 {
        let p = step_profile(20, 6.0 + i as f32 * 0.17, 150.0, 30.0);
        assert_eq!(
            find_outermost_edge(&p, Polarity::DarkOutside, 4.0, 0.5),
            find_edge(&p, Polarity::DarkOutside, 4.0)
        );
    }
    assert!(find_outermost_edge(&[80.0; 20], Polarity::Any, 4.0, 0.5).is_none());
    assert!(find_outermost_edge(&[], Polarity::Any, 4.0, 0.5).is_none());
    let wrong_sign = step_profile(20, 9.3, 25.0, 160.0);
    assert!(find_outermost_edge(&wrong_sign, Polarity::DarkOutside, 4.0, 0.5).is_none());
}

#[test]
fn flat_short_and_faint_profiles_have_no_edge() {
    assert!(find_edge(&[80.0; 20], Polarity::Any, 4.0).is_none());
    assert!(find_edge(&[0.0, 255.0, 0.0], Polarity::Any, 4.0).is_none());
    assert!(find_edge(&[], Polarity::Any, 4.0).is_none());
    let faint = step_profile(20, 9.0, 30.0, 27.0);
    assert!(find_edge(&faint, Polarity::DarkOutside, 4.0).is_none());
}

#[test]
fn a_valley_between_two_shaded_surfaces_is_found() {
    // Left surface darkens toward its silhouette (shading), the right one starts darker and
    // brightens: the boundary is the minimum, not the steepest descent.
    let mut worst = 0.0f32;
    for i in 0..40 {
        let boundary = 7.0 + i as f32 * 0.15;
        let intensity = |x: f32| {
            if x < boundary {
                (100.0 + 9.0 * (boundary - x)).min(170.0)
            } else {
                100.0 + 6.0 * (x - boundary)
            }
        };
        // Box-filter each pixel by supersampling.
        let p: Vec<f32> = (0..20)
            .map(|k| {
                (0..16)
                    .map(|j| intensity(k as f32 - 0.5 + (j as f32 + 0.5) / 16.0))
                    .sum::<f32>()
                    / 16.0
            })
            .collect();
        let found = find_valley(&p, 4.0).expect("valley");
        worst = worst.max((found.position - boundary).abs());
        let steepest = find_edge(&p, Polarity::DarkOutside, 4.0).expect("descent");
        assert!(
            steepest.position < boundary - 1.0,
            "the descent is inside the boundary"
        );
    }
    assert!(worst < 0.35, "worst valley error {worst} px");
}

#[test]
fn shallow_valleys_are_rejected() {
    let p: Vec<f32> = (0..20)
        .map(|k| 100.0 + ((k as f32) - 10.0).abs() * 0.2)
        .collect();
    assert!(find_valley(&p, 4.0).is_none());
}

/// A 64×64 image, bright on the side of the line through (32, 32) opposite `normal` and dark
/// beyond it, with a one-pixel ramp: an edge whose outward normal is `normal`.
fn oblique_edge(normal: Vector2<f32>) -> Vec<u8> {
    let mut image = vec![0u8; 64 * 64];
    for y in 0..64 {
        for x in 0..64 {
            let d = normal.dot(&Vector2::new(x as f32 - 32.0, y as f32 - 32.0));
            let inside = (0.5 - d).clamp(0.0, 1.0);
            image[y * 64 + x] = (30.0 + 150.0 * inside) as u8;
        }
    }
    image
}

#[test]
fn an_edge_is_kept_only_when_it_runs_along_the_predicted_one() {
    let limit = 30f32.to_radians().tan();
    let centre = Vector2::new(32.0f32, 32.0);
    // Slices along the image axes and oblique to them: the stencil is the image's.
    for slice_deg in [0.0f32, 37.0, 135.0, -100.0] {
        let s = slice_deg.to_radians();
        let outward = Vector2::new(s.cos(), s.sin());
        for (degrees, kept) in [
            (0.0f32, true),
            (20.0, true),
            (-25.0, true),
            (40.0, false),
            (70.0, false),
            (90.0, false),
        ] {
            let a = s + degrees.to_radians();
            let image = oblique_edge(Vector2::new(a.cos(), a.sin()));
            let frame = FrameView::packed(&image, 64, 64).unwrap();
            assert_eq!(
                edge_runs_along(&frame, centre, outward, limit),
                kept,
                "an edge turned {degrees} degrees from a slice at {slice_deg} degrees"
            );
        }
    }
    let outward = Vector2::new(1.0f32, 0.0);
    // Where the stencil leaves the frame there is nothing to judge.
    let image = oblique_edge(Vector2::new(0.0, 1.0));
    let frame = FrameView::packed(&image, 64, 64).unwrap();
    assert!(edge_runs_along(
        &frame,
        Vector2::new(0.2, 32.0),
        outward,
        limit
    ));
}

#[test]
fn the_angle_limit_is_off_at_a_right_angle_and_the_tangent_below_it() {
    let mut config = FeatureConfig::default();
    let limit = config.edge_tangent_limit().expect("on by default");
    assert!(
        (limit - 30f32.to_radians().tan()).abs() < 1e-5,
        "30 degrees by default"
    );
    config.max_edge_angle_rad = core::f32::consts::FRAC_PI_2;
    assert_eq!(config.edge_tangent_limit(), None, "off at a right angle");
    config.max_edge_angle_rad = -1.0;
    assert_eq!(config.edge_tangent_limit(), Some(0.0));
}
