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

use core::fmt;

use crate::camera::Camera;
use crate::frame::FrameView;
use crate::projection::ProjectedModel;

mod edges;
mod reads;
mod region;
mod reverse;
mod samples;
mod scene;
pub mod shading;
pub mod shading_cache;
pub mod shading_refine;
mod state;

pub use edges::{BuiltEdges, EdgeMap, EDGE_BINS, GRADIENT_STEP_PX};
pub use reads::{reach_cells, CellRect, Reads};
pub use region::{Region, EXTENT_PERCENTILE, MAX_EXTENT_BINS, MIN_REGION_SAMPLES};
pub use reverse::MAX_REVERSE_CELLS;
use samples::ChamferSum;
pub use samples::{visit, Samples, SilhouettePoint, MAX_SAMPLES, MAX_SAMPLES_PER_LINE};
pub use scene::Scene;
pub use state::{mean_score, BoundedScore, StateScorer, MIN_LINK_PX};

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
    /// Weight of the reverse chamfer term (`likelihood::reverse`): the score loses this much
    /// times the term over its cap (0, the default, leaves it out and computes nothing).
    pub reverse_weight: f32,
    /// Reverse distances are truncated here (px).
    pub reverse_cap_px: f32,
    /// The reverse term's edge cells lie within the hand's image bounds widened by this (px).
    pub reverse_margin_px: f32,
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
            reverse_weight: 0.0,
            reverse_cap_px: 12.0,
            reverse_margin_px: 8.0,
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
    /// The reverse chamfer term (px), when weighed and an edge lay near the hand.
    pub reverse_px: Option<f32>,
    /// The combined score (0..=1, higher is better): `1 − chamfer/cap` and the silhouette
    /// agreement, weighted by [`LikelihoodConfig::silhouette_weight`], less
    /// [`LikelihoodConfig::reverse_weight`] times the reverse term over its cap (floored at 0).
    pub score: f32,
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
    let mut likelihood = evaluate_edges(view, camera, edges, config);
    add_silhouette(&mut likelihood, view, camera, frame, config);
    add_reverse(&mut likelihood, view, edges, config);
    likelihood
}

/// Lowers `likelihood`'s score by the reverse chamfer term, when it is weighed and the
/// view has points in the frame. Only lowers it, so every bound on the score stays one.
pub(crate) fn add_reverse(
    likelihood: &mut Likelihood,
    view: &ProjectedModel,
    edges: &EdgeMap<'_>,
    config: &LikelihoodConfig,
) {
    let weight = config.reverse_weight;
    let weighed = weight > 0.0;
    if !weighed || likelihood.points == 0 {
        return;
    }
    likelihood.reverse_px = reverse::reverse_px(view, edges, config);
    if let Some(px) = likelihood.reverse_px {
        let term = (px / config.reverse_cap_px.max(1e-3)).clamp(0.0, 1.0);
        likelihood.score = (likelihood.score - weight * term).max(0.0);
    }
}

/// The chamfer half of [`evaluate`]: every field but the silhouette's, and a `score` that
/// [`add_silhouette`] can only lower — the score with a perfect silhouette agreement, or 0
/// (final) when no silhouette point lies in the frame.
pub(crate) fn evaluate_edges(
    view: &ProjectedModel,
    camera: &Camera,
    edges: &EdgeMap<'_>,
    config: &LikelihoodConfig,
) -> Likelihood {
    let cap = config.chamfer_cap_px.max(1e-3);
    // The chamfer term of each visible silhouette point as it is visited: no buffer of points
    // (`Samples::chamfer`'s sum, in the same order).
    let mut chamfer = ChamferSum::new(cap);
    let hidden = samples::visit(view, camera, config, |p| chamfer.add(edges, p.bin, &p.at));
    let (chamfer_px, inside, outside) = (chamfer.mean_px(), chamfer.inside, chamfer.outside());
    if inside == 0 {
        return Likelihood {
            chamfer_px: cap,
            points_outside: outside,
            points_hidden: hidden,
            ..Likelihood::default()
        };
    }
    Likelihood {
        chamfer_px,
        points: inside,
        points_outside: outside,
        points_hidden: hidden,
        silhouette: None,
        reverse_px: None,
        score: combine(edge_term(chamfer_px, config), Some(1.0), config),
    }
}

/// Completes [`evaluate_edges`]' `likelihood` with the silhouette term and the final score;
/// nothing to add when no silhouette point lay in the frame.
pub(crate) fn add_silhouette(
    likelihood: &mut Likelihood,
    view: &ProjectedModel,
    camera: &Camera,
    frame: &FrameView<'_>,
    config: &LikelihoodConfig,
) {
    if likelihood.points == 0 {
        return;
    }
    let silhouette = (config.silhouette_grid > 0)
        .then(|| crate::silhouette::score(view, camera, frame, usize::from(config.silhouette_grid)))
        .flatten()
        .map(|s| s.agreement);
    likelihood.silhouette = silhouette;
    likelihood.score = combine(edge_term(likelihood.chamfer_px, config), silhouette, config);
}

/// The highest score [`evaluate`] can give under `config`: a camera not yet scored counts
/// this much in a bound.
pub(crate) fn ceiling(config: &LikelihoodConfig) -> f32 {
    combine(1.0, Some(1.0), config)
}

/// The chamfer term, 1 with every point on an edge and 0 at the cap.
fn edge_term(chamfer_px: f32, config: &LikelihoodConfig) -> f32 {
    1.0 - chamfer_px / config.chamfer_cap_px.max(1e-3)
}

/// The combined score of an edge term and a silhouette agreement (0..=1 each). One
/// expression for the score and its bounds: it rises with each argument, so a bound built
/// from larger arguments is never under the score.
fn combine(edge_term: f32, silhouette: Option<f32>, config: &LikelihoodConfig) -> f32 {
    let w = config.silhouette_weight.clamp(0.0, 1.0);
    match silhouette {
        Some(a) => (1.0 - w) * edge_term + w * a,
        None => (1.0 - w) * edge_term,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nalgebra::Vector2;

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
}
