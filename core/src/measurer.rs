//! Where the tracker's features come from: the seam between the Gauss–Newton loop and the
//! cameras' frames.
//!
//! In one process the frames are at hand ([`LocalFrames`]). In the thesis' stereo set-up each
//! camera had its own board: per iteration the host sent the state to every board, each
//! searched its own frame and sent back what it found, and the host solved once. A host
//! driving boards implements [`Measurer`] over its links; the tracker's loop is the same
//! code either way, so the two give the same states.

use crate::camera::Camera;
use crate::config::MAX_CAMERAS;
use crate::features::{FeatureConfig, LinkFeatures};
use crate::fill::{FillConfig, FillPoints};
use crate::frame::FrameView;
use crate::palm_outline::HullEdge;
use crate::projection::ProjectedModel;
use crate::search::CameraSearch;

/// Features for the tracker, one iteration at a time.
pub trait Measurer {
    /// An iteration begins at state `q`; `refine` is false on a frame's first iteration (a
    /// remote measurer sends the state to every board here, so they search in parallel).
    fn begin_iteration(&mut self, q: &[f32], refine: bool);

    /// The features of link `index` of `view` (camera number `camera_index`, `camera`, at the
    /// state of this iteration) into `out`: empty when the camera has nothing for it.
    #[allow(clippy::too_many_arguments)]
    fn link_features(
        &mut self,
        camera_index: usize,
        camera: &Camera,
        view: &ProjectedModel,
        index: usize,
        config: &FeatureConfig,
        refine: bool,
        out: &mut LinkFeatures,
    );

    /// The features across the palm's hull edge `edge` of `view` (camera number
    /// `camera_index`, at the state of this iteration) into `out`
    /// ([`find_palm_edge_features`](crate::features::find_palm_edge_features)): empty when
    /// the camera has nothing for it. Asked only when `config.palm_edges` is on.
    #[allow(clippy::too_many_arguments)]
    fn palm_edge_features(
        &mut self,
        camera_index: usize,
        camera: &Camera,
        view: &ProjectedModel,
        edge: &HullEdge,
        config: &FeatureConfig,
        refine: bool,
        out: &mut LinkFeatures,
    );

    /// The silhouette agreement of `view` (camera number `camera_index` at the last
    /// iteration's state) on a `grid` × `grid` lattice
    /// ([`silhouette::score`](crate::silhouette::score)); `None` when it cannot be scored.
    fn silhouette(
        &mut self,
        camera_index: usize,
        camera: &Camera,
        view: &ProjectedModel,
        grid: usize,
    ) -> Option<f32>;

    /// The region edge points of `view` (camera number `camera_index`, at the state of this
    /// iteration) into `out` ([`fill::gather`](crate::fill::gather)). Asked only when
    /// `config.is_on()`; a measurer without the frames at hand leaves `out` empty.
    fn fill(
        &mut self,
        camera_index: usize,
        camera: &Camera,
        view: &ProjectedModel,
        config: &FillConfig,
        out: &mut FillPoints,
    ) {
        let _ = (camera_index, camera, view, config);
        out.clear();
    }
}

/// The frames of one instant in this process: `frames[i]` is camera `i`'s.
#[derive(Debug)]
pub struct LocalFrames<'f, 'a> {
    frames: &'f [FrameView<'a>],
    searches: [CameraSearch; MAX_CAMERAS],
}

impl<'f, 'a> LocalFrames<'f, 'a> {
    /// One frame per camera, in the tracker's camera order (the caller checks counts and
    /// sizes).
    pub fn new(frames: &'f [FrameView<'a>]) -> Self {
        LocalFrames {
            frames,
            searches: [CameraSearch::new(); MAX_CAMERAS],
        }
    }
}

impl<'a> LocalFrames<'_, 'a> {
    /// Camera `index`'s frame and its search, when there is such a camera.
    fn camera(&mut self, index: usize) -> Option<(&FrameView<'a>, &mut CameraSearch)> {
        Some((self.frames.get(index)?, self.searches.get_mut(index)?))
    }
}

impl Measurer for LocalFrames<'_, '_> {
    fn begin_iteration(&mut self, _q: &[f32], refine: bool) {
        if !refine {
            for s in &mut self.searches {
                s.restart();
            }
        }
    }

    fn link_features(
        &mut self,
        camera_index: usize,
        camera: &Camera,
        view: &ProjectedModel,
        index: usize,
        config: &FeatureConfig,
        refine: bool,
        out: &mut LinkFeatures,
    ) {
        match self.camera(camera_index) {
            Some((frame, search)) => {
                search.link(view, camera, frame, index, config, refine, out);
            }
            None => *out = LinkFeatures::default(),
        }
    }

    fn palm_edge_features(
        &mut self,
        camera_index: usize,
        camera: &Camera,
        view: &ProjectedModel,
        edge: &HullEdge,
        config: &FeatureConfig,
        refine: bool,
        out: &mut LinkFeatures,
    ) {
        match self.camera(camera_index) {
            Some((frame, search)) => {
                search.palm_edge(view, camera, frame, edge, config, refine, out);
            }
            None => *out = LinkFeatures::default(),
        }
    }

    fn silhouette(
        &mut self,
        camera_index: usize,
        camera: &Camera,
        view: &ProjectedModel,
        grid: usize,
    ) -> Option<f32> {
        let frame = self.frames.get(camera_index)?;
        crate::silhouette::score(view, camera, frame, grid).map(|s| s.agreement)
    }

    fn fill(
        &mut self,
        camera_index: usize,
        camera: &Camera,
        view: &ProjectedModel,
        config: &FillConfig,
        out: &mut FillPoints,
    ) {
        match self.frames.get(camera_index) {
            Some(frame) => crate::fill::gather(view, camera, frame, config, out),
            None => out.clear(),
        }
    }
}
