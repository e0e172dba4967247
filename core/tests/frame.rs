//! `FrameView`: construction errors, strides, and bilinear sampling on images whose exact
//! values are known (a linear ramp is reproduced exactly by bilinear interpolation).

use digiteyes_core::frame::{FrameError, FrameView};
use digiteyes_core::nalgebra::Vector2;

/// Intensity of the ramp image at integer or fractional (x, y).
fn ramp(x: f32, y: f32) -> f32 {
    10.0 + 3.0 * x + 7.0 * y
}

/// A `w × h` ramp image with rows `stride` bytes apart; padding bytes are 255, a value the
/// ramp never takes, so reading one shows up.
fn ramp_image(w: usize, h: usize, stride: usize) -> Vec<u8> {
    assert!(ramp((w - 1) as f32, (h - 1) as f32) < 255.0);
    let mut data = vec![255u8; stride * h];
    for y in 0..h {
        for x in 0..w {
            data[y * stride + x] = ramp(x as f32, y as f32) as u8;
        }
    }
    data
}

#[test]
fn new_error_paths() {
    let data = [0u8; 100];
    assert_eq!(
        FrameView::new(&data, 0, 5, 5).unwrap_err(),
        FrameError::ZeroSize
    );
    assert_eq!(
        FrameView::new(&data, 5, 0, 5).unwrap_err(),
        FrameError::ZeroSize
    );
    assert_eq!(
        FrameView::new(&data, 10, 2, 9).unwrap_err(),
        FrameError::StrideTooSmall
    );
    // A 10 × 10 frame with stride 12 needs 9 · 12 + 10 = 118 bytes: the last row's padding
    // is not required.
    assert_eq!(
        FrameView::new(&data, 10, 10, 12).unwrap_err(),
        FrameError::BufferTooSmall {
            needed: 118,
            got: 100
        }
    );
    assert_eq!(
        FrameView::packed(&data, 11, 10).unwrap_err(),
        FrameError::BufferTooSmall {
            needed: 110,
            got: 100
        }
    );
    let exact = [0u8; 118];
    assert!(FrameView::new(&exact, 10, 10, 12).is_ok());
    assert!(FrameView::new(&exact[..117], 10, 10, 12).is_err());
    // stride · (height − 1) overflows usize: too small, never a wrapped size.
    assert_eq!(
        FrameView::new(&data, 4, 3, usize::MAX / 2 + 1).unwrap_err(),
        FrameError::BufferTooSmall {
            needed: usize::MAX,
            got: 100
        }
    );
    assert!(matches!(
        FrameView::new(&data, usize::MAX, 2, usize::MAX),
        Err(FrameError::BufferTooSmall { .. })
    ));
    // Error texts carry the numbers.
    let text = FrameError::BufferTooSmall {
        needed: 118,
        got: 100,
    }
    .to_string();
    assert!(text.contains("118") && text.contains("100"), "{text}");
}

#[test]
fn accessors_and_pixels() {
    let data = ramp_image(8, 6, 11);
    let f = FrameView::new(&data, 8, 6, 11).unwrap();
    assert_eq!((f.width(), f.height(), f.stride()), (8, 6, 11));
    for y in 0..6 {
        for x in 0..8 {
            assert_eq!(f.pixel(x, y), Some(ramp(x as f32, y as f32) as u8));
        }
    }
    // Padding columns 8..11 are not pixels.
    assert_eq!(f.pixel(8, 0), None);
    assert_eq!(f.pixel(10, 0), None);
    assert_eq!(f.pixel(0, 6), None);
    assert_eq!(f.pixel(usize::MAX, usize::MAX), None);
    // A row is its `width` pixels, without the padding; none below the last.
    for y in 0..6 {
        let row = f.row(y).unwrap();
        assert_eq!(row.len(), 8);
        for (x, &v) in row.iter().enumerate() {
            assert_eq!(Some(v), f.pixel(x, y));
        }
    }
    assert_eq!(f.row(6), None);
    assert_eq!(f.row(usize::MAX), None);
}

#[test]
fn sampling_is_exact_at_pixel_centres() {
    for stride in [8, 13] {
        let data = ramp_image(8, 6, stride);
        let f = FrameView::new(&data, 8, 6, stride).unwrap();
        for y in 0..6 {
            for x in 0..8 {
                assert_eq!(
                    f.sample(x as f32, y as f32),
                    Some(f32::from(f.pixel(x, y).unwrap())),
                    "({x}, {y}), stride {stride}"
                );
            }
        }
    }
    // A non-linear image too: centres return the stored byte, not a blend.
    let data: Vec<u8> = (0..20u32).map(|i| (i * i * 7 % 251) as u8).collect();
    let f = FrameView::packed(&data, 5, 4).unwrap();
    for y in 0..4 {
        for x in 0..5 {
            assert_eq!(
                f.sample(x as f32, y as f32),
                Some(f32::from(data[y * 5 + x]))
            );
        }
    }
}

#[test]
fn bilinear_sampling_reproduces_a_linear_ramp() {
    // Bilinear interpolation of a linear function is the function itself, so sub-pixel
    // samples have known values; padding (255) would break that if it were read.
    let data = ramp_image(8, 6, 11);
    let f = FrameView::new(&data, 8, 6, 11).unwrap();
    // Dyadic fractions: exact in f32.
    for &(x, y) in &[
        (2.25, 3.75),
        (0.5, 0.5),
        (6.5, 4.5),
        (7.0, 4.25),
        (6.75, 5.0),
        (7.0, 5.0),
        (0.0, 0.125),
    ] {
        assert_eq!(f.sample(x, y), Some(ramp(x, y)), "({x}, {y})");
    }
    // Arbitrary points: exact up to f32 rounding.
    for i in 0..=70 {
        for j in 0..=50 {
            let (x, y) = (i as f32 * 0.1, j as f32 * 0.1);
            let got = f.sample(x, y).unwrap();
            assert!((got - ramp(x, y)).abs() < 1e-4, "({x}, {y}): {got}");
        }
    }
}

#[test]
fn sampling_outside_the_frame_or_at_nan_is_none() {
    let data = ramp_image(8, 6, 8);
    let f = FrameView::packed(&data, 8, 6).unwrap();
    // The valid region is [0, w − 1] × [0, h − 1] = [0, 7] × [0, 5], edges included.
    assert!(f.sample(7.0, 5.0).is_some());
    assert!(f.sample(0.0, 0.0).is_some());
    for &(x, y) in &[
        (-0.001, 0.0),
        (0.0, -0.001),
        (7.001, 0.0),
        (0.0, 5.001),
        (7.5, 2.0),
        (-1.0, -1.0),
        (1e30, 1.0),
        (f32::NAN, 1.0),
        (1.0, f32::NAN),
        (f32::INFINITY, 1.0),
        (1.0, f32::NEG_INFINITY),
    ] {
        assert_eq!(f.sample(x, y), None, "({x}, {y})");
    }
}

#[test]
fn one_pixel_and_one_row_frames() {
    let f = FrameView::packed(&[42], 1, 1).unwrap();
    assert_eq!(f.sample(0.0, 0.0), Some(42.0));
    assert_eq!(f.sample(0.5, 0.0), None);
    assert_eq!(f.sample(0.0, 0.5), None);
    let row = [10u8, 20, 40];
    let f = FrameView::packed(&row, 3, 1).unwrap();
    assert_eq!(f.sample(0.5, 0.0), Some(15.0));
    assert_eq!(f.sample(1.5, 0.0), Some(30.0));
    assert_eq!(f.sample(2.0, 0.0), Some(40.0));
    assert_eq!(f.sample(1.0, 0.25), None);
    let column = [10u8, 20, 40];
    let f = FrameView::packed(&column, 1, 3).unwrap();
    assert_eq!(f.sample(0.0, 1.25), Some(25.0));
}

#[test]
fn sample_segment_in_and_out_of_bounds() {
    let data = ramp_image(8, 6, 10);
    let f = FrameView::new(&data, 8, 6, 10).unwrap();
    // Five points from (1, 2) in steps of (0.5, 0.75): the last is (3, 5), on the border.
    let mut out = [0.0f32; 5];
    assert!(f.sample_segment(Vector2::new(1.0, 2.0), Vector2::new(0.5, 0.75), &mut out));
    for (k, v) in out.iter().enumerate() {
        let (x, y) = (1.0 + 0.5 * k as f32, 2.0 + 0.75 * k as f32);
        assert_eq!(*v, ramp(x, y), "sample {k}");
    }
    // One step further leaves the frame.
    let mut out = [0.0f32; 6];
    assert!(!f.sample_segment(Vector2::new(1.0, 2.0), Vector2::new(0.5, 0.75), &mut out));
    // Backwards off the left edge, a start outside, non-finite start or step.
    let mut out = [0.0f32; 4];
    assert!(!f.sample_segment(Vector2::new(1.0, 1.0), Vector2::new(-0.5, 0.0), &mut out));
    assert!(!f.sample_segment(Vector2::new(-1.0, 1.0), Vector2::new(1.0, 0.0), &mut out));
    assert!(!f.sample_segment(
        Vector2::new(f32::NAN, 1.0),
        Vector2::new(1.0, 0.0),
        &mut out
    ));
    assert!(!f.sample_segment(
        Vector2::new(1.0, 1.0),
        Vector2::new(f32::INFINITY, 0.0),
        &mut out
    ));
    assert!(!f.sample_segment(
        Vector2::new(1.0, 1.0),
        Vector2::new(0.0, f32::NAN),
        &mut out
    ));
    // Backwards from the far corner stays inside.
    let mut out = [0.0f32; 4];
    assert!(f.sample_segment(Vector2::new(7.0, 5.0), Vector2::new(-2.0, -1.0), &mut out));
    assert_eq!(
        out,
        [
            ramp(7.0, 5.0),
            ramp(5.0, 4.0),
            ramp(3.0, 3.0),
            ramp(1.0, 2.0)
        ]
    );
    // Nothing to sample is trivially fine, even from outside.
    assert!(f.sample_segment(Vector2::new(-5.0, -5.0), Vector2::new(1.0, 1.0), &mut []));
    // A single sample is the point itself.
    let mut one = [0.0f32];
    assert!(f.sample_segment(Vector2::new(2.5, 0.5), Vector2::new(100.0, 100.0), &mut one));
    assert_eq!(one[0], ramp(2.5, 0.5));
}

#[test]
fn sobel_reads_the_ramp_gradient_and_nothing_past_the_border() {
    let (w, h, stride) = (9, 7, 12);
    let data = ramp_image(w, h, stride);
    let frame = FrameView::new(&data, w, h, stride).unwrap();
    // 4 × (I[x+1] − I[x−1]) = 8 × the slope, exactly, on every inner pixel.
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            assert_eq!(frame.sobel(x, y), Some([3 * 8, 7 * 8]), "({x}, {y})");
        }
    }
    for (x, y) in [
        (0, 3),
        (w - 1, 3),
        (4, 0),
        (4, h - 1),
        (w, 3),
        (usize::MAX, usize::MAX),
    ] {
        assert_eq!(frame.sobel(x, y), None, "({x}, {y})");
    }
}
