//! Finding the hand without help (after Stenger et al.'s tree-based search): hypotheses are
//! scored by the image [likelihood](crate::likelihood), coarse to fine, keeping the best few
//! at each level:
//!
//! 1. **Coarse**: palm rotations covering SO(3) (palm normals spread evenly over the sphere ×
//!    turns about the normal) × depths across the [`WorkingVolume`], the fingers relaxed: each
//!    such template is projected once into the first camera and slid over the frame's edge
//!    map (chamfer matching), which places it in the image — the palm's position across the
//!    view costs table look-ups, not projections.
//! 2. **Fingers**: each of the best with every pose of a small library (open, relaxed, spread,
//!    half curl, fist, pointing, pinch).
//! 3. **Refine**: around each of the best, the palm moved along each axis, turned about each
//!    axis, and each finger bent and stretched, with steps halving each round.
//!
//! The search is *anytime*: [`Acquirer::step`] spends at most
//! [`AcquireConfig::evaluations_per_frame`] evaluations per call and picks up where it left
//! off, so a board answers every frame while it searches. Only free states are hypothesised;
//! fixed states keep the base state's values. The best leaf is handed back for Gauss–Newton
//! refinement and acceptance by the caller.

use heapless::Vec;

use crate::camera::Camera;
use crate::config::{MAX_CAMERAS, MAX_STATES};
use crate::estimator::FreeMask;
use crate::frame::FrameView;
use crate::kinematics::Poses;
use crate::likelihood::{evaluate, EdgeMap, LikelihoodConfig, Samples};
use crate::model::Model;
use crate::nalgebra::{Vector2, Vector3};
use crate::projection::ProjectedModel;

/// Chamfer look-ups a slide may make for the cost of one evaluation (an evaluation looks up
/// about this many silhouette points, and projects and samples the silhouette besides).
pub const LOOKUPS_PER_EVALUATION: u32 = 600;

/// The best hypotheses kept between levels.
pub const MAX_KEEP: usize = 8;

/// The palm's position (mm) and rotation (the quaternion) are states 4..7 and 0..4.
const QUATERNION: core::ops::Range<usize> = 0..4;
const TRANSLATION: core::ops::Range<usize> = 4..7;

/// A box of world space the palm's origin is searched in (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WorkingVolume {
    /// Centre (world, mm).
    pub centre_mm: [f32; 3],
    /// Half the box's side along each world axis (mm).
    pub half_size_mm: [f32; 3],
}

impl WorkingVolume {
    /// Half-size of the default volume (mm): a hand's reach about where the cameras look.
    pub const DEFAULT_HALF_SIZE_MM: f32 = 120.0;

    /// The default volume for a rig: a cube of [`Self::DEFAULT_HALF_SIZE_MM`] about the world
    /// origin when every camera sees it in front of it (the renderer's and the thesis' rigs
    /// look at the hand there), else about the point nearest every camera's optical axis
    /// (one camera: its axis at `fallback_depth_mm`).
    pub fn from_cameras(cameras: &[Camera], fallback_depth_mm: f32) -> Self {
        let origin = Vector3::zeros();
        let half = [Self::DEFAULT_HALF_SIZE_MM; 3];
        let sees_origin = !cameras.is_empty()
            && cameras.iter().all(|c| {
                c.project(&origin).is_some_and(|uv| {
                    uv.x >= 0.0 && uv.y >= 0.0 && uv.x < c.width as f32 && uv.y < c.height as f32
                })
            });
        if sees_origin {
            return WorkingVolume {
                centre_mm: [0.0; 3],
                half_size_mm: half,
            };
        }
        let mut centre = Vector3::zeros();
        for c in cameras {
            // The optical axis in the world: R's third row.
            let axis = Vector3::new(c.r[(2, 0)], c.r[(2, 1)], c.r[(2, 2)]);
            centre += c.centre() + axis * fallback_depth_mm;
        }
        centre /= cameras.len().max(1) as f32;
        WorkingVolume {
            centre_mm: [centre.x, centre.y, centre.z],
            half_size_mm: half,
        }
    }
}

/// How hard and how wide to search.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AcquireConfig {
    /// Work per [`Acquirer::step`] at most, in evaluations: one hypothesis scored counts 1,
    /// a slide counts its chamfer look-ups over [`LOOKUPS_PER_EVALUATION`].
    pub evaluations_per_frame: u16,
    /// Depths of the coarse templates across the volume (as seen from the first camera).
    pub depths: u8,
    /// The slide's step as a share of the frame's width.
    pub slide_step: f32,
    /// Coarse palm normals, spread over the sphere.
    pub normals: u8,
    /// Coarse turns about each normal.
    pub spins: u8,
    /// Levels of the template tree after the coarse slide (each slides children of the best
    /// templates locally: turned, moved in depth, other finger poses).
    pub tree_levels: u8,
    /// First steps of the template tree: palm rotation (rad), depth (mm).
    pub tree_steps: [f32; 2],
    /// Rounds of local refinement.
    pub refine_rounds: u8,
    /// First refinement steps: palm translation (mm), palm rotation (rad), finger bend (rad).
    pub refine_steps: [f32; 3],
    /// The score.
    pub likelihood: LikelihoodConfig,
}

impl Default for AcquireConfig {
    fn default() -> Self {
        AcquireConfig {
            evaluations_per_frame: 1000,
            depths: 3,
            slide_step: 1.0 / 20.0,
            normals: 20,
            spins: 6,
            tree_levels: 3,
            tree_steps: [0.35, 60.0],
            refine_rounds: 4,
            refine_steps: [30.0, 0.35, 0.4],
            likelihood: LikelihoodConfig::default(),
        }
    }
}

/// A scored hypothesis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// Mean likelihood score over the cameras (0..=1, higher is better).
    pub score: f32,
    /// The state (every model state; the first `n_states` are used).
    pub q: [f32; MAX_STATES],
}

/// What a [`Acquirer::step`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Progress {
    /// Still searching; this many hypotheses were scored in this step.
    Searching {
        /// Hypotheses scored in this step.
        evaluated: u16,
    },
    /// The search is over: its best leaf (to refine and accept or refuse).
    Found(Candidate),
}

/// Where the search is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stage {
    Coarse(u32),
    Tree { level: u8, next: u32 },
    Fingers(u32),
    Refine { round: u8, next: u32 },
    Done,
}

/// Finger poses of the library: (abduction, MCP, PIP, DIP) for fingers 1–4 (the thumb's
/// five states follow in [`THUMB_POSES`]).
const FINGER_POSES: [[[f32; 4]; 4]; 7] = [
    [[0.0, 0.0, 0.0, 0.0]; 4], // open
    [[0.0, 0.3, 0.4, 0.2]; 4], // relaxed
    [
        [-0.25, 0.0, 0.0, 0.0],
        [-0.08, 0.0, 0.0, 0.0],
        [0.08, 0.0, 0.0, 0.0],
        [0.25, 0.0, 0.0, 0.0],
    ], // spread
    [[0.0, 0.7, 0.9, 0.5]; 4], // half curl
    [[0.0, 1.3, 1.5, 0.9]; 4], // fist
    [
        [0.0, 0.0, 0.0, 0.0],
        [0.0, 1.3, 1.5, 0.9],
        [0.0, 1.3, 1.5, 0.9],
        [0.0, 1.3, 1.5, 0.9],
    ], // pointing
    [
        [0.0, 0.6, 0.8, 0.4],
        [0.0, 0.3, 0.4, 0.2],
        [0.0, 0.3, 0.4, 0.2],
        [0.0, 0.3, 0.4, 0.2],
    ], // pinch
];

/// The thumb's states (q23..q27) for each pose of [`FINGER_POSES`].
const THUMB_POSES: [[f32; 5]; 7] = [
    [0.0; 5],
    [0.0, 0.1, 0.2, 0.2, 0.2],
    [0.0, 0.3, 0.0, 0.0, 0.0],
    [0.0, 0.2, 0.4, 0.5, 0.3],
    [0.0, 0.4, 0.6, 0.8, 0.5],
    [0.0, 0.4, 0.6, 0.8, 0.5],
    [0.0, 0.3, 0.5, 0.6, 0.4],
];

/// The library pose the coarse level uses.
const RELAXED: usize = 1;

/// First state of finger `f` (0..4: fingers 1–4, then the thumb).
const fn finger_start(f: usize) -> usize {
    7 + 4 * f
}

/// The anytime hierarchical search.
#[derive(Debug, Clone)]
pub struct Acquirer {
    config: AcquireConfig,
    volume: WorkingVolume,
    base: [f32; MAX_STATES],
    n_states: usize,
    free: FreeMask,
    stage: Stage,
    best: Vec<Candidate, MAX_KEEP>,
    /// The level's new best, built while the level runs.
    next: Vec<Candidate, MAX_KEEP>,
    poses: Option<Poses>,
    view: ProjectedModel,
    /// Hypotheses scored since the last restart.
    pub evaluations: u32,
    /// Chamfer look-ups of the slide under way (what it costs against the budget).
    lookups: u32,
    /// The most one hypothesis or slide has cost (evaluations): how far a step can overrun
    /// its budget, since the last item is finished once begun.
    pub largest_item_cost: u16,
}

impl Acquirer {
    /// A search for the hand of `model`: free states from `free`, the others kept at `base`
    /// (one value per model state), the palm within `volume`.
    pub fn new(
        model: &Model,
        base: &[f32],
        free: FreeMask,
        volume: WorkingVolume,
        config: AcquireConfig,
    ) -> Self {
        let mut b = [0.0f32; MAX_STATES];
        for (d, s) in b.iter_mut().zip(base) {
            *d = *s;
        }
        if crate::quaternion::normalised([b[0], b[1], b[2], b[3]]).is_none() {
            b[..4].copy_from_slice(&[1.0, 0.0, 0.0, 0.0]);
        }
        Acquirer {
            config,
            volume,
            base: b,
            n_states: model.n_states().min(MAX_STATES),
            free,
            stage: Stage::Coarse(0),
            best: Vec::new(),
            next: Vec::new(),
            poses: None,
            view: ProjectedModel::new(),
            evaluations: 0,
            lookups: 0,
            largest_item_cost: 0,
        }
    }

    /// The best hypotheses of the last finished level (best first): when the search is over,
    /// its leaves, to refine one by one.
    pub fn best(&self) -> &[Candidate] {
        &self.best
    }

    /// Starts the search over (the hand was lost, or a found leaf was refused).
    pub fn restart(&mut self) {
        self.stage = Stage::Coarse(0);
        self.best.clear();
        self.next.clear();
        self.evaluations = 0;
    }

    /// The parameters.
    pub fn config(&self) -> &AcquireConfig {
        &self.config
    }

    /// Templates in the coarse level.
    pub fn coarse_count(&self) -> u32 {
        let rotations = if self.frees(QUATERNION) {
            u32::from(self.config.normals.max(1)) * u32::from(self.config.spins.max(1))
        } else {
            1
        };
        u32::from(self.config.depths.max(1)) * rotations
    }

    /// Scores up to [`AcquireConfig::evaluations_per_frame`] hypotheses on `frames` (one per
    /// camera, with their edge maps) and moves the search on.
    #[inline(never)] // a stage of the search: kept whole so profiles can attribute its cost
    pub fn step(
        &mut self,
        model: &Model,
        cameras: &[Camera],
        frames: &[FrameView<'_>],
        edges: &[EdgeMap<'_>],
    ) -> Progress {
        let budget = self.config.evaluations_per_frame.max(1);
        let mut evaluated = 0u16;
        while evaluated < budget {
            if let Stage::Coarse(i) = self.stage {
                if i >= self.coarse_count() {
                    self.finish_level();
                    continue;
                }
                self.lookups = 0;
                if let (Some(camera), Some(edges)) = (cameras.first(), edges.first()) {
                    if let Some(c) = self.slide_template(model, camera, edges, i) {
                        keep(&mut self.next, c);
                    }
                }
                evaluated = evaluated.saturating_add(self.finish_item(0));
                continue;
            }
            if let Stage::Tree { level, next } = self.stage {
                let (Some(camera), Some(map)) = (cameras.first(), edges.first()) else {
                    self.finish_level();
                    continue;
                };
                let Some(child) = self.tree_child(camera, level, next) else {
                    self.finish_level();
                    continue;
                };
                self.lookups = 0;
                let near = camera.width as f32 * self.config.slide_step * 2.0;
                if let Some(c) = self.place(model, camera, map, child, Some(near)) {
                    keep(&mut self.next, c);
                }
                evaluated = evaluated.saturating_add(self.finish_item(1));
                continue;
            }
            let Some(q) = self.hypothesis() else {
                self.finish_level();
                if self.stage == Stage::Done {
                    break;
                }
                continue;
            };
            // Each finer hypothesis is first placed where its silhouette fits best nearby.
            let near = cameras
                .first()
                .map(|c| c.width as f32 * self.config.slide_step * 2.0);
            self.lookups = 0;
            let q = match (cameras.first(), edges.first(), near) {
                (Some(c), Some(e), Some(r)) => self
                    .place(model, c, e, q, Some(r))
                    .map_or(q, |placed| placed.q),
                _ => q,
            };
            let score = self.score(model, cameras, frames, edges, &q);
            keep(&mut self.next, Candidate { score, q });
            evaluated = evaluated.saturating_add(self.finish_item(1));
        }
        match (self.stage, self.best.first()) {
            (Stage::Done, Some(best)) => Progress::Found(*best),
            (Stage::Done, None) => {
                // Nothing could be scored (every hypothesis out of view): start again.
                self.restart();
                Progress::Searching { evaluated }
            }
            _ => Progress::Searching { evaluated },
        }
    }

    /// The mean likelihood score of `q` over the cameras (0 when it cannot be posed).
    pub fn score(
        &mut self,
        model: &Model,
        cameras: &[Camera],
        frames: &[FrameView<'_>],
        edges: &[EdgeMap<'_>],
        q: &[f32; MAX_STATES],
    ) -> f32 {
        let q = &q[..self.n_states];
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
        let mut n = 0;
        for ((camera, frame), edges) in cameras.iter().zip(frames).zip(edges).take(MAX_CAMERAS) {
            self.view.update(model, poses, camera, 4.0);
            sum += evaluate(&self.view, camera, frame, edges, &self.config.likelihood).score;
            n += 1;
        }
        if n == 0 {
            0.0
        } else {
            sum / n as f32
        }
    }

    /// Coarse template `i`: posed at its rotation and depth, projected into `camera` once,
    /// slid over the frame's edge map; the best place as a candidate (edge term only).
    fn slide_template(
        &mut self,
        model: &Model,
        camera: &Camera,
        edges: &EdgeMap<'_>,
        i: u32,
    ) -> Option<Candidate> {
        let depths = u32::from(self.config.depths.max(1));
        let (d, r) = (i % depths, i / depths);
        let mut q = self.base;
        if self.frees(QUATERNION) {
            let spins = u32::from(self.config.spins.max(1));
            let rotation = coarse_rotation(
                r / spins,
                u32::from(self.config.normals.max(1)),
                r % spins,
                spins,
            );
            q[..4].copy_from_slice(&rotation);
        }
        self.set_fingers(&mut q, RELAXED);
        // The reference point: on the ray from the camera through the volume's centre, at
        // this template's depth across the volume.
        let centre = Vector3::from(self.volume.centre_mm);
        let eye = camera.centre();
        let z_centre = camera.to_camera(&centre).z;
        if self.frees(TRANSLATION) && z_centre > 1.0 {
            let half = self
                .volume
                .half_size_mm
                .iter()
                .copied()
                .fold(0.0f32, f32::max);
            let t = (d as f32 + 0.5) / depths as f32 * 2.0 - 1.0;
            let z = (z_centre + t * half).max(z_centre * 0.25);
            let p = eye + (centre - eye) * (z / z_centre);
            q[4..7].copy_from_slice(&[p.x, p.y, p.z]);
        }
        self.place(model, camera, edges, q, None)
    }

    /// Slides hypothesis `q` (its rotation, fingers and depth from `camera`) over `camera`'s
    /// edge map — over the whole frame, or within `near_px` of where `q` projects — and
    /// returns `q` moved to where its silhouette best meets like-oriented edges, scored by the
    /// chamfer term alone. `None` when it cannot be posed or shows nothing.
    pub fn place(
        &mut self,
        model: &Model,
        camera: &Camera,
        edges: &EdgeMap<'_>,
        mut q: [f32; MAX_STATES],
        near_px: Option<f32>,
    ) -> Option<Candidate> {
        let n = self.n_states;
        let posed = match self.poses.as_mut() {
            Some(p) => p.update(model, &q[..n]).is_ok(),
            None => match Poses::compute(model, &q[..n]) {
                Ok(p) => {
                    self.poses = Some(p);
                    true
                }
                Err(_) => false,
            },
        };
        let poses = self.poses.as_ref().filter(|_| posed)?;
        self.view.update(model, poses, camera, 4.0);
        let samples = Samples::of(&self.view, camera, &self.config.likelihood);
        if samples.points.is_empty() {
            return None;
        }
        let palm = Vector3::new(q[4], q[5], q[6]);
        let anchor = camera.project(&palm)?;
        let depth = camera.to_camera(&palm).z;
        let cap = self.config.likelihood.chamfer_cap_px.max(1e-3);
        let mut step = (camera.width as f32 * self.config.slide_step).max(1.0);
        let (mut lo, mut hi) = (
            Vector2::new(step / 2.0, step / 2.0),
            Vector2::new(camera.width as f32, camera.height as f32),
        );
        if let Some(r) = near_px {
            // A local slide: half the step, around where `q` projects.
            step = (step / 2.0).max(1.0);
            lo = anchor - Vector2::new(r, r);
            hi = anchor + Vector2::new(r + step / 2.0, r + step / 2.0);
        }
        let mut best = (
            samples.chamfer(edges, Vector2::zeros(), cap).0,
            Vector2::zeros(),
        );
        if self.frees(TRANSLATION) {
            // The palm's origin visits a grid over the frame (or the window).
            let mut v = lo.y;
            while v < hi.y {
                let mut u = lo.x;
                while u < hi.x {
                    let offset = Vector2::new(u, v) - anchor;
                    let (c, _) = samples.chamfer(edges, offset, cap);
                    self.lookups += samples.points.len() as u32;
                    if c < best.0 {
                        best = (c, offset);
                    }
                    u += step;
                }
                v += step;
            }
        }
        if self.frees(TRANSLATION) && best.1 != Vector2::zeros() {
            // Back-project the palm's new pixel at the template's depth.
            let uv = anchor + best.1;
            let ray = Vector3::new(
                (uv.x - camera.cx) / camera.fx * depth,
                (uv.y - camera.cy) / camera.fy * depth,
                depth,
            );
            let p = camera.r.transpose() * (ray - camera.t);
            q[4..7].copy_from_slice(&[p.x, p.y, p.z]);
        }
        Some(Candidate {
            score: 1.0 - best.0 / cap,
            q,
        })
    }

    /// Counts a finished hypothesis or slide, moves the search on, and returns what it cost
    /// against the budget: `scored` full evaluations plus the slide's look-ups (at least 1).
    fn finish_item(&mut self, scored: u32) -> u16 {
        let cost = u16::try_from((scored + self.lookups / LOOKUPS_PER_EVALUATION).max(1))
            .unwrap_or(u16::MAX);
        self.largest_item_cost = self.largest_item_cost.max(cost);
        self.evaluations += 1;
        self.advance();
        cost
    }

    fn advance(&mut self) {
        self.stage = match self.stage {
            Stage::Coarse(i) => Stage::Coarse(i + 1),
            Stage::Tree { level, next } => Stage::Tree {
                level,
                next: next + 1,
            },
            Stage::Fingers(i) => Stage::Fingers(i + 1),
            Stage::Refine { round, next } => Stage::Refine {
                round,
                next: next + 1,
            },
            Stage::Done => Stage::Done,
        };
    }

    /// Ends a level: its best become the seeds of the next.
    fn finish_level(&mut self) {
        // Refinement and the finger level keep the seeds themselves in the running; the first
        // full-score level re-scores them (its first hypothesis of each seed is the seed).
        if !matches!(self.stage, Stage::Coarse(_) | Stage::Fingers(_)) {
            for c in self.best.clone() {
                keep(&mut self.next, c);
            }
        }
        self.best = core::mem::take(&mut self.next);
        self.stage = match self.stage {
            Stage::Coarse(_) if !self.best.is_empty() && self.config.tree_levels > 0 => {
                Stage::Tree { level: 0, next: 0 }
            }
            Stage::Coarse(_) if !self.best.is_empty() => Stage::Fingers(0),
            Stage::Tree { level, .. } if level + 1 < self.config.tree_levels => Stage::Tree {
                level: level + 1,
                next: 0,
            },
            Stage::Tree { .. } => Stage::Fingers(0),
            Stage::Fingers(_) => Stage::Refine { round: 0, next: 0 },
            Stage::Refine { round, .. } if round + 1 < self.config.refine_rounds => Stage::Refine {
                round: round + 1,
                next: 0,
            },
            _ => Stage::Done,
        };
    }

    /// The hypothesis at the current place of the search; `None` when the level is over.
    fn hypothesis(&self) -> Option<[f32; MAX_STATES]> {
        match self.stage {
            Stage::Coarse(_) | Stage::Tree { .. } => None,
            Stage::Fingers(i) => {
                let poses = FINGER_POSES.len() as u32;
                let seed = self.best.get((i / poses) as usize)?;
                let mut q = seed.q;
                self.set_fingers(&mut q, (i % poses) as usize);
                Some(q)
            }
            Stage::Refine { round, next } => self.refined(round, next),
            Stage::Done => None,
        }
    }

    /// Child `next` of the tree level `level` around the kept templates: the seed itself, its
    /// palm turned either way about each axis, moved nearer and farther along `camera`'s ray,
    /// or its fingers in another pose; steps halve each level.
    fn tree_child(&self, camera: &Camera, level: u8, next: u32) -> Option<[f32; MAX_STATES]> {
        const POSES: [usize; 3] = [0, 3, 4]; // open, half curl, fist
        const CHILDREN: u32 = 1 + 6 + 2 + POSES.len() as u32;
        let seed = self.best.get((next / CHILDREN) as usize)?;
        let m = next % CHILDREN;
        let scale = 1.0 / (1u32 << level) as f32;
        let mut q = seed.q;
        let sign = if m.is_multiple_of(2) { 1.0 } else { -1.0 };
        match m {
            0 => {}
            1..=6 if self.frees(QUATERNION) => {
                let mut axis = [0.0f32; 3];
                axis[((m - 1) / 2) as usize] = sign;
                let turned = compose(
                    &[q[0], q[1], q[2], q[3]],
                    &axis_angle(axis, self.config.tree_steps[0] * scale),
                );
                q[..4].copy_from_slice(&turned);
            }
            7 | 8 if self.frees(TRANSLATION) => {
                let eye = camera.centre();
                let p = Vector3::new(q[4], q[5], q[6]);
                let along = p - eye;
                let len = along.norm().max(1.0);
                let moved = p + along / len * (sign * self.config.tree_steps[1] * scale);
                q[4..7].copy_from_slice(&[moved.x, moved.y, moved.z]);
            }
            9.. => self.set_fingers(&mut q, POSES[(m - 9) as usize]),
            _ => return Some(seed.q),
        }
        Some(q)
    }

    /// Neighbour `next` of the refinement round `round` around the kept seeds.
    fn refined(&self, round: u8, next: u32) -> Option<[f32; MAX_STATES]> {
        const MOVES: u32 = 6 + 6 + 10;
        let seed = self.best.get((next / MOVES) as usize)?;
        let m = next % MOVES;
        let scale = 1.0 / (1u32 << round) as f32;
        let [dt, dr, db] = self.config.refine_steps.map(|s| s * scale);
        let sign = if m.is_multiple_of(2) { 1.0 } else { -1.0 };
        let mut q = seed.q;
        match m {
            0..=5 => {
                if !self.frees(TRANSLATION) {
                    return Some(seed.q);
                }
                q[4 + (m / 2) as usize] += sign * dt;
            }
            6..=11 => {
                if !self.frees(QUATERNION) {
                    return Some(seed.q);
                }
                let mut axis = [0.0f32; 3];
                axis[((m - 6) / 2) as usize] = sign;
                let turned = compose(&[q[0], q[1], q[2], q[3]], &axis_angle(axis, dr));
                q[..4].copy_from_slice(&turned);
            }
            _ => {
                let finger = ((m - 12) / 2) as usize;
                let start = finger_start(finger);
                // The flexions of one finger (fingers 1–4: MCP, PIP, DIP; thumb: its last three).
                let range = if finger < 4 {
                    start + 1..start + 4
                } else {
                    start + 2..start + 5
                };
                for s in range {
                    if s < self.n_states && self.free.contains(s) {
                        q[s] += sign * db;
                    }
                }
            }
        }
        Some(q)
    }

    fn frees(&self, range: core::ops::Range<usize>) -> bool {
        range.into_iter().all(|s| self.free.contains(s))
    }

    /// Sets the free finger states of `q` to library pose `pose`, within the model's limits
    /// (known after the first [`Acquirer::score`]; before it, as given).
    fn set_fingers(&self, q: &mut [f32; MAX_STATES], pose: usize) {
        let Some(fingers) = FINGER_POSES.get(pose) else {
            return;
        };
        for (f, values) in fingers.iter().enumerate() {
            for (k, v) in values.iter().enumerate() {
                let s = finger_start(f) + k;
                if s < self.n_states && self.free.contains(s) {
                    q[s] = *v;
                }
            }
        }
        if let Some(thumb) = THUMB_POSES.get(pose) {
            for (k, v) in thumb.iter().enumerate() {
                let s = finger_start(4) + k;
                if s < self.n_states && self.free.contains(s) {
                    q[s] = *v;
                }
            }
        }
    }
}

/// Keeps `c` among the best [`MAX_KEEP`] of `list` (sorted, best first).
fn keep(list: &mut Vec<Candidate, MAX_KEEP>, c: Candidate) {
    if !c.score.is_finite() {
        return;
    }
    let at = list
        .iter()
        .position(|o| c.score > o.score)
        .unwrap_or(list.len());
    if at >= MAX_KEEP {
        return;
    }
    if list.is_full() {
        list.pop();
    }
    // Room was made: cannot fail.
    let _ = list.insert(at, c);
}

/// Quaternion (w, x, y, z) of a turn of `angle` rad about unit `axis`.
fn axis_angle(axis: [f32; 3], angle: f32) -> [f32; 4] {
    let (s, c) = (libm::sinf(angle / 2.0), libm::cosf(angle / 2.0));
    [c, axis[0] * s, axis[1] * s, axis[2] * s]
}

/// `a ⊗ b`: turn by `b` in `a`'s frame.
fn compose(a: &[f32; 4], b: &[f32; 4]) -> [f32; 4] {
    let [aw, ax, ay, az] = *a;
    let [bw, bx, by, bz] = *b;
    [
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    ]
}

/// Coarse rotation: the palm's z axis turned onto normal `k` of `normals` spread over the
/// sphere (a Fibonacci lattice), then turned by spin `j` of `spins` about it.
fn coarse_rotation(k: u32, normals: u32, j: u32, spins: u32) -> [f32; 4] {
    const GOLDEN_ANGLE: f32 = 2.399_963;
    let z = 1.0 - 2.0 * (k as f32 + 0.5) / normals as f32;
    let r = libm::sqrtf((1.0 - z * z).max(0.0));
    let phi = k as f32 * GOLDEN_ANGLE;
    let n = [r * libm::cosf(phi), r * libm::sinf(phi), z];
    // Turn e_z onto n: about e_z × n by acos(n_z).
    let axis = [-n[1], n[0], 0.0];
    let len = libm::sqrtf(axis[0] * axis[0] + axis[1] * axis[1]);
    let align = if len < 1e-6 {
        if z > 0.0 {
            [1.0, 0.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0, 0.0]
        }
    } else {
        axis_angle(
            [axis[0] / len, axis[1] / len, 0.0],
            libm::acosf(z.clamp(-1.0, 1.0)),
        )
    };
    let spin = axis_angle(
        [0.0, 0.0, 1.0],
        j as f32 * core::f32::consts::TAU / spins as f32,
    );
    compose(&align, &spin)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keep_holds_the_best_in_order() {
        let mut list = Vec::new();
        for (i, s) in [
            0.3f32,
            0.9,
            0.1,
            0.5,
            0.7,
            0.2,
            0.8,
            0.6,
            0.4,
            0.95,
            f32::NAN,
        ]
        .into_iter()
        .enumerate()
        {
            keep(
                &mut list,
                Candidate {
                    score: s,
                    q: [i as f32; MAX_STATES],
                },
            );
        }
        let scores: Vec<f32, MAX_KEEP> = list.iter().map(|c| c.score).collect();
        assert_eq!(&scores[..], [0.95, 0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3]);
    }

    #[test]
    fn coarse_rotations_are_unit_and_spread() {
        let all: Vec<[f32; 4], 120> = (0..20)
            .flat_map(|k| (0..6).map(move |j| coarse_rotation(k, 20, j, 6)))
            .collect();
        for q in &all {
            let n = libm::sqrtf(q.iter().map(|v| v * v).sum::<f32>());
            assert!((n - 1.0).abs() < 1e-5);
        }
        // Every rotation of a fine random set lies within 50° of some coarse one.
        let mut worst = 0.0f32;
        for i in 0..500 {
            let t = i as f32 * 0.618_034;
            let axis = [
                libm::cosf(t * 7.0),
                libm::sinf(t * 7.0),
                libm::cosf(t * 3.0),
            ];
            let len = libm::sqrtf(axis.iter().map(|v| v * v).sum::<f32>());
            let r = axis_angle(axis.map(|v| v / len), (t * 13.0) % core::f32::consts::PI);
            let nearest = all
                .iter()
                .map(|c| crate::quaternion::angle_between(*c, r))
                .fold(f32::INFINITY, f32::min);
            worst = worst.max(nearest);
        }
        assert!(worst < 50.0 * core::f32::consts::PI / 180.0, "{worst} rad");
    }
}
