//! Visibility from the model's depth order: the cheap real-time form of the thesis' Ch. 3
//! occlusion reasoning. A predicted edge that falls inside a nearer link or the palm is hidden
//! and its slice is masked; an edge whose outside lies over a farther part of the hand has an
//! unknown contrast sign.

use nalgebra::Vector2;

use crate::camera::Camera;
use crate::projection::ProjectedModel;

/// What lies at an image point, seen from link `link` at a given depth.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Cover {
    /// Nothing else of the hand is there.
    Clear,
    /// Another link or the palm is there, farther than the query.
    Behind,
    /// Another link or the palm is there, nearer than the query: the point is hidden.
    Hidden,
}

/// What covers image point `p` for a point of link `link` (index into `view.links`) at camera
/// depth `depth` (mm). Links sharing a joint with `link` are ignored: their capsules merge.
pub fn cover(
    view: &ProjectedModel,
    camera: &Camera,
    link: usize,
    p: &Vector2<f32>,
    depth: f32,
) -> Cover {
    let mut result = Cover::Clear;
    for (j, other) in view.links.iter().enumerate() {
        if j == link || !other.bounds.contains(p) || view.adjacent(link, j) {
            continue;
        }
        let (s, dist) = other.closest(p);
        if dist < other.radius_at(s) {
            if other.depth_at(s) < depth {
                return Cover::Hidden;
            }
            result = Cover::Behind;
        }
    }
    if let Some(palm) = &view.palm {
        if let Some(z) = palm.depth_at(camera, p) {
            if z < depth {
                return Cover::Hidden;
            }
            result = Cover::Behind;
        }
    }
    result
}
