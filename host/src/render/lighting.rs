//! How the rendered hand is lit: a Lambertian surface under one directional light near the
//! camera, plus ambient light. The built-in scenarios keep [`Lighting::default`]; the random
//! sweep draws its own per seed, so the tracker is not judged under one light alone.

use nalgebra::Vector3;

/// The hand's default albedo: its grey level (0–255) when lit face-on.
pub const ALBEDO: f64 = 200.0;
/// Default fraction of the albedo seen on surfaces facing away from the light.
pub const AMBIENT: f64 = 0.35;
/// Default direction towards the light, camera coordinates (up-left of the camera),
/// unnormalised.
pub const LIGHT: [f64; 3] = [-0.35, -0.5, -1.0];

/// The light on the hand, the same in every camera's own coordinates (a light beside each
/// camera).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lighting {
    /// Grey level (0–255) of a surface facing the light.
    pub albedo: f64,
    /// Fraction of the albedo seen on surfaces facing away from the light (0..=1).
    pub ambient: f64,
    /// Direction towards the light, camera coordinates (+z looks into the scene, so a light
    /// beside the camera has a negative z); need not be normalised.
    pub toward_light: [f64; 3],
}

impl Default for Lighting {
    fn default() -> Self {
        Lighting {
            albedo: ALBEDO,
            ambient: AMBIENT,
            toward_light: LIGHT,
        }
    }
}

impl Lighting {
    /// The light `angle_rad` off the camera's axis, in the image direction `azimuth_rad`
    /// (0: towards +u, π/2: towards +v).
    pub fn beside_camera(albedo: f64, ambient: f64, angle_rad: f64, azimuth_rad: f64) -> Self {
        let (s, c) = angle_rad.sin_cos();
        Lighting {
            albedo,
            ambient,
            toward_light: [s * azimuth_rad.cos(), s * azimuth_rad.sin(), -c],
        }
    }

    /// The darkest grey level the hand can show: a surface facing away from the light.
    pub fn darkest(&self) -> f64 {
        self.albedo * self.ambient
    }

    /// The unit vector towards the light (the default's when the direction is zero or not
    /// finite).
    pub fn unit_toward_light(&self) -> Vector3<f64> {
        Vector3::from(self.toward_light)
            .try_normalize(1e-12)
            .filter(|v| v.iter().all(|x| x.is_finite()))
            .unwrap_or_else(|| Vector3::from(LIGHT).normalize())
    }

    /// The grey level of a surface with unit normal `normal` (camera coordinates), given the
    /// unit vector towards the light.
    pub fn shade(&self, normal: &Vector3<f64>, toward_light: &Vector3<f64>) -> f64 {
        self.albedo * (self.ambient + (1.0 - self.ambient) * normal.dot(toward_light).max(0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_shades_as_the_fixed_light_did() {
        let l = Lighting::default();
        let light = l.unit_toward_light();
        let facing = light;
        assert!((l.shade(&facing, &light) - ALBEDO).abs() < 1e-9);
        let away = -light;
        assert!((l.shade(&away, &light) - ALBEDO * AMBIENT).abs() < 1e-9);
    }

    #[test]
    fn a_light_beside_the_camera_points_back_towards_it() {
        let l = Lighting::beside_camera(180.0, 0.3, 0.5, 1.0);
        let v = l.unit_toward_light();
        assert!((v.norm() - 1.0).abs() < 1e-12);
        assert!((v.z + 0.5f64.cos()).abs() < 1e-12, "{v:?}");
        assert!((l.darkest() - 54.0).abs() < 1e-9);
    }

    #[test]
    fn a_zero_direction_falls_back_to_the_default_light() {
        let l = Lighting {
            toward_light: [0.0; 3],
            ..Lighting::default()
        };
        assert_eq!(l.unit_toward_light(), Vector3::from(LIGHT).normalize());
    }
}
