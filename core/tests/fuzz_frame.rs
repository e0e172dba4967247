//! Property tests of `FrameView`: any dimensions, stride and buffer either make a view or a
//! `FrameError` exactly when the arithmetic says so, and sampling any coordinates never panics
//! and never reads outside the frame.
//!
//! Case counts: 2000 cases per property, three properties (6000 views, each sampled at up to
//! 64 points plus up to 8 segments); well under a second.

use digiteyes_core::frame::{FrameError, FrameView};
use digiteyes_core::nalgebra::Vector2;
use proptest::prelude::*;

const CASES: u32 = 2000;

/// Coordinates: mostly near the frame, sometimes anything an f32 can be.
fn coord() -> impl Strategy<Value = f32> {
    prop_oneof![
        3 => -2.0f32..42.0,
        1 => (0u16..42).prop_map(f32::from),
        1 => any::<f32>(),
        1 => prop::sample::select(vec![
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -0.0,
            f32::MAX,
            f32::MIN,
            f32::EPSILON,
            -f32::EPSILON,
        ]),
    ]
}

/// What `FrameView::new` must decide, from its documented rules.
fn expected(len: usize, w: usize, h: usize, stride: usize) -> Result<(), FrameError> {
    if w == 0 || h == 0 {
        return Err(FrameError::ZeroSize);
    }
    if stride < w {
        return Err(FrameError::StrideTooSmall);
    }
    match stride.checked_mul(h - 1).and_then(|v| v.checked_add(w)) {
        Some(needed) if needed <= len => Ok(()),
        Some(needed) => Err(FrameError::BufferTooSmall { needed, got: len }),
        None => Err(FrameError::BufferTooSmall {
            needed: usize::MAX,
            got: len,
        }),
    }
}

/// Sampling rules that hold for every view.
fn check_sampling(f: &FrameView, points: &[(f32, f32)], segments: &[(f32, f32, f32, f32, usize)]) {
    let (wmax, hmax) = ((f.width() - 1) as f32, (f.height() - 1) as f32);
    for &(x, y) in points {
        let inside = x >= 0.0 && y >= 0.0 && x <= wmax && y <= hmax;
        match f.sample(x, y) {
            Some(v) => {
                assert!(inside, "({x}, {y}) outside {}x{}", f.width(), f.height());
                // Bilinear weights are convex: the value lies within the byte range.
                assert!((0.0..=255.0).contains(&v), "({x}, {y}) -> {v}");
            }
            None => assert!(!inside, "({x}, {y}) inside {}x{}", f.width(), f.height()),
        }
        if x.is_finite() && y.is_finite() && x >= 0.0 && y >= 0.0 {
            let _ = f.pixel(x as usize, y as usize);
            if let Some(row) = f.row(y as usize) {
                assert_eq!(row.len(), f.width());
            }
        }
    }
    for &(sx, sy, dx, dy, n) in segments {
        let mut out = vec![-1.0f32; n];
        if f.sample_segment(Vector2::new(sx, sy), Vector2::new(dx, dy), &mut out) {
            assert!(out.iter().all(|v| (0.0..=255.0).contains(v)), "{out:?}");
        }
    }
}

fn segments() -> impl Strategy<Value = Vec<(f32, f32, f32, f32, usize)>> {
    prop::collection::vec(
        (coord(), coord(), -3.0f32..3.0, -3.0f32..3.0, 0usize..70),
        0..8,
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: CASES, ..ProptestConfig::default() })]

    /// Small frames: every combination of size, stride and buffer length near the boundary.
    #[test]
    fn small_frames(
        w in 0usize..40,
        h in 0usize..40,
        extra in 0usize..8,
        shrink in 0usize..3,
        slack in 0usize..40,
        fill in any::<u8>(),
        points in prop::collection::vec((coord(), coord()), 0..64),
        segs in segments(),
    ) {
        let stride = (w + extra).saturating_sub(shrink);
        // Buffers from a few bytes short of the need to a little over it.
        let need = stride.saturating_mul(h.saturating_sub(1)).saturating_add(w);
        let len = (need + slack).saturating_sub(20);
        let data: Vec<u8> = (0..len).map(|i| (i as u8).wrapping_mul(31) ^ fill).collect();
        let view = FrameView::new(&data, w, h, stride);
        prop_assert_eq!(view.map(|_| ()), expected(len, w, h, stride));
        if let Ok(f) = view {
            check_sampling(&f, &points, &segs);
        }
    }

    /// Any usize dimensions over a small buffer: errors (including overflow), or — for a
    /// single row, whose stride is never multiplied — a view that still samples safely.
    #[test]
    fn huge_dimensions(
        w in prop_oneof![any::<usize>(), 0usize..300],
        h in prop_oneof![any::<usize>(), 0usize..3],
        stride in prop_oneof![any::<usize>(), 0usize..300],
        len in 0usize..300,
        points in prop::collection::vec((coord(), coord()), 0..16),
        segs in segments(),
    ) {
        let data = vec![7u8; len];
        let view = FrameView::new(&data, w, h, stride);
        prop_assert_eq!(view.map(|_| ()), expected(len, w, h, stride));
        if let Ok(f) = view {
            check_sampling(&f, &points, &segs);
        }
    }

    /// A constant image samples to the constant wherever a sample exists.
    #[test]
    fn constant_image_samples_constant(
        w in 1usize..20,
        h in 1usize..20,
        value in any::<u8>(),
        points in prop::collection::vec((coord(), coord()), 1..32),
    ) {
        let data = vec![value; w * h];
        let f = FrameView::packed(&data, w, h).unwrap();
        for (x, y) in points {
            if let Some(v) = f.sample(x, y) {
                prop_assert_eq!(v, f32::from(value));
            }
        }
    }
}
