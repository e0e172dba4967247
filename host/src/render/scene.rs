//! The hand as ray-castable primitives in one camera's coordinates.
//!
//! Every `cyl` link becomes a capsule from its frame's origin to its child's origin (the
//! cylinder plus a sphere of the same radius at each end), every `box` an oriented box placed
//! by its size and centre in its frame. Poses come from the core's kinematics and points go
//! through the core's camera, so the renderer and the tracker share one geometry.

use anyhow::Result;
use digiteyes_core::camera::Camera;
use digiteyes_core::model::Model;
use digiteyes_core::nalgebra::Vector3 as V3f;
use nalgebra::Vector3;

use super::shapes::{world_shapes, WorldShape};

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
        let to_cam = |p: &V3f<f32>| {
            let c = camera.to_camera(p);
            Vector3::new(f64::from(c.x), f64::from(c.y), f64::from(c.z))
        };
        let mut placed = Vec::new();
        for shape in world_shapes(model, q)? {
            let Some(rect) = project_rect(camera, shape.hull_corners()) else {
                continue;
            };
            let primitive = match shape {
                WorldShape::Capsule { a, b, r, .. } => Primitive::Capsule(Capsule {
                    a: to_cam(&V3f::from(a)),
                    b: to_cam(&V3f::from(b)),
                    r: f64::from(r),
                }),
                WorldShape::Box {
                    centre, axes, half, ..
                } => Primitive::Box(OrientedBox {
                    centre: to_cam(&V3f::from(centre)),
                    axes: axes.map(|a| {
                        let c = camera.r * V3f::from(a);
                        Vector3::new(f64::from(c.x), f64::from(c.y), f64::from(c.z)).normalize()
                    }),
                    half: half.map(f64::from),
                }),
            };
            placed.push(Placed { primitive, rect });
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
