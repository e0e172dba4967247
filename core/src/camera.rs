//! Calibrated pinhole cameras (no lens distortion), as in `docs/sequence-format.md`.
//!
//! A world point `p_w` (mm) maps to camera coordinates `p_c = R · p_w + t` (camera z forward,
//! x right, y down), then to pixels `u = fx · x_c / z_c + cx`, `v = fy · y_c / z_c + cy`.
//! Pixel (0, 0) is the centre of the top-left pixel.

use core::fmt;

use nalgebra::{Matrix2x3, Matrix3, Vector2, Vector3};

use crate::float::Length;
use crate::state::TRANSLATION;

/// Points nearer than this to the camera plane (mm) do not project.
pub const MIN_DEPTH: f32 = 1.0;

/// A calibrated pinhole camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Image width (px).
    pub width: u32,
    /// Image height (px).
    pub height: u32,
    /// Focal length along u (px).
    pub fx: f32,
    /// Focal length along v (px).
    pub fy: f32,
    /// Principal point u (px).
    pub cx: f32,
    /// Principal point v (px).
    pub cy: f32,
    /// World-to-camera rotation.
    pub r: Matrix3<f32>,
    /// World-to-camera translation (mm).
    pub t: Vector3<f32>,
}

/// Why a camera description is unusable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum CameraError {
    /// Width or height is zero.
    ZeroSize,
    /// A focal length is not a positive finite number.
    BadFocalLength,
    /// A number is NaN or infinite.
    NotFinite,
    /// `R` is not a rotation (orthonormal, determinant +1, to 1e-3).
    NotARotation,
}

impl fmt::Display for CameraError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::ZeroSize => write!(f, "camera width and height must be positive"),
            Self::BadFocalLength => write!(f, "focal lengths fx, fy must be positive"),
            Self::NotFinite => write!(f, "camera parameters must be finite numbers"),
            Self::NotARotation => write!(f, "R is not a rotation matrix"),
        }
    }
}

impl core::error::Error for CameraError {}

impl Camera {
    /// A `width`×`height` camera at `eye` (world, mm) looking along `forward`, with
    /// `up` pointing up the image as far as it can, focal length `focal_px` and the
    /// principal point at the image's centre. `None` when `forward` is zero or parallel to
    /// `up`, or the result fails [`Camera::validate`].
    pub fn looking_along(
        eye: Vector3<f32>,
        forward: Vector3<f32>,
        up: Vector3<f32>,
        (width, height): (u32, u32),
        focal_px: f32,
    ) -> Option<Camera> {
        let forward = forward.try_normalized(f32::EPSILON)?;
        let right = forward.cross(&up).try_normalized(f32::EPSILON)?;
        let down = forward.cross(&right);
        let r = Matrix3::from_rows(&[right.transpose(), down.transpose(), forward.transpose()]);
        let camera = Camera {
            width,
            height,
            fx: focal_px,
            fy: focal_px,
            cx: (width as f32 - 1.0) * 0.5,
            cy: (height as f32 - 1.0) * 0.5,
            r,
            t: -(r * eye),
        };
        camera.validate().ok().map(|()| camera)
    }

    /// Checks the parameters; every camera the tracker uses has passed this.
    pub fn validate(&self) -> Result<(), CameraError> {
        if self.width == 0 || self.height == 0 {
            return Err(CameraError::ZeroSize);
        }
        let finite = [self.fx, self.fy, self.cx, self.cy]
            .iter()
            .all(|v| v.is_finite())
            && self.r.iter().all(|v| v.is_finite())
            && self.t.iter().all(|v| v.is_finite());
        if !finite {
            return Err(CameraError::NotFinite);
        }
        if !(self.fx > 0.0 && self.fy > 0.0) {
            return Err(CameraError::BadFocalLength);
        }
        let gram = self.r * self.r.transpose() - Matrix3::identity();
        if gram.iter().any(|v| v.abs() > 1e-3) || self.r.determinant() < 0.0 {
            return Err(CameraError::NotARotation);
        }
        Ok(())
    }

    /// A world point in camera coordinates (mm).
    pub fn to_camera(&self, p_w: &Vector3<f32>) -> Vector3<f32> {
        self.r * p_w + self.t
    }

    /// The camera centre in world coordinates (mm).
    pub fn centre(&self) -> Vector3<f32> {
        -(self.r.transpose() * self.t)
    }

    /// Pixel of a world point, or `None` when it lies within [`MIN_DEPTH`] of the camera
    /// plane or behind it, or is not finite (NaN or infinite coordinates, or a pixel that
    /// overflows `f32`).
    pub fn project(&self, p_w: &Vector3<f32>) -> Option<Vector2<f32>> {
        let c = self.to_camera(p_w);
        if !(c.z >= MIN_DEPTH && c.z.is_finite()) {
            return None;
        }
        let uv = Vector2::new(self.fx * c.x / c.z + self.cx, self.fy * c.y / c.z + self.cy);
        (uv.x.is_finite() && uv.y.is_finite()).then_some(uv)
    }

    /// The ray through pixel `uv` in camera coordinates, scaled to depth 1:
    /// `((u − cx) / fx, (v − cy) / fy, 1)` — the inverse of [`Camera::project`] up to depth.
    #[inline]
    pub fn ray(&self, uv: &Vector2<f32>) -> Vector3<f32> {
        Vector3::new((uv.x - self.cx) / self.fx, (uv.y - self.cy) / self.fy, 1.0)
    }

    /// Pixel of a world point, its depth `z_c` (mm), and `∂(u, v)/∂p_w` (px/mm); `None` where
    /// [`Camera::project`] would, for the same reasons.
    pub fn project_with_jacobian(
        &self,
        p_w: &Vector3<f32>,
    ) -> Option<(Vector2<f32>, f32, Matrix2x3<f32>)> {
        let c = self.to_camera(p_w);
        if !(c.z >= MIN_DEPTH && c.z.is_finite()) {
            return None;
        }
        let iz = 1.0 / c.z;
        let uv = Vector2::new(self.fx * c.x * iz + self.cx, self.fy * c.y * iz + self.cy);
        if !(uv.x.is_finite() && uv.y.is_finite()) {
            return None;
        }
        let d_cam = Matrix2x3::new(
            self.fx * iz,
            0.0,
            -self.fx * c.x * iz * iz,
            0.0,
            self.fy * iz,
            -self.fy * c.y * iz * iz,
        );
        Some((uv, c.z, d_cam * self.r))
    }

    /// Length in pixels of `length_mm` seen face-on at depth `depth` (mm).
    pub fn pixels_at_depth(&self, length_mm: f32, depth: f32) -> f32 {
        0.5 * (self.fx + self.fy) * length_mm / depth.max(MIN_DEPTH)
    }

    /// Whether pixel `uv` lies inside the image, at least `margin` px from its border.
    pub fn contains(&self, uv: &Vector2<f32>, margin: f32) -> bool {
        uv.x >= margin
            && uv.y >= margin
            && uv.x <= self.width as f32 - 1.0 - margin
            && uv.y <= self.height as f32 - 1.0 - margin
    }
}

/// The palm's distance (mm) from the first of `cameras`, if there is a camera and `state`
/// has a palm position: the depth one camera reads only through the hand's size.
pub fn palm_depth_mm(cameras: &[Camera], state: &[f32]) -> Option<f32> {
    let camera = cameras.first()?;
    let p = state.get(TRANSLATION)?;
    Some((Vector3::new(p[0], p[1], p[2]) - camera.centre()).norm())
}
