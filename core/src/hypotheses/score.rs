//! The image likelihood of a whole state over every camera.

use crate::camera::Camera;
use crate::frame::FrameView;
use crate::kinematics::Poses;
use crate::likelihood::{evaluate, EdgeMap, LikelihoodConfig};
use crate::model::Model;
use crate::projection::ProjectedModel;

/// Shortest link drawn when scoring (px): the tracker's own default.
const MIN_LINK_PX: f32 = 4.0;

/// Scores states against frames, with the working memory for posing and projecting them.
#[derive(Debug, Clone, Default)]
pub struct StateScorer {
    poses: Option<Poses>,
    view: ProjectedModel,
}

impl StateScorer {
    /// A scorer.
    pub fn new() -> Self {
        Self::default()
    }

    /// The mean likelihood score of `q` (one value per model state) over the cameras
    /// (0..=1, higher is better); 0 when `q` cannot be posed or no camera is given.
    pub fn score(
        &mut self,
        model: &Model,
        cameras: &[Camera],
        frames: &[FrameView<'_>],
        edges: &[EdgeMap<'_>],
        q: &[f32],
        config: &LikelihoodConfig,
    ) -> f32 {
        let posed = match self.poses.as_mut() {
            Some(p) => p.update(model, q).is_ok(),
            None => match Poses::compute(model, q) {
                Ok(p) => {
                    self.poses = Some(p);
                    true
                }
                Err(_) => false,
            },
        };
        let Some(poses) = self.poses.as_ref().filter(|_| posed) else {
            return 0.0;
        };
        let mut sum = 0.0;
        let mut n = 0u32;
        for ((camera, frame), edges) in cameras.iter().zip(frames).zip(edges) {
            self.view.update(model, poses, camera, MIN_LINK_PX);
            sum += evaluate(&self.view, camera, frame, edges, config).score;
            n += 1;
        }
        if n == 0 {
            0.0
        } else {
            sum / n as f32
        }
    }
}
