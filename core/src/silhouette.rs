//! How well the projected hand's silhouette agrees with the image: the region evidence the
//! slice search does not see.
//!
//! The slice search only asks whether *some* edge lies near each predicted edge, so a track
//! that has slid onto a neighbouring finger's edges, or folded a finger over the palm, can
//! find nearly every feature with a small residual. The silhouette asks a different question:
//! are the pixels the model covers hand-like and the pixels around it not? On a regular grid
//! over the projected hand's bounds (grown by [`MARGIN`] of their size on each side) each
//! sample is classed *inside* (some link capsule or the palm box covers it) or *outside*, and
//! the two classes' intensities are compared:
//!
//! - `contrast`: mean inside minus mean outside (grey levels). The hand is brighter than the
//!   background in every rig this tracker is built for, so a right track has a clearly positive
//!   contrast; a track whose links lie over background or over the palm has less.
//! - `separation`: the Fisher ratio `(m_in − m_out)² / (var_in + var_out)`: how cleanly one
//!   threshold splits the two classes (about 3+ for a right track on a plain background).
//! - `agreement`: the share of samples on the predicted side of the midpoint between the two
//!   means.
//!
//! No template images and no allocation: a fixed grid of at most [`MAX_GRID`]² samples per
//! camera, each tested against the projected capsules and the palm.

use nalgebra::Vector2;

use crate::camera::Camera;
use crate::frame::FrameView;
use heapless::Vec;

use crate::config::MAX_LINKS;
use crate::projection::{Bounds, ProjectedLink, ProjectedModel, ProjectedPalm};

/// Samples along each side of the grid, at most.
pub const MAX_GRID: usize = 48;

/// The grid covers the hand's bounds grown by this share of their width and height on each
/// side, so the background around the hand is sampled too.
pub const MARGIN: f32 = 0.25;

/// The fewest samples of each class for a score to mean anything.
pub const MIN_CLASS_SAMPLES: u32 = 8;

/// The silhouette evidence of one camera at one state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SilhouetteScore {
    /// Mean intensity inside minus outside the predicted silhouette (grey levels).
    pub contrast: f32,
    /// Fisher ratio of the two classes (dimensionless, ≥ 0).
    pub separation: f32,
    /// Share of samples on the predicted side of the midpoint threshold (0..=1).
    pub agreement: f32,
    /// Samples inside the predicted silhouette.
    pub inside: u32,
    /// Samples outside it (within the grown bounds and the frame).
    pub outside: u32,
}

/// Whether the projected hand covers image point `p` (a capsule link or the palm box).
pub fn covers(view: &ProjectedModel, camera: &Camera, p: &Vector2<f32>) -> bool {
    view.links.iter().any(|link| link_covers(link, p))
        || view
            .palm
            .as_ref()
            .is_some_and(|palm| palm.depth_at(camera, p).is_some())
}

/// [`covers`] restricted to the links `among` (indices into `view.links`) and the palm if
/// given: the same answer when they are every part whose bounds could hold `p`.
fn covers_among(
    view: &ProjectedModel,
    camera: &Camera,
    among: &[u8],
    palm: Option<&ProjectedPalm>,
    p: &Vector2<f32>,
) -> bool {
    among.iter().any(|&k| {
        view.links
            .get(usize::from(k))
            .is_some_and(|link| link_covers(link, p))
    }) || palm.is_some_and(|palm| palm.depth_at(camera, p).is_some())
}

/// Whether `link`'s capsule covers image point `p`.
fn link_covers(link: &ProjectedLink, p: &Vector2<f32>) -> bool {
    if !link.bounds.contains(p) {
        return false;
    }
    let (s, dist) = link.closest(p);
    dist < link.radius_at(s)
}

/// The image bounds of everything projected, or `None` when nothing is.
pub fn hand_bounds(view: &ProjectedModel) -> Option<Bounds> {
    let mut all = view
        .links
        .iter()
        .map(|l| l.bounds)
        .chain(view.palm.map(|p| p.bounds));
    let first = all.next()?;
    Some(all.fold(first, |acc, b| Bounds {
        min: Vector2::new(acc.min.x.min(b.min.x), acc.min.y.min(b.min.y)),
        max: Vector2::new(acc.max.x.max(b.max.x), acc.max.y.max(b.max.y)),
    }))
}

/// Scores the silhouette of `view` against `frame` on a `grid` × `grid` lattice (clamped to
/// 2..=[`MAX_GRID`]). `None` when nothing of the hand is projected or either class has fewer
/// than [`MIN_CLASS_SAMPLES`] samples inside the frame.
pub fn score(
    view: &ProjectedModel,
    camera: &Camera,
    frame: &FrameView<'_>,
    grid: usize,
) -> Option<SilhouetteScore> {
    let grid = grid.clamp(2, MAX_GRID);
    let bounds = hand_bounds(view)?;
    let size = bounds.max - bounds.min;
    if !(size.x.is_finite() && size.y.is_finite()) {
        return None;
    }
    let min = bounds.min - size * MARGIN;
    let step = size * (1.0 + 2.0 * MARGIN) / (grid - 1) as f32;
    // One pass classifies and samples, counting each class's grey levels (rounded) in a
    // histogram (1 KB on the stack); the agreement with the midpoint between the class means
    // is then counted from the histograms.
    let mut levels = [[0u16; 256]; 2];
    let (mut lowest, mut highest) = (u8::MAX, 0u8);
    let mut sum = [0.0f32; 2];
    let mut sum_sq = [0.0f32; 2];
    let mut count = [0u32; 2];
    for j in 0..grid {
        let y = min.y + step.y * j as f32;
        // The parts whose bounds span this row: no other part covers a point of it.
        let mut row: Vec<u8, MAX_LINKS> = Vec::new();
        for (k, link) in view.links.iter().enumerate() {
            if link.bounds.min.y <= y && y <= link.bounds.max.y {
                let _ = row.push(k as u8);
            }
        }
        let palm = view
            .palm
            .as_ref()
            .filter(|palm| palm.bounds.min.y <= y && y <= palm.bounds.max.y);
        for i in 0..grid {
            let p = Vector2::new(min.x + step.x * i as f32, y);
            let Some(v) = frame.sample(p.x, p.y) else {
                continue;
            };
            let k = usize::from(covers_among(view, camera, &row, palm, &p));
            let level = (v + 0.5) as u8;
            levels[k][usize::from(level)] += 1;
            lowest = lowest.min(level);
            highest = highest.max(level);
            sum[k] += v;
            sum_sq[k] += v * v;
            count[k] += 1;
        }
    }
    let (outside, inside) = (count[0], count[1]);
    if inside < MIN_CLASS_SAMPLES || outside < MIN_CLASS_SAMPLES {
        return None;
    }
    let mean = [sum[0] / outside as f32, sum[1] / inside as f32];
    let var = [
        (sum_sq[0] / outside as f32 - mean[0] * mean[0]).max(0.0),
        (sum_sq[1] / inside as f32 - mean[1] * mean[1]).max(0.0),
    ];
    let contrast = mean[1] - mean[0];
    let separation = contrast * contrast / (var[0] + var[1]).max(1.0);
    let threshold = 0.5 * (mean[0] + mean[1]);
    // The hand is the brighter class: inside samples above the threshold agree, and outside
    // ones at or below it.
    let agree: u32 = (lowest..=highest)
        .map(|level| {
            let class = usize::from(f32::from(level) > threshold);
            u32::from(levels[class][usize::from(level)])
        })
        .sum();
    Some(SilhouetteScore {
        contrast,
        separation,
        agreement: agree as f32 / (inside + outside) as f32,
        inside,
        outside,
    })
}
