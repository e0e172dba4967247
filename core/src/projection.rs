//! The model seen by one camera: every capsule link's axis and radius in the image, and the
//! palm, with depths for visibility reasoning.

use heapless::Vec;
use nalgebra::{Matrix3, Vector2, Vector3};

use crate::camera::Camera;
use crate::config::MAX_LINKS;
use crate::float::Length;
use crate::kinematics::Poses;
use crate::model::{Model, Shape};

/// Unit direction of the image axis from `a` to `b` and its normal `(−d_y, d_x)`; `(1, 0)`
/// and `(0, 1)` for an axis shorter than 1e-6 px.
#[inline]
pub fn axis_frame(a: &Vector2<f32>, b: &Vector2<f32>) -> (Vector2<f32>, Vector2<f32>) {
    let d = b - a;
    let len = d.length();
    let dir = if len > 1e-6 {
        d / len
    } else {
        Vector2::new(1.0, 0.0)
    };
    (dir, Vector2::new(-dir.y, dir.x))
}

/// An axis-aligned box in the image (px).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    /// Smallest corner (px).
    pub min: Vector2<f32>,
    /// Largest corner (px).
    pub max: Vector2<f32>,
}

impl Bounds {
    /// Whether `p` lies inside.
    pub fn contains(&self, p: &Vector2<f32>) -> bool {
        p.x >= self.min.x && p.y >= self.min.y && p.x <= self.max.x && p.y <= self.max.y
    }

    pub(crate) fn around(a: Vector2<f32>, b: Vector2<f32>, pad: f32) -> Bounds {
        Bounds {
            min: Vector2::new(a.x.min(b.x) - pad, a.y.min(b.y) - pad),
            max: Vector2::new(a.x.max(b.x) + pad, a.y.max(b.y) + pad),
        }
    }
}

/// One capsule link in the image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProjectedLink {
    /// The link's frame (its capsule axis starts at this frame's origin).
    pub frame: u8,
    /// The frame where the axis ends.
    pub child: u8,
    /// Whether the child is a fingertip (a tip search runs beyond `b`).
    pub distal: bool,
    /// Whether the link's next link, seen from this camera, is taken to leave the hand's
    /// outline ending at `b`: it turns back over this link (more than 90° from its image
    /// axis), or is shorter in the image than this link's end radius and points away from
    /// the camera. A finger curled away from the camera then shows its knuckle where a
    /// straight one shows its tip. (Where a short next link still reaches beyond the
    /// knuckle's outline, the outline ends a little farther than `b`; the stricter test,
    /// that it does not, was measured and gave less: `docs/robustness.md`.) False for a
    /// fingertip's link (see `distal`) and for a link with no next one.
    pub knuckle_ends: bool,
    /// Capsule radius (mm).
    pub radius_mm: f32,
    /// Axis start and end in the world (mm).
    pub p0: Vector3<f32>,
    /// Axis end in the world (mm).
    pub p1: Vector3<f32>,
    /// Axis start in the image (px).
    pub a: Vector2<f32>,
    /// Axis end in the image (px).
    pub b: Vector2<f32>,
    /// Camera depth of the axis start and end (mm).
    pub z0: f32,
    /// Camera depth of the axis end (mm).
    pub z1: f32,
    /// Distance from the image axis to each silhouette line at the axis start (px), for the
    /// side along the axis normal `(−d_y, d_x)` and the opposite side: exact under perspective
    /// (the image lines of the two planes through the camera centre tangent to the cylinder).
    pub r0: [f32; 2],
    /// The same at the axis end (px).
    pub r1: [f32; 2],
    /// Distance along the image axis from `b` to the outline of the capsule's end sphere (px):
    /// where a fingertip's silhouette ends.
    pub tip_offset: f32,
    /// Image bounds of the whole capsule (px).
    pub bounds: Bounds,
}

impl ProjectedLink {
    /// Unit direction of the image axis from `a` to `b` and its normal `(−d_y, d_x)`
    /// ([`axis_frame`]).
    #[inline]
    pub fn axis_frame(&self) -> (Vector2<f32>, Vector2<f32>) {
        axis_frame(&self.a, &self.b)
    }

    /// Unit normal `(−d_y, d_x)` of the image axis: the direction of side +1.
    #[inline]
    pub fn normal(&self) -> Vector2<f32> {
        self.axis_frame().1
    }

    /// The silhouette line on side `side` (+1 along [`normal`](Self::normal), −1 opposite),
    /// from beside `a` to beside `b` (px).
    #[inline]
    pub fn silhouette(&self, side: i8) -> (Vector2<f32>, Vector2<f32>) {
        let k = usize::from(side < 0);
        let offset = self.normal() * f32::from(side);
        (self.a + offset * self.r0[k], self.b + offset * self.r1[k])
    }

    /// Image length of the axis (px).
    pub fn length(&self) -> f32 {
        (self.b - self.a).length()
    }

    /// Closest axis parameter `s ∈ [0, 1]` to image point `p`, and the distance (px).
    pub fn closest(&self, p: &Vector2<f32>) -> (f32, f32) {
        let d = self.b - self.a;
        let len2 = d.norm_squared();
        let s = if len2 > 1e-9 {
            ((p - self.a).dot(&d) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (s, (self.a + d * s - p).length())
    }

    /// Mean projected radius at axis parameter `s` (px).
    pub fn radius_at(&self, s: f32) -> f32 {
        0.5 * (self.side_radius_at(s, 1) + self.side_radius_at(s, -1))
    }

    /// The capsule's image width, side to side, averaged over its two ends (px).
    pub fn mean_width_px(&self) -> f32 {
        0.5 * (self.r0[0] + self.r0[1] + self.r1[0] + self.r1[1])
    }

    /// Distance from the image axis to the silhouette on side `side` (+1 along the normal
    /// `(−d_y, d_x)`, −1 opposite) at axis parameter `s` (px).
    pub fn side_radius_at(&self, s: f32, side: i8) -> f32 {
        let k = usize::from(side < 0);
        self.r0[k] + (self.r1[k] - self.r0[k]) * s
    }

    /// Camera depth of the axis at parameter `s` (mm).
    pub fn depth_at(&self, s: f32) -> f32 {
        self.z0 + (self.z1 - self.z0) * s
    }
}

/// Corners of a box: corner `k` takes the low or high bound on x, y, z by bits 0, 1, 2 of `k`.
pub const BOX_CORNERS: usize = 8;

/// The palm box as one camera sees it, for exact ray tests and its outline
/// ([`crate::palm_outline`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProjectedPalm {
    /// Image bounds of the box's corners (px).
    pub bounds: Bounds,
    /// The model frame the box belongs to (the palm, frame 0).
    pub frame: u8,
    /// The box's corners in the world (mm), numbered as [`BOX_CORNERS`] says.
    pub corners_mm: [Vector3<f32>; BOX_CORNERS],
    /// The corners in the image (px); every corner is in front of the camera.
    pub corners_px: [Vector2<f32>; BOX_CORNERS],
    /// The corners' camera depths (mm).
    pub corners_z: [f32; BOX_CORNERS],
    /// Camera centre in the palm frame (mm).
    origin: Vector3<f32>,
    /// Maps a camera ray `((u−cx)/fx, (v−cy)/fy, 1)` to a direction in the palm frame.
    to_palm: Matrix3<f32>,
    lo: Vector3<f32>,
    hi: Vector3<f32>,
}

impl ProjectedPalm {
    /// Camera depth (mm) at which the ray through pixel `p` enters the palm box, if it does.
    pub fn depth_at(&self, camera: &Camera, p: &Vector2<f32>) -> Option<f32> {
        self.enter(camera, p).map(|(depth, _)| depth)
    }

    /// Where the ray through pixel `p` enters the palm box, if it does: the camera depth (mm)
    /// and the outward unit normal of the face it enters by, in camera coordinates. A ray
    /// that starts inside the box (the camera in the palm) enters by no face: `None`.
    pub fn hit_at(&self, camera: &Camera, p: &Vector2<f32>) -> Option<(f32, Vector3<f32>)> {
        let (depth, (k, sign)) = self.enter(camera, p).and_then(|(d, f)| Some((d, f?)))?;
        let mut normal = Vector3::zeros();
        normal[k] = sign;
        // `to_palm` is the rotation from camera to palm axes: its transpose maps back.
        Some((depth, self.to_palm.transpose() * normal))
    }

    /// The slab test of the ray through pixel `p` against the box: the depth (mm) at which it
    /// enters, and the face it enters by (palm axis, and −1 for the low face or +1 for the
    /// high one), none when it starts inside.
    fn enter(&self, camera: &Camera, p: &Vector2<f32>) -> Option<(f32, Option<(usize, f32)>)> {
        if !self.bounds.contains(p) {
            return None;
        }
        let dir = self.to_palm * camera.ray(p);
        let (mut t_in, mut t_out) = (0.0f32, f32::INFINITY);
        let mut face = None;
        for k in 0..3 {
            if dir[k].abs() < 1e-12 {
                if self.origin[k] < self.lo[k] || self.origin[k] > self.hi[k] {
                    return None;
                }
                continue;
            }
            let t1 = (self.lo[k] - self.origin[k]) / dir[k];
            let t2 = (self.hi[k] - self.origin[k]) / dir[k];
            let near = t1.min(t2);
            if near > t_in {
                t_in = near;
                // Moving up axis k the ray enters by the low face, whose normal is −k.
                face = Some((k, if dir[k] > 0.0 { -1.0 } else { 1.0 }));
            }
            t_out = t_out.min(t1.max(t2));
        }
        (t_in <= t_out).then_some((t_in, face))
    }
}

/// Why a link was left out of one camera's view.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SkipCounts {
    /// Links with an end behind or at the camera.
    pub behind: u16,
    /// Links whose axis is shorter than the minimum in the image (seen end-on).
    pub end_on: u16,
    /// Links wholly outside the frame.
    pub off_frame: u16,
}

/// Every capsule link and the palm as one camera sees them.
#[derive(Debug, Clone)]
pub struct ProjectedModel {
    /// Links in view, in table order.
    pub links: Vec<ProjectedLink, MAX_LINKS>,
    /// The palm box, when the model has one in view.
    pub palm: Option<ProjectedPalm>,
    /// Links left out, and why.
    pub skipped: SkipCounts,
}

impl ProjectedModel {
    /// An empty projection.
    pub const fn new() -> Self {
        ProjectedModel {
            links: Vec::new(),
            palm: None,
            skipped: SkipCounts {
                behind: 0,
                end_on: 0,
                off_frame: 0,
            },
        }
    }

    /// Projects every capsule link and the palm of `model` at `poses` into `camera`.
    /// Links shorter than `min_length_px` in the image are skipped as end-on.
    #[inline(never)] // a stage of Table 4.1: kept whole so profiles can attribute its cost
    pub fn update(&mut self, model: &Model, poses: &Poses, camera: &Camera, min_length_px: f32) {
        self.links.clear();
        self.palm = None;
        self.skipped = SkipCounts::default();
        let frame_bounds = Bounds {
            min: Vector2::new(0.0, 0.0),
            max: Vector2::new(camera.width as f32 - 1.0, camera.height as f32 - 1.0),
        };
        for (i, link) in model.links().iter().enumerate() {
            match link.shape {
                Shape::Cylinder { radius } => {
                    let Some(&child) = link.children.first() else {
                        continue;
                    };
                    let (Some(p0), Some(p1)) = (poses.origin(i), poses.origin(usize::from(child)))
                    else {
                        continue;
                    };
                    let (Some(a), Some(b)) = (camera.project(&p0), camera.project(&p1)) else {
                        self.skipped.behind += 1;
                        continue;
                    };
                    let z0 = camera.to_camera(&p0).z;
                    let z1 = camera.to_camera(&p1).z;
                    let (r0, r1) = silhouette_offsets(camera, &p0, &p1, radius, &a, &b);
                    let tip_offset = sphere_outline_offset(camera, &p1, radius, &a, &b);
                    let bounds = Bounds::around(a, b, r0[0].max(r0[1]).max(r1[0]).max(r1[1]));
                    if !overlaps(&bounds, &frame_bounds) {
                        self.skipped.off_frame += 1;
                        continue;
                    }
                    if (b - a).length() < min_length_px {
                        self.skipped.end_on += 1;
                        continue;
                    }
                    let distal = model
                        .links()
                        .get(usize::from(child))
                        .is_some_and(|c| matches!(c.shape, Shape::Tip { .. }));
                    let knuckle_ends = !distal
                        && knuckle_ends(
                            model,
                            poses,
                            camera,
                            child,
                            (&a, &b),
                            z1,
                            r1[0].max(r1[1]),
                        );
                    let _ = self.links.push(ProjectedLink {
                        frame: i as u8,
                        child,
                        distal,
                        knuckle_ends,
                        radius_mm: radius,
                        p0,
                        p1,
                        a,
                        b,
                        z0,
                        z1,
                        r0,
                        r1,
                        tip_offset,
                        bounds,
                    });
                }
                Shape::Box { size, centre } => {
                    if let Some(pose) = poses.frame(i) {
                        self.palm = project_box(camera, pose.r, pose.t, size, centre).map(|p| {
                            ProjectedPalm {
                                frame: i as u8,
                                ..p
                            }
                        });
                    }
                }
                _ => {}
            }
        }
    }

    /// Whether links `i` and `j` (indices into `links`) share a joint.
    pub fn adjacent(&self, i: usize, j: usize) -> bool {
        match (self.links.get(i), self.links.get(j)) {
            (Some(a), Some(b)) => a.child == b.frame || b.child == a.frame,
            _ => false,
        }
    }
}

impl Default for ProjectedModel {
    fn default() -> Self {
        Self::new()
    }
}

fn overlaps(a: &Bounds, b: &Bounds) -> bool {
    a.min.x <= b.max.x && a.max.x >= b.min.x && a.min.y <= b.max.y && a.max.y >= b.min.y
}

fn project_box(
    camera: &Camera,
    r: Matrix3<f32>,
    t: Vector3<f32>,
    size: [f32; 3],
    centre: [f32; 3],
) -> Option<ProjectedPalm> {
    let half = Vector3::new(size[0], size[1], size[2]) * 0.5;
    let c = Vector3::new(centre[0], centre[1], centre[2]);
    let (lo, hi) = (c - half, c + half);
    let mut bounds = Bounds {
        min: Vector2::new(f32::INFINITY, f32::INFINITY),
        max: Vector2::new(f32::NEG_INFINITY, f32::NEG_INFINITY),
    };
    let mut corners_mm = [Vector3::zeros(); BOX_CORNERS];
    let mut corners_px = [Vector2::zeros(); BOX_CORNERS];
    let mut corners_z = [0.0f32; BOX_CORNERS];
    for (corner, ((mm, px), z)) in corners_mm
        .iter_mut()
        .zip(corners_px.iter_mut())
        .zip(corners_z.iter_mut())
        .enumerate()
    {
        let local = Vector3::new(
            if corner & 1 == 0 { lo.x } else { hi.x },
            if corner & 2 == 0 { lo.y } else { hi.y },
            if corner & 4 == 0 { lo.z } else { hi.z },
        );
        *mm = r * local + t;
        let uv = camera.project(mm)?;
        *px = uv;
        *z = camera.to_camera(mm).z;
        bounds.min = bounds.min.inf(&uv);
        bounds.max = bounds.max.sup(&uv);
    }
    let rt = r.transpose();
    Some(ProjectedPalm {
        bounds,
        frame: 0,
        corners_mm,
        corners_px,
        corners_z,
        origin: rt * (camera.centre() - t),
        to_palm: rt * camera.r.transpose(),
        lo,
        hi,
    })
}

/// Whether the link after frame `child` leaves the outline of the link `a`→`b` ending at `b`
/// ([`ProjectedLink::knuckle_ends`]): its image axis turns back (a negative dot product with
/// `b − a`), or is shorter than `end_radius_px` while its far end lies deeper than `depth_b`
/// (mm). False when it cannot be projected.
fn knuckle_ends(
    model: &Model,
    poses: &Poses,
    camera: &Camera,
    child: u8,
    (a, b): (&Vector2<f32>, &Vector2<f32>),
    depth_b: f32,
    end_radius_px: f32,
) -> bool {
    let Some(next) = model
        .links()
        .get(usize::from(child))
        .filter(|l| matches!(l.shape, Shape::Cylinder { .. }))
        .and_then(|l| l.children.first())
    else {
        return false;
    };
    let Some(far) = poses.origin(usize::from(*next)) else {
        return false;
    };
    let Some(end) = camera.project(&far) else {
        return false;
    };
    let onward = end - b;
    let turns_back = onward.dot(&(b - a)) < 0.0;
    let short_and_away = onward.length() < end_radius_px && camera.to_camera(&far).z > depth_b;
    turns_back || short_and_away
}

/// Offsets (px) from the image axis to the two silhouette lines of the cylinder of radius
/// `radius` around `p0`–`p1`, at `a` and at `b`, each `[side +1, side −1]`. The silhouette
/// lines are the images of the two planes through the camera centre tangent to the cylinder;
/// falls back to `f·R/z` when the camera is inside the cylinder.
fn silhouette_offsets(
    camera: &Camera,
    p0: &Vector3<f32>,
    p1: &Vector3<f32>,
    radius: f32,
    a: &Vector2<f32>,
    b: &Vector2<f32>,
) -> ([f32; 2], [f32; 2]) {
    let fallback = |z: f32| {
        let r = camera.pixels_at_depth(radius, z);
        [r, r]
    };
    let approx = (
        fallback(camera.to_camera(p0).z),
        fallback(camera.to_camera(p1).z),
    );
    let axis = p1 - p0;
    let Some(d) = axis.try_normalized(1e-6) else {
        return approx;
    };
    let rel = p0 - camera.centre();
    let w = rel - d * rel.dot(&d);
    let dist = w.length();
    if dist <= radius * 1.001 {
        return approx;
    }
    let w = w / dist;
    let m = d.cross(&w);
    let sin = radius / dist;
    let cos = crate::float::sqrt(1.0 - sin * sin);
    let (_, normal) = axis_frame(a, b);
    let mut out = approx;
    for sign in [1.0f32, -1.0] {
        let n_c = camera.r * (m * cos + w * (sign * sin));
        let l = Vector3::new(
            n_c.x / camera.fx,
            n_c.y / camera.fy,
            n_c.z - n_c.x * camera.cx / camera.fx - n_c.y * camera.cy / camera.fy,
        );
        let along = l.x * normal.x + l.y * normal.y;
        if along.abs() < 1e-12 {
            return approx;
        }
        let at = |p: &Vector2<f32>| -(l.x * p.x + l.y * p.y + l.z) / along;
        let (o0, o1) = (at(a), at(b));
        let k = usize::from(o0 + o1 < 0.0);
        out.0[k] = o0.abs();
        out.1[k] = o1.abs();
    }
    out
}

/// Distance (px) along the image axis direction from `b` (the image of the sphere centre `c`)
/// to the outline of the sphere of radius `radius` at `c`: exact, since the image line through
/// `b` along the axis back-projects to a plane through the camera centre and `c`.
fn sphere_outline_offset(
    camera: &Camera,
    c: &Vector3<f32>,
    radius: f32,
    a: &Vector2<f32>,
    b: &Vector2<f32>,
) -> f32 {
    let z = camera.to_camera(c).z;
    let approx = camera.pixels_at_depth(radius, z);
    let d = b - a;
    let len = d.length();
    if len < 1e-6 {
        return approx;
    }
    let dir = d / len;
    let ray = |p: Vector2<f32>| camera.ray(&p).normalized();
    let to_centre = camera.to_camera(c);
    let dist = to_centre.length();
    if dist <= radius * 1.001 {
        return approx;
    }
    let rc = to_centre / dist;
    let beside = ray(b + dir * 10.0);
    let Some(t) = (beside - rc * beside.dot(&rc)).try_normalized(1e-9) else {
        return approx;
    };
    let sin = radius / dist;
    let cos = crate::float::sqrt(1.0 - sin * sin);
    let tangent = rc * cos + t * sin;
    if tangent.z < 1e-6 {
        return approx;
    }
    let uv = Vector2::new(
        camera.fx * tangent.x / tangent.z + camera.cx,
        camera.fy * tangent.y / tangent.z + camera.cy,
    );
    dir.dot(&(uv - b))
}
