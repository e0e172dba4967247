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

use super::reads::{CellRect, Reads};
use super::region::{Region, RegionBuilder};
use super::{LikelihoodConfig, LikelihoodError};

/// Orientation bins of edge normals over 0..π (30° each).
pub const EDGE_BINS: usize = 6;

/// Gradients are sampled on every this many pixels of every this many rows (within a cell
/// of at least this size).
pub const GRADIENT_STEP_PX: usize = 2;

/// Cells of a row whose strongest gradients one sweep along the pixel rows keeps at once.
const CELL_CHUNK: usize = 64;

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

/// What a built [`EdgeMap`] holds besides its buffer's bytes: enough to open the same map
/// again from that buffer ([`EdgeMap::reopen`]) without building it a second time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BuiltEdges {
    width: usize,
    height: usize,
    min_gradient: f32,
    cols: usize,
    rows: usize,
    stride_px: usize,
    edge_cells: u32,
    region: Option<Region>,
    within: CellRect,
}

impl BuiltEdges {
    /// Whether this is the map [`EdgeMap::build`] makes of a frame of `frame`'s size under
    /// `config` (the size and the parameters the build used; not the pixels).
    pub fn fits(&self, frame: &FrameView<'_>, config: &LikelihoodConfig) -> bool {
        self.width == frame.width()
            && self.height == frame.height()
            && self.stride_px == usize::from(config.stride_px)
            && self.min_gradient.to_bits() == config.min_gradient.to_bits()
    }

    /// Whether the map reads as one built over the whole frame wherever `reads` reads it
    /// under `config` (a map built for other reads may have left those cells out).
    pub fn covers(&self, reads: &Reads, config: &LikelihoodConfig) -> bool {
        let needed = reads.cells(self.cols, self.rows, self.stride_px, config);
        self.within.contains(&needed)
    }
}

/// A frame's edges as per-orientation distance maps on a coarse grid, in a caller's buffer.
#[derive(Debug)]
pub struct EdgeMap<'b> {
    dist: &'b mut [u8],
    cols: usize,
    rows: usize,
    stride_px: usize,
    /// Edge cells marked (over all bins), among the cells found (every cell of a map built
    /// for the search or for [`Reads::Everywhere`]).
    pub edge_cells: u32,
    /// The frame's bright region (the hand is brighter than the background), when the frame
    /// has one.
    pub region: Option<Region>,
    /// The cells whose marks and distances were found; every other cell reads as far from
    /// any edge.
    within: CellRect,
}

impl<'b> EdgeMap<'b> {
    /// Bytes of buffer a `width × height` frame needs at `stride_px`.
    pub fn bytes_needed(width: usize, height: usize, stride_px: u8) -> usize {
        let s = usize::from(stride_px.max(1));
        width.div_ceil(s) * height.div_ceil(s) * EDGE_BINS
    }

    /// The bytes a build of `frame`'s map under `config` uses, or why a buffer of
    /// `buffer_len` bytes cannot hold it: what every build checks first, for a caller that
    /// must know before it starts work it could not finish.
    pub fn check_buffer(
        buffer_len: usize,
        frame: &FrameView<'_>,
        config: &LikelihoodConfig,
    ) -> Result<usize, LikelihoodError> {
        if config.stride_px == 0 {
            return Err(LikelihoodError::ZeroStride);
        }
        let needed = Self::bytes_needed(frame.width(), frame.height(), config.stride_px);
        if buffer_len < needed {
            return Err(LikelihoodError::BufferTooSmall {
                needed: u32::try_from(needed).unwrap_or(u32::MAX),
            });
        }
        Ok(needed)
    }

    /// Finds `frame`'s edges, their distance maps and its bright region into `buffer`: the
    /// map the search needs (it places its hypotheses on the region).
    #[inline(never)] // a stage of the search: kept whole so profiles can attribute its cost
    pub fn build(
        buffer: &'b mut [u8],
        frame: &FrameView<'_>,
        config: &LikelihoodConfig,
    ) -> Result<Self, LikelihoodError> {
        let (w, h) = (frame.width(), frame.height());
        let mut region = RegionBuilder::new(w, h);
        let mut map = Self::build_marking(buffer, frame, config, Reads::Everywhere, &mut region)?;
        map.region = region.finish(frame);
        Ok(map)
    }

    /// [`EdgeMap::build`] without the bright region (`region` is `None`), for a score, which
    /// never reads the region, and only over the cells a score that reads the map as `reads`
    /// says depends on ([`Reads::cells`]; [`Reads::Everywhere`]: every cell). Those reads
    /// return what they would on [`EdgeMap::build`]'s map, bit for bit. The region's histogram
    /// and its second pass are about a fifth of a build (1.6 M of 7.4 M instructions at
    /// 640×480 on x86-64), and a hand a third of a 640×480 frame wide reads about a fifth of
    /// its cells.
    #[inline(never)] // a stage of the loop: kept whole so profiles can attribute its cost
    pub fn build_edges_for(
        buffer: &'b mut [u8],
        frame: &FrameView<'_>,
        config: &LikelihoodConfig,
        reads: Reads,
    ) -> Result<Self, LikelihoodError> {
        Self::build_marking(buffer, frame, config, reads, &mut NoGreyLevels)
    }

    /// The distance maps of the cells `reads` needs, the sampled grey levels given to `grey`.
    fn build_marking(
        buffer: &'b mut [u8],
        frame: &FrameView<'_>,
        config: &LikelihoodConfig,
        reads: Reads,
        grey: &mut impl GreyLevels,
    ) -> Result<Self, LikelihoodError> {
        let needed = Self::check_buffer(buffer.len(), frame, config)?;
        let (w, h) = (frame.width(), frame.height());
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
            within: reads.cells(cols, rows, s, config),
        };
        map.mark_edges(frame, config.min_gradient, grey);
        for bin in 0..EDGE_BINS {
            map.transform(bin);
        }
        Ok(map)
    }

    /// What opens this map again from its buffer ([`EdgeMap::reopen`]), given the frame and
    /// the parameters it was built from ([`EdgeMap::build`]'s).
    pub fn built(&self, frame: &FrameView<'_>, config: &LikelihoodConfig) -> BuiltEdges {
        BuiltEdges {
            width: frame.width(),
            height: frame.height(),
            min_gradient: config.min_gradient,
            cols: self.cols,
            rows: self.rows,
            stride_px: self.stride_px,
            edge_cells: self.edge_cells,
            region: self.region,
            within: self.within,
        }
    }

    /// The map `built` describes, from the buffer it was built in, as it was: the caller
    /// vouches that `buffer` has not been written since ([`EdgeMap::built`] on the same frame).
    /// A scorer that needs the frame's map twice saves the second build (2.7 M instructions
    /// for a 320×240 frame on x86-64). Fails only when `buffer` is too small for `built`'s cells.
    pub fn reopen(buffer: &'b mut [u8], built: BuiltEdges) -> Result<Self, LikelihoodError> {
        let needed = built.cols * built.rows * EDGE_BINS;
        let Some(dist) = buffer.get_mut(..needed) else {
            return Err(LikelihoodError::BufferTooSmall {
                needed: u32::try_from(needed).unwrap_or(u32::MAX),
            });
        };
        Ok(EdgeMap {
            dist,
            cols: built.cols,
            rows: built.rows,
            stride_px: built.stride_px,
            edge_cells: built.edge_cells,
            region: built.region,
            within: built.within,
        })
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
    /// nearest orientation bins, and gives the sampled grey levels to `region`.
    fn mark_edges(
        &mut self,
        frame: &FrameView<'_>,
        min_gradient: f32,
        region: &mut impl GreyLevels,
    ) {
        let (w, h, s) = (frame.width(), frame.height(), self.stride_px);
        let step = GRADIENT_STEP_PX.min(s).max(1);
        // Integer gradients: compare squared magnitudes in i32 (at most 2 · 255²).
        let min2 = (min_gradient.max(0.0) * min_gradient.max(0.0)) as i32;
        let row = |y: usize| frame.row(y).unwrap_or(&[]);
        let px = |row: &[u8], x: usize| i32::from(row.get(x).copied().unwrap_or(0));
        // Odd rows and columns (every one when the step is 1).
        let odd = |v: usize| if step > 1 { v | 1 } else { v };
        let within = self.within;
        for cy in within.y0..within.y1.min(self.rows) {
            let (y0, y1) = ((cy * s).max(1), ((cy + 1) * s).min(h.saturating_sub(1)));
            // Up to CELL_CHUNK cells of the row at once, so each pixel row is looked up once
            // per chunk; each cell still visits its pixels row by row, left to right.
            let last = within.x1.min(self.cols);
            let mut c0 = within.x0;
            while c0 < last {
                let c1 = (c0 + CELL_CHUNK).min(last);
                let mut best = [(min2, 0i32, 0i32); CELL_CHUNK];
                let mut y = odd(y0);
                while y < y1 {
                    let (above, at, below) = (row(y - 1), row(y), row(y + 1));
                    for (cx, best) in (c0..c1).zip(best.iter_mut()) {
                        let (x0, x1) = ((cx * s).max(1), ((cx + 1) * s).min(w.saturating_sub(1)));
                        let mut x = odd(x0);
                        while x < x1 {
                            let centre = px(at, x);
                            region.add(centre);
                            let gx = px(at, x + 1) - px(at, x - 1);
                            let gy = px(below, x) - px(above, x);
                            let m2 = gx * gx + gy * gy;
                            if m2 > best.0 {
                                *best = (m2, gx, gy);
                            }
                            x += step;
                        }
                    }
                    y += step;
                }
                for (cx, &(m2, gx, gy)) in (c0..c1).zip(best.iter()) {
                    if m2 > min2 {
                        let (first, second) = bin_of(libm::atan2f(gy as f32, gx as f32));
                        let at = cy * self.cols + cx;
                        self.edge_cells += 1;
                        for bin in [first, second] {
                            if let Some(d) = self.plane(bin).get_mut(at) {
                                *d = 0;
                            }
                        }
                    }
                }
                c0 = c1;
            }
        }
    }

    /// The 3-4 chamfer distance transform of one bin's plane within the cells found, in
    /// place (two passes); the cells beyond stay as far as they were filled.
    fn transform(&mut self, bin: usize) {
        let (cols, rows) = (self.cols, self.rows);
        let r = self.within;
        let (x0, x1, y1) = (r.x0, r.x1.min(cols), r.y1.min(rows));
        let plane = self.plane(bin);
        if x0 >= x1 || r.y0 >= y1 {
            return;
        }
        // Forward: from the left and the row above.
        for y in r.y0..y1 {
            let (above, rest) = plane.split_at_mut(y * cols);
            let Some(row) = rest.get_mut(x0..x1) else {
                return;
            };
            let prev = match y.checked_sub(1) {
                Some(p) if y > r.y0 => above.get(p * cols + x0..p * cols + x1).unwrap_or(&[]),
                _ => &[],
            };
            relax_row(row, prev, 1);
        }
        // Backward: from the right and the row below.
        for y in (r.y0..y1).rev() {
            let (head, below) = plane.split_at_mut((y + 1) * cols);
            let Some(row) = head.get_mut(y * cols + x0..y * cols + x1) else {
                return;
            };
            let next = if y + 1 < y1 {
                below.get(x0..x1).unwrap_or(&[])
            } else {
                &[]
            };
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

/// Where [`EdgeMap::mark_edges`] puts each sampled grey level: the region's histogram, or
/// nowhere ([`EdgeMap::build_edges_for`]). A type, not a flag, so the pass without the region has
/// no test in its inner loop.
trait GreyLevels {
    fn add(&mut self, grey: i32);
}

impl GreyLevels for RegionBuilder {
    #[inline]
    fn add(&mut self, grey: i32) {
        RegionBuilder::add(self, grey);
    }
}

/// The grey levels of a map built without its region.
struct NoGreyLevels;

impl GreyLevels for NoGreyLevels {
    #[inline]
    fn add(&mut self, _grey: i32) {}
}

/// One row of a chamfer pass: each cell relaxed from the three cells of `other` (the row the
/// pass comes from: above for `dir` = 1, below for −1) beside it, then along the row from
/// the side the pass starts (`dir` = 1: left to right; −1: right to left). The 3-4 mask's
/// cells in the other row are the same either way (4, 3, 4), so only the run along the row
/// turns round. Every value stays ≤ [`FAR`].
#[inline]
fn relax_row(row: &mut [u8], other: &[u8], dir: i32) {
    relax_across(row, other);
    if dir > 0 {
        relax_along(row.iter_mut());
    } else {
        relax_along(row.iter_mut().rev());
    }
}

/// Each cell from the three cells of `other` beside it (3 straight across, 4 diagonally),
/// independent per cell; nothing when `other` is not as long as `row` (the first row of a
/// pass). Rows of any width (the mirrored pass before stop 48 relaxed rows over 512 cells
/// along the row only).
#[inline]
fn relax_across(row: &mut [u8], other: &[u8]) {
    let n = row.len();
    if other.len() != n {
        return;
    }
    if n < 2 {
        for (d, o) in row.iter_mut().zip(other) {
            *d = (*d).min(o + 3);
        }
        return;
    }
    if let (Some(first), Some(&o0), Some(&o1)) = (row.first_mut(), other.first(), other.get(1)) {
        *first = (*first).min(o0 + 3).min(o1 + 4);
    }
    if let (Some(last), Some(&ol), Some(&o)) = (row.last_mut(), other.get(n - 2), other.get(n - 1))
    {
        *last = (*last).min(o + 3).min(ol + 4);
    }
    // Inner cells against three equally long views of `other` (its cells before, across and
    // after each): plain slices, which the compiler turns into vector code.
    let (Some(inner), Some(before), Some(across), Some(after)) = (
        row.get_mut(1..n - 1),
        other.get(..n - 2),
        other.get(1..n - 1),
        other.get(2..),
    ) else {
        return;
    };
    for (((d, &a), &b), &c) in inner.iter_mut().zip(before).zip(across).zip(after) {
        *d = (*d).min(b + 3).min((a + 4).min(c + 4));
    }
}

/// A running minimum along `cells`, in the order given: each cell from the one before (3).
#[inline]
fn relax_along<'a>(cells: impl Iterator<Item = &'a mut u8>) {
    let mut before = FAR;
    for v in cells {
        let d = (*v).min(before + 3).min(FAR);
        *v = d;
        before = d;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    extern crate std;
    use std::{vec, vec::Vec};

    /// Each cell's strongest gradient found the plain way, cell by cell, every pixel through
    /// `FrameView::pixel` (the map's gradient pass before it read rows): an oracle for
    /// [`EdgeMap::mark_edges`]. Returns the marked planes (0 on an edge, `FAR` elsewhere) and the
    /// edge cells.
    fn marked_plainly(frame: &FrameView<'_>, s: usize, min_gradient: f32) -> (Vec<u8>, u32) {
        let (w, h) = (frame.width(), frame.height());
        let (cols, rows) = (w.div_ceil(s), h.div_ceil(s));
        let mut planes = vec![FAR; cols * rows * EDGE_BINS];
        let mut edge_cells = 0;
        let step = GRADIENT_STEP_PX.min(s).max(1);
        let min2 = (min_gradient * min_gradient) as i32;
        let px = |x: usize, y: usize| i32::from(frame.pixel(x, y).unwrap_or(0));
        let odd = |v: usize| if step > 1 { v | 1 } else { v };
        for cy in 0..rows {
            let (y0, y1) = ((cy * s).max(1), ((cy + 1) * s).min(h.saturating_sub(1)));
            for cx in 0..cols {
                let (x0, x1) = ((cx * s).max(1), ((cx + 1) * s).min(w.saturating_sub(1)));
                let mut best = (min2, 0i32, 0i32);
                let mut y = odd(y0);
                while y < y1 {
                    let mut x = odd(x0);
                    while x < x1 {
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
                    edge_cells += 1;
                    for bin in [first, second] {
                        planes[bin * cols * rows + cy * cols + cx] = 0;
                    }
                }
            }
        }
        (planes, edge_cells)
    }

    /// The gradient pass, which reads pixel rows a chunk of cells at a time, marks the same
    /// cells as the plain pass, on frames wider than one chunk of cells, with padded rows, at
    /// every cell size from 1 to 5 px.
    #[test]
    fn the_gradient_pass_marks_the_cells_the_plain_pass_marks() {
        let (w, h, stride) = (401usize, 37usize, 407usize);
        let mut pixels = vec![0u8; stride * h];
        let mut seed = 12345u32;
        for (i, p) in pixels.iter_mut().enumerate() {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            // Noise over a few bright blocks, so strong and weak gradients both occur.
            let (x, y) = (i % stride, i / stride);
            let block = if (x / 23 + y / 11) % 3 == 0 { 150 } else { 40 };
            *p = block + (seed >> 28) as u8;
        }
        let frame = FrameView::new(&pixels, w, h, stride).unwrap();
        for s in 1..=5u8 {
            let config = LikelihoodConfig {
                stride_px: s,
                ..LikelihoodConfig::default()
            };
            let mut marked = vec![0u8; EdgeMap::bytes_needed(w, h, s)];
            let (cols, rows) = (w.div_ceil(usize::from(s)), h.div_ceil(usize::from(s)));
            assert!(
                cols > CELL_CHUNK,
                "the frame spans more than one chunk of cells"
            );
            marked.fill(FAR);
            let mut map = EdgeMap {
                dist: &mut marked,
                cols,
                rows,
                stride_px: usize::from(s),
                edge_cells: 0,
                region: None,
                within: CellRect::all(cols, rows),
            };
            let mut region = RegionBuilder::new(w, h);
            map.mark_edges(&frame, config.min_gradient, &mut region);
            let edge_cells = map.edge_cells;
            let (plain, plain_cells) = marked_plainly(&frame, usize::from(s), config.min_gradient);
            assert!(plain_cells > 10, "stride {s}: {plain_cells} edge cells");
            assert_eq!(edge_cells, plain_cells, "stride {s}");
            assert_eq!(marked, plain, "stride {s}");
        }
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

    #[test]
    fn the_two_passes_give_the_exact_3_4_chamfer_distance() {
        // Against the distance itself: 3 a cell straight, 4 diagonally, so 3·max + min of the
        // cell offsets to the nearest edge cell, held at FAR.
        let mut seed = 12345u32;
        let mut next = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            seed >> 8
        };
        for (cols, rows, edges) in [(1, 5, 1), (5, 1, 1), (2, 2, 1), (37, 23, 6), (90, 4, 2)] {
            let mut dist = [FAR; 90 * 23];
            let mut marked = [(0usize, 0usize); 6];
            for m in marked.iter_mut().take(edges) {
                *m = (next() as usize % cols, next() as usize % rows);
                dist[m.1 * cols + m.0] = 0;
            }
            let mut map = EdgeMap {
                dist: &mut dist[..cols * rows],
                cols,
                rows,
                stride_px: 4,
                edge_cells: edges as u32,
                region: None,
                within: CellRect::all(cols, rows),
            };
            map.transform(0);
            for y in 0..rows {
                for x in 0..cols {
                    let exact = marked[..edges]
                        .iter()
                        .map(|&(ex, ey)| {
                            let (dx, dy) = (x.abs_diff(ex), y.abs_diff(ey));
                            3 * dx.max(dy) + dx.min(dy)
                        })
                        .min()
                        .unwrap()
                        .min(usize::from(FAR));
                    assert_eq!(
                        usize::from(map.dist[y * cols + x]),
                        exact,
                        "{cols}x{rows} at ({x}, {y})"
                    );
                }
            }
        }
    }

    #[test]
    fn a_map_built_without_its_region_has_the_same_distances() {
        // A noisy frame with a bright blob and a gradient ramp: edges of every orientation.
        let (w, h) = (97usize, 61usize);
        let mut pixels = vec![0u8; w * h];
        let mut seed = 12345u32;
        for y in 0..h {
            for x in 0..w {
                seed = seed.wrapping_mul(1_103_515_245).wrapping_add(12_345);
                let noise = (seed >> 16) % 23;
                let (dx, dy) = (x as i32 - 40, y as i32 - 30);
                let blob = if dx * dx + 2 * dy * dy < 500 { 150 } else { 0 };
                pixels[y * w + x] = (20 + x as u32 + noise + blob).min(255) as u8;
            }
        }
        let frame = FrameView::packed(&pixels, w, h).unwrap();
        for stride_px in 1..=5u8 {
            let config = LikelihoodConfig {
                stride_px,
                ..LikelihoodConfig::default()
            };
            let needed = EdgeMap::bytes_needed(w, h, stride_px);
            let (mut full, mut edges) = (vec![7u8; needed], vec![9u8; needed]);
            let with = EdgeMap::build(&mut full, &frame, &config).unwrap();
            let without =
                EdgeMap::build_edges_for(&mut edges, &frame, &config, Reads::Everywhere).unwrap();
            assert!(with.region.is_some(), "the blob is a region");
            assert_eq!(without.region, None);
            assert_eq!(without.edge_cells, with.edge_cells);
            assert!(with.edge_cells > 0);
            assert_eq!(without.cells(), with.cells());
            assert_eq!(without.dist, with.dist, "stride {stride_px}");
        }
    }

    #[test]
    fn a_map_built_for_some_reads_reads_there_as_the_whole_frames_map() {
        let (w, h) = (203usize, 151usize);
        let mut pixels = vec![0u8; w * h];
        let mut seed = 777u32;
        let mut next = || {
            seed = seed.wrapping_mul(1_103_515_245).wrapping_add(12_345);
            seed >> 16
        };
        for y in 0..h {
            for x in 0..w {
                let (dx, dy) = (x as i32 - 90, y as i32 - 70);
                let blob = if dx * dx + 3 * dy * dy < 2_500 {
                    140
                } else {
                    0
                };
                let stripe = if (x / 9) % 4 == 0 { 60 } else { 0 };
                pixels[y * w + x] = (15 + next() % 30 + blob + stripe).min(255) as u8;
            }
        }
        let frame = FrameView::packed(&pixels, w, h).unwrap();
        let boxes = [
            (60.0, 40.0, 120.0, 100.0),
            (-30.0, 100.0, 20.0, 400.0),
            (150.5, 3.2, 202.9, 20.1),
            (0.0, 0.0, 0.0, 0.0),
        ];
        for stride_px in [1u8, 2, 3, 4, 5] {
            for cap in [6.0f32, 24.0, 40.0] {
                let config = LikelihoodConfig {
                    stride_px,
                    chamfer_cap_px: cap,
                    ..LikelihoodConfig::default()
                };
                let needed = EdgeMap::bytes_needed(w, h, stride_px);
                let mut whole = vec![0u8; needed];
                let full = EdgeMap::build_edges_for(&mut whole, &frame, &config, Reads::Everywhere)
                    .unwrap();
                for &(x0, y0, x1, y1) in &boxes {
                    let bounds = crate::projection::Bounds {
                        min: Vector2::new(x0, y0),
                        max: Vector2::new(x1, y1),
                    };
                    let reads = Reads::Within(bounds);
                    let mut part = vec![0u8; needed];
                    let map = EdgeMap::build_edges_for(&mut part, &frame, &config, reads).unwrap();
                    assert!(map.built(&frame, &config).covers(&reads, &config));
                    assert!(!map
                        .built(&frame, &config)
                        .covers(&Reads::Everywhere, &config));
                    // Every point within the bounds: the truncated distance of every bin.
                    let s = f32::from(stride_px);
                    let mut y = y0.max(0.0);
                    while y <= y1 {
                        let mut x = x0.max(0.0);
                        while x <= x1 {
                            let p = Vector2::new(x, y);
                            for bin in 0..EDGE_BINS {
                                let a = map.distance_px(bin, &p).map(|d| d.min(cap));
                                let b = full.distance_px(bin, &p).map(|d| d.min(cap));
                                assert_eq!(a, b, "stride {stride_px} cap {cap} at {p:?}");
                            }
                            x += s * 0.5;
                        }
                        y += s * 0.5;
                    }
                    // Every mark the reverse term can visit: the bounds widened by its margin
                    // and the cell it rounds up to.
                    let m = config.reverse_margin_px + s;
                    let mut y = (y0 - m).max(0.0);
                    while y <= y1 + m {
                        let mut x = (x0 - m).max(0.0);
                        while x <= x1 + m {
                            let p = Vector2::new(x, y);
                            for bin in 0..EDGE_BINS {
                                let a = map.distance_units(bin, &p) == Some(0);
                                let b = full.distance_units(bin, &p) == Some(0);
                                assert_eq!(a, b, "mark, stride {stride_px} at {p:?}");
                            }
                            x += s;
                        }
                        y += s;
                    }
                }
            }
        }
    }

    #[test]
    fn a_map_reopened_from_its_buffer_is_the_map_built() {
        let (w, h) = (64usize, 48usize);
        let mut pixels = [20u8; 64 * 48];
        for y in 10..30 {
            for x in 12..40 {
                pixels[y * w + x] = 180;
            }
        }
        let frame = FrameView::packed(&pixels, w, h).unwrap();
        let config = LikelihoodConfig::default();
        let mut buffer = [0u8; 16 * 12 * EDGE_BINS];
        let (built, distances) = {
            let map = EdgeMap::build(&mut buffer, &frame, &config).unwrap();
            let d: [Option<f32>; 4] = core::array::from_fn(|k| {
                map.distance_px(k % EDGE_BINS, &Vector2::new(5.0 + 13.0 * k as f32, 20.0))
            });
            (map.built(&frame, &config), d)
        };
        assert!(built.fits(&frame, &config));
        let again = EdgeMap::reopen(&mut buffer, built).unwrap();
        assert_eq!(again.built(&frame, &config), built);
        assert_eq!(again.region, built.region);
        for (k, d) in distances.iter().enumerate() {
            let p = Vector2::new(5.0 + 13.0 * k as f32, 20.0);
            assert_eq!(again.distance_px(k % EDGE_BINS, &p), *d);
        }
        // Another size or another threshold is another map; a short buffer is an error.
        let small = FrameView::packed(&pixels[..64 * 40], 64, 40).unwrap();
        assert!(!built.fits(&small, &config));
        let other = LikelihoodConfig {
            min_gradient: config.min_gradient + 1.0,
            ..config
        };
        assert!(!built.fits(&frame, &other));
        let mut short = [0u8; 10];
        assert!(matches!(
            EdgeMap::reopen(&mut short, built),
            Err(LikelihoodError::BufferTooSmall { .. })
        ));
    }
}
