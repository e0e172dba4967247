//! What the camera sees behind the hand: a plain dark grey, or seeded clutter (a gradient,
//! textured rectangles and soft blobs) that puts distracting edges near the hand.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The plain background's grey level (0–255), clearly darker than the hand.
pub const PLAIN_GREY: f32 = 20.0;

/// The background behind the hand.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Background {
    /// A uniform grey level (0–255).
    Plain(f32),
    /// A cluttered, textured scene drawn from this seed (grey levels about 5–150).
    Clutter {
        /// Seed of the random scene.
        seed: u64,
    },
}

impl Default for Background {
    fn default() -> Self {
        Background::Plain(PLAIN_GREY)
    }
}

/// The background image, `width × height` grey levels (0–255), row-major.
pub fn background_image(width: usize, height: usize, background: Background) -> Vec<f32> {
    match background {
        Background::Plain(grey) => vec![grey; width * height],
        Background::Clutter { seed } => clutter(width, height, seed),
    }
}

fn clutter(width: usize, height: usize, seed: u64) -> Vec<f32> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x0063_6c75_7474_6572);
    let (w, h) = (width as f32, height as f32);
    let scale = w.max(h) / 640.0;
    // A gradient in a random direction.
    let angle: f32 = rng.random_range(0.0..std::f32::consts::TAU);
    let (s, c) = angle.sin_cos();
    let (g0, g1): (f32, f32) = (rng.random_range(10.0..30.0), rng.random_range(40.0..70.0));
    let half_diag = 0.5 * (w * w + h * h).sqrt();
    let mut img = Vec::with_capacity(width * height);
    for y in 0..height {
        for x in 0..width {
            let along = ((x as f32 - 0.5 * w) * c + (y as f32 - 0.5 * h) * s) / half_diag;
            img.push(g0 + (g1 - g0) * 0.5 * (along + 1.0));
        }
    }
    // Rotated rectangles, some striped.
    for _ in 0..28 {
        let cx = rng.random_range(0.0..w);
        let cy = rng.random_range(0.0..h);
        let hw = rng.random_range(8.0..90.0) * scale;
        let hh = rng.random_range(4.0..50.0) * scale;
        let angle: f32 = rng.random_range(0.0..std::f32::consts::PI);
        let grey: f32 = rng.random_range(5.0..140.0);
        let stripe = if rng.random_bool(0.35) {
            rng.random_range(4.0..14.0) * scale
        } else {
            0.0
        };
        let (s, c) = angle.sin_cos();
        let reach = hw.hypot(hh);
        let (x0, x1) = span(cx, reach, width);
        let (y0, y1) = span(cy, reach, height);
        for y in y0..y1 {
            for x in x0..x1 {
                let (dx, dy) = (x as f32 - cx, y as f32 - cy);
                let (a, b) = (dx * c + dy * s, -dx * s + dy * c);
                if a.abs() <= hw && b.abs() <= hh {
                    let dark_stripe = stripe > 0.0 && (a / stripe).rem_euclid(2.0) < 1.0;
                    img[y * width + x] = if dark_stripe { 0.5 * grey } else { grey };
                }
            }
        }
    }
    // Soft blobs.
    for _ in 0..14 {
        let cx = rng.random_range(0.0..w);
        let cy = rng.random_range(0.0..h);
        let sigma = rng.random_range(10.0..50.0) * scale;
        let amp: f32 = rng.random_range(-30.0..60.0);
        let (x0, x1) = span(cx, 3.0 * sigma, width);
        let (y0, y1) = span(cy, 3.0 * sigma, height);
        for y in y0..y1 {
            for x in x0..x1 {
                let r2 = (x as f32 - cx).powi(2) + (y as f32 - cy).powi(2);
                img[y * width + x] += amp * (-r2 / (2.0 * sigma * sigma)).exp();
            }
        }
    }
    // A fine texture over everything.
    let (fx, fy, phase) = (
        rng.random_range(0.05..0.2f32),
        rng.random_range(0.05..0.2f32),
        rng.random_range(0.0..6.0f32),
    );
    for y in 0..height {
        for x in 0..width {
            let t = (x as f32 * fx + phase).sin() * (y as f32 * fy).cos();
            let v = &mut img[y * width + x];
            *v = (*v + 6.0 * t).clamp(0.0, 160.0);
        }
    }
    img
}

/// Pixel index range `[lo, hi)` covering `centre ± reach`, clipped to `0..len`.
fn span(centre: f32, reach: f32, len: usize) -> (usize, usize) {
    let lo = (centre - reach).floor().max(0.0) as usize;
    let hi = ((centre + reach).ceil().max(0.0) as usize + 1).min(len);
    (lo.min(len), hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clutter_is_seeded_and_textured() {
        let a = background_image(64, 48, Background::Clutter { seed: 3 });
        let b = background_image(64, 48, Background::Clutter { seed: 3 });
        let c = background_image(64, 48, Background::Clutter { seed: 4 });
        assert_eq!(a, b);
        assert_ne!(a, c);
        let (lo, hi) = a
            .iter()
            .fold((f32::MAX, f32::MIN), |(l, h), &v| (l.min(v), h.max(v)));
        assert!(hi - lo > 30.0 && lo >= 0.0 && hi <= 160.0);
    }
}
