//! The hand as ray-castable primitives in one camera's coordinates.
//!
//! Every `cyl` link becomes a capsule from its frame's origin to its child's origin (the
//! cylinder plus a sphere of the same radius at each end), every `box` an oriented box placed
//! by its size and centre in its frame. Poses come from the core's kinematics and points go
//! through the core's camera, so the renderer and the tracker share one geometry.

use anyhow::{anyhow, Result};
use digiteyes_core::camera::Camera;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::{Model, Shape};
use digiteyes_core::nalgebra::Vector3 as V3f;
use nalgebra::Vector3;

use super::intersect::{ray_box, ray_capsule, Capsule, Hit, OrientedBox};

/// A primitive's shape.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Primitive {
    /// A finger link.
    Capsule(Capsule),
    /// The palm.
    Box(OrientedBox),
}

/// An inclusive pixel rectangle (columns `x0..=x1`, rows `y0..=y1`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PixelRect {
    /// First column.
    pub x0: usize,
    /// Last column.
    pub x1: usize,
    /// First row.
    pub y0: usize,
    /// Last row.
    pub y1: usize,
}

/// A primitive with the pixels its projection can cover.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placed {
    /// The shape, camera coordinates (mm).
    pub primitive: Primitive,
    /// A rectangle containing its projection, clipped to the image.
    pub rect: PixelRect,
}

/// The visible primitives of a hand seen by one camera.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The primitives that fall (at least partly) inside the image.
    pub placed: Vec<Placed>,
}

impl Scene {
    /// Places the shapes of `model` at states `q` (quaternion, mm, rad) in `camera`'s view.
    pub fn build(model: &Model, camera: &Camera, q: &[f32]) -> Result<Scene> {
        let poses = Poses::compute(model, q).map_err(|e| anyhow!("state: {e}"))?;
        let to_cam = |p: &V3f<f32>| {
            let c = camera.to_camera(p);
            Vector3::new(f64::from(c.x), f64::from(c.y), f64::from(c.z))
        };
        let mut placed = Vec::new();
        for (i, link) in model.links().iter().enumerate() {
            let Some(pose) = poses.frame(i) else { continue };
            match link.shape {
                Shape::Cylinder { radius } => {
                    let Some(&child) = link.children.first() else {
                        continue;
                    };
                    let Some(end) = poses.origin(usize::from(child)) else {
                        continue;
                    };
                    let r = f64::from(radius);
                    let corners = sphere_box_corners(&pose.t, radius)
                        .into_iter()
                        .chain(sphere_box_corners(&end, radius));
                    if let Some(rect) = project_rect(camera, corners) {
                        placed.push(Placed {
                            primitive: Primitive::Capsule(Capsule {
                                a: to_cam(&pose.t),
                                b: to_cam(&end),
                                r,
                            }),
                            rect,
                        });
                    }
                }
                Shape::Box { size, centre } => {
                    let centre_w = pose.apply(&V3f::new(centre[0], centre[1], centre[2]));
                    let axes_w = [0, 1, 2].map(|k| pose.r.column(k).into_owned());
                    let mut corners = Vec::with_capacity(8);
                    for sx in [-0.5f32, 0.5] {
                        for sy in [-0.5f32, 0.5] {
                            for sz in [-0.5f32, 0.5] {
                                corners.push(
                                    centre_w
                                        + axes_w[0] * (sx * size[0])
                                        + axes_w[1] * (sy * size[1])
                                        + axes_w[2] * (sz * size[2]),
                                );
                            }
                        }
                    }
                    if let Some(rect) = project_rect(camera, corners) {
                        let axes = axes_w.map(|a| {
                            let c = camera.r * a;
                            Vector3::new(f64::from(c.x), f64::from(c.y), f64::from(c.z)).normalize()
                        });
                        placed.push(Placed {
                            primitive: Primitive::Box(OrientedBox {
                                centre: to_cam(&centre_w),
                                axes,
                                half: size.map(|s| 0.5 * f64::from(s)),
                            }),
                            rect,
                        });
                    }
                }
                Shape::Tip { .. } | Shape::None => {}
            }
        }
        Ok(Scene { placed })
    }

    /// The nearest hit of the ray along unit direction `d` among the primitives `candidates`
    /// (indices into [`Scene::placed`]).
    pub fn nearest(&self, d: &Vector3<f64>, candidates: &[usize]) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        for &i in candidates {
            let hit = match &self.placed[i].primitive {
                Primitive::Capsule(c) => ray_capsule(d, c),
                Primitive::Box(b) => ray_box(d, b),
            };
            if let Some(h) = hit {
                if best.is_none_or(|b| h.t < b.t) {
                    best = Some(h);
                }
            }
        }
        best
    }
}

/// The 8 corners of the axis-aligned box around a sphere (world, mm).
fn sphere_box_corners(centre: &V3f<f32>, r: f32) -> [V3f<f32>; 8] {
    let mut out = [*centre; 8];
    for (k, o) in out.iter_mut().enumerate() {
        let s = |bit: usize| if k & bit == 0 { -r } else { r };
        *o += V3f::new(s(1), s(2), s(4));
    }
    out
}

/// The pixel rectangle containing the projections of world points `corners` whose convex hull
/// contains a shape, grown by one pixel and clipped to the image. The whole image if a corner
/// does not project (it is at or behind the camera plane); `None` if the rectangle misses the
/// image.
fn project_rect(camera: &Camera, corners: impl IntoIterator<Item = V3f<f32>>) -> Option<PixelRect> {
    let (w, h) = (camera.width as f32, camera.height as f32);
    let mut lo = [f32::INFINITY; 2];
    let mut hi = [f32::NEG_INFINITY; 2];
    for p in corners {
        let Some(uv) = camera.project(&p) else {
            return Some(PixelRect {
                x0: 0,
                x1: camera.width as usize - 1,
                y0: 0,
                y1: camera.height as usize - 1,
            });
        };
        for k in 0..2 {
            lo[k] = lo[k].min(uv[k]);
            hi[k] = hi[k].max(uv[k]);
        }
    }
    // Pixel x covers u in [x - 0.5, x + 0.5].
    let (x0, y0) = ((lo[0] - 1.0).floor(), (lo[1] - 1.0).floor());
    let (x1, y1) = ((hi[0] + 1.0).ceil(), (hi[1] + 1.0).ceil());
    if x1 < 0.0 || y1 < 0.0 || x0 > w - 1.0 || y0 > h - 1.0 {
        return None;
    }
    Some(PixelRect {
        x0: x0.max(0.0) as usize,
        x1: x1.min(w - 1.0) as usize,
        y0: y0.max(0.0) as usize,
        y1: y1.min(h - 1.0) as usize,
    })
}
