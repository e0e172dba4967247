//! A frame's edges as per-orientation distance maps on a coarse grid, and its bright region,
//! built once per frame in a buffer the caller owns.
//!
//! The frame is split into cells of `stride_px` pixels. Gradients are taken (integer central
//! differences) only on every [`GRADIENT_STEP_PX`]th pixel of every [`GRADIENT_STEP_PX`]th
//! row: a step edge between two pixels changes the central difference of both, and one of
//! any two neighbours is sampled, so no edge is missed, at a quarter of the pixels. Each cell
//! keeps its strongest gradient above `min_gradient`, entered in its two nearest orientation
//! bins; each bin then gets a two-pass 3-4 chamfer distance transform in `u8`.
//!
//! The same pass histograms the sampled grey levels for the frame's [`Region`].

use core::f32::consts::PI;

use crate::frame::FrameView;
use crate::nalgebra::Vector2;

use super::region::{Region, RegionBuilder};
use super::{LikelihoodConfig, LikelihoodError};

/// Orientation bins of edge normals over 0..π (30° each).
pub const EDGE_BINS: usize = 6;

/// Gradients are sampled on every this many pixels of every this many rows (within a cell
/// of at least this size).
pub const GRADIENT_STEP_PX: usize = 2;

/// A cell's distance in chamfer units (3 per cell along a row or column, 4 diagonally),
/// held at most here (83 cells): low enough that adding 4 cannot overflow a `u8`, so the
/// passes need no saturating arithmetic.
const FAR: u8 = 250;

/// The orientation bin of a line whose normal points at `angle` (rad, any value), and the
/// other bin nearest it.
pub(crate) fn bin_of(angle: f32) -> (usize, usize) {
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
    /// The frame's bright region (the hand is brighter than the background), when the frame
    /// has one.
    pub region: Option<Region>,
}

impl<'b> EdgeMap<'b> {
    /// Bytes of buffer a `width × height` frame needs at `stride_px`.
    pub fn bytes_needed(width: usize, height: usize, stride_px: u8) -> usize {
        let s = usize::from(stride_px.max(1));
        width.div_ceil(s) * height.div_ceil(s) * EDGE_BINS
    }

    /// Finds `frame`'s edges, their distance maps and its bright region into `buffer`.
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
            region: None,
        };
        let mut region = RegionBuilder::new(w, h);
        map.mark_edges(frame, config.min_gradient, &mut region);
        map.region = region.finish(frame);
        for bin in 0..EDGE_BINS {
            map.transform(bin);
        }
        Ok(map)
    }

    /// Cells across and down.
    pub fn cells(&self) -> (usize, usize) {
        (self.cols, self.rows)
    }

    fn plane(&mut self, bin: usize) -> &mut [u8] {
        let n = self.cols * self.rows;
        self.dist
            .get_mut(bin * n..(bin + 1) * n)
            .unwrap_or_default()
    }

    /// Marks each cell's strongest sampled gradient (if above `min_gradient`) in its two
    /// nearest orientation bins, and histograms the sampled grey levels into `region`.
    fn mark_edges(&mut self, frame: &FrameView<'_>, min_gradient: f32, region: &mut RegionBuilder) {
        let (w, h, s) = (frame.width(), frame.height(), self.stride_px);
        let step = GRADIENT_STEP_PX.min(s).max(1);
        // Integer gradients: compare squared magnitudes in i32 (at most 2 · 255²).
        let min2 = (min_gradient.max(0.0) * min_gradient.max(0.0)) as i32;
        let px = |x: usize, y: usize| i32::from(frame.pixel(x, y).unwrap_or(0));
        for cy in 0..self.rows {
            let (y0, y1) = ((cy * s).max(1), ((cy + 1) * s).min(h.saturating_sub(1)));
            for cx in 0..self.cols {
                let (x0, x1) = ((cx * s).max(1), ((cx + 1) * s).min(w.saturating_sub(1)));
                let mut best = (min2, 0i32, 0i32);
                // Odd rows and columns (every one when the step is 1).
                let odd = |v: usize| if step > 1 { v | 1 } else { v };
                let mut y = odd(y0);
                while y < y1 {
                    let mut x = odd(x0);
                    while x < x1 {
                        let centre = px(x, y);
                        region.add(centre);
                        let gx = px(x + 1, y) - px(x - 1, y);
                        let gy = px(x, y + 1) - px(x, y - 1);
                        let m2 = gx * gx + gy * gy;
                        if m2 > best.0 {
                            best = (m2, gx, gy);
                        }
                        x += step;
                    }
                    y += step;
                }
                if best.0 > min2 {
                    let (first, second) = bin_of(libm::atan2f(best.2 as f32, best.1 as f32));
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
        let cols = self.cols;
        let plane = self.plane(bin);
        if cols == 0 {
            return;
        }
        // Forward: from the left and the row above.
        for y in 0..plane.len() / cols {
            let (above, rest) = plane.split_at_mut(y * cols);
            let Some(row) = rest.get_mut(..cols) else {
                return;
            };
            let prev = above.get(above.len().saturating_sub(cols)..).unwrap_or(&[]);
            relax_row(row, prev, 1);
        }
        // Backward: from the right and the row below.
        for y in (0..plane.len() / cols).rev() {
            let (head, below) = plane.split_at_mut((y + 1) * cols);
            let Some(row) = head.get_mut(y * cols..) else {
                return;
            };
            let next = below.get(..cols).unwrap_or(&[]);
            relax_row(row, next, -1);
        }
    }

    /// Distance (px) from image point `p` to the nearest edge whose normal lies in `bin`;
    /// `None` outside the frame.
    #[inline]
    pub fn distance_px(&self, bin: usize, p: &Vector2<f32>) -> Option<f32> {
        self.distance_units(bin, p)
            .map(|d| f32::from(d) / 3.0 * self.stride_px as f32)
    }

    /// The raw distance of [`Self::distance_px`] in chamfer units (3 per cell).
    #[inline]
    pub fn distance_units(&self, bin: usize, p: &Vector2<f32>) -> Option<u8> {
        if !(p.x >= 0.0 && p.y >= 0.0) {
            return None;
        }
        let s = self.stride_px as f32;
        let (cx, cy) = ((p.x / s) as usize, (p.y / s) as usize);
        if cx >= self.cols || cy >= self.rows || bin >= EDGE_BINS {
            return None;
        }
        let n = self.cols * self.rows;
        self.dist.get(bin * n + cy * self.cols + cx).copied()
    }

    /// Side of a cell (px).
    pub fn stride_px(&self) -> usize {
        self.stride_px
    }
}

/// One row of a chamfer pass: `row` relaxed from its neighbour along the pass (`dir` = 1:
/// left to right, from `other`, the row above; −1: right to left, from the row below).
#[inline]
fn relax_row(row: &mut [u8], other: &[u8], dir: i32) {
    if dir > 0 {
        relax_forward(row, other);
    } else {
        row.reverse();
        // The other row reversed on the fly: the same pass, mirrored.
        let mut mirrored = [FAR; MAX_PASS_CELLS];
        let m = other.len().min(MAX_PASS_CELLS);
        for (d, s) in mirrored.iter_mut().zip(other.iter().take(m).rev()) {
            *d = *s;
        }
        relax_forward(row, mirrored.get(..m).unwrap_or(&[]));
        row.reverse();
    }
}

/// Cells of a row the mirrored pass handles with the row above or below (wider rows are
/// relaxed along the row only).
const MAX_PASS_CELLS: usize = 512;

/// Left to right: each cell from the three cells of `other` above it (independent per
/// cell), then from its left neighbour (a running minimum). Every value stays ≤ [`FAR`].
#[inline]
fn relax_forward(row: &mut [u8], other: &[u8]) {
    let n = row.len();
    if other.len() == n && n > 1 {
        if let (Some(first), Some(&o0), Some(&o1)) = (row.first_mut(), other.first(), other.get(1))
        {
            *first = (*first).min(o0 + 3).min(o1 + 4);
        }
        for (d, w) in row.iter_mut().skip(1).zip(other.windows(3)) {
            let (ul, u, ur) = (w[0], w[1], w[2]);
            *d = (*d).min(u + 3).min((ul + 4).min(ur + 4));
        }
        if let (Some(last), Some(&ol), Some(&o)) =
            (row.last_mut(), other.get(n - 2), other.get(n - 1))
        {
            *last = (*last).min(o + 3).min(ol + 4);
        }
    } else if other.len() == n {
        for (d, o) in row.iter_mut().zip(other) {
            *d = (*d).min(o + 3);
        }
    }
    let mut left = FAR;
    for v in row.iter_mut() {
        let d = (*v).min(left + 3).min(FAR);
        *v = d;
        left = d;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn a_square_is_found_and_its_distances_grow_away_from_it() {
        let (w, h) = (64usize, 48usize);
        let mut pixels = [20u8; 64 * 48];
        for y in 16..32 {
            for x in 20..44 {
                pixels[y * w + x] = 200;
            }
        }
        let frame = FrameView::packed(&pixels, w, h).unwrap();
        let config = LikelihoodConfig::default();
        let mut buffer = [0u8; 16 * 12 * EDGE_BINS];
        let map = EdgeMap::build(&mut buffer, &frame, &config).unwrap();
        assert!(map.edge_cells > 8, "{}", map.edge_cells);
        // The left side's normal is horizontal (bin 0): on it, within a cell; 16 px away, about 16.
        let on = map.distance_px(0, &Vector2::new(20.0, 24.0)).unwrap();
        let off = map.distance_px(0, &Vector2::new(4.0, 24.0)).unwrap();
        assert!(on <= 4.0 && (12.0..=20.0).contains(&off), "{on} {off}");
        // The top's normal is vertical (bin 3): far from the left side's bin.
        let top = map.distance_px(3, &Vector2::new(32.0, 16.0)).unwrap();
        assert!(top <= 4.0, "{top}");
        let region = map.region.unwrap();
        assert!((region.centre_px.x - 31.5).abs() < 3.0, "{region:?}");
        assert!((region.centre_px.y - 23.5).abs() < 3.0, "{region:?}");
    }
}
