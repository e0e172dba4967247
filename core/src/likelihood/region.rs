//! The frame's bright region: where the hand most likely is, before any hypothesis.
//!
//! The hand is brighter than the background in every rig this tracker is built for (the
//! silhouette term of the [likelihood](super) rests on the same fact). The grey levels sampled
//! by the edge pass are histogrammed; Otsu's threshold splits them into dark and bright; a
//! second pass over the same samples gives the bright samples' centroid and their extent
//! (between the [`EXTENT_PERCENTILE`]th and the (100 − it)th percentile along each image axis,
//! so a few bright noise pixels do not stretch it). The search places its hypotheses on this
//! region ([`crate::acquire`]); it is evidence for *where* to look, never for accepting.
//!
//! A frame without a hand still has a "region" (Otsu splits noise or clutter too); only the
//! likelihood of a refined state decides whether a hand is there.

use crate::frame::FrameView;
use crate::nalgebra::Vector2;

use super::edges::GRADIENT_STEP_PX;

/// Grey-level histogram bins (4 levels each).
const GREY_BINS: usize = 64;

/// Bins of the bright samples' column and row histograms (the extent's percentiles).
pub const MAX_EXTENT_BINS: usize = 128;

/// The extent of the region runs between this percentile of the bright samples and its
/// complement along each image axis (%).
pub const EXTENT_PERCENTILE: u32 = 2;

/// The fewest bright samples for a region.
pub const MIN_REGION_SAMPLES: u32 = 16;

/// The frame's bright region (not `defmt::Format`: nalgebra's vectors are not).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Region {
    /// Otsu's threshold (grey level): brighter samples are the region.
    pub threshold: u8,
    /// Centroid of the bright samples (px).
    pub centre_px: Vector2<f32>,
    /// Smallest corner of the bright samples' extent (px).
    pub min_px: Vector2<f32>,
    /// Largest corner of the bright samples' extent (px).
    pub max_px: Vector2<f32>,
    /// Bright area (px², sampled).
    pub area_px: f32,
    /// Mean bright grey level minus mean dark grey level.
    pub contrast: f32,
}

impl Region {
    /// The extent's width and height (px).
    pub fn size_px(&self) -> Vector2<f32> {
        self.max_px - self.min_px
    }

    /// The centre of the extent (px).
    pub fn extent_centre_px(&self) -> Vector2<f32> {
        (self.min_px + self.max_px) / 2.0
    }
}

/// Gathers the grey-level histogram during the edge pass.
#[derive(Debug)]
pub(crate) struct RegionBuilder {
    histogram: [u32; GREY_BINS],
    width: usize,
    height: usize,
}

impl RegionBuilder {
    pub(crate) fn new(width: usize, height: usize) -> Self {
        RegionBuilder {
            histogram: [0; GREY_BINS],
            width,
            height,
        }
    }

    /// One sampled grey level.
    #[inline]
    pub(crate) fn add(&mut self, grey: i32) {
        if let Some(b) = self.histogram.get_mut((grey.clamp(0, 255) as usize) >> 2) {
            *b += 1;
        }
    }

    /// Otsu's threshold over the histogram, then the bright samples' centroid and extent.
    pub(crate) fn finish(&self, frame: &FrameView<'_>) -> Option<Region> {
        let total: u32 = self.histogram.iter().sum();
        if total == 0 {
            return None;
        }
        let sum_all: f32 = self
            .histogram
            .iter()
            .enumerate()
            .map(|(i, &n)| i as f32 * n as f32)
            .sum();
        let (mut best, mut split) = (0.0f32, 0usize);
        let (mut n_dark, mut sum_dark) = (0u32, 0.0f32);
        for (i, &n) in self.histogram.iter().enumerate() {
            n_dark += n;
            sum_dark += i as f32 * n as f32;
            let n_bright = total - n_dark;
            if n_dark == 0 || n_bright == 0 {
                continue;
            }
            let m_dark = sum_dark / n_dark as f32;
            let m_bright = (sum_all - sum_dark) / n_bright as f32;
            let between =
                n_dark as f32 * n_bright as f32 * (m_bright - m_dark) * (m_bright - m_dark);
            if between > best {
                best = between;
                split = i;
            }
        }
        // Bright: grey level at or above the first level of the bin after the split.
        let threshold = ((split + 1) * 4).min(255) as u8;
        let (w, h) = (self.width, self.height);
        let mut cols = [0u32; MAX_EXTENT_BINS];
        let mut rows = [0u32; MAX_EXTENT_BINS];
        let (mut n, mut sx, mut sy) = (0u32, 0.0f32, 0.0f32);
        let (mut sum_bright, mut sum_dark, mut n_dark) = (0.0f32, 0.0f32, 0u32);
        let col_of = |x: usize| (x * MAX_EXTENT_BINS / w.max(1)).min(MAX_EXTENT_BINS - 1);
        let row_of = |y: usize| (y * MAX_EXTENT_BINS / h.max(1)).min(MAX_EXTENT_BINS - 1);
        let step = GRADIENT_STEP_PX;
        let mut y = 1;
        while y + 1 < h {
            let row = frame.row(y).unwrap_or(&[]);
            let mut x = 1;
            while x + 1 < w {
                let v = row.get(x).copied().unwrap_or(0);
                if v >= threshold {
                    n += 1;
                    sx += x as f32;
                    sy += y as f32;
                    sum_bright += f32::from(v);
                    if let Some(c) = cols.get_mut(col_of(x)) {
                        *c += 1;
                    }
                    if let Some(r) = rows.get_mut(row_of(y)) {
                        *r += 1;
                    }
                } else {
                    n_dark += 1;
                    sum_dark += f32::from(v);
                }
                x += step;
            }
            y += step;
        }
        if n < MIN_REGION_SAMPLES || n_dark == 0 {
            return None;
        }
        let cut = (n * EXTENT_PERCENTILE / 100).max(1);
        let span = |counts: &[u32; MAX_EXTENT_BINS], size: usize| -> (f32, f32) {
            let bin_px = size as f32 / MAX_EXTENT_BINS as f32;
            let (mut lo, mut acc) = (0usize, 0u32);
            for (i, &c) in counts.iter().enumerate() {
                acc += c;
                if acc >= cut {
                    lo = i;
                    break;
                }
            }
            let (mut hi, mut acc) = (MAX_EXTENT_BINS - 1, 0u32);
            for (i, &c) in counts.iter().enumerate().rev() {
                acc += c;
                if acc >= cut {
                    hi = i;
                    break;
                }
            }
            (lo as f32 * bin_px, (hi + 1) as f32 * bin_px)
        };
        let (x0, x1) = span(&cols, w);
        let (y0, y1) = span(&rows, h);
        Some(Region {
            threshold,
            centre_px: Vector2::new(sx / n as f32, sy / n as f32),
            min_px: Vector2::new(x0, y0),
            max_px: Vector2::new(x1, y1),
            area_px: (n as usize * step * step) as f32,
            contrast: sum_bright / n as f32 - sum_dark / n_dark as f32,
        })
    }
}
