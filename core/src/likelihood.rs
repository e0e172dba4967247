//! How well a hypothesised hand state explains a frame, from the projected model alone (no
//! stored templates), after Stenger et al.'s tree-based filter: an oriented-edge chamfer term
//! (how far each projected silhouette line lies from an image edge of like orientation) and a
//! region term (the silhouette's [agreement](crate::silhouette) with the image).
//!
//! The frame's edges are found once per frame into an [`EdgeMap`] — on a grid of
//! `stride_px` cells, each cell holding, per orientation bin, its distance to the nearest
//! edge cell of that bin (a two-pass 3-4 chamfer distance transform) — in a buffer the
//! caller owns ([`EdgeMap::bytes_needed`]). Each hypothesis then costs one projection and a
//! few table look-ups per link ([`evaluate`]).

use core::f32::consts::PI;
use core::fmt;

use heapless::Vec;

use crate::camera::Camera;
use crate::config::MAX_LINKS;
use crate::frame::FrameView;
use crate::nalgebra::Vector2;
use crate::projection::ProjectedModel;
use crate::visibility::{cover, Cover};

/// Orientation bins of edge normals over 0..π (30° each).
pub const EDGE_BINS: usize = 6;

/// A cell's distance in chamfer units (3 per cell along a row or column, 4 diagonally),
/// saturating here: 85 cells.
const FAR: u8 = u8::MAX;

/// Parameters of the edge map and of the score.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LikelihoodConfig {
    /// Side of an edge map cell (px, ≥ 1): 4 keeps a VGA frame's map at 115 KB.
    pub stride_px: u8,
    /// The weakest edge marked: central-difference gradient magnitude (grey levels over 2 px).
    pub min_gradient: f32,
    /// Chamfer distances are truncated here (px), so one missing edge cannot dominate.
    pub chamfer_cap_px: f32,
    /// Points sampled along each silhouette line of each link.
    pub samples_per_line: u8,
    /// Grid of the silhouette term ([`silhouette::score`](crate::silhouette::score)); 0 leaves
    /// the term out.
    pub silhouette_grid: u8,
    /// Weight of the silhouette term in [`Likelihood::score`] (0..=1); the chamfer term has
    /// the rest.
    pub silhouette_weight: f32,
}

impl Default for LikelihoodConfig {
    fn default() -> Self {
        LikelihoodConfig {
            stride_px: 4,
            min_gradient: 24.0,
            chamfer_cap_px: 24.0,
            samples_per_line: 6,
            silhouette_grid: 16,
            silhouette_weight: 0.4,
        }
    }
}

/// Why an edge map could not be built.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LikelihoodError {
    /// The caller's buffer is smaller than [`EdgeMap::bytes_needed`].
    BufferTooSmall {
        /// Bytes needed.
        needed: u32,
    },
    /// `stride_px` is 0.
    ZeroStride,
}

impl fmt::Display for LikelihoodError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BufferTooSmall { needed } => {
                write!(f, "the edge map needs a buffer of {needed} bytes")
            }
            Self::ZeroStride => write!(f, "the edge map's stride must be at least 1 px"),
        }
    }
}

impl core::error::Error for LikelihoodError {}

/// The orientation bin of a line whose normal points at `angle` (rad, any value).
fn bin_of(angle: f32) -> (usize, usize) {
    let mut a = angle % PI;
    if a < 0.0 {
        a += PI;
    }
    let x = a / PI * EDGE_BINS as f32;
    let nearest = (libm::roundf(x) as usize) % EDGE_BINS;
    let floor = (libm::floorf(x) as usize) % EDGE_BINS;
    // The other bin this angle is closest to, so an edge near a bin border matches both.
    let second = if floor == nearest {
        (nearest + 1) % EDGE_BINS
    } else {
        floor
    };
    (nearest, second)
}

/// A frame's edges as per-orientation distance maps on a coarse grid, in a caller's buffer.
#[derive(Debug)]
pub struct EdgeMap<'b> {
    dist: &'b mut [u8],
    cols: usize,
    rows: usize,
    stride_px: usize,
    /// Edge cells marked (over all bins).
    pub edge_cells: u32,
}

impl<'b> EdgeMap<'b> {
    /// Bytes of buffer a `width × height` frame needs at `stride_px`.
    pub fn bytes_needed(width: usize, height: usize, stride_px: u8) -> usize {
        let s = usize::from(stride_px.max(1));
        width.div_ceil(s) * height.div_ceil(s) * EDGE_BINS
    }

    /// Finds `frame`'s edges and their distance maps into `buffer`.
    #[inline(never)] // a stage of the search: kept whole so profiles can attribute its cost
    pub fn build(
        buffer: &'b mut [u8],
        frame: &FrameView<'_>,
        config: &LikelihoodConfig,
    ) -> Result<Self, LikelihoodError> {
        if config.stride_px == 0 {
            return Err(LikelihoodError::ZeroStride);
        }
        let (w, h) = (frame.width(), frame.height());
        let needed = Self::bytes_needed(w, h, config.stride_px);
        let Some(dist) = buffer.get_mut(..needed) else {
            return Err(LikelihoodError::BufferTooSmall {
                needed: u32::try_from(needed).unwrap_or(u32::MAX),
            });
        };
        let s = usize::from(config.stride_px);
        let (cols, rows) = (w.div_ceil(s), h.div_ceil(s));
        dist.fill(FAR);
        let mut map = EdgeMap {
            dist,
            cols,
            rows,
            stride_px: s,
            edge_cells: 0,
        };
        map.mark_edges(frame, config.min_gradient);
        for bin in 0..EDGE_BINS {
            map.transform(bin);
        }
        Ok(map)
    }

    fn plane(&mut self, bin: usize) -> &mut [u8] {
        let n = self.cols * self.rows;
        self.dist
            .get_mut(bin * n..(bin + 1) * n)
            .unwrap_or_default()
    }

    /// Marks each cell's strongest edge pixel (if above `min_gradient`) in its two nearest
    /// orientation bins.
    fn mark_edges(&mut self, frame: &FrameView<'_>, min_gradient: f32) {
        let (w, h, s) = (frame.width(), frame.height(), self.stride_px);
        let min2 = min_gradient * min_gradient;
        for cy in 0..self.rows {
            for cx in 0..self.cols {
                let mut best = (min2, 0.0f32, 0.0f32);
                for y in (cy * s).max(1)..((cy + 1) * s).min(h.saturating_sub(1)) {
                    for x in (cx * s).max(1)..((cx + 1) * s).min(w.saturating_sub(1)) {
                        let px = |x: usize, y: usize| f32::from(frame.pixel(x, y).unwrap_or(0));
                        let gx = px(x + 1, y) - px(x - 1, y);
                        let gy = px(x, y + 1) - px(x, y - 1);
                        let m2 = gx * gx + gy * gy;
                        if m2 > best.0 {
                            best = (m2, gx, gy);
                        }
                    }
                }
                if best.0 > min2 {
                    let (first, second) = bin_of(libm::atan2f(best.2, best.1));
                    let at = cy * self.cols + cx;
                    self.edge_cells += 1;
                    for bin in [first, second] {
                        if let Some(d) = self.plane(bin).get_mut(at) {
                            *d = 0;
                        }
                    }
                }
            }
        }
    }

    /// The 3-4 chamfer distance transform of one bin's plane, in place (two passes).
    fn transform(&mut self, bin: usize) {
        let (cols, rows) = (self.cols, self.rows);
        let plane = self.plane(bin);
        let relax = |plane: &mut [u8], at: usize, from: usize, step: u8| {
            if let (Some(&f), Some(&t)) = (plane.get(from), plane.get(at)) {
                let via = f.saturating_add(step);
                if via < t {
                    plane[at] = via;
                }
            }
        };
        for y in 0..rows {
            for x in 0..cols {
                let at = y * cols + x;
                if x > 0 {
                    relax(plane, at, at - 1, 3);
                }
                if y > 0 {
                    relax(plane, at, at - cols, 3);
                    if x > 0 {
                        relax(plane, at, at - cols - 1, 4);
                    }
                    if x + 1 < cols {
                        relax(plane, at, at - cols + 1, 4);
                    }
                }
            }
        }
        for y in (0..rows).rev() {
            for x in (0..cols).rev() {
                let at = y * cols + x;
                if x + 1 < cols {
                    relax(plane, at, at + 1, 3);
                }
                if y + 1 < rows {
                    relax(plane, at, at + cols, 3);
                    if x + 1 < cols {
                        relax(plane, at, at + cols + 1, 4);
                    }
                    if x > 0 {
                        relax(plane, at, at + cols - 1, 4);
                    }
                }
            }
        }
    }

    /// Distance (px) from image point `p` to the nearest edge whose normal lies in `bin`;
    /// `None` outside the frame.
    pub fn distance_px(&self, bin: usize, p: &Vector2<f32>) -> Option<f32> {
        if !(p.x >= 0.0 && p.y >= 0.0) {
            return None;
        }
        let s = self.stride_px as f32;
        let (cx, cy) = ((p.x / s) as usize, (p.y / s) as usize);
        if cx >= self.cols || cy >= self.rows || bin >= EDGE_BINS {
            return None;
        }
        let n = self.cols * self.rows;
        let d = *self.dist.get(bin * n + cy * self.cols + cx)?;
        Some(f32::from(d) / 3.0 * s)
    }
}

/// How well one hypothesis explains one frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Likelihood {
    /// Mean truncated distance from the projected silhouette lines to like-oriented image
    /// edges (px; 0 = every sampled point on an edge).
    pub chamfer_px: f32,
    /// Silhouette points sampled inside the frame.
    pub points: u16,
    /// Points that fell outside the frame (each costs the cap).
    pub points_outside: u16,
    /// Points hidden by a nearer part of the hand (left out).
    pub points_hidden: u16,
    /// The silhouette's agreement with the image (0..=1), when it could be scored.
    pub silhouette: Option<f32>,
    /// The combined score (0..=1, higher is better): `1 − chamfer/cap` and the silhouette
    /// agreement, weighted by [`LikelihoodConfig::silhouette_weight`].
    pub score: f32,
}

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
        let mut out = Samples::default();
        let n = usize::from(config.samples_per_line).clamp(1, MAX_SAMPLES_PER_LINE);
        for (index, link) in view.links.iter().enumerate() {
            let d = link.b - link.a;
            let len = d.norm();
            if len < 1e-3 {
                continue;
            }
            let dir = d / len;
            let normal = Vector2::new(-dir.y, dir.x);
            let (bin, _) = bin_of(libm::atan2f(normal.y, normal.x));
            for (side, sign) in [(0usize, 1.0f32), (1, -1.0)] {
                for i in 0..n {
                    let s = (i as f32 + 0.5) / n as f32;
                    let r = link.r0[side] + s * (link.r1[side] - link.r0[side]);
                    let p = link.a + d * s + normal * (sign * r);
                    if cover(view, camera, index, &p, link.depth_at(s)) == Cover::Hidden {
                        // A nearer part of the hand hides this line: no edge is expected.
                        out.hidden = out.hidden.saturating_add(1);
                        continue;
                    }
                    // Bounded by MAX_SAMPLES: cannot overflow.
                    let _ = out.points.push(SilhouettePoint {
                        at: p,
                        bin: bin as u8,
                    });
                }
            }
        }
        out
    }

    /// The mean truncated chamfer distance (px) of the points shifted by `offset` (px) to
    /// like-oriented edges, and how many fell inside the frame; points outside cost `cap_px`.
    pub fn chamfer(&self, edges: &EdgeMap<'_>, offset: Vector2<f32>, cap_px: f32) -> (f32, u16) {
        let (mut sum, mut inside) = (0.0f32, 0u16);
        for p in &self.points {
            match edges.distance_px(usize::from(p.bin), &(p.at + offset)) {
                Some(d) => {
                    sum += d.min(cap_px);
                    inside = inside.saturating_add(1);
                }
                None => sum += cap_px,
            }
        }
        if self.points.is_empty() {
            (cap_px, 0)
        } else {
            (sum / self.points.len() as f32, inside)
        }
    }
}

/// Scores the projected model `view` (camera `camera`) against `frame`, whose edges are
/// `edges`. A view with no link in the frame scores 0.
#[inline(never)] // a stage of the search: kept whole so profiles can attribute its cost
pub fn evaluate(
    view: &ProjectedModel,
    camera: &Camera,
    frame: &FrameView<'_>,
    edges: &EdgeMap<'_>,
    config: &LikelihoodConfig,
) -> Likelihood {
    let samples = Samples::of(view, camera, config);
    let cap = config.chamfer_cap_px.max(1e-3);
    let (chamfer_px, inside) = samples.chamfer(edges, Vector2::zeros(), cap);
    let outside = (samples.points.len() as u16).saturating_sub(inside);
    if inside == 0 {
        return Likelihood {
            chamfer_px: cap,
            points_outside: outside,
            points_hidden: samples.hidden,
            ..Likelihood::default()
        };
    }
    let silhouette = (config.silhouette_grid > 0)
        .then(|| crate::silhouette::score(view, camera, frame, usize::from(config.silhouette_grid)))
        .flatten()
        .map(|s| s.agreement);
    let w = config.silhouette_weight.clamp(0.0, 1.0);
    let edge_term = 1.0 - chamfer_px / cap;
    let score = match silhouette {
        Some(a) => (1.0 - w) * edge_term + w * a,
        None => (1.0 - w) * edge_term,
    };
    Likelihood {
        chamfer_px,
        points: inside,
        points_outside: outside,
        points_hidden: samples.hidden,
        silhouette,
        score,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_small_buffer_or_a_zero_stride_is_an_error() {
        let pixels = [0u8; 64 * 48];
        let frame = FrameView::packed(&pixels, 64, 48).unwrap();
        let config = LikelihoodConfig::default();
        let needed = EdgeMap::bytes_needed(64, 48, config.stride_px);
        assert_eq!(needed, 16 * 12 * EDGE_BINS);
        let mut small = [0u8; 100];
        assert_eq!(
            EdgeMap::build(&mut small, &frame, &config).err(),
            Some(LikelihoodError::BufferTooSmall {
                needed: needed as u32
            })
        );
        let mut buffer = [0u8; 16 * 12 * EDGE_BINS];
        let zero = LikelihoodConfig {
            stride_px: 0,
            ..config
        };
        assert_eq!(
            EdgeMap::build(&mut buffer, &frame, &zero).err(),
            Some(LikelihoodError::ZeroStride)
        );
        // A flat frame has no edges: every distance is the farthest.
        let map = EdgeMap::build(&mut buffer, &frame, &config).unwrap();
        assert_eq!(map.edge_cells, 0);
        let far = map.distance_px(0, &Vector2::new(10.0, 10.0)).unwrap();
        assert!(far > 300.0, "{far}");
        assert_eq!(map.distance_px(0, &Vector2::new(-1.0, 10.0)), None);
    }

    #[test]
    fn bins_wrap_around_half_a_turn_and_name_the_next_nearest() {
        assert_eq!(bin_of(0.0).0, 0);
        assert_eq!(bin_of(PI).0, 0);
        assert_eq!(bin_of(-PI / 2.0).0, bin_of(PI / 2.0).0);
        let (a, b) = bin_of(PI / 6.0 * 0.6);
        assert_eq!((a, b), (1, 0));
        let (a, b) = bin_of(PI / 6.0 * 0.4);
        assert_eq!((a, b), (0, 1));
    }
}
