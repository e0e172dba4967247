//! One camera's slice search across the iterations of a frame: the first iteration searches
//! every link with the configured window; later ones narrow each link's window to what its
//! last search needed (coarse to fine), so a frame's later iterations cost less. A window
//! whose edge the direction test refused stays refused for the rest of the frame
//! ([`RefusedWindows`]).
//!
//! The in-process tracker keeps one per camera; a board measuring for a stereo host
//! ([`measurer`](crate::measurer)) keeps its own, so both narrow the windows alike.

use crate::camera::Camera;
use crate::config::MAX_LINKS;
use crate::features::{
    find_link_features_refusing, find_palm_edge_features_refusing, FeatureConfig, LinkFeatures,
    RefusedWindows, MIN_WINDOW_SAMPLES,
};
use crate::frame::FrameView;
use crate::palm_outline::HullEdge;
use crate::projection::{ProjectedModel, BOX_CORNERS};

/// Pairs of box corners a palm hull edge may join, numbered `8 · low + high`.
const CORNER_PAIRS: usize = BOX_CORNERS * BOX_CORNERS;

/// The reach of each link's last search in the current frame, and the windows refused in it.
#[derive(Debug, Clone, Copy)]
pub struct CameraSearch {
    /// `reach_px[link]`: how far from its prediction the last search of model link `link`
    /// found something ([`LinkFeatures::reach_px`], px); infinite when unknown.
    reach_px: [f32; MAX_LINKS],
    /// `palm_reach_px[8 · low + high]`: the same for the palm's hull edge joining box corners
    /// `low` < `high` (px); infinite when unknown.
    palm_reach_px: [f32; CORNER_PAIRS],
    /// `refused[link]`: the windows of model link `link` refused this frame.
    refused: [RefusedWindows; MAX_LINKS],
    /// `palm_refused[8 · low + high]`: the same for a palm hull edge.
    palm_refused: [RefusedWindows; CORNER_PAIRS],
}

impl Default for CameraSearch {
    fn default() -> Self {
        Self::new()
    }
}

impl CameraSearch {
    /// A search that knows nothing yet: every window at its configured width.
    pub const fn new() -> Self {
        CameraSearch {
            reach_px: [f32::INFINITY; MAX_LINKS],
            palm_reach_px: [f32::INFINITY; CORNER_PAIRS],
            refused: [RefusedWindows::NONE; MAX_LINKS],
            palm_refused: [RefusedWindows::NONE; CORNER_PAIRS],
        }
    }

    /// Forgets the reaches and the refusals: the next searches use the configured windows
    /// and judge every edge afresh (a new frame).
    pub fn restart(&mut self) {
        *self = Self::new();
    }

    /// Searches link `index` of `view` on `frame` into `out`. With `refine`, the window is
    /// narrowed to what this link's last search needed plus `config.refine_margin_px`.
    /// Returns the features found (edges and tip).
    #[allow(clippy::too_many_arguments)]
    pub fn link(
        &mut self,
        view: &ProjectedModel,
        camera: &Camera,
        frame: &FrameView<'_>,
        index: usize,
        config: &FeatureConfig,
        refine: bool,
        out: &mut LinkFeatures,
    ) -> u16 {
        let link_frame = view
            .links
            .get(index)
            .map_or(usize::MAX, |l| usize::from(l.frame));
        let reach = self
            .reach_px
            .get(link_frame)
            .copied()
            .unwrap_or(f32::INFINITY);
        let features = narrowed(config, refine, reach);
        let mut none = RefusedWindows::NONE;
        let refused = self.refused.get_mut(link_frame).unwrap_or(&mut none);
        find_link_features_refusing(view, camera, frame, index, &features, refused, out);
        let found = out.edges.len() as u16 + u16::from(out.tip.is_some());
        if let Some(r) = self.reach_px.get_mut(link_frame) {
            *r = if found == 0 {
                f32::INFINITY
            } else {
                out.reach_px
            };
        }
        found
    }

    /// Searches the palm's hull edge `edge` of `view` on `frame` into `out`
    /// ([`find_palm_edge_features`](crate::features::find_palm_edge_features)), narrowing
    /// the window with `refine` as [`CameraSearch::link`] does, by what the last search of the
    /// edge between the same two box corners needed. Returns the edge points found.
    #[allow(clippy::too_many_arguments)]
    pub fn palm_edge(
        &mut self,
        view: &ProjectedModel,
        camera: &Camera,
        frame: &FrameView<'_>,
        edge: &HullEdge,
        config: &FeatureConfig,
        refine: bool,
        out: &mut LinkFeatures,
    ) -> u16 {
        let [c0, c1] = edge.corners;
        let pair = usize::from(c0.min(c1)) * BOX_CORNERS + usize::from(c0.max(c1));
        let reach = self
            .palm_reach_px
            .get(pair)
            .copied()
            .unwrap_or(f32::INFINITY);
        let features = narrowed(config, refine, reach);
        let mut none = RefusedWindows::NONE;
        let refused = self.palm_refused.get_mut(pair).unwrap_or(&mut none);
        find_palm_edge_features_refusing(view, camera, frame, edge, &features, refused, out);
        let found = out.edges.len() as u16;
        if let Some(r) = self.palm_reach_px.get_mut(pair) {
            *r = if found == 0 {
                f32::INFINITY
            } else {
                out.reach_px
            };
        }
        found
    }
}

/// `config` with the window narrowed, when `refine`, to a last search's `reach_px` plus the
/// margin each side (never wider than configured).
fn narrowed(config: &FeatureConfig, refine: bool, reach_px: f32) -> FeatureConfig {
    let mut features = *config;
    if refine {
        let need = 2.0 * (reach_px + features.refine_margin_px) + MIN_WINDOW_SAMPLES as f32;
        if need < f32::from(features.window_px) {
            features.window_px = libm::ceilf(need) as u8;
        }
    }
    features
}
