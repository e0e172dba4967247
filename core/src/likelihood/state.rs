//! The likelihood of a whole hand state over every camera: the state posed once, projected
//! into each camera and [evaluated](super::evaluate) there. The one place a state is scored —
//! by the search ([`crate::acquire`]), its leaves' acceptance and the hypotheses
//! ([`crate::hypotheses`]) alike.

use crate::camera::Camera;
use crate::config::MAX_CAMERAS;
use crate::frame::FrameView;
use crate::kinematics::Poses;
use crate::model::Model;
use crate::projection::ProjectedModel;

use super::{evaluate, EdgeMap, Likelihood, LikelihoodConfig};

/// Shortest link drawn when scoring (px): the tracker's own default.
pub const MIN_LINK_PX: f32 = 4.0;

/// Scores states against frames, with the working memory for posing and projecting them.
#[derive(Debug, Clone, Default)]
pub struct StateScorer {
    /// The last state posed.
    pub(crate) poses: Option<Poses>,
    /// The last projection (of the last state posed, into the last camera).
    pub(crate) view: ProjectedModel,
}

impl StateScorer {
    /// A scorer.
    pub fn new() -> Self {
        Self::default()
    }

    /// Poses `q` (one value per model state); false when it cannot be posed.
    pub(crate) fn pose(&mut self, model: &Model, q: &[f32]) -> bool {
        match self.poses.as_mut() {
            Some(p) => p.update(model, q).is_ok(),
            None => match Poses::compute(model, q) {
                Ok(p) => {
                    self.poses = Some(p);
                    true
                }
                Err(_) => false,
            },
        }
    }

    /// Projects the posed hand into `camera`; false when nothing is posed.
    pub(crate) fn project(&mut self, model: &Model, camera: &Camera) -> bool {
        match self.poses.as_ref() {
            Some(poses) => {
                self.view.update(model, poses, camera, MIN_LINK_PX);
                true
            }
            None => false,
        }
    }

    /// The likelihood of `q` (one value per model state) in each camera into `out`; returns
    /// how many were scored (0 when `q` cannot be posed).
    #[allow(clippy::too_many_arguments)] // the state, the rig, its frames and edge maps, the score
    pub fn likelihoods(
        &mut self,
        model: &Model,
        cameras: &[Camera],
        frames: &[FrameView<'_>],
        edges: &[EdgeMap<'_>],
        q: &[f32],
        config: &LikelihoodConfig,
        out: &mut [Likelihood; MAX_CAMERAS],
    ) -> usize {
        if !self.pose(model, q) {
            return 0;
        }
        let mut n = 0;
        for (((camera, frame), edges), slot) in
            cameras.iter().zip(frames).zip(edges).zip(out.iter_mut())
        {
            if !self.project(model, camera) {
                return 0;
            }
            *slot = evaluate(&self.view, camera, frame, edges, config);
            n += 1;
        }
        n
    }

    /// The mean and the worst camera's likelihood score of `q` (0..=1, higher is better);
    /// both 0 when `q` cannot be posed or no camera is given.
    pub fn score_cameras(
        &mut self,
        model: &Model,
        cameras: &[Camera],
        frames: &[FrameView<'_>],
        edges: &[EdgeMap<'_>],
        q: &[f32],
        config: &LikelihoodConfig,
    ) -> (f32, f32) {
        let mut each = [Likelihood::default(); MAX_CAMERAS];
        let n = self.likelihoods(model, cameras, frames, edges, q, config, &mut each);
        if n == 0 {
            return (0.0, 0.0);
        }
        let worst = each[..n]
            .iter()
            .map(|l| l.score)
            .fold(f32::INFINITY, f32::min);
        (mean_score(&each[..n]), worst)
    }

    /// The mean likelihood score of `q` over the cameras (0..=1, higher is better); 0 when
    /// `q` cannot be posed or no camera is given.
    pub fn score(
        &mut self,
        model: &Model,
        cameras: &[Camera],
        frames: &[FrameView<'_>],
        edges: &[EdgeMap<'_>],
        q: &[f32],
        config: &LikelihoodConfig,
    ) -> f32 {
        self.score_cameras(model, cameras, frames, edges, q, config)
            .0
    }
}

/// The mean score of `each` (0 for none).
pub fn mean_score(each: &[Likelihood]) -> f32 {
    if each.is_empty() {
        0.0
    } else {
        each.iter().map(|l| l.score).sum::<f32>() / each.len() as f32
    }
}
