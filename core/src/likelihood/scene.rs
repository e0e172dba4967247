//! What a hypothesised state is scored against: the hand model, the cameras, and one
//! instant's frames and edge maps.

use crate::camera::Camera;
use crate::frame::FrameView;
use crate::model::Model;

use super::EdgeMap;

/// One instant as the likelihood sees it: camera `i`'s frame and [`EdgeMap`] at index `i`
/// of `frames` and `edges`. Cameras beyond the shortest of the three are not scored.
#[derive(Debug, Clone, Copy)]
pub struct Scene<'a> {
    /// The hand model the states pose.
    pub model: &'a Model,
    /// The rig.
    pub cameras: &'a [Camera],
    /// Each camera's frame.
    pub frames: &'a [FrameView<'a>],
    /// Each camera's edge map of its frame.
    pub edges: &'a [EdgeMap<'a>],
}

impl<'a> Scene<'a> {
    /// The scene of `model` seen by `cameras` in `frames`, with their `edges`.
    pub fn new(
        model: &'a Model,
        cameras: &'a [Camera],
        frames: &'a [FrameView<'a>],
        edges: &'a [EdgeMap<'a>],
    ) -> Self {
        Scene {
            model,
            cameras,
            frames,
            edges,
        }
    }

    /// Cameras that have a frame and an edge map (at most `MAX_CAMERAS`).
    pub fn cameras_scored(&self) -> usize {
        self.cameras
            .len()
            .min(self.frames.len())
            .min(self.edges.len())
            .min(crate::config::MAX_CAMERAS)
    }
}
