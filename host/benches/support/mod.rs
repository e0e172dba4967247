//! Shared by the `tracker` benchmark and the `stage_costs` example: a rendered scenario loaded
//! into memory, and the Table 4.1 stages of one tracker iteration run one at a time.
//!
//! [`Stages`] replays `Tracker::iterate` (core/src/tracker.rs) stage by stage with the same
//! public stage functions, in the same order, so each stage can be timed or counted on its
//! own; `Stages::iterate` checks it agrees with the tracker (same rows, same step).
#![allow(dead_code)] // each of the two targets uses a different part

use std::path::Path;

use anyhow::{anyhow, ensure, Result};
use digiteyes_core::camera::Camera;
use digiteyes_core::config::MAX_STATES;
use digiteyes_core::estimator::{add_link_rows, LinkJacobian, NormalEquations};
use digiteyes_core::features::{find_link_features, LinkFeatures};
use digiteyes_core::frame::FrameView;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::Model;
use digiteyes_core::nalgebra::SVector;
use digiteyes_core::projection::ProjectedModel;
use digiteyes_core::tracker::{Tracker, TrackerConfig};
use digiteyes_host::sequence::Sequence;
use digiteyes_host::{render_scenario, RenderOptions};
use image::GrayImage;

/// The seed every figure in docs/performance.md was measured with.
pub const SEED: u64 = 1;

/// Renders scenario `name` into `dir` (frames 0..`frames`) unless `dir` already holds a
/// sequence with at least that many frames.
pub fn render_if_missing(name: &str, dir: &Path, frames: usize) -> Result<()> {
    if let Ok(seq) = Sequence::open(dir) {
        if seq.frames >= frames {
            return Ok(());
        }
    }
    let opts = RenderOptions {
        seed: SEED,
        frames: Some(frames),
        ..Default::default()
    };
    render_scenario(name, dir, &opts)
}

/// A sequence held in memory: every frame of every camera, and what a tracker needs.
pub struct Case {
    /// The sequence as opened.
    pub sequence: Sequence,
    /// `images[k][c]`: frame `k` of camera `c`.
    pub images: Vec<Vec<GrayImage>>,
    /// The truth at frame 0 (quaternion, mm, rad), as the tracker's `f32`.
    pub initial: Vec<f32>,
}

impl Case {
    /// Opens the sequence in `dir` and reads its first `frames` frames (all when `None`).
    pub fn load(dir: &Path, frames: Option<usize>) -> Result<Case> {
        let sequence = Sequence::open(dir)?;
        let n = frames.unwrap_or(sequence.frames);
        ensure!(
            n <= sequence.frames,
            "{} has {} frames, {n} wanted",
            dir.display(),
            sequence.frames
        );
        let images = (0..n)
            .map(|k| {
                (0..sequence.cameras.len())
                    .map(|c| sequence.read_frame(c, k))
                    .collect::<Result<Vec<_>>>()
            })
            .collect::<Result<Vec<_>>>()?;
        let initial = sequence.initial_state.iter().map(|&v| v as f32).collect();
        Ok(Case {
            sequence,
            images,
            initial,
        })
    }

    /// The model.
    pub fn model(&self) -> &Model {
        &self.sequence.model
    }

    /// The cameras.
    pub fn cameras(&self) -> &[Camera] {
        &self.sequence.cameras
    }

    /// Views of frame `k` of every camera.
    pub fn views(&self, k: usize) -> Vec<FrameView<'_>> {
        self.images[k]
            .iter()
            .map(|img| {
                FrameView::packed(img.as_raw(), img.width() as usize, img.height() as usize)
                    .expect("a frame read from a sequence has its camera's size")
            })
            .collect()
    }

    /// A tracker at the truth of frame 0.
    pub fn tracker(&self, config: TrackerConfig) -> Result<Tracker> {
        Tracker::new(
            self.model().clone(),
            self.cameras(),
            &self.initial,
            self.sequence.free_mask(),
            config,
        )
        .map_err(|e| anyhow!("cannot start the tracker: {e}"))
    }
}

/// The working memory of one iteration, with the stages of `Tracker::iterate` as methods.
pub struct Stages<'a> {
    /// The tracker whose model, cameras, free states and configuration are used.
    pub tracker: &'a Tracker,
    /// Kinematics output.
    pub poses: Poses,
    /// Projection output, one per camera.
    pub views: Vec<ProjectedModel>,
    /// Features output: `features[c][i]` for link `i` of camera `c`'s view.
    pub features: Vec<Vec<LinkFeatures>>,
    /// Scratch features for [`Stages::features`] (as the tracker reuses one).
    pub scratch: LinkFeatures,
    /// Jacobian scratch.
    pub jacobian: LinkJacobian,
    /// Normal equations.
    pub normal: NormalEquations,
}

impl<'a> Stages<'a> {
    /// Stages for `tracker`, with poses at `q`.
    pub fn new(tracker: &'a Tracker, q: &[f32]) -> Stages<'a> {
        let cameras = tracker.cameras().len();
        Stages {
            tracker,
            poses: Poses::compute(tracker.model(), q).expect("a valid state"),
            views: vec![ProjectedModel::new(); cameras],
            features: vec![Vec::new(); cameras],
            scratch: LinkFeatures::default(),
            jacobian: LinkJacobian::default(),
            normal: NormalEquations::new(),
        }
    }

    /// Kinematics: `Poses::update`.
    pub fn kinematics(&mut self, q: &[f32]) {
        self.poses
            .update(self.tracker.model(), q)
            .expect("a valid state");
    }

    /// Projection into every camera: `ProjectedModel::update`.
    pub fn projection(&mut self) {
        let min_px = self.tracker.config().features.min_link_px;
        for (view, camera) in self.views.iter_mut().zip(self.tracker.cameras()) {
            view.update(self.tracker.model(), &self.poses, camera, min_px);
        }
    }

    /// Features of every link in every camera into one scratch buffer, as the tracker does:
    /// `find_link_features` (visibility mask included). Returns the features found.
    pub fn features(&mut self, frames: &[FrameView<'_>]) -> u32 {
        let config = &self.tracker.config().features;
        let mut found = 0;
        for ((view, camera), frame) in self.views.iter().zip(self.tracker.cameras()).zip(frames) {
            for index in 0..view.links.len() {
                find_link_features(view, camera, frame, index, config, &mut self.scratch);
                found += self.scratch.edges.len() as u32 + u32::from(self.scratch.tip.is_some());
            }
        }
        found
    }

    /// Features of every link kept per link, for [`Stages::jacobian_normal`].
    pub fn keep_features(&mut self, frames: &[FrameView<'_>]) {
        let config = &self.tracker.config().features;
        for (c, ((view, camera), frame)) in self
            .views
            .iter()
            .zip(self.tracker.cameras())
            .zip(frames)
            .enumerate()
        {
            self.features[c].clear();
            for index in 0..view.links.len() {
                let mut out = LinkFeatures::default();
                find_link_features(view, camera, frame, index, config, &mut out);
                self.features[c].push(out);
            }
        }
    }

    /// Jacobian and normal equations of every link with features (from
    /// [`Stages::keep_features`]): `LinkJacobian::compute` + `add_link_rows`. Returns the rows.
    pub fn jacobian_normal(&mut self) -> u16 {
        let model = self.tracker.model();
        let cameras = self.tracker.cameras().len();
        let config = &self.tracker.config().estimator.for_cameras(cameras);
        let free = self.tracker.free();
        self.normal.clear();
        for ((view, camera), features) in self
            .views
            .iter()
            .zip(self.tracker.cameras())
            .zip(&self.features)
        {
            for (link, f) in view.links.iter().zip(features) {
                if f.edges.is_empty() && f.tip.is_none() {
                    continue;
                }
                self.jacobian.compute(model, &self.poses, camera, link);
                add_link_rows(&mut self.normal, link, f, &self.jacobian, config, free);
            }
        }
        self.normal.rows()
    }

    /// The solve: `NormalEquations::step`.
    pub fn solve(&self) -> Option<SVector<f32, MAX_STATES>> {
        self.normal.step(
            self.tracker.model().n_states(),
            self.tracker.free(),
            &self.tracker.config().estimator.conditioning,
        )
    }

    /// One whole iteration at `q`, stage by stage. Returns the rows and the step.
    pub fn iterate(
        &mut self,
        q: &[f32],
        frames: &[FrameView<'_>],
    ) -> (u16, Option<SVector<f32, MAX_STATES>>) {
        self.kinematics(q);
        self.projection();
        self.keep_features(frames);
        let rows = self.jacobian_normal();
        (rows, self.solve())
    }
}
