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
    let point = crate::projection::Bounds { min: *p, max: *p };
    let (among, palm) = candidates(view, link, &point);
    cover_among(view, camera, &among, palm, p, depth)
}

/// The parts of the hand that can cover any point of the box `region` for link `link`: the
/// other links (not sharing a joint with it) whose bounds meet the box, and whether the palm's
/// do. [`cover_among`] over them answers as [`cover`] does for every point in the box.
pub fn candidates(
    view: &ProjectedModel,
    link: usize,
    region: &crate::projection::Bounds,
) -> (heapless::Vec<u8, { crate::config::MAX_LINKS }>, bool) {
    let meets = |b: &crate::projection::Bounds| {
        b.min.x <= region.max.x
            && b.max.x >= region.min.x
            && b.min.y <= region.max.y
            && b.max.y >= region.min.y
    };
    let mut out = heapless::Vec::new();
    for (j, other) in view.links.iter().enumerate() {
        if j != link && meets(&other.bounds) && !view.adjacent(link, j) {
            let _ = out.push(j as u8);
        }
    }
    let palm = view.palm.as_ref().is_some_and(|p| meets(&p.bounds));
    (out, palm)
}

/// [`cover`] restricted to the links `among` (indices into `view.links`) and, if `palm`, the
/// palm: the same answer as `cover` when they are [`candidates`] for a box holding `p`.
#[inline(never)] // the visibility mask of Table 4.1's features stage: kept whole for profiles
pub fn cover_among(
    view: &ProjectedModel,
    camera: &Camera,
    among: &[u8],
    palm: bool,
    p: &Vector2<f32>,
    depth: f32,
) -> Cover {
    let mut result = Cover::Clear;
    for &j in among {
        let Some(other) = view.links.get(usize::from(j)) else {
            continue;
        };
        if !other.bounds.contains(p) {
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
    if let (true, Some(palm)) = (palm, &view.palm) {
        if let Some(z) = palm.depth_at(camera, p) {
            if z < depth {
                return Cover::Hidden;
            }
            result = Cover::Behind;
        }
    }
    result
}
