//! Image-plane effects after ray casting: optical blur, sensor noise and 8-bit quantisation.

use image::GrayImage;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// Blurs a `width × height` image in place with a separable Gaussian of standard deviation
/// `sigma` (px); edges are clamped. No-op for `sigma <= 0`.
pub fn gaussian_blur(img: &mut [f32], width: usize, height: usize, sigma: f32) {
    if sigma <= 0.0 || !sigma.is_finite() {
        return;
    }
    let radius = (3.0 * sigma).ceil() as isize;
    let mut kernel: Vec<f32> = (-radius..=radius)
        .map(|i| (-(i * i) as f32 / (2.0 * sigma * sigma)).exp())
        .collect();
    let sum: f32 = kernel.iter().sum();
    kernel.iter_mut().for_each(|k| *k /= sum);
    let mut tmp = vec![0.0f32; img.len()];
    let clamp = |i: isize, n: usize| i.clamp(0, n as isize - 1) as usize;
    for y in 0..height {
        let row = &img[y * width..(y + 1) * width];
        for x in 0..width {
            let mut acc = 0.0;
            for (k, w) in kernel.iter().enumerate() {
                acc += w * row[clamp(x as isize + k as isize - radius, width)];
            }
            tmp[y * width + x] = acc;
        }
    }
    for y in 0..height {
        for x in 0..width {
            let mut acc = 0.0;
            for (k, w) in kernel.iter().enumerate() {
                acc += w * tmp[clamp(y as isize + k as isize - radius, height) * width + x];
            }
            img[y * width + x] = acc;
        }
    }
}

/// Adds zero-mean Gaussian noise of standard deviation `sigma` (grey levels), drawn from
/// `seed`. No-op for `sigma <= 0`.
pub fn add_noise(img: &mut [f32], sigma: f32, seed: u64) {
    if sigma.is_nan() || sigma <= 0.0 {
        return;
    }
    let Ok(normal) = Normal::new(0.0f32, sigma) else {
        return;
    };
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    for v in img.iter_mut() {
        *v += normal.sample(&mut rng);
    }
}

/// Rounds to 8-bit grey levels, clamping to 0–255.
pub fn quantise(img: &[f32], width: usize, height: usize) -> GrayImage {
    let pixels = img
        .iter()
        .map(|v| v.round().clamp(0.0, 255.0) as u8)
        .collect();
    GrayImage::from_raw(width as u32, height as u32, pixels)
        .unwrap_or_else(|| GrayImage::new(width as u32, height as u32))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blur_keeps_the_mean_and_softens_a_step() {
        let (w, h) = (20, 3);
        let mut img: Vec<f32> = (0..w * h)
            .map(|i| if i % w < 10 { 0.0 } else { 100.0 })
            .collect();
        gaussian_blur(&mut img, w, h, 1.0);
        assert!((img[9] - 50.0).abs() < 30.0 && img[9] > 5.0);
        assert!((img[0]).abs() < 1e-3 && (img[19] - 100.0).abs() < 1e-3);
    }

    #[test]
    fn noise_has_the_requested_spread() {
        let mut img = vec![100.0f32; 20_000];
        add_noise(&mut img, 8.0, 1);
        let mean = img.iter().sum::<f32>() / img.len() as f32;
        let var = img.iter().map(|v| (v - mean).powi(2)).sum::<f32>() / img.len() as f32;
        assert!((mean - 100.0).abs() < 0.3 && (var.sqrt() - 8.0).abs() < 0.3);
    }
}
