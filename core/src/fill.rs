//! Region rows: the hand's bright pixels the model leaves uncovered pull the nearest link's
//! outline out to them, and the dark pixels a link covers pull its outline in.
//!
//! The slice search asks only whether an edge lies within a window of each predicted edge,
//! so a finger that has slid onto a neighbour's edges, or off its own by more than the
//! window, feels no pull back. The region says more: on a grid over the projected hand's
//! bounds (grown by [`FillConfig::reach_px`]), each sample is classed bright or dark by the
//! midpoint between the mean grey level the model covers and the mean it leaves uncovered
//! (the hand is brighter than the background, the premise of
//! [`silhouette`](crate::silhouette)). Then
//!
//! - a bright sample no part of the model covers, within `reach_px` of a link's outline,
//!   becomes an edge point of the nearest link on its side: the row pulls that outline out
//!   to the sample;
//! - a dark sample a link covers (the nearest link whose capsule contains it) becomes an edge
//!   point of that link on its side: the row pulls the outline in past it.
//!
//! Only samples beside a link's axis (projecting onto it between its ends) are used; the
//! ends are the tip search's. No allocation: the samples live in a caller-owned
//! [`FillPoints`] of fixed capacity.

use heapless::Vec;
use nalgebra::Vector2;

use crate::camera::Camera;
use crate::frame::FrameView;
use crate::projection::ProjectedModel;
use crate::silhouette::{hand_bounds, MIN_CLASS_SAMPLES};

/// Samples along each side of the grid, at most.
pub const MAX_FILL_GRID: usize = 48;

/// Region edge points kept per camera and iteration, at most (the rest are dropped, counted
/// in [`FillPoints::dropped`]).
pub const MAX_FILL_POINTS: usize = 512;

/// The least contrast between the mean grey level the model covers and the mean it leaves
/// uncovered for the region to say anything (grey levels): below it (a blank frame, a hand
/// the model has left altogether) no samples are gathered.
pub const MIN_FILL_CONTRAST: f32 = 8.0;

/// A sample the model does not cover.
const UNCOVERED: u8 = u8::MAX;
/// A sample the palm covers.
const PALM: u8 = u8::MAX - 1;
/// A sample outside the frame.
const OFF_FRAME: u8 = u8::MAX - 2;

/// The region rows' parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FillConfig {
    /// Weight of each region row relative to a slice edge's (0: no region rows, the
    /// tracker as it was before them, bit for bit). Default 0.1, measured on fresh seeds
    /// (`docs/robustness.md`, "Region rows").
    pub weight: f32,
    /// Samples along each side of the grid (clamped to 2..=[`MAX_FILL_GRID`]).
    pub grid: u8,
    /// A bright uncovered sample pulls an outline only within this distance of it (px).
    pub reach_px: f32,
}

impl Default for FillConfig {
    fn default() -> Self {
        FillConfig {
            weight: 0.1,
            grid: 32,
            reach_px: 12.0,
        }
    }
}

impl FillConfig {
    /// No region rows.
    pub const OFF: FillConfig = FillConfig {
        weight: 0.0,
        grid: 32,
        reach_px: 12.0,
    };

    /// Whether region rows are added.
    pub fn is_on(&self) -> bool {
        self.weight > 0.0
    }
}

/// One region sample, for link `link` of the view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FillPoint {
    /// Index of the link in [`ProjectedModel::links`].
    pub link: u8,
    /// The sample (px).
    pub position: Vector2<f32>,
}

/// The region edge points of one camera at one state.
#[derive(Debug, Clone, Default)]
pub struct FillPoints {
    /// The points, in grid order.
    pub points: Vec<FillPoint, MAX_FILL_POINTS>,
    /// Points beyond [`MAX_FILL_POINTS`], not kept.
    pub dropped: u16,
}

impl FillPoints {
    /// Empties the points.
    pub fn clear(&mut self) {
        self.points.clear();
        self.dropped = 0;
    }

    fn push(&mut self, point: FillPoint) {
        if self.points.push(point).is_err() {
            self.dropped = self.dropped.saturating_add(1);
        }
    }
}

/// The link of `view` whose capsule covers `p` most deeply (by distance from its axis as a
/// share of its radius), or [`PALM`] / [`UNCOVERED`].
fn cover_class(view: &ProjectedModel, camera: &Camera, p: &Vector2<f32>) -> u8 {
    let mut best = (UNCOVERED, 1.0f32);
    for (index, link) in view.links.iter().enumerate() {
        if !link.bounds.contains(p) {
            continue;
        }
        let (s, dist) = link.closest(p);
        let radius = link.radius_at(s);
        if radius > 0.0 && dist < radius * best.1 {
            best = (index.min(usize::from(PALM) - 1) as u8, dist / radius);
        }
    }
    if best.0 == UNCOVERED
        && view
            .palm
            .as_ref()
            .is_some_and(|palm| palm.depth_at(camera, p).is_some())
    {
        return PALM;
    }
    best.0
}

/// The nearest link outline to `p` within `reach_px`, by the distance beyond its capsule.
fn nearest_outline(view: &ProjectedModel, p: &Vector2<f32>, reach_px: f32) -> Option<usize> {
    let mut best: Option<(usize, f32)> = None;
    for (index, link) in view.links.iter().enumerate() {
        let b = &link.bounds;
        if p.x < b.min.x - reach_px
            || p.y < b.min.y - reach_px
            || p.x > b.max.x + reach_px
            || p.y > b.max.y + reach_px
        {
            continue;
        }
        let (s, dist) = link.closest(p);
        let gap = dist - link.radius_at(s);
        if gap < reach_px && best.is_none_or(|(_, g)| gap < g) {
            best = Some((index, gap));
        }
    }
    best.map(|(index, _)| index)
}

/// Gathers the region samples of `view` on `frame` into `out` (emptied first). Nothing when
/// the hand projects nowhere, either class has fewer than [`MIN_CLASS_SAMPLES`], or what the
/// model covers is not brighter than the rest by [`MIN_FILL_CONTRAST`].
pub fn gather(
    view: &ProjectedModel,
    camera: &Camera,
    frame: &FrameView<'_>,
    config: &FillConfig,
    out: &mut FillPoints,
) {
    out.clear();
    let grid = usize::from(config.grid).clamp(2, MAX_FILL_GRID);
    let Some(bounds) = hand_bounds(view) else {
        return;
    };
    let reach = config.reach_px.max(0.0);
    let grow = Vector2::new(reach, reach);
    let min = bounds.min - grow;
    let size = bounds.max - bounds.min + grow * 2.0;
    if !(size.x.is_finite() && size.y.is_finite()) {
        return;
    }
    let step = size / (grid - 1) as f32;
    let at =
        |i: usize, j: usize| Vector2::new(min.x + step.x * i as f32, min.y + step.y * j as f32);
    let mut value = [0u8; MAX_FILL_GRID * MAX_FILL_GRID];
    let mut class = [OFF_FRAME; MAX_FILL_GRID * MAX_FILL_GRID];
    let mut sum = [0.0f32; 2];
    let mut count = [0u32; 2];
    for j in 0..grid {
        for i in 0..grid {
            let p = at(i, j);
            let Some(v) = frame.sample(p.x, p.y) else {
                continue;
            };
            let c = cover_class(view, camera, &p);
            let k = usize::from(c != UNCOVERED);
            value[j * grid + i] = (v + 0.5) as u8;
            class[j * grid + i] = c;
            sum[k] += v;
            count[k] += 1;
        }
    }
    if count[0] < MIN_CLASS_SAMPLES || count[1] < MIN_CLASS_SAMPLES {
        return;
    }
    let (uncovered, covered) = (sum[0] / count[0] as f32, sum[1] / count[1] as f32);
    let contrast = covered - uncovered;
    if contrast.is_nan() || contrast < MIN_FILL_CONTRAST {
        return;
    }
    let threshold = 0.5 * (covered + uncovered);
    for j in 0..grid {
        for i in 0..grid {
            let c = class[j * grid + i];
            let bright = f32::from(value[j * grid + i]) > threshold;
            let p = at(i, j);
            let link = match (c, bright) {
                (UNCOVERED, true) => nearest_outline(view, &p, reach),
                (OFF_FRAME | PALM | UNCOVERED, _) | (_, true) => None,
                (_, false) => Some(usize::from(c)),
            };
            if let Some(index) = link {
                out.push(FillPoint {
                    link: index as u8,
                    position: p,
                });
            }
        }
    }
}
