//! Where the palm is searched for: a box of world space, by default from the rig.

use crate::camera::Camera;
use crate::nalgebra::Vector3;

/// A box of world space the palm's origin is searched in (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WorkingVolume {
    /// Centre (world, mm).
    pub centre_mm: [f32; 3],
    /// Half the box's side along each world axis (mm).
    pub half_size_mm: [f32; 3],
}

impl WorkingVolume {
    /// Half-size of the default volume (mm): a hand's reach about where the cameras look.
    pub const DEFAULT_HALF_SIZE_MM: f32 = 120.0;

    /// The default volume for a rig: a cube of [`Self::DEFAULT_HALF_SIZE_MM`] about the world
    /// origin when every camera sees it in front of it (the renderer's and the thesis' rigs
    /// look at the hand there), else about the point nearest every camera's optical axis
    /// (one camera: its axis at `fallback_depth_mm`).
    pub fn from_cameras(cameras: &[Camera], fallback_depth_mm: f32) -> Self {
        let origin = Vector3::zeros();
        let half = [Self::DEFAULT_HALF_SIZE_MM; 3];
        let sees_origin = !cameras.is_empty()
            && cameras.iter().all(|c| {
                c.project(&origin).is_some_and(|uv| {
                    uv.x >= 0.0 && uv.y >= 0.0 && uv.x < c.width as f32 && uv.y < c.height as f32
                })
            });
        if sees_origin {
            return WorkingVolume {
                centre_mm: [0.0; 3],
                half_size_mm: half,
            };
        }
        let mut centre = Vector3::zeros();
        for c in cameras {
            // The optical axis in the world: R's third row.
            let axis = Vector3::new(c.r[(2, 0)], c.r[(2, 1)], c.r[(2, 2)]);
            centre += c.centre() + axis * fallback_depth_mm;
        }
        centre /= cameras.len().max(1) as f32;
        WorkingVolume {
            centre_mm: [centre.x, centre.y, centre.z],
            half_size_mm: half,
        }
    }
}
