//! The palm box's own silhouette in one camera: the convex hull of its 8 projected corners
//! (issue 9). Each hull edge runs between two box corners, so it is carried as a radius-0
//! "link" segment ([`ProjectedLink`] with `r0 = r1 = 0`) in the palm's frame: the link
//! Jacobian ([`LinkJacobian`](crate::estimator::LinkJacobian)) and the edge-point rows of
//! [`add_link_rows`](crate::estimator::add_link_rows) then serve the palm's edges unchanged —
//! a found edge point's residual is its distance from the predicted hull edge line, and the
//! row's derivative comes from the two corners' derivatives (7 palm states) through the
//! camera.

use heapless::Vec;
use nalgebra::Vector2;

use crate::float::Length;
use crate::projection::{Bounds, ProjectedLink, ProjectedPalm, BOX_CORNERS};

/// Most edges of a box's image outline: a box seen from any point outside it shows 4 or 6.
pub const MAX_HULL_EDGES: usize = 6;

/// A hull vertex is kept only where the outline turns by more than this cross product of
/// the unit directions in and out of it (sin of the turn): nearly collinear corners would
/// give hull edges no longer than a rounding error.
pub const MIN_HULL_TURN: f32 = 1e-4;

/// One edge of the palm's image outline.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HullEdge {
    /// The two box corners it joins (numbered as [`BOX_CORNERS`] says), in hull order.
    pub corners: [u8; 2],
    /// The edge as a radius-0 link segment of the palm's frame: `a`, `b` the corners in the
    /// image (px), `p0`, `p1` in the world (mm), `z0`, `z1` their camera depths (mm).
    pub segment: ProjectedLink,
    /// Which side of the segment is outside the palm: +1 along its normal `(−d_y, d_x)`, −1
    /// opposite (the `side` of the edge points found on it).
    pub outward: i8,
}

impl HullEdge {
    /// Unit vector from the edge out of the palm (px).
    pub fn outward_normal(&self) -> Vector2<f32> {
        self.segment.normal() * f32::from(self.outward)
    }
}

/// The palm's image outline: its hull edges, in hull order.
#[derive(Debug, Clone, Default)]
pub struct PalmOutline {
    /// The hull edges (empty when the palm is not in view or has a corner behind the camera).
    pub edges: Vec<HullEdge, MAX_HULL_EDGES>,
}

impl PalmOutline {
    /// An empty outline.
    pub const fn new() -> Self {
        PalmOutline { edges: Vec::new() }
    }

    /// The outline of `palm` (cleared when `None`): every hull edge of its projected corners
    /// at least `min_edge_px` long. A palm with a corner behind the camera is never projected
    /// ([`ProjectedModel::update`](crate::projection::ProjectedModel::update)), so has no
    /// outline.
    pub fn update(&mut self, palm: Option<&ProjectedPalm>, min_edge_px: f32) {
        self.edges.clear();
        let Some(palm) = palm else {
            return;
        };
        let mut hull = [0u8; BOX_CORNERS];
        let n = convex_hull(&palm.corners_px, &mut hull);
        if n < 3 {
            return;
        }
        let hull = &hull[..n];
        let mut centre = Vector2::zeros();
        for &k in hull {
            centre += palm.corners_px[usize::from(k)];
        }
        centre /= n as f32;
        for (i, &c0) in hull.iter().enumerate() {
            let c1 = hull[(i + 1) % n];
            let (i0, i1) = (usize::from(c0), usize::from(c1));
            let (a, b) = (palm.corners_px[i0], palm.corners_px[i1]);
            if (b - a).length() < min_edge_px {
                continue;
            }
            let segment = ProjectedLink {
                frame: palm.frame,
                child: palm.frame,
                distal: false,
                knuckle_ends: false,
                radius_mm: 0.0,
                p0: palm.corners_mm[i0],
                p1: palm.corners_mm[i1],
                a,
                b,
                z0: palm.corners_z[i0],
                z1: palm.corners_z[i1],
                r0: [0.0; 2],
                r1: [0.0; 2],
                tip_offset: 0.0,
                bounds: Bounds {
                    min: a.inf(&b),
                    max: a.sup(&b),
                },
            };
            let mid = (a + b) * 0.5;
            let outward = if segment.normal().dot(&(mid - centre)) >= 0.0 {
                1
            } else {
                -1
            };
            // At most 6 edges for a box; a 7th could only come of rounding: left out.
            let _ = self.edges.push(HullEdge {
                corners: [c0, c1],
                segment,
                outward,
            });
        }
    }

    /// The hull edge joining corners `corners` (either order), if it is on the outline.
    pub fn find(&self, corners: [u8; 2]) -> Option<&HullEdge> {
        self.edges.iter().find(|e| {
            e.corners == corners || (e.corners[0] == corners[1] && e.corners[1] == corners[0])
        })
    }
}

/// The convex hull of `points` as indices into them, into `out`; returns how many. The hull
/// turns the same way at every vertex: `(p[k] − p[k−1]) × (p[k+1] − p[k]) > 0` with `×` the
/// 2-D cross product `x₁y₂ − y₁x₂` (counter-clockwise with y up, so clockwise on the screen,
/// y down). Collinear and repeated points are left out; non-finite points are ignored.
/// Andrew's monotone chain, without allocation.
pub fn convex_hull(points: &[Vector2<f32>; BOX_CORNERS], out: &mut [u8; BOX_CORNERS]) -> usize {
    let mut order = [0u8; BOX_CORNERS];
    let mut m = 0;
    for (k, p) in points.iter().enumerate() {
        if p.x.is_finite() && p.y.is_finite() {
            order[m] = k as u8;
            m += 1;
        }
    }
    let order = &mut order[..m];
    let key = |k: &u8| points[usize::from(*k)];
    order.sort_unstable_by(|i, j| {
        let (p, q) = (key(i), key(j));
        p.x.total_cmp(&q.x).then(p.y.total_cmp(&q.y))
    });
    // Twice the points, less one: the lower chain then the upper, sharing their ends.
    let mut chain = [0u8; 2 * BOX_CORNERS];
    let mut n = 0;
    let turns = |chain: &[u8], n: usize, next: u8| {
        let (o, a, b) = (
            key(&chain[n - 2]),
            key(&chain[n - 1]),
            points[usize::from(next)],
        );
        let (u, v) = (a - o, b - a);
        let scale = u.length() * v.length();
        scale > 0.0 && u.x * v.y - u.y * v.x > MIN_HULL_TURN * scale
    };
    for &k in order.iter() {
        while n >= 2 && !turns(&chain, n, k) {
            n -= 1;
        }
        if n >= 1 && key(&chain[n - 1]) == points[usize::from(k)] {
            continue;
        }
        chain[n] = k;
        n += 1;
    }
    let lower = n + 1;
    for &k in order.iter().rev().skip(1) {
        while n >= lower && !turns(&chain, n, k) {
            n -= 1;
        }
        chain[n] = k;
        n += 1;
    }
    // The last point repeats the first.
    let count = n.saturating_sub(1).min(BOX_CORNERS);
    if count < 3 {
        return 0;
    }
    out[..count].copy_from_slice(&chain[..count]);
    count
}
