//! Which joints the cameras see: a joint is seen when it moves a link of which some camera
//! sees a point of the axis (inside the frame, not hidden by a nearer part of the hand by the
//! core's own depth-order test, `visibility::cover`).
#![allow(dead_code)] // each example uses part of it

use anyhow::Result;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::{Model, BASE_STATES};
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

/// A joint's guess while it is not seen.
#[derive(Clone, Copy)]
pub enum Unseen {
    /// Kept at the oracle's last value.
    Hold,
    /// Gone on at the speed it last had while seen, clamped to its range.
    Velocity,
}

/// The seen-oracle's states over `truth`, and the share of joint-frames not seen.
pub fn oracle(
    sequence: &Sequence,
    truth: &[Vec<f32>],
    points: usize,
    how: Unseen,
) -> Result<(Vec<Vec<f32>>, f64)> {
    let model = &sequence.model;
    let n = model.n_states();
    let mut out: Vec<Vec<f32>> = Vec::with_capacity(truth.len());
    let mut speed = vec![0.0f32; n];
    let (mut unseen, mut total) = (0usize, 0usize);
    for (k, t) in truth.iter().enumerate() {
        let poses = Poses::compute(model, t)?;
        let seen = joints(sequence, &poses, points);
        let mut state = t.clone();
        if let Some(last) = out.last() {
            for j in BASE_STATES..n {
                total += 1;
                if seen[j] {
                    speed[j] = t[j] - truth[k - 1][j];
                    continue;
                }
                unseen += 1;
                let step = match how {
                    Unseen::Hold => 0.0,
                    Unseen::Velocity => speed[j],
                };
                let mut v = last[j] + step;
                if let Some(l) = model.limit(j) {
                    v = v.clamp(l.lo, l.hi);
                }
                state[j] = v;
            }
        }
        out.push(state);
    }
    Ok((out, unseen as f64 / total.max(1) as f64))
}
