//! Finding the hand without help (after Stenger et al.'s tree-based search): hypotheses are
//! scored by the image [likelihood](crate::likelihood), coarse to fine, keeping the best
//! [`MAX_KEEP`] at each level. Every hypothesis is first [placed](place) on the frame's
//! bright region, so the search is over what the hand looks like — its rotation and its
//! fingers — not where it is:
//!
//! 1. **Coarse**: palm rotations covering SO(3) (palm normals spread evenly over the sphere ×
//!    turns about the normal) × a few finger poses of the [library], each placed on the
//!    region (depth from the region's size, or from both views) and scored in every camera.
//! 2. **Tree**: children of the best: turned either way about each palm axis, moved nearer or
//!    farther (one camera), or given every other pose of the library; placed again, scored;
//!    the steps halve each level.
//! 3. **Refine**: around each of the best, the palm moved along each axis, turned about each
//!    axis, and each finger bent and stretched, with steps halving each round (not placed:
//!    these are the small moves placement would undo).
//!
//! The search is *anytime*: [`Acquirer::step`] spends at most
//! [`AcquireConfig::evaluations_per_frame`] evaluations (one hypothesis scored in one camera)
//! per call and picks up where it left off, so a board answers every frame while it searches.
//! Only free states are hypothesised; fixed states keep the base state's values. The search's
//! leaves go to Gauss–Newton and [acceptance](accept) — [`Finder`] does both, a few leaves a
//! frame.

use heapless::Vec;

use crate::camera::Camera;
use crate::config::{MAX_CAMERAS, MAX_STATES};
use crate::estimator::FreeMask;
use crate::likelihood::{
    BoundedScore, EdgeMap, Likelihood, LikelihoodConfig, Reads, Region, Samples, Scene,
};
use crate::model::Model;
use crate::nalgebra::{Vector2, Vector3};

pub mod accept;
mod finder;
pub mod library;
pub mod place;
mod rotation;
mod volume;

pub use accept::{AcceptConfig, LeafScore, Verdict};
pub use finder::{Finder, FinderConfig, FinderStep, DEPTH_VARIANTS, HELD_VARIANTS, LOCAL_TURN_RAD};
pub use library::{FingerPose, POSE_COUNT};
pub use place::{triangulate, Depth};
pub use volume::WorkingVolume;

use library::{finger_start, set_finger, set_fingers, FINGERS};
use place::Scratch;
use rotation::{axis_angle, coarse_rotation, compose};

/// Chamfer look-ups a slide ([`Acquirer::place`]) may make for the cost of one evaluation.
pub const LOOKUPS_PER_EVALUATION: u32 = 600;

/// What one hypothesis costs against the budget, camera by camera, in eighths of an
/// evaluation (one camera's chamfer and silhouette terms at the tree's sampling): the shares
/// of its instructions measured on x86-64 (docs/performance.md, "A bound on each
/// hypothesis' score"), rounded to the nearest eighth (the coarse level's full score, 5.5,
/// up).
pub mod charge {
    /// Eighths in one evaluation.
    pub const EIGHTHS: u32 = 8;
    /// A camera scored in full at the tree's sampling.
    pub const FULL: u32 = 8;
    /// A camera whose silhouette term the bound left out.
    pub const EDGES_ONLY: u32 = 5;
    /// A camera scored in full on the coarse level's cheaper sampling.
    pub const COARSE_FULL: u32 = 6;
    /// The same with the silhouette term left out.
    pub const COARSE_EDGES_ONLY: u32 = 4;
    /// A camera the bound left unscored: its share of placing and posing the hypothesis.
    pub const UNSCORED: u32 = 2;

    // A full evaluation is one; each part of one costs less, and a coarse score less than
    // the tree's.
    const _: () = assert!(FULL == EIGHTHS);
    const _: () = assert!(EDGES_ONLY < FULL && COARSE_FULL < FULL && UNSCORED < EDGES_ONLY);
    const _: () = assert!(COARSE_EDGES_ONLY < COARSE_FULL && UNSCORED < COARSE_EDGES_ONLY);
}

/// Variants of a state [`Acquirer::variant`] gives: itself, six turns, two depths.
pub const LOCAL_VARIANTS: u32 = 9;

/// The best hypotheses kept between levels.
pub const MAX_KEEP: usize = 8;

/// The palm's position (mm) and rotation (the quaternion) are states 4..7 and 0..4.
const QUATERNION: core::ops::Range<usize> = 0..4;
const TRANSLATION: core::ops::Range<usize> = 4..7;

/// The coarse level's finger poses, in the order [`AcquireConfig::coarse_poses`] takes them.
const COARSE_POSES: [FingerPose; POSE_COUNT] = [
    FingerPose::MidRange,
    FingerPose::Relaxed,
    FingerPose::Fist,
    FingerPose::Open,
    FingerPose::HalfCurl,
    FingerPose::Spread,
    FingerPose::Pointing,
    FingerPose::Pinch,
];

/// How hard and how wide to search.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AcquireConfig {
    /// Work per [`Acquirer::step`] at most, in evaluations per camera: one hypothesis scored
    /// in full in one camera counts 1; the coarse level's cheaper score
    /// ([`AcquireConfig::coarse_sampling`]) and the terms the score's bound leaves out count
    /// less ([`charge`]; a slide by [`Acquirer::place`] counts its chamfer look-ups over
    /// [`LOOKUPS_PER_EVALUATION`]). A
    /// step with two cameras may spend twice this, so a stereo search scores as many
    /// hypotheses per frame as a mono one, and a searching frame costs about the same
    /// multiple of a tracking frame (which also costs twice) in either rig.
    pub evaluations_per_frame: u16,
    /// Depths tried across the volume when the first camera's frame has no bright region.
    pub depths: u8,
    /// The slide's step ([`Acquirer::place`]) as a share of the frame's width.
    pub slide_step: f32,
    /// Coarse palm normals, spread over the sphere.
    pub normals: u8,
    /// Coarse turns about each normal.
    pub spins: u8,
    /// Finger poses of the coarse level (1..=[`POSE_COUNT`]).
    pub coarse_poses: u8,
    /// Levels of the tree after the coarse level.
    pub tree_levels: u8,
    /// The first this many tree levels also try every pose of the library on each kept
    /// hypothesis; the later ones only turn (and, in one camera, move) it.
    pub tree_pose_levels: u8,
    /// First steps of the tree: palm rotation (rad), depth (share of the depth, one camera).
    pub tree_steps: [f32; 2],
    /// The coarse level's cheaper score: points per silhouette line and silhouette grid
    /// (the other levels use [`AcquireConfig::likelihood`]'s).
    pub coarse_sampling: [u8; 2],
    /// Rounds of local refinement.
    pub refine_rounds: u8,
    /// The best hypotheses refinement moves around (1..=[`MAX_KEEP`]).
    pub refine_seeds: u8,
    /// First refinement steps: palm translation (mm), palm rotation (rad), finger bend (rad).
    pub refine_steps: [f32; 3],
    /// The score. Its reverse chamfer term is off by default (and never weighed on the
    /// coarse levels): the acceptance's bars ([`AcceptConfig`]) are set without it
    /// (docs/recovery.md, "The reverse chamfer term").
    pub likelihood: LikelihoodConfig,
}

impl Default for AcquireConfig {
    fn default() -> Self {
        AcquireConfig {
            evaluations_per_frame: 100,
            depths: 3,
            slide_step: 1.0 / 20.0,
            normals: 20,
            spins: 6,
            coarse_poses: 3,
            tree_levels: 3,
            tree_pose_levels: 1,
            tree_steps: [0.35, 0.15],
            coarse_sampling: [3, 10],
            refine_rounds: 0,
            refine_seeds: 4,
            refine_steps: [16.0, 0.2, 0.3],
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
    /// Still searching; this many evaluations were spent in this step.
    Searching {
        /// Evaluations spent in this step.
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
    Refine { round: u8, next: u32 },
    Done,
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
    scratch: Scratch,
    /// Hypotheses scored since the last restart.
    pub evaluations: u32,
    /// Chamfer look-ups of the slide under way (what it costs against the budget).
    lookups: u32,
    /// Eighths of an evaluation spent and not yet charged ([`charge`]).
    uncharged_eighths: u32,
    /// The most one hypothesis or slide has cost (evaluations): how far a step can overrun
    /// its budget, since the last item is finished once begun.
    pub largest_item_cost: u16,
    /// What the last [`Acquirer::step`] spent against its budget (also when it ended the
    /// search).
    pub last_step_cost: u16,
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
            scratch: Scratch::new(),
            evaluations: 0,
            lookups: 0,
            uncharged_eighths: 0,
            largest_item_cost: 0,
            last_step_cost: 0,
        }
    }

    /// The best hypotheses of the last finished level (best first): when the search is over,
    /// its leaves, to refine.
    pub fn best(&self) -> &[Candidate] {
        &self.best
    }

    /// Starts the search over (the hand was lost, or every leaf was refused).
    pub fn restart(&mut self) {
        self.stage = Stage::Coarse(0);
        self.best.clear();
        self.next.clear();
        self.evaluations = 0;
        self.uncharged_eighths = 0;
    }

    /// The parameters.
    pub fn config(&self) -> &AcquireConfig {
        &self.config
    }

    /// What one [`Acquirer::step`] with `cameras` cameras may spend, in evaluations (at
    /// least 1): [`AcquireConfig::evaluations_per_frame`] per camera.
    pub fn budget(&self, cameras: usize) -> u16 {
        let cameras = cameras.clamp(1, MAX_CAMERAS) as u16;
        self.config
            .evaluations_per_frame
            .max(1)
            .saturating_mul(cameras)
    }

    /// The working volume.
    pub fn volume(&self) -> &WorkingVolume {
        &self.volume
    }

    /// Whether the search has ended (its leaves are [`Acquirer::best`]).
    pub fn is_done(&self) -> bool {
        self.stage == Stage::Done
    }

    fn rotations(&self) -> u32 {
        if self.frees(QUATERNION) {
            u32::from(self.config.normals.max(1)) * u32::from(self.config.spins.max(1))
        } else {
            1
        }
    }

    fn coarse_poses(&self) -> u32 {
        u32::from(self.config.coarse_poses).clamp(1, POSE_COUNT as u32)
    }

    /// Hypotheses in the coarse level.
    pub fn coarse_count(&self) -> u32 {
        self.rotations() * self.coarse_poses()
    }

    /// Spends up to [`AcquireConfig::evaluations_per_frame`] on `frames` (one per camera,
    /// with their edge maps) and moves the search on.
    pub fn step(&mut self, scene: &Scene<'_>) -> Progress {
        self.step_after(scene, 0)
    }

    /// [`Acquirer::step`] on a frame that has already spent `spent` evaluations of its budget
    /// elsewhere (at least one is still spent here, so the search always moves on).
    #[inline(never)] // a stage of the search: kept whole so profiles can attribute its cost
    pub fn step_after(&mut self, scene: &Scene<'_>, spent: u16) -> Progress {
        let (model, cameras) = (scene.model, scene.cameras);
        let mut regions: [Option<Region>; MAX_CAMERAS] = [None; MAX_CAMERAS];
        for (r, e) in regions.iter_mut().zip(scene.edges) {
            *r = e.region;
        }
        let n_cameras = scene.cameras_scored();
        let budget = self.budget(n_cameras).saturating_sub(spent).max(1);
        let regions = &regions[..n_cameras];
        let mut evaluated = 0u16;
        while evaluated < budget && self.stage != Stage::Done {
            let Some((mut q, depth)) = self.hypothesis(cameras) else {
                self.finish_level();
                continue;
            };
            if let Some(depth) = depth {
                if self.frees(TRANSLATION)
                    && !place::place(
                        &mut self.scratch,
                        model,
                        cameras,
                        regions,
                        &self.volume,
                        &mut q,
                        self.n_states,
                        depth,
                    )
                {
                    // No region: the hypothesis stays where the volume puts it.
                    self.fallback_position(cameras, &mut q);
                }
            }
            let likelihood = match self.stage {
                // The coarse levels only order the tree's nodes: no reverse term, whose cost
                // would multiply with their many hypotheses.
                Stage::Coarse(_) => LikelihoodConfig {
                    samples_per_line: self.config.coarse_sampling[0],
                    silhouette_grid: self.config.coarse_sampling[1],
                    reverse_weight: 0.0,
                    ..self.config.likelihood
                },
                _ => self.config.likelihood,
            };
            // A hypothesis that cannot beat the last of a full list is not kept: the terms
            // that could not lift it over are not computed.
            let bar = match self.next.last() {
                Some(last) if self.next.is_full() => last.score,
                _ => f32::NEG_INFINITY,
            };
            let bounded = self
                .scratch
                .score_above(scene, &q[..self.n_states], &likelihood, bar);
            if let Some(score) = bounded.score {
                keep(&mut self.next, Candidate { score, q });
            }
            let eighths = spent_eighths(
                &bounded,
                n_cameras.max(1) as u32,
                matches!(self.stage, Stage::Coarse(_)),
            );
            // Whole evaluations are charged, the rest carried to the next hypothesis.
            let all = self.uncharged_eighths + eighths;
            self.uncharged_eighths = all % charge::EIGHTHS;
            evaluated = evaluated.saturating_add(self.finish_item(all / charge::EIGHTHS));
        }
        self.last_step_cost = evaluated;
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

    /// Variant `k` of `q` for the local re-acquisition: 0 is `q` itself; 1..=6 its palm
    /// turned by `turn_rad` either way about each of its axes; 7 and 8 its palm moved
    /// `depth_share` nearer and farther along the first camera's ray. Variants that do not
    /// apply (the states fixed) give `q`. `k` is taken modulo [`LOCAL_VARIANTS`].
    pub fn variant(
        &self,
        cameras: &[Camera],
        q: &[f32; MAX_STATES],
        k: u32,
        turn_rad: f32,
        depth_share: f32,
    ) -> [f32; MAX_STATES] {
        let m = k % LOCAL_VARIANTS;
        let mut out = *q;
        let sign = if m.is_multiple_of(2) { -1.0 } else { 1.0 };
        match m {
            1..=6 if self.frees(QUATERNION) => {
                let mut axis = [0.0f32; 3];
                axis[((m - 1) / 2) as usize] = sign;
                let turned = compose(&[q[0], q[1], q[2], q[3]], &axis_angle(axis, turn_rad));
                out[..4].copy_from_slice(&turned);
            }
            7 | 8 if self.frees(TRANSLATION) => {
                if let Some(camera) = cameras.first() {
                    let eye = camera.centre();
                    let p = Vector3::new(q[4], q[5], q[6]);
                    let moved = eye + (p - eye) * (1.0 + sign * depth_share);
                    out[4..7].copy_from_slice(&[moved.x, moved.y, moved.z]);
                }
            }
            _ => {}
        }
        out
    }

    /// `q` with its free finger states set to library pose `pose` (taken modulo
    /// [`POSE_COUNT`]); its palm and fixed states kept.
    pub fn with_pose(&self, q: &[f32; MAX_STATES], pose: usize) -> [f32; MAX_STATES] {
        let mut out = *q;
        set_fingers(&mut out, pose % POSE_COUNT, self.n_states, self.free);
        out
    }

    /// The library pose under `q`'s palm that scores best on this frame (mean over the
    /// cameras), with its score: [`POSE_COUNT`] evaluations in every camera.
    pub fn best_pose(
        &mut self,
        scene: &Scene<'_>,
        q: &[f32; MAX_STATES],
    ) -> ([f32; MAX_STATES], f32) {
        let mut best = (*q, f32::NEG_INFINITY);
        for pose in 0..POSE_COUNT {
            let posed = self.with_pose(q, pose);
            let score = self.score(scene, &posed);
            if score > best.1 {
                best = (posed, score);
            }
        }
        best
    }

    /// `q` with each finger in turn (fingers 1–4, then the thumb) given the pose of the
    /// library's that scores best on this frame with the other fingers as they are, when one
    /// scores more than the finger as it is; its palm kept. Returns the new state, its mean
    /// score over the cameras and `q`'s: `POSE_COUNT` × 5 + 1 evaluations in every camera.
    /// A track that holds the palm and has a finger or two wrong is a local minimum of
    /// Gauss–Newton, not of the likelihood.
    pub fn polish_fingers(
        &mut self,
        scene: &Scene<'_>,
        q: &[f32; MAX_STATES],
    ) -> ([f32; MAX_STATES], f32, f32) {
        let start = self.score(scene, q);
        let mut best = (*q, start);
        for finger in 0..FINGERS {
            let mut kept = best;
            for pose in 0..POSE_COUNT {
                let mut posed = best.0;
                set_finger(&mut posed, pose, finger, self.n_states, self.free);
                if posed == best.0 {
                    continue;
                }
                let score = self.score(scene, &posed);
                if score > kept.1 {
                    kept = (posed, score);
                }
            }
            best = kept;
        }
        (best.0, best.1, start)
    }

    /// Moves the palm of `q` onto this frame's bright regions (`edges`' regions), its depth
    /// kept in one camera and triangulated in two ([`place`]): a leaf found on an earlier
    /// frame put where the hand is now. False (and `q` unchanged) when it cannot be placed
    /// or the palm's position is not free.
    pub fn replace(
        &mut self,
        model: &Model,
        cameras: &[Camera],
        edges: &[EdgeMap<'_>],
        q: &mut [f32; MAX_STATES],
    ) -> bool {
        if !self.frees(TRANSLATION) {
            return false;
        }
        let mut regions: [Option<Region>; MAX_CAMERAS] = [None; MAX_CAMERAS];
        for (r, e) in regions.iter_mut().zip(edges) {
            *r = e.region;
        }
        let n_cameras = cameras.len().min(edges.len()).min(MAX_CAMERAS);
        let mut moved = *q;
        let placed = place::place(
            &mut self.scratch,
            model,
            &cameras[..n_cameras],
            &regions[..n_cameras],
            &self.volume,
            &mut moved,
            self.n_states,
            Depth::Keep,
        );
        if placed {
            *q = moved;
        }
        placed
    }

    /// The mean likelihood score of `q` over the cameras (0 when it cannot be posed).
    pub fn score(&mut self, scene: &Scene<'_>, q: &[f32; MAX_STATES]) -> f32 {
        self.score_cameras(scene, q).0
    }

    /// The mean and the worst likelihood score of `q` over the cameras (0 when it cannot be
    /// posed).
    pub fn score_cameras(&mut self, scene: &Scene<'_>, q: &[f32; MAX_STATES]) -> (f32, f32) {
        let config = self.config.likelihood;
        self.score_cameras_under(scene, q, &config)
    }

    /// What `accept` reads of a refined leaf `q`: its mean and worst camera's score, and its
    /// worst camera's reverse chamfer term when `accept` has a bar on it for this rig.
    pub fn leaf_score(
        &mut self,
        scene: &Scene<'_>,
        q: &[f32; MAX_STATES],
        accept: &AcceptConfig,
    ) -> LeafScore {
        let config = self.config.likelihood;
        let (score, worst_camera, reverse_px) = if accept.weighs_reverse(scene.cameras.len()) {
            self.scratch
                .score_cameras_and_reverse(scene, &q[..self.n_states], &config)
        } else {
            let (score, worst) = self.score_cameras_under(scene, q, &config);
            (score, worst, None)
        };
        LeafScore {
            score,
            worst_camera,
            reverse_px,
        }
    }

    /// The largest reverse chamfer term of `q` over the cameras (px), under the search's
    /// likelihood whatever its `reverse_weight` ([`crate::likelihood::StateScorer::worst_reverse_px`]).
    pub fn worst_reverse_px(&mut self, scene: &Scene<'_>, q: &[f32; MAX_STATES]) -> Option<f32> {
        let config = self.config.likelihood;
        self.scratch
            .worst_reverse_px(scene, &q[..self.n_states], &config)
    }

    /// Adds where scoring `q` reads each camera's edge map to `reads`
    /// ([`crate::likelihood::StateScorer::add_reads`]).
    pub fn add_reads(
        &mut self,
        model: &Model,
        cameras: &[Camera],
        q: &[f32; MAX_STATES],
        reads: &mut [Reads],
    ) {
        self.scratch
            .add_reads(model, cameras, &q[..self.n_states], reads);
    }

    /// [`Self::score_cameras`] under another likelihood `config` (whose edge maps `scene`
    /// holds).
    pub fn score_cameras_under(
        &mut self,
        scene: &Scene<'_>,
        q: &[f32; MAX_STATES],
        config: &LikelihoodConfig,
    ) -> (f32, f32) {
        self.scratch
            .score_cameras(scene, &q[..self.n_states], config)
    }

    /// The likelihood of `q` in each camera into `out`; returns how many were scored (0 when
    /// `q` cannot be posed).
    pub fn likelihoods(
        &mut self,
        scene: &Scene<'_>,
        q: &[f32; MAX_STATES],
        out: &mut [Likelihood; MAX_CAMERAS],
    ) -> usize {
        let config = self.config.likelihood;
        self.scratch
            .likelihoods(scene, &q[..self.n_states], &config, out)
    }

    /// Without a region: the palm on the ray through the volume's centre, at depth `k` of
    /// [`AcquireConfig::depths`] across the volume (from the coarse index).
    fn fallback_position(&self, cameras: &[Camera], q: &mut [f32; MAX_STATES]) {
        let Some(camera) = cameras.first() else {
            return;
        };
        let depths = u32::from(self.config.depths.max(1));
        let d = match self.stage {
            Stage::Coarse(i) => i % depths,
            _ => depths / 2,
        };
        let centre = Vector3::from(self.volume.centre_mm);
        let eye = camera.centre();
        let z_centre = camera.to_camera(&centre).z;
        if z_centre > 1.0 {
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
        if !(self.scratch.pose(model, &q[..n]) && self.scratch.project(model, camera)) {
            return None;
        }
        let samples = Samples::of(&self.scratch.view, camera, &self.config.likelihood);
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
    /// against the budget: `scored` evaluations charged plus a slide's look-ups.
    fn finish_item(&mut self, scored: u32) -> u16 {
        // `scored` is 0 only for a coarse item whose charge is carried to the next.
        let cost =
            u16::try_from(scored + self.lookups / LOOKUPS_PER_EVALUATION).unwrap_or(u16::MAX);
        self.lookups = 0;
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
            Stage::Refine { round, next } => Stage::Refine {
                round,
                next: next + 1,
            },
            Stage::Done => Stage::Done,
        };
    }

    /// Ends a level: its best become the seeds of the next.
    fn finish_level(&mut self) {
        // Refinement keeps its seeds in the running (the tree re-scores them as its first
        // child of each seed, on the frame of the day).
        if matches!(self.stage, Stage::Refine { .. }) {
            for c in self.best.clone() {
                keep(&mut self.next, c);
            }
        }
        self.best = core::mem::take(&mut self.next);
        self.stage = match self.stage {
            _ if self.best.is_empty() => Stage::Done,
            Stage::Coarse(_) if self.config.tree_levels > 0 => Stage::Tree { level: 0, next: 0 },
            Stage::Tree { level, .. } if level + 1 < self.config.tree_levels => Stage::Tree {
                level: level + 1,
                next: 0,
            },
            Stage::Coarse(_) | Stage::Tree { .. } if self.config.refine_rounds > 0 => {
                Stage::Refine { round: 0, next: 0 }
            }
            Stage::Refine { round, .. } if round + 1 < self.config.refine_rounds => Stage::Refine {
                round: round + 1,
                next: 0,
            },
            _ => Stage::Done,
        };
    }

    /// The hypothesis at the current place of the search and how to place it (`None`: as it
    /// is); `None` when the level is over.
    fn hypothesis(&mut self, cameras: &[Camera]) -> Option<([f32; MAX_STATES], Option<Depth>)> {
        loop {
            match self.stage {
                Stage::Coarse(i) => {
                    if i >= self.coarse_count() {
                        return None;
                    }
                    let poses = self.coarse_poses();
                    let (r, p) = (i / poses, i % poses);
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
                    let pose = COARSE_POSES
                        .get(p as usize)
                        .copied()
                        .unwrap_or(FingerPose::Relaxed);
                    set_fingers(&mut q, pose as usize, self.n_states, self.free);
                    return Some((q, Some(Depth::FromRegion)));
                }
                Stage::Tree { level, next } => match self.tree_child(cameras, level, next)? {
                    Some(q) => return Some((q, Some(Depth::Keep))),
                    None => self.advance(),
                },
                Stage::Refine { round, next } => {
                    return self.refined(round, next).map(|q| (q, None))
                }
                Stage::Done => return None,
            }
        }
    }

    /// Child `next` of tree level `level` around the kept hypotheses: the seed itself, its
    /// palm turned either way about each axis, moved nearer and farther along the first
    /// camera's ray (one camera only: two triangulate the depth), or its fingers in another
    /// pose of the library; steps halve each level. `None`: the level is over; `Some(None)`:
    /// this child does not apply.
    fn tree_child(
        &self,
        cameras: &[Camera],
        level: u8,
        next: u32,
    ) -> Option<Option<[f32; MAX_STATES]>> {
        const CHILDREN: u32 = 1 + 6 + 2 + POSE_COUNT as u32;
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
            7 | 8 if self.frees(TRANSLATION) && cameras.len() == 1 => {
                let Some(camera) = cameras.first() else {
                    return Some(None);
                };
                let eye = camera.centre();
                let p = Vector3::new(q[4], q[5], q[6]);
                let moved = eye + (p - eye) * (1.0 + sign * self.config.tree_steps[1] * scale);
                q[4..7].copy_from_slice(&[moved.x, moved.y, moved.z]);
            }
            9.. if level < self.config.tree_pose_levels => {
                set_fingers(&mut q, (m - 9) as usize, self.n_states, self.free)
            }
            _ => return Some(None),
        }
        Some(Some(q))
    }

    /// Neighbour `next` of the refinement round `round` around the kept seeds.
    fn refined(&self, round: u8, next: u32) -> Option<[f32; MAX_STATES]> {
        const MOVES: u32 = 6 + 6 + 10;
        let seeds = usize::from(self.config.refine_seeds).clamp(1, MAX_KEEP);
        let seed = self
            .best
            .get(..seeds.min(self.best.len()))?
            .get((next / MOVES) as usize)?;
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
}

/// What scoring one hypothesis in `cameras` cameras cost, in eighths of an evaluation
/// ([`charge`]): each camera by the terms its score computed.
fn spent_eighths(bounded: &BoundedScore, cameras: u32, coarse: bool) -> u32 {
    let (full, edges_only) = if coarse {
        (charge::COARSE_FULL, charge::COARSE_EDGES_ONLY)
    } else {
        (charge::FULL, charge::EDGES_ONLY)
    };
    let edges = u32::from(bounded.edge_terms).min(cameras);
    let silhouettes = u32::from(bounded.silhouette_terms).min(edges);
    silhouettes * full + (edges - silhouettes) * edges_only + (cameras - edges) * charge::UNSCORED
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_hypothesis_is_charged_for_the_terms_its_score_computed() {
        let spent = |edge_terms, silhouette_terms, cameras, coarse| {
            let bounded = BoundedScore {
                score: None,
                edge_terms,
                silhouette_terms,
            };
            spent_eighths(&bounded, cameras, coarse)
        };
        // Scored in full: one evaluation a camera on the tree, less on the coarse level.
        assert_eq!(spent(1, 1, 1, false), charge::EIGHTHS);
        assert_eq!(spent(2, 2, 2, false), 2 * charge::EIGHTHS);
        assert_eq!(spent(1, 1, 1, true), charge::COARSE_FULL);
        // The silhouette left out by the bound, then a whole second camera.
        assert_eq!(spent(1, 0, 1, false), charge::EDGES_ONLY);
        assert_eq!(spent(2, 1, 2, false), charge::FULL + charge::EDGES_ONLY);
        assert_eq!(spent(1, 1, 2, true), charge::COARSE_FULL + charge::UNSCORED);
        assert_eq!(
            spent(1, 0, 2, true),
            charge::COARSE_EDGES_ONLY + charge::UNSCORED
        );
        // Not posed: only the placing is charged. Counts past the cameras are clamped.
        assert_eq!(spent(0, 0, 2, false), 2 * charge::UNSCORED);
        assert_eq!(spent(3, 5, 2, false), 2 * charge::FULL);
    }

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
}
