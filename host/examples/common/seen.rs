//! Which joints the cameras see: a joint is seen when it moves a link of which some camera
//! sees a point of the axis (inside the frame, not hidden by a nearer part of the hand by the
//! core's own depth-order test, `visibility::cover`).
#![allow(dead_code)] // each example uses part of it

use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::Model;
use digiteyes_core::projection::ProjectedModel;
use digiteyes_core::visibility::{cover, Cover};
use digiteyes_host::sequence::Sequence;
use nalgebra::Vector2;

/// Points tested along each link's axis.
const AXIS_POINTS: usize = 7;

/// Whether each joint state moves a link of which some camera sees at least `points` of
/// [`AXIS_POINTS`] points along the axis, at `poses`.
pub fn joints(sequence: &Sequence, poses: &Poses, points: usize) -> Vec<bool> {
    let model: &Model = &sequence.model;
    let mut seen = vec![false; model.n_states()];
    let mut view = ProjectedModel::default();
    for camera in &sequence.cameras {
        view.update(model, poses, camera, 0.0);
        let inside = |p: &Vector2<f32>| {
            p.x >= 0.0 && p.y >= 0.0 && p.x < camera.width as f32 && p.y < camera.height as f32
        };
        for (i, link) in view.links.iter().enumerate() {
            let visible = (0..AXIS_POINTS)
                .filter(|&k| {
                    let s = (k as f32 + 0.5) / AXIS_POINTS as f32;
                    let p = link.a + (link.b - link.a) * s;
                    let front = link.depth_at(s) - link.radius_mm;
                    inside(&p) && cover(&view, camera, i, &p, front) != Cover::Hidden
                })
                .count();
            if visible >= points {
                for s in model.chain(usize::from(link.frame)).unwrap_or_default() {
                    seen[usize::from(s)] = true;
                }
            }
        }
    }
    seen
}
