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
//!   belongs to the nearest link, a link the model hides counting nearer
//!   ([`FillConfig::hidden_gap_share`]): its row pulls that link's outline out to the sample;
//! - a dark sample a link covers belongs to the link that covers it most deeply: its row
//!   pulls the outline in past it;
//! - a sample near the midpoint ([`FillConfig::class_margin`]) is neither: the hand's own
//!   shaded side is not background; nor is a dark sample in a link's core unless it is
//!   darker still ([`FillConfig::core_share`]): a shadow on a finger is the hand's.
//!
//! Each row moves the outline where it is nearest the sample, a side or an end
//! ([`region_row`](crate::estimator::region_row)); the palm's samples are left to its outline
//! edges.
//!
//! The samples are gathered on a frame's first iteration and kept, class and link, for its
//! later ones: a bright sample pulls only while it lies outside its link, a dark one only
//! while inside ([`region_row`](crate::estimator::region_row)). No allocation: the samples
//! live in a caller-owned [`FillPoints`] of fixed capacity.

use heapless::Vec;
use nalgebra::Vector2;

use crate::camera::Camera;
use crate::config::MAX_LINKS;
use crate::float::Length;
use crate::frame::FrameView;
use crate::projection::{ProjectedLink, ProjectedModel};
use crate::silhouette::{hand_bounds, MIN_CLASS_SAMPLES};

/// Samples along each side of the grid, at most.
pub const MAX_FILL_GRID: usize = 48;

/// Region samples kept per camera and frame, at most (the rest are dropped, counted in
/// [`FillPoints::dropped`]).
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
    /// tracker as it was before them, bit for bit). Default 1, measured on fresh seeds
    /// with [`FillConfig::class_margin`] (`docs/robustness.md`, "Region rows").
    pub weight: f32,
    /// Samples along each side of the grid (clamped to 2..=[`MAX_FILL_GRID`]).
    pub grid: u8,
    /// A bright uncovered sample pulls an outline only within this distance of it (px).
    pub reach_px: f32,
    /// A frame's first this many iterations gather the samples afresh at their own state
    /// (at least 1); the later ones keep the last gathered.
    pub gather_iterations: u8,
    /// How clearly a sample must be bright or dark to be classed at all, as a share of the
    /// contrast between the covered and uncovered means: a sample within this share of the
    /// midpoint between them is left out (0: every sample is classed). Default 0.3: a dark
    /// sample is then no brighter than the uncovered mean plus 0.2 of the contrast, a bright
    /// one no darker than the covered mean less 0.2 of it. By the midpoint alone, the hand's
    /// own shaded side is classed dark under a link at the truth (23 samples a view on the
    /// sweep, against 0.7 at 0.3; `examples/fill_truth.rs`): rows that pull right links in.
    pub class_margin: f32,
    /// A link whose image is shorter than this many times its width has its rows weighed
    /// down by its length over this many widths ([`FillConfig::link_weight`]; 0: every link
    /// at full weight). Default 1: a finger seen end-on is the thesis' singular
    /// configuration, whose outline says little of how its bend is split among its joints.
    pub full_length_widths: f32,
    /// A dark sample in a link's core, nearer its axis than this share of its radius, is
    /// classed dark only when it lies [`FillConfig::core_margin`] of the contrast below the
    /// midpoint, not [`FillConfig::class_margin`] (0: every dark sample by the class margin,
    /// as before). Where the hand shades itself (a shadow another part casts on a finger, a
    /// part darker than the rest) the samples in a link's core are the hand's own, and rows
    /// pulling its outline in past them read the hand smaller, so, with one camera, farther;
    /// background in a link's core means the link is off its finger by most of its width,
    /// and is darker. Default 0.7 (`docs/robustness.md`, "A shadow in a link's core is the
    /// hand's").
    pub core_share: f32,
    /// The class margin of a dark sample in a link's core ([`FillConfig::core_share`]), as a
    /// share of the contrast. Default 0.4: no brighter than the uncovered mean plus 0.1 of it.
    pub core_margin: f32,
    /// A bright sample the model leaves uncovered goes to the link whose outline is nearest;
    /// the gap to a link the model hides wholly (three points of its axis behind a nearer
    /// part, [`hidden_link`]) counts at this share of its length. Below 1 a hidden link is
    /// preferred: the image shows hand where the model shows none, and a link the model has
    /// put out of sight beside it is the likeliest owner, where a visible link's outline is
    /// already held by its own edges. 1: every link alike (before stop 69); infinite (or NaN):
    /// hidden links never chosen. Default 0.5: one camera +1.3 points of track life on 600
    /// fresh sweep seeds, two +0.7 (`docs/robustness.md`, "A hidden link takes the hand it
    /// leaves uncovered").
    pub hidden_gap_share: f32,
}

impl Default for FillConfig {
    fn default() -> Self {
        FillConfig {
            weight: 1.0,
            grid: 32,
            reach_px: 12.0,
            gather_iterations: 1,
            class_margin: 0.3,
            full_length_widths: 1.0,
            core_share: 0.7,
            core_margin: 0.4,
            hidden_gap_share: 0.5,
        }
    }
}

impl FillConfig {
    /// No region rows.
    pub const OFF: FillConfig = FillConfig {
        weight: 0.0,
        grid: 32,
        reach_px: 12.0,
        gather_iterations: 1,
        class_margin: 0.3,
        full_length_widths: 1.0,
        core_share: 0.7,
        core_margin: 0.4,
        hidden_gap_share: 0.5,
    };

    /// Whether region rows are added.
    pub fn is_on(&self) -> bool {
        self.weight > 0.0
    }

    /// The weight of `link`'s region rows: [`FillConfig::weight`], times its image length
    /// over [`FillConfig::full_length_widths`] of its image widths when shorter.
    pub fn link_weight(&self, link: &ProjectedLink) -> f32 {
        let widths = self.full_length_widths * link.mean_width_px();
        if widths > 0.0 {
            self.weight * ((link.b - link.a).length() / widths).min(1.0)
        } else {
            self.weight
        }
    }
}

/// One region sample: a grid cell and the link it belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FillSample {
    /// The cell, `j × grid + i` ([`FillPoints::position`]).
    pub cell: u16,
    /// The model frame of the link the sample belongs to ([`ProjectedLink::frame`]), which
    /// names the link whatever the view's order at a later iteration.
    ///
    /// [`ProjectedLink::frame`]: crate::projection::ProjectedLink::frame
    pub frame: u8,
    /// Bright and left uncovered (the link's outline is to reach out to it), or dark and
    /// covered (the outline is to pull in past it).
    pub bright: bool,
}

/// The region samples of one camera, gathered on a frame's first iteration and kept for its
/// later ones (4 bytes a sample).
#[derive(Debug, Clone, Default)]
pub struct FillPoints {
    /// The grid's first cell (px).
    pub origin: Vector2<f32>,
    /// The grid's spacing (px).
    pub step: Vector2<f32>,
    /// Cells along each side of the grid.
    pub grid: u16,
    /// The samples, in grid order.
    pub points: Vec<FillSample, MAX_FILL_POINTS>,
    /// Samples beyond [`MAX_FILL_POINTS`], not kept.
    pub dropped: u16,
}

impl FillPoints {
    /// Empties the samples.
    pub fn clear(&mut self) {
        self.points.clear();
        self.dropped = 0;
    }

    /// Where sample `sample` lies in the image (px).
    pub fn position(&self, sample: &FillSample) -> Vector2<f32> {
        let grid = self.grid.max(1);
        let (i, j) = (sample.cell % grid, sample.cell / grid);
        self.origin
            + self
                .step
                .component_mul(&Vector2::new(f32::from(i), f32::from(j)))
    }

    fn push(&mut self, point: FillSample) {
        if self.points.push(point).is_err() {
            self.dropped = self.dropped.saturating_add(1);
        }
    }
}

/// The link of `view` whose capsule covers `p` most deeply (by distance from its axis as a
/// share of its radius), or [`PALM`] / [`UNCOVERED`].
///
/// Only the links in `among` (indices into `view.links`, ascending) are looked at: the
/// answer is the same as over every link when `among` holds every link whose bounds contain
/// `p` ([`links_across`]).
fn cover_class(view: &ProjectedModel, camera: &Camera, among: &[u8], p: &Vector2<f32>) -> u8 {
    let mut best = (UNCOVERED, 1.0f32);
    for &index in among {
        let index = usize::from(index);
        let Some(link) = view.links.get(index) else {
            continue;
        };
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

/// How far below the class midpoint (grey levels) a dark sample at `p`, covered by link
/// `index` of `view`, must lie to be classed dark: [`FillConfig::core_margin`] of the contrast
/// in the link's core ([`FillConfig::core_share`] of its radius), 0 elsewhere (the class
/// margin has already been passed).
fn core_bar(
    view: &ProjectedModel,
    index: usize,
    p: &Vector2<f32>,
    config: &FillConfig,
    contrast: f32,
) -> f32 {
    let Some(link) = view.links.get(index) else {
        return 0.0;
    };
    let (s, dist) = link.closest(p);
    if dist < config.core_share * link.radius_at(s) {
        config.core_margin.max(0.0) * contrast
    } else {
        0.0
    }
}

/// The links of `view` whose bounds span image row `y` (px), in order: every link whose
/// bounds contain a point of that row is among them.
fn links_across(view: &ProjectedModel, y: f32) -> Vec<u8, MAX_LINKS> {
    let mut out = Vec::new();
    for (index, link) in view.links.iter().enumerate() {
        if y >= link.bounds.min.y && y <= link.bounds.max.y {
            let _ = out.push(index as u8);
        }
    }
    out
}

/// Whether the model hides link `index` of `view` wholly from `camera`: the points at 0.2,
/// 0.5 and 0.8 of its axis, at the capsule's front, each behind a nearer part of the hand
/// ([`cover`](crate::visibility::cover); the links sharing a joint with it do not count).
pub fn hidden_link(view: &ProjectedModel, camera: &Camera, index: usize) -> bool {
    let Some(link) = view.links.get(index) else {
        return false;
    };
    [0.2f32, 0.5, 0.8].iter().all(|&s| {
        let p = link.a + (link.b - link.a) * s;
        let front = link.depth_at(s) - link.radius_mm;
        crate::visibility::cover(view, camera, index, &p, front) == crate::visibility::Cover::Hidden
    })
}

/// The link outline nearest `p` within `reach_px`, by the distance beyond its capsule, the
/// distance to a link `hidden` marks counted at `hidden_share` of itself (not a finite
/// number: such links are passed over).
fn nearest_outline(
    view: &ProjectedModel,
    p: &Vector2<f32>,
    reach_px: f32,
    hidden: &[bool; MAX_LINKS],
    hidden_share: f32,
) -> Option<usize> {
    let mut best: Option<(usize, f32)> = None;
    for (index, link) in view.links.iter().enumerate() {
        let is_hidden = hidden.get(index).copied().unwrap_or(false);
        if is_hidden && !hidden_share.is_finite() {
            continue;
        }
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
        let ranked = if is_hidden {
            gap * hidden_share.max(0.0)
        } else {
            gap
        };
        if gap < reach_px && best.is_none_or(|(_, g)| ranked < g) {
            best = Some((index, ranked));
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
    out.origin = min;
    out.step = step;
    out.grid = grid as u16;
    let at =
        |i: usize, j: usize| Vector2::new(min.x + step.x * i as f32, min.y + step.y * j as f32);
    let mut value = [0u8; MAX_FILL_GRID * MAX_FILL_GRID];
    let mut class = [OFF_FRAME; MAX_FILL_GRID * MAX_FILL_GRID];
    let mut sum = [0.0f32; 2];
    let mut count = [0u32; 2];
    for j in 0..grid {
        let across = links_across(view, at(0, j).y);
        for i in 0..grid {
            let p = at(i, j);
            let Some(v) = frame.sample(p.x, p.y) else {
                continue;
            };
            let c = cover_class(view, camera, &across, &p);
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
    let margin = config.class_margin.max(0.0) * contrast;
    // Which links the model hides: asked once, at the first bright sample left uncovered,
    // and only when hidden links are ranked apart.
    let mut hidden: Option<[bool; MAX_LINKS]> = None;
    let ranks_hidden = config.hidden_gap_share != 1.0;
    for j in 0..grid {
        for i in 0..grid {
            let c = class[j * grid + i];
            let v = f32::from(value[j * grid + i]);
            if (v - threshold).abs() < margin {
                continue;
            }
            let bright = v > threshold;
            let p = at(i, j);
            let link = match (c, bright) {
                (UNCOVERED, true) => {
                    let hidden = hidden.get_or_insert_with(|| {
                        let mut flags = [false; MAX_LINKS];
                        if ranks_hidden {
                            for (index, h) in flags.iter_mut().enumerate().take(view.links.len()) {
                                *h = hidden_link(view, camera, index);
                            }
                        }
                        flags
                    });
                    nearest_outline(view, &p, reach, hidden, config.hidden_gap_share)
                }
                (OFF_FRAME | PALM | UNCOVERED, _) | (_, true) => None,
                (_, false) => Some(usize::from(c))
                    .filter(|&index| threshold - v >= core_bar(view, index, &p, config, contrast)),
            };
            if let Some(link) = link.and_then(|index| view.links.get(index)) {
                out.push(FillSample {
                    cell: (j * grid + i) as u16,
                    frame: link.frame,
                    bright,
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::Poses;
    use crate::model::Model;
    use nalgebra::Vector3;

    /// 640×480 cameras 450 mm from the hand: from above, and from two oblique sides.
    fn cameras() -> [Camera; 3] {
        let hand = Vector3::new(3.0f32, -2.0, 45.0);
        let view = |from: Vector3<f32>, up: Vector3<f32>| {
            let from = from.normalize();
            Camera::looking_along(hand + from * 450.0, -from, up, (640, 480), 1000.0).unwrap()
        };
        [
            view(Vector3::z(), Vector3::x()),
            view(Vector3::new(0.5, 0.5, 0.7), Vector3::z()),
            view(Vector3::new(-0.6, 0.3, 0.4), Vector3::z()),
        ]
    }

    /// The covering link at every 2 px over the hand's grid, culled by row, is the one found
    /// among all links, over poses whose fingers bend and cross over each other.
    #[test]
    fn the_links_across_a_row_cover_as_every_link_does() {
        let model = Model::hand().unwrap();
        let all: Vec<u8, MAX_LINKS> = (0..MAX_LINKS as u8).collect();
        let mut compared = 0usize;
        let mut covered = 0usize;
        for (k, camera) in (0..12).zip(cameras().iter().cycle()) {
            let mut q = [0.0f32; 28];
            q[..7].copy_from_slice(&[0.05, 0.02, 0.9975, -0.07, 3.0, -2.0, 45.0]);
            for (i, v) in q.iter_mut().enumerate().skip(7) {
                *v = 0.1 * ((i * 7 + k * 13) % 17) as f32 - 0.3;
            }
            let poses = Poses::compute(&model, &q).unwrap();
            let mut view = ProjectedModel::new();
            view.update(&model, &poses, camera, 1.0);
            let bounds = hand_bounds(&view).unwrap();
            let mut y = bounds.min.y - 12.0;
            while y <= bounds.max.y + 12.0 {
                let across = links_across(&view, y);
                let mut x = bounds.min.x - 12.0;
                while x <= bounds.max.x + 12.0 {
                    let p = Vector2::new(x, y);
                    let culled = cover_class(&view, camera, &across, &p);
                    assert_eq!(culled, cover_class(&view, camera, &all, &p), "{p:?}");
                    compared += 1;
                    covered += usize::from(culled != UNCOVERED && culled != PALM);
                    x += 2.0;
                }
                y += 2.0;
            }
        }
        assert!(
            covered * 10 > compared,
            "{covered} of {compared} points on a link"
        );
    }
}
