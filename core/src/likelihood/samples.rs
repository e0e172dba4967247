//! The visible silhouette points of a projected hand: what the chamfer term compares with
//! the frame's edges.

use heapless::Vec;

use crate::camera::Camera;
use crate::config::MAX_LINKS;
use crate::float::Length;
use crate::nalgebra::Vector2;
use crate::projection::ProjectedModel;
use crate::visibility::{candidates, cover_among, Cover};

use super::edges::{bin_of, EdgeMap};
use super::LikelihoodConfig;

/// Most silhouette points one view yields: two lines per link, at most 16 points each.
pub const MAX_SAMPLES: usize = MAX_LINKS * 2 * MAX_SAMPLES_PER_LINE;

/// Most points sampled along one silhouette line.
pub const MAX_SAMPLES_PER_LINE: usize = 16;

/// A visible point of the projected silhouette and the orientation bin of its line's normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SilhouettePoint {
    /// Where (px).
    pub at: Vector2<f32>,
    /// The orientation bin of the silhouette line's normal.
    pub bin: u8,
}

/// The visible silhouette points of a view: what the chamfer term compares with the edges.
#[derive(Debug, Clone, Default)]
pub struct Samples {
    /// Points not hidden by a nearer part of the hand.
    pub points: Vec<SilhouettePoint, MAX_SAMPLES>,
    /// Points hidden by a nearer part of the hand (left out).
    pub hidden: u16,
}

impl Samples {
    /// The visible silhouette points of `view` (camera `camera`):
    /// [`LikelihoodConfig::samples_per_line`] along each side of each link.
    pub fn of(view: &ProjectedModel, camera: &Camera, config: &LikelihoodConfig) -> Self {
        let mut points = Vec::new();
        let hidden = visit(view, camera, config, |p| {
            // Bounded by MAX_SAMPLES: cannot overflow.
            let _ = points.push(p);
        });
        Samples { points, hidden }
    }

    /// The mean truncated chamfer distance (px) of the points shifted by `offset` (px) to
    /// like-oriented edges, and how many fell inside the frame; points outside cost `cap_px`.
    pub fn chamfer(&self, edges: &EdgeMap<'_>, offset: Vector2<f32>, cap_px: f32) -> (f32, u16) {
        let mut sum = ChamferSum::new(cap_px);
        for p in &self.points {
            sum.add(edges, p.bin, &(p.at + offset));
        }
        (sum.mean_px(), sum.inside)
    }
}

/// The chamfer term summed point by point: each point's distance (px) to the nearest edge of
/// its orientation bin, truncated at the cap; a point outside the frame costs the cap.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ChamferSum {
    cap_px: f32,
    sum_px: f32,
    /// Points added.
    pub(crate) points: u32,
    /// Points added that fell inside the frame.
    pub(crate) inside: u16,
}

impl ChamferSum {
    pub(crate) fn new(cap_px: f32) -> Self {
        ChamferSum {
            cap_px,
            sum_px: 0.0,
            points: 0,
            inside: 0,
        }
    }

    /// Adds the point at `at` (px) of orientation bin `bin`.
    #[inline]
    pub(crate) fn add(&mut self, edges: &EdgeMap<'_>, bin: u8, at: &Vector2<f32>) {
        self.points += 1;
        match edges.distance_px(usize::from(bin), at) {
            Some(d) => {
                self.sum_px += d.min(self.cap_px);
                self.inside = self.inside.saturating_add(1);
            }
            None => self.sum_px += self.cap_px,
        }
    }

    /// The mean truncated distance (px); the cap when no point was added.
    pub(crate) fn mean_px(&self) -> f32 {
        if self.points == 0 {
            self.cap_px
        } else {
            self.sum_px / self.points as f32
        }
    }

    /// Points added that fell outside the frame.
    pub(crate) fn outside(&self) -> u16 {
        u16::try_from(self.points)
            .unwrap_or(u16::MAX)
            .saturating_sub(self.inside)
    }
}

/// Calls `visible` with each visible silhouette point of `view` (camera `camera`), in
/// [`Samples::of`]'s order, and returns how many were hidden by a nearer part of the hand:
/// the points without a buffer to hold them (at most [`MAX_SAMPLES`]).
pub fn visit(
    view: &ProjectedModel,
    camera: &Camera,
    config: &LikelihoodConfig,
    mut visible: impl FnMut(SilhouettePoint),
) -> u16 {
    let mut hidden = 0u16;
    let n = usize::from(config.samples_per_line).clamp(1, MAX_SAMPLES_PER_LINE);
    for (index, link) in view.links.iter().enumerate() {
        let d = link.b - link.a;
        let len = d.length();
        if len < 1e-3 {
            continue;
        }
        let dir = d / len;
        let normal = Vector2::new(-dir.y, dir.x);
        let (bin, _) = bin_of(libm::atan2f(normal.y, normal.x));
        // The parts that can hide any of this link's points, found once for the link (its
        // bounds hold every silhouette point): the same verdicts as per point, cheaper.
        let (among, palm) = candidates(view, index, &link.bounds);
        for (side, sign) in [(0usize, 1.0f32), (1, -1.0)] {
            for i in 0..n {
                let s = (i as f32 + 0.5) / n as f32;
                let r = link.r0[side] + s * (link.r1[side] - link.r0[side]);
                let p = link.a + d * s + normal * (sign * r);
                if cover_among(view, camera, &among, palm, &p, link.depth_at(s)) == Cover::Hidden {
                    // A nearer part of the hand hides this line: no edge is expected.
                    hidden = hidden.saturating_add(1);
                    continue;
                }
                visible(SilhouettePoint {
                    at: p,
                    bin: bin as u8,
                });
            }
        }
    }
    hidden
}
