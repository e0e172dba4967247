//! The hand's solid shapes in the world frame: one place that says which link is a capsule
//! from where to where and where the palm box sits, for the ray-casting renderer and the UI's
//! 3D view alike.

use anyhow::{anyhow, Result};
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::{Model, Shape};
use digiteyes_core::nalgebra::Vector3;
use serde::Serialize;

/// A solid part of the hand, world coordinates (mm).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum WorldShape {
    /// A finger link: the cylinder from `a` to `b` with a sphere of radius `r` at each end.
    Capsule {
        /// Model frame the link hangs on.
        frame: usize,
        /// Start of the axis (the frame's origin).
        a: [f32; 3],
        /// End of the axis (the origin of the frame's first child).
        b: [f32; 3],
        /// Radius (mm).
        r: f32,
    },
    /// The palm: a box at `centre` with unit edge directions `axes` and half sizes `half`.
    Box {
        /// Model frame the box hangs on.
        frame: usize,
        /// Centre.
        centre: [f32; 3],
        /// Unit directions of the box's edges (the frame's x, y, z axes).
        axes: [[f32; 3]; 3],
        /// Half the edge lengths along `axes` (mm).
        half: [f32; 3],
    },
}

impl WorldShape {
    /// Corners of boxes around the shape (world, mm) whose convex hull contains it: the box
    /// around each end sphere of a capsule (16 points), the palm box's own 8 corners.
    pub fn hull_corners(&self) -> Vec<Vector3<f32>> {
        match *self {
            WorldShape::Capsule { a, b, r, .. } => [a, b]
                .into_iter()
                .flat_map(|centre| {
                    corners(
                        Vector3::from(centre),
                        [[r, 0.0, 0.0], [0.0, r, 0.0], [0.0, 0.0, r]],
                    )
                })
                .collect(),
            WorldShape::Box {
                centre, axes, half, ..
            } => corners(
                Vector3::from(centre),
                [0, 1, 2].map(|k| (Vector3::from(axes[k]) * half[k]).into()),
            )
            .collect(),
        }
    }
}

/// The 8 points `centre ± e0 ± e1 ± e2`.
fn corners(centre: Vector3<f32>, edges: [[f32; 3]; 3]) -> impl Iterator<Item = Vector3<f32>> {
    (0..8).map(move |k| {
        let s = |bit: usize| if k & (1 << bit) == 0 { -1.0 } else { 1.0 };
        centre
            + Vector3::from(edges[0]) * s(0)
            + Vector3::from(edges[1]) * s(1)
            + Vector3::from(edges[2]) * s(2)
    })
}

/// The shapes of `model` at states `q` (quaternion, mm, rad), in model frame order.
pub fn world_shapes(model: &Model, q: &[f32]) -> Result<Vec<WorldShape>> {
    let poses = Poses::compute(model, q).map_err(|e| anyhow!("state: {e}"))?;
    Ok(shapes_at(model, &poses))
}

/// The shapes of `model` posed by `poses`.
pub fn shapes_at(model: &Model, poses: &Poses) -> Vec<WorldShape> {
    let mut out = Vec::new();
    for (i, link) in model.links().iter().enumerate() {
        let Some(pose) = poses.frame(i) else { continue };
        match link.shape {
            Shape::Cylinder { radius } => {
                let end = link
                    .children
                    .first()
                    .and_then(|&child| poses.origin(usize::from(child)));
                if let Some(end) = end {
                    out.push(WorldShape::Capsule {
                        frame: i,
                        a: pose.t.into(),
                        b: end.into(),
                        r: radius,
                    });
                }
            }
            Shape::Box { size, centre } => {
                let centre = pose.apply(&Vector3::new(centre[0], centre[1], centre[2]));
                out.push(WorldShape::Box {
                    frame: i,
                    centre: centre.into(),
                    axes: [0, 1, 2].map(|k| pose.r.column(k).into_owned().into()),
                    half: size.map(|s| 0.5 * s),
                });
            }
            Shape::Tip { .. } | Shape::None => {}
        }
    }
    out
}
