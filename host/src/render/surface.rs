//! What the hand's surface does with the light beyond a matte, even grey: each part's own
//! albedo, a glossy highlight, and the shadows the hand casts on itself.
//!
//! The tracker's shading fit (`digiteyes_core::likelihood::shading`) models the hand as one
//! matte grey under one light, exactly as the default renderer draws it. A [`Surface`] breaks
//! that on purpose, so a measurement can say how much of what the fit buys is the renderer
//! agreeing with it: `render --surface varied` and `bench robustness --surface varied` draw
//! one per seed ([`Surface::varied`]) from a stream of its own, so the rig, the motion, the
//! noise and the light stay those of the matte seed.

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The hand's surface: how each ray's hit is shaded besides [`super::Lighting`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Surface {
    /// Each part's albedo is the light's, times `1 + spread · u` with `u` in −1..1 drawn per
    /// part (palm, each finger link) from `seed`: 0 for one grey.
    pub albedo_spread: f64,
    /// Peak of the Blinn–Phong highlight, as a fraction of the albedo (0 for none).
    pub specular: f64,
    /// The highlight's exponent (larger: smaller and sharper).
    pub shininess: f64,
    /// Points that another part hides from the light get the ambient share alone.
    pub cast_shadows: bool,
    /// Draws the parts' albedo factors.
    pub seed: u64,
}

/// Mixed into a seed for [`Surface::varied`]'s draws, a stream apart from the scenario's.
const SURFACE_STREAM: u64 = 0x5_0f7a_ce00_d1ce;

/// How far above a surface a shadow ray starts (mm), so it does not hit its own surface.
const SHADOW_RAY_LIFT_MM: f64 = 0.01;

impl Default for Surface {
    /// Matte and even: what the renderer always drew, what the tracker's shading fit assumes.
    fn default() -> Self {
        Surface {
            albedo_spread: 0.0,
            specular: 0.0,
            shininess: 1.0,
            cast_shadows: false,
            seed: 0,
        }
    }
}

impl Surface {
    /// A surface drawn from `seed`: parts' albedo within ±10–25 % of each other, a highlight
    /// of 15–50 % of the albedo with exponent 8–40, and cast shadows.
    pub fn varied(seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ SURFACE_STREAM);
        Surface {
            albedo_spread: rng.random_range(0.10..0.25),
            specular: rng.random_range(0.15..0.5),
            shininess: rng.random_range(8.0..40.0),
            cast_shadows: true,
            seed: rng.random(),
        }
    }

    /// Whether the surface is the default's matte, even grey.
    pub fn is_matte(&self) -> bool {
        *self == Surface::default()
    }

    /// The albedo factor of part `part` (its index among the model's shapes): the same in
    /// every frame and camera.
    pub fn albedo_factor(&self, part: usize) -> f64 {
        if self.albedo_spread == 0.0 {
            return 1.0;
        }
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed.wrapping_add(part as u64));
        1.0 + self.albedo_spread * rng.random_range(-1.0..1.0)
    }

    /// The highlight's share of the albedo at a point with unit normal `normal`, seen along
    /// the unit ray `ray` (from the camera) and lit from the unit direction `toward_light`.
    pub fn highlight(
        &self,
        normal: &Vector3<f64>,
        ray: &Vector3<f64>,
        toward_light: &Vector3<f64>,
    ) -> f64 {
        if self.specular == 0.0 || normal.dot(toward_light) <= 0.0 {
            return 0.0;
        }
        let Some(half) = (toward_light - ray).try_normalize(1e-12) else {
            return 0.0;
        };
        self.specular * normal.dot(&half).max(0.0).powf(self.shininess)
    }

    /// Where a shadow ray starts: the hit at distance `t` along the unit ray `ray`, lifted off
    /// the surface along its `normal`.
    pub fn shadow_origin(t: f64, ray: &Vector3<f64>, normal: &Vector3<f64>) -> Vector3<f64> {
        ray * t + normal * SHADOW_RAY_LIFT_MM
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_is_matte_and_even() {
        let s = Surface::default();
        assert!(s.is_matte());
        assert_eq!(s.albedo_factor(3), 1.0);
        let n = Vector3::new(0.0, 0.0, -1.0);
        assert_eq!(s.highlight(&n, &Vector3::new(0.0, 0.0, 1.0), &n), 0.0);
    }

    #[test]
    fn a_varied_surface_is_drawn_from_its_seed() {
        let (a, b) = (Surface::varied(7), Surface::varied(8));
        assert_eq!(a, Surface::varied(7));
        assert_ne!(a, b);
        assert!(!a.is_matte() && a.cast_shadows);
        let factors: Vec<f64> = (0..16).map(|p| a.albedo_factor(p)).collect();
        assert!(factors
            .iter()
            .all(|f| (f - 1.0).abs() <= a.albedo_spread + 1e-12));
        assert!(factors.iter().any(|f| (f - factors[0]).abs() > 1e-3));
        assert_eq!(a.albedo_factor(5), a.albedo_factor(5));
    }

    #[test]
    fn the_highlight_peaks_at_the_mirror_direction() {
        let s = Surface::varied(1);
        let ray = Vector3::new(0.0, 0.0, 1.0);
        let toward_light = Vector3::new(0.0, 0.0, -1.0);
        let facing = Vector3::new(0.0, 0.0, -1.0);
        assert!((s.highlight(&facing, &ray, &toward_light) - s.specular).abs() < 1e-12);
        let tilted = Vector3::new(0.5, 0.0, -1.0).normalize();
        assert!(s.highlight(&tilted, &ray, &toward_light) < 0.5 * s.specular);
        let away = Vector3::new(0.0, 0.0, 1.0);
        assert_eq!(s.highlight(&away, &ray, &toward_light), 0.0);
    }
}
