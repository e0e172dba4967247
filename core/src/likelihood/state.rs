//! The likelihood of a whole hand state over every camera: the state posed once, projected
//! into each camera and [evaluated](super::evaluate) there. The one place a state is scored —
//! by the search ([`crate::acquire`]), its leaves' acceptance and the hypotheses
//! ([`crate::hypotheses`]) alike.

use crate::camera::Camera;
use crate::config::MAX_CAMERAS;
use crate::kinematics::Poses;
use crate::model::Model;
use crate::projection::ProjectedModel;

use super::{
    add_reverse, add_silhouette, ceiling, evaluate, evaluate_edges, reverse, Likelihood,
    LikelihoodConfig, Reads, Scene,
};
use crate::silhouette::hand_bounds;

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

    /// Adds where scoring `q` (one value per model state) reads each camera's edge map to
    /// `reads` (one per camera): its hand's image bounds there
    /// ([`crate::silhouette::hand_bounds`]). A state that cannot be posed is scored without
    /// reading any map, so it adds nothing.
    pub fn add_reads(&mut self, model: &Model, cameras: &[Camera], q: &[f32], reads: &mut [Reads]) {
        if !self.pose(model, q) {
            return;
        }
        for (camera, r) in cameras.iter().zip(reads.iter_mut()) {
            if !self.project(model, camera) {
                return;
            }
            *r = r.with(hand_bounds(&self.view));
        }
    }

    /// The likelihood of `q` (one value per model state) in each camera into `out`; returns
    /// how many were scored (0 when `q` cannot be posed).
    pub fn likelihoods(
        &mut self,
        scene: &Scene<'_>,
        q: &[f32],
        config: &LikelihoodConfig,
        out: &mut [Likelihood; MAX_CAMERAS],
    ) -> usize {
        self.likelihoods_and_reverse(scene, q, config, out, None)
    }

    /// [`Self::likelihoods`], and with `worst_reverse` also [`Self::worst_reverse_px`] from
    /// the same poses and projections.
    fn likelihoods_and_reverse(
        &mut self,
        scene: &Scene<'_>,
        q: &[f32],
        config: &LikelihoodConfig,
        out: &mut [Likelihood; MAX_CAMERAS],
        mut worst_reverse: Option<&mut Option<f32>>,
    ) -> usize {
        if !self.pose(scene.model, q) {
            return 0;
        }
        let mut n = 0;
        for (((camera, frame), edges), slot) in scene
            .cameras
            .iter()
            .zip(scene.frames)
            .zip(scene.edges)
            .zip(out.iter_mut())
        {
            if !self.project(scene.model, camera) {
                return 0;
            }
            *slot = evaluate(&self.view, camera, frame, edges, config);
            if let Some(worst) = worst_reverse.as_deref_mut() {
                // `evaluate` computed the term only when it weighs it and saw the hand.
                let px = slot
                    .reverse_px
                    .or_else(|| reverse::reverse_px(&self.view, edges, config));
                if let Some(px) = px {
                    *worst = Some(worst.map_or(px, |w| w.max(px)));
                }
            }
            n += 1;
        }
        n
    }

    /// The mean score of `q` over the cameras, bit for bit [`Self::score`]'s, unless that
    /// mean cannot exceed `bar`: then the score is `None`, found without the terms that could
    /// not have lifted it over. Before each camera's silhouette term, and before each further
    /// camera, the mean is bounded from above by the `evaluate_edges` bound for a camera
    /// whose edges are scored and the `ceiling` for one not yet scored; a bound at or
    /// under `bar` ends it. What was computed is counted in the result, so a caller can
    /// charge for it.
    pub fn score_above(
        &mut self,
        scene: &Scene<'_>,
        q: &[f32],
        config: &LikelihoodConfig,
        bar: f32,
    ) -> BoundedScore {
        let mut out = BoundedScore::default();
        if !self.pose(scene.model, q) {
            out.score = Some(0.0);
            return out;
        }
        let n = scene.cameras_scored();
        let mut each = [Likelihood {
            score: ceiling(config),
            ..Likelihood::default()
        }; MAX_CAMERAS];
        for (k, ((camera, frame), edges)) in scene
            .cameras
            .iter()
            .zip(scene.frames)
            .zip(scene.edges)
            .enumerate()
            .take(n)
        {
            if mean_score(&each[..n]) <= bar {
                return out;
            }
            if !self.project(scene.model, camera) {
                out.score = Some(0.0);
                return out;
            }
            each[k] = evaluate_edges(&self.view, camera, edges, config);
            out.edge_terms += 1;
            if mean_score(&each[..n]) <= bar {
                return out;
            }
            if each[k].points > 0 {
                add_silhouette(&mut each[k], &self.view, camera, frame, config);
                add_reverse(&mut each[k], &self.view, edges, config);
                out.silhouette_terms += 1;
            }
        }
        out.score = Some(mean_score(&each[..n]));
        out
    }

    /// The mean and the worst camera's likelihood score of `q` (0..=1, higher is better);
    /// both 0 when `q` cannot be posed or no camera is given.
    pub fn score_cameras(
        &mut self,
        scene: &Scene<'_>,
        q: &[f32],
        config: &LikelihoodConfig,
    ) -> (f32, f32) {
        let mut each = [Likelihood::default(); MAX_CAMERAS];
        let n = self.likelihoods(scene, q, config, &mut each);
        mean_and_worst(&each[..n])
    }

    /// [`Self::score_cameras`] and [`Self::worst_reverse_px`] together, `q` posed and
    /// projected once: the mean and worst camera's score, and the worst reverse term (`None`
    /// when `q` cannot be posed or no camera has an edge near the hand).
    pub fn score_cameras_and_reverse(
        &mut self,
        scene: &Scene<'_>,
        q: &[f32],
        config: &LikelihoodConfig,
    ) -> (f32, f32, Option<f32>) {
        let mut each = [Likelihood::default(); MAX_CAMERAS];
        let mut worst_reverse = None;
        let n = self.likelihoods_and_reverse(scene, q, config, &mut each, Some(&mut worst_reverse));
        if n == 0 {
            // A camera that could not be projected ends the scoring; so it ends the term.
            worst_reverse = None;
        }
        let (mean, worst) = mean_and_worst(&each[..n]);
        (mean, worst, worst_reverse)
    }

    /// The largest [reverse chamfer term](super) of `q` over the cameras (px,
    /// 0..=`reverse_cap_px`), whatever `config`'s `reverse_weight`: how far the worst view's
    /// edges near the hand lie from the lines that would explain them. `None` when `q` cannot
    /// be posed or no camera has an edge near the projected hand.
    pub fn worst_reverse_px(
        &mut self,
        scene: &Scene<'_>,
        q: &[f32],
        config: &LikelihoodConfig,
    ) -> Option<f32> {
        if !self.pose(scene.model, q) {
            return None;
        }
        let mut worst: Option<f32> = None;
        for (camera, edges) in scene.cameras.iter().zip(scene.edges) {
            if !self.project(scene.model, camera) {
                return None;
            }
            if let Some(px) = reverse::reverse_px(&self.view, edges, config) {
                worst = Some(worst.map_or(px, |w| w.max(px)));
            }
        }
        worst
    }

    /// The mean likelihood score of `q` over the cameras (0..=1, higher is better); 0 when
    /// `q` cannot be posed or no camera is given.
    pub fn score(&mut self, scene: &Scene<'_>, q: &[f32], config: &LikelihoodConfig) -> f32 {
        self.score_cameras(scene, q, config).0
    }
}

/// A score [`StateScorer::score_above`] computed, or found not to exceed its bar.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BoundedScore {
    /// The mean score over the cameras, or `None` when it could not exceed the bar.
    pub score: Option<f32>,
    /// Cameras whose chamfer term was computed.
    pub edge_terms: u8,
    /// Cameras whose silhouette term was computed.
    pub silhouette_terms: u8,
}

/// The mean and the smallest score of `each` (both 0 for none).
fn mean_and_worst(each: &[Likelihood]) -> (f32, f32) {
    if each.is_empty() {
        return (0.0, 0.0);
    }
    let worst = each.iter().map(|l| l.score).fold(f32::INFINITY, f32::min);
    (mean_score(each), worst)
}

/// The mean score of `each` (0 for none).
pub fn mean_score(each: &[Likelihood]) -> f32 {
    if each.is_empty() {
        0.0
    } else {
        each.iter().map(|l| l.score).sum::<f32>() / each.len() as f32
    }
}
