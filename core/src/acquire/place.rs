//! Putting a hypothesis where the frame's bright region is: a hypothesis' rotation and
//! fingers say what the hand looks like, the [`Region`]s say where it is.
//!
//! - **Stereo** (two cameras, each with a region): the centre of the hypothesis' image bounds
//!   in each camera is triangulated, and so is the centre of each camera's region; the palm
//!   is moved by the difference. Depth comes from the two views.
//! - **One camera**: the palm is put on the ray through the region's centre; its depth is
//!   either set from the region's size (the hypothesis' image bounds at a known depth against
//!   the region's extent: image size falls as 1/depth) or kept, and the palm is then moved
//!   across the view so the centre of its image bounds meets the region's centre.
//!
//! Each way costs one or two extra projections, no search over the image.

use crate::camera::Camera;
use crate::config::MAX_STATES;
use crate::float::Length;
use crate::likelihood::{Region, StateScorer};
use crate::model::Model;
use crate::nalgebra::{Vector2, Vector3};
use crate::silhouette::hand_bounds;

use super::volume::WorkingVolume;

/// The palm's translation: states 4..7.
const TRANSLATION: core::ops::Range<usize> = 4..7;

/// How a placement sets the palm's depth from the first camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Depth {
    /// From the region's size (one camera) or triangulation (two).
    FromRegion,
    /// Kept as the hypothesis has it (one camera); two cameras still triangulate.
    Keep,
}

/// Scratch of one placement: the poses and one camera's projection (the scorer's).
pub(crate) type Scratch = StateScorer;

impl StateScorer {
    /// The centre and diagonal (px) of the projected hand's bounds in `camera`.
    fn bounds_in(
        &mut self,
        model: &Model,
        camera: &Camera,
        q: &[f32],
    ) -> Option<(Vector2<f32>, f32)> {
        if !(self.pose(model, q) && self.project(model, camera)) {
            return None;
        }
        let b = hand_bounds(&self.view)?;
        let size = b.max - b.min;
        Some(((b.min + b.max) / 2.0, size.length()))
    }
}

/// The point nearest both rays through pixel `a` of camera `ca` and pixel `b` of `cb`
/// (world, mm); `None` for parallel rays or a point behind either camera.
pub fn triangulate(
    ca: &Camera,
    a: &Vector2<f32>,
    cb: &Camera,
    b: &Vector2<f32>,
) -> Option<Vector3<f32>> {
    let (oa, ob) = (ca.centre(), cb.centre());
    let da = ca.r.transpose() * ca.ray(a);
    let db = cb.r.transpose() * cb.ray(b);
    // Minimise |oa + s·da − ob − t·db|².
    let w = oa - ob;
    let (aa, ab, bb) = (da.dot(&da), da.dot(&db), db.dot(&db));
    let (aw, bw) = (da.dot(&w), db.dot(&w));
    let det = aa * bb - ab * ab;
    if det.abs() < 1e-9 * aa * bb {
        return None;
    }
    let s = (ab * bw - bb * aw) / det;
    let t = (aa * bw - ab * aw) / det;
    // Depths along rays scaled to z = 1 are camera depths.
    if !(s > 0.0 && t > 0.0) {
        return None;
    }
    Some(((oa + da * s) + (ob + db * t)) / 2.0)
}

/// The world point of pixel `uv` of `camera` at camera depth `z` (mm).
fn back_project(camera: &Camera, uv: &Vector2<f32>, z: f32) -> Vector3<f32> {
    camera.r.transpose() * (camera.ray(uv) * z - camera.t)
}

/// Moves the palm of `q` so the hypothesis lies over the regions of `cameras` (see the module
/// doc). False when it cannot be placed (not posed, out of view, no region in the first
/// camera). The palm stays within `volume`'s depth range from the first camera.
#[allow(clippy::too_many_arguments)] // the search's scratch, the rig, the frame's regions and the hypothesis
pub(crate) fn place(
    scratch: &mut Scratch,
    model: &Model,
    cameras: &[Camera],
    regions: &[Option<Region>],
    volume: &WorkingVolume,
    q: &mut [f32; MAX_STATES],
    n_states: usize,
    depth: Depth,
) -> bool {
    let (Some(c0), Some(Some(r0))) = (cameras.first(), regions.first()) else {
        return false;
    };
    let centre = Vector3::from(volume.centre_mm);
    let z_centre = c0.to_camera(&centre).z;
    let half = volume.half_size_mm.iter().copied().fold(0.0f32, f32::max);
    if z_centre <= half * 0.25 {
        return false;
    }
    let (z_near, z_far) = ((z_centre - half).max(z_centre * 0.25), z_centre + half);
    let goal0 = r0.extent_centre_px();
    let palm = Vector3::new(q[4], q[5], q[6]);
    let z_now = c0.to_camera(&palm).z;
    let z0 = match depth {
        Depth::FromRegion => z_centre,
        Depth::Keep if z_now.is_finite() && z_now > 1.0 => z_now.clamp(z_near, z_far),
        Depth::Keep => z_centre,
    };
    set_palm(q, &back_project(c0, &goal0, z0));
    let qs = &q[..n_states.min(MAX_STATES)];
    let Some((at0, diag0)) = scratch.bounds_in(model, c0, qs) else {
        return false;
    };
    // Two cameras: triangulate the hypothesis' centre and the regions' centre.
    if let (Some(c1), Some(Some(r1))) = (cameras.get(1), regions.get(1)) {
        if scratch.project(model, c1) {
            if let Some(b1) = hand_bounds(&scratch.view) {
                let at1 = (b1.min + b1.max) / 2.0;
                let goal1 = r1.extent_centre_px();
                if let (Some(now), Some(goal)) = (
                    triangulate(c0, &at0, c1, &at1),
                    triangulate(c0, &goal0, c1, &goal1),
                ) {
                    let moved = Vector3::new(q[4], q[5], q[6]) + (goal - now);
                    let z = c0.to_camera(&moved).z;
                    if z.is_finite() && z >= z_near && z <= z_far {
                        set_palm(q, &moved);
                        return palm_is_finite(q);
                    }
                }
            }
        }
    }
    // One camera: the depth from the size (image size falls as 1/depth), then the centre.
    let size_o = r0.size_px().length();
    let z1 = match depth {
        Depth::FromRegion if size_o > 1.0 && diag0 > 1.0 => {
            (z0 * diag0 / size_o).clamp(z_near, z_far)
        }
        _ => z0,
    };
    // Weak perspective about the palm's pixel (`goal0`): moving from z0 to z1 scales the
    // hypothesis' image about it by z0 / z1.
    let predicted = goal0 + (at0 - goal0) * (z0 / z1);
    let uv = goal0 + (goal0 - predicted);
    set_palm(q, &back_project(c0, &uv, z1));
    palm_is_finite(q)
}

/// Whether the palm's position is finite: all a placement changes of a state that was posed,
/// so the placed state poses too (the scorer poses it again when it scores it).
fn palm_is_finite(q: &[f32; MAX_STATES]) -> bool {
    q[TRANSLATION].iter().all(|v| v.is_finite())
}

fn set_palm(q: &mut [f32; MAX_STATES], p: &Vector3<f32>) {
    if let Some(t) = q.get_mut(TRANSLATION) {
        t.copy_from_slice(&[p.x, p.y, p.z]);
    }
}
