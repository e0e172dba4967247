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
    /// Its index among the model's shapes ([`world_shapes`]): the same in every frame.
    pub part: usize,
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
    /// Every primitive, in the image or not: what can cast a shadow.
    pub all: Vec<Primitive>,
}

impl Scene {
    /// Places the shapes of `model` at states `q` (quaternion, mm, rad) in `camera`'s view.
    pub fn build(model: &Model, camera: &Camera, q: &[f32]) -> Result<Scene> {
        let to_cam = |p: &V3f<f32>| {
            let c = camera.to_camera(p);
            Vector3::new(f64::from(c.x), f64::from(c.y), f64::from(c.z))
        };
        let mut placed = Vec::new();
        let mut all = Vec::new();
        for (part, shape) in world_shapes(model, q)?.into_iter().enumerate() {
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
            all.push(primitive);
            if let Some(rect) = project_rect(camera, shape.hull_corners()) {
                placed.push(Placed {
                    part,
                    primitive,
                    rect,
                });
            }
        }
        Ok(Scene { placed, all })
    }

    /// The nearest hit of the ray along unit direction `d` among the primitives `candidates`
    /// (indices into [`Scene::placed`]), with the part it hit ([`Placed::part`]).
    pub fn nearest(&self, d: &Vector3<f64>, candidates: &[usize]) -> Option<(usize, Hit)> {
        let mut best: Option<(usize, Hit)> = None;
        for &i in candidates {
            let placed = &self.placed[i];
            if let Some(h) = placed.primitive.hit(d) {
                if best.is_none_or(|(_, b)| h.t < b.t) {
                    best = Some((placed.part, h));
                }
            }
        }
        best
    }

    /// Whether the ray from `origin` along unit direction `d` (camera coordinates, mm) meets
    /// any part of the hand: a point there is in the hand's shadow from a light along `d`.
    pub fn blocks(&self, origin: &Vector3<f64>, d: &Vector3<f64>) -> bool {
        self.all
            .iter()
            .any(|p| p.moved_by(&-origin).hit(d).is_some())
    }
}

impl Primitive {
    /// The nearest hit of the ray from the camera centre along unit direction `d`.
    fn hit(&self, d: &Vector3<f64>) -> Option<Hit> {
        match self {
            Primitive::Capsule(c) => ray_capsule(d, c),
            Primitive::Box(b) => ray_box(d, b),
        }
    }

    /// The primitive translated by `offset` (mm).
    fn moved_by(&self, offset: &Vector3<f64>) -> Primitive {
        match *self {
            Primitive::Capsule(c) => Primitive::Capsule(Capsule {
                a: c.a + offset,
                b: c.b + offset,
                r: c.r,
            }),
            Primitive::Box(b) => Primitive::Box(OrientedBox {
                centre: b.centre + offset,
                ..b
            }),
        }
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

#[cfg(test)]
mod tests {
    use super::super::Surface;
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> Vector3<f64> {
        Vector3::new(x, y, z)
    }

    /// A palm-like box 100 mm in front of the camera, and a finger capsule beyond it.
    fn palm_and_finger() -> Scene {
        let palm = Primitive::Box(OrientedBox {
            centre: v(0.0, 0.0, 100.0),
            axes: [v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0), v(0.0, 0.0, 1.0)],
            half: [20.0, 20.0, 5.0],
        });
        let finger = Primitive::Capsule(Capsule {
            a: v(-30.0, 0.0, 130.0),
            b: v(30.0, 0.0, 130.0),
            r: 5.0,
        });
        Scene {
            placed: Vec::new(),
            all: vec![palm, finger],
        }
    }

    #[test]
    fn a_point_behind_a_part_is_in_its_shadow() {
        let scene = palm_and_finger();
        // The finger's near side, under the palm as seen from a light at the camera.
        let on_finger = v(0.0, 0.0, 124.99);
        let toward_camera = v(0.0, 0.0, -1.0);
        assert!(scene.blocks(&on_finger, &toward_camera));
        // The same point lit from the side: nothing in the way.
        assert!(!scene.blocks(&on_finger, &v(1.0, 0.0, -0.2).normalize()));
        // The palm's own face toward the camera is lit.
        assert!(!scene.blocks(&v(0.0, 0.0, 94.99), &toward_camera));
    }

    #[test]
    fn a_part_does_not_shadow_its_own_lit_side() {
        let scene = palm_and_finger();
        let (normal, toward_light) = (v(0.0, -1.0, 0.0), v(0.0, -1.0, -0.3).normalize());
        let on_finger = Surface::shadow_origin(1.0, &v(0.0, -5.0, 130.0), &normal);
        assert!(!scene.blocks(&on_finger, &toward_light));
    }
}
