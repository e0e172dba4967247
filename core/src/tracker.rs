//! The per-frame tracking loop (Sec. 4.3.2) and its report.
//!
//! For each frame: optionally predict the start state by constant velocity, then `iterations`
//! times — pose the links, project them into every camera, find slice features again (across
//! every link and, with `palm_edges`, across the palm box's image outline), add the residual
//! rows of every camera to one set of normal equations (Sec. 2.5.5), take the conditioned
//! Gauss–Newton step.

use core::fmt;

use heapless::Vec;

use crate::camera::{Camera, CameraError};
use crate::config::{MAX_CAMERAS, MAX_LINKS, MAX_STATES};
use crate::estimator::{
    add_link_rows, add_palm_edge_rows, add_region_rows, apply_step, EstimatorConfig, FreeMask,
    LinkJacobian, NormalEquations, Robust,
};
use crate::features::{FeatureConfig, LinkFeatures};
use crate::fill::{FillConfig, FillPoints};
use crate::frame::{FrameError, FrameView};
use crate::hypotheses::fingers::Fingers;
use crate::kinematics::{KinematicsError, Poses};
use crate::likelihood::shading_cache::ShadingCache;
use crate::likelihood::shading_refine::{refine_finger, RefineOutcome, ShadingRefineConfig};
use crate::measurer::{LocalFrames, Measurer};
use crate::model::Model;
use crate::motion::{velocity_trust, MotionConfig, PriorWeights};
use crate::palm_outline::PalmOutline;
use crate::projection::ProjectedModel;
use crate::state::{clamp_to_limit, renormalise_quaternion, TRANSLATION};

/// What a search's refinement runs the tracker under for one frame, in place of its
/// configured settings ([`Tracker::track_under`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RefineOverrides {
    /// The robust weight of edge and tip residuals.
    pub robust: Robust,
    /// The edge-direction test (rad; π/2 or more: off).
    pub max_edge_angle_rad: f32,
    /// Whether each step holds the joints it would carry out of their ranges at their bounds.
    pub bounded_step: bool,
    /// The prior toward the predicted state: after [`Tracker::restart_fresh`], toward the
    /// start itself.
    pub prior: PriorWeights,
    /// Gauss–Newton iterations at most (0: the tracker's own [`TrackerConfig::iterations`]).
    pub iterations: u8,
}

/// The cameras, if there are 1 to [`MAX_CAMERAS`] and each is usable.
fn checked_cameras(cameras: &[Camera]) -> Result<Vec<Camera, MAX_CAMERAS>, TrackerError> {
    if cameras.is_empty() {
        return Err(TrackerError::CameraCount);
    }
    let cameras: Vec<Camera, MAX_CAMERAS> =
        Vec::from_slice(cameras).map_err(|_| TrackerError::CameraCount)?;
    for c in &cameras {
        c.validate().map_err(TrackerError::Camera)?;
    }
    Ok(cameras)
}

/// The state a tracker starts (or restarts) from: `state`, its quaternion renormalised (empty
/// if it does not fit [`MAX_STATES`]; its poses have been checked by then).
fn start_state(state: &[f32]) -> Vec<f32, MAX_STATES> {
    let mut q = Vec::from_slice(state).unwrap_or_default();
    renormalise_quaternion(&mut q);
    q
}

/// How far beyond a frame's edges (share of its width and height) the palm's origin may
/// project before a frame is `lost` for having left every camera's view.
pub const VIEW_SLACK: f32 = 0.25;

/// How fast the silhouette reference follows the frames not lost (share per frame).
pub const SILHOUETTE_REFERENCE_RATE: f32 = 0.05;

/// Tracker parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub struct TrackerConfig {
    /// Gauss–Newton iterations per frame at most; features are found again at every one.
    pub iterations: u8,
    /// Predict each frame's start state by constant velocity from the last two frames.
    pub predict: bool,
    /// Stop iterating once no joint or quaternion state moves more than this (rad).
    pub converged_rad: f32,
    /// ... and no translation state more than this (mm).
    pub converged_mm: f32,
    /// The frame is `lost` when fewer than this fraction of expected features were found.
    pub lost_min_found: f32,
    /// The frame is `lost` when the residual RMS exceeds this (px).
    pub lost_rms_px: f32,
    /// The frame is `lost` when the silhouette agreement falls this far below its reference
    /// (0..=1; the reference is the agreement of the first frame, then follows the frames
    /// not lost slowly, so a background's own level — plain or cluttered — sets the bar).
    /// 0 turns the check off (default 0.04).
    pub lost_silhouette_drop: f32,
    /// Samples along each side of the silhouette check's grid (0: no check; default 24).
    pub silhouette_grid: u8,
    /// Slice search parameters.
    pub features: FeatureConfig,
    /// Residual and solve parameters.
    pub estimator: EstimatorConfig,
    /// Prediction, prior toward it, and what a lost frame keeps.
    pub motion: MotionConfig,
    /// Region rows ([`crate::fill`]); on by default.
    pub fill: FillConfig,
    /// A finger moved where the hand's shading says it lies, after a frame
    /// ([`Tracker::refine_shading`]); off by default.
    pub shading_refine: ShadingRefineConfig,
}

impl Default for TrackerConfig {
    fn default() -> Self {
        TrackerConfig {
            iterations: 8,
            predict: true,
            converged_rad: 2e-4,
            converged_mm: 5e-3,
            lost_min_found: 0.3,
            lost_rms_px: 6.0,
            lost_silhouette_drop: 0.04,
            silhouette_grid: 24,
            features: FeatureConfig::default(),
            estimator: EstimatorConfig::default(),
            motion: MotionConfig::default(),
            fill: FillConfig::default(),
            shading_refine: ShadingRefineConfig::default(),
        }
    }
}

/// What the tracker did with one frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameReport {
    /// Root-mean-square image residual of the last iteration (px).
    pub rms_px: f32,
    /// Features found in the last iteration (edge points and tips).
    pub features_found: u16,
    /// Features the model predicted visible and in the frame in the last iteration.
    pub features_expected: u16,
    /// Predicted features masked as hidden by a nearer part of the hand (last iteration).
    pub features_masked: u16,
    /// Links skipped in the last iteration (end-on, off-frame or behind a camera).
    pub links_skipped: u16,
    /// Iterations run.
    pub iterations: u8,
    /// The silhouette's agreement with the image in the last iteration, the smallest over the
    /// cameras that could score it (0..=1; [`silhouette`](crate::silhouette)); 1 when none
    /// could or the check is off.
    pub silhouette_agreement: f32,
    /// Too few features, or the residual exploded: the state is not to be trusted.
    pub lost: bool,
}

/// Why the tracker could not be set up or could not use a frame.
///
/// Exhaustive on purpose: a board maps each to a wire `Refusal`, and a new kind of error must
/// be given one there.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum TrackerError {
    /// No cameras, or more than [`MAX_CAMERAS`].
    CameraCount,
    /// A camera is unusable.
    Camera(CameraError),
    /// The number of frames differs from the number of cameras.
    FrameCount,
    /// A frame is unusable (e.g. not the camera's size).
    Frame(FrameError),
    /// The state is unusable.
    State(KinematicsError),
    /// The free mask names a state the model does not have (the first such).
    BadFreeState(u8),
}

impl fmt::Display for TrackerError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::CameraCount => write!(f, "need 1 to {MAX_CAMERAS} cameras"),
            Self::Camera(e) => write!(f, "camera: {e}"),
            Self::FrameCount => write!(f, "one frame per camera is needed"),
            Self::Frame(e) => write!(f, "frame: {e}"),
            Self::State(e) => write!(f, "state: {e}"),
            Self::BadFreeState(s) => write!(f, "free state q{s} is not in the model"),
        }
    }
}

impl core::error::Error for TrackerError {}

/// Working memory of one iteration, kept between frames so nothing is allocated per frame.
#[derive(Debug, Clone)]
struct Workspace {
    poses: Poses,
    views: [ProjectedModel; MAX_CAMERAS],
    outline: PalmOutline,
    features: LinkFeatures,
    jacobian: LinkJacobian,
    normal: NormalEquations,
    /// Each camera's region samples, gathered on a frame's first iteration.
    fill: [FillPoints; MAX_CAMERAS],
    /// The fixed surfaces around the finger [`Tracker::refine_shading`] searches.
    shading: ShadingCache,
    /// How many cameras found features on each link (by frame) in this frame's last
    /// iteration; 0 before its first.
    seen_by: [u8; MAX_LINKS],
}

/// What a [`Tracker`] knows of one hand between frames: the state, the motion the next
/// prediction extrapolates, and the silhouette reference. Saved and restored to run one
/// tracker for several hypotheses ([`crate::hypotheses`]).
#[derive(Debug, Clone, PartialEq)]
pub struct TrackMemory {
    /// The state estimate (quaternion, mm, rad).
    pub state: Vec<f32, MAX_STATES>,
    /// The change of each state over the last frame as trusted; `None` after a reset.
    pub velocity: Option<[f32; MAX_STATES]>,
    /// The silhouette agreement a right track has in these images.
    pub silhouette_reference: Option<f32>,
}

/// Tracks one hand over frames from one or more calibrated cameras.
#[derive(Debug, Clone)]
pub struct Tracker {
    model: Model,
    cameras: Vec<Camera, MAX_CAMERAS>,
    state: Vec<f32, MAX_STATES>,
    /// The change of each state over the last frame, scaled by how far that frame's evidence
    /// is trusted; `None` before the first frame and after a reset.
    velocity: Option<[f32; MAX_STATES]>,
    /// The silhouette agreement a right track has in these images (see
    /// [`TrackerConfig::lost_silhouette_drop`]); `None` until the first frame.
    silhouette_reference: Option<f32>,
    free: FreeMask,
    config: TrackerConfig,
    /// The model's fingers, for [`Tracker::refine_shading`].
    fingers: Fingers,
    /// Calls of [`Tracker::refine_shading`] so far: whose turn it is.
    shading_calls: u32,
    work: Workspace,
}

/// A tracker's start, checked ([`Tracker::checked_start`]): its cameras, free states (the
/// whole quaternion freed with any of it), the poses of its start state and that state (its
/// quaternion renormalised).
pub(crate) struct TrackerStart {
    cameras: Vec<Camera, MAX_CAMERAS>,
    pub(crate) free: FreeMask,
    poses: Poses,
    pub(crate) state: Vec<f32, MAX_STATES>,
}

impl Tracker {
    /// A tracker starting from `initial` (one value per model state: quaternion, mm, rad),
    /// estimating the states in `free` ([`FreeMask::all`] for every state). Freeing any
    /// quaternion state frees all four.
    pub fn new(
        model: Model,
        cameras: &[Camera],
        initial: &[f32],
        free: FreeMask,
        config: TrackerConfig,
    ) -> Result<Self, TrackerError> {
        let start = Tracker::checked_start(&model, cameras, initial, free)?;
        Ok(Tracker::started(model, start, config))
    }

    /// What [`Tracker::new`] checks and computes of its arguments before the tracker is
    /// built: the whole fallible part, so that the value itself is built once, in its place
    /// (a board pays every copy of it in stack).
    pub(crate) fn checked_start(
        model: &Model,
        cameras: &[Camera],
        initial: &[f32],
        free: FreeMask,
    ) -> Result<TrackerStart, TrackerError> {
        let cameras = checked_cameras(cameras)?;
        if let Some(s) = free.first_beyond(model.n_states()) {
            return Err(TrackerError::BadFreeState(s));
        }
        let poses = Poses::compute(model, initial).map_err(TrackerError::State)?;
        Ok(TrackerStart {
            cameras,
            free: free.with_whole_quaternion(),
            poses,
            state: start_state(initial),
        })
    }

    /// The tracker of a checked start ([`Tracker::checked_start`]).
    #[inline]
    pub(crate) fn started(model: Model, start: TrackerStart, config: TrackerConfig) -> Tracker {
        Tracker {
            fingers: Fingers::of(&model),
            shading_calls: 0,
            model,
            cameras: start.cameras,
            state: start.state,
            velocity: None,
            silhouette_reference: None,
            free: start.free,
            config,
            work: Workspace {
                poses: start.poses,
                views: Default::default(),
                outline: PalmOutline::new(),
                features: LinkFeatures::default(),
                jacobian: LinkJacobian::default(),
                normal: NormalEquations::new(),
                fill: Default::default(),
                shading: ShadingCache::default(),
                seen_by: [0; MAX_LINKS],
            },
        }
    }

    /// New cameras and parameters for the frames to come, keeping what the tracker knows of
    /// the hand: the state, the free states, the motion (the velocity the next prediction
    /// extrapolates) and the silhouette reference. On an error nothing changes.
    pub fn reconfigure(
        &mut self,
        cameras: &[Camera],
        config: TrackerConfig,
    ) -> Result<(), TrackerError> {
        let cameras = checked_cameras(cameras)?;
        self.cameras = cameras;
        self.config = config;
        Ok(())
    }

    /// [`Tracker::track`] under `overrides` instead of the configured robust weight, edge
    /// test, step, prior and iterations, which are back in place afterwards, error or not: a
    /// search refines its leaves under its own
    /// ([`FinderConfig::leaf_overrides`](crate::acquire::FinderConfig::leaf_overrides)).
    pub fn track_under(
        &mut self,
        overrides: &RefineOverrides,
        frames: &[FrameView<'_>],
    ) -> Result<FrameReport, TrackerError> {
        let own = self.config;
        self.config.estimator.robust = overrides.robust;
        self.config.features.max_edge_angle_rad = overrides.max_edge_angle_rad;
        self.config.estimator.bounded_step = overrides.bounded_step;
        self.config.motion.prior = overrides.prior;
        if overrides.iterations > 0 {
            self.config.iterations = overrides.iterations;
        }
        let report = self.track(frames);
        self.config = own;
        report
    }

    /// [`Tracker::track`] with at most `iterations` Gauss–Newton iterations (0, or more than
    /// the configured [`TrackerConfig::iterations`]: the configured number), which are back in
    /// place afterwards, error or not.
    pub fn track_at_most(
        &mut self,
        iterations: u8,
        frames: &[FrameView<'_>],
    ) -> Result<FrameReport, TrackerError> {
        let own = self.config.iterations;
        if iterations == 0 || iterations >= own {
            return self.track(frames);
        }
        self.config.iterations = iterations;
        let report = self.track(frames);
        self.config.iterations = own;
        report
    }

    /// [`Tracker::track_at_most`] without region rows and without the silhouette check (the
    /// frame's agreement reported as 1, the reference untouched), which are back in place
    /// afterwards, error or not: a hypothesis only carried along between scored frames
    /// ([`HypothesesConfig::light_others`](crate::hypotheses::HypothesesConfig::light_others)),
    /// for about half the instructions of a frame.
    pub fn track_light(
        &mut self,
        iterations: u8,
        frames: &[FrameView<'_>],
    ) -> Result<FrameReport, TrackerError> {
        let own = self.config;
        self.config.fill.weight = 0.0;
        self.config.silhouette_grid = 0;
        let report = self.track_at_most(iterations, frames);
        self.config = own;
        report
    }

    /// The prior toward the predicted state the frames to come are tracked under, in place
    /// of the configured one (which [`Tracker::config`] then shows). Weights that are not
    /// finite and non-negative are refused: `false`, and nothing changes.
    pub fn set_prior(&mut self, prior: PriorWeights) -> bool {
        if !prior.is_valid() {
            return false;
        }
        self.config.motion.prior = prior;
        true
    }

    /// Restarts tracking from `state`, forgetting the motion so far.
    pub fn reset(&mut self, state: &[f32]) -> Result<(), TrackerError> {
        self.work
            .poses
            .update(&self.model, state)
            .map_err(TrackerError::State)?;
        self.state = start_state(state);
        // The silhouette reference is the images' level, not the motion's: it stays.
        self.velocity = None;
        Ok(())
    }

    /// Restarts from `state` as [`Tracker::reset`] does, and also forgets the silhouette
    /// reference, so the next frame sets it afresh: for a state found by a search, which may
    /// be refused, so that a refused guess leaves nothing behind.
    pub fn restart_fresh(&mut self, state: &[f32]) -> Result<(), TrackerError> {
        self.reset(state)?;
        self.silhouette_reference = None;
        Ok(())
    }

    /// What the tracker knows of the hand between frames.
    pub fn memory(&self) -> TrackMemory {
        TrackMemory {
            state: self.state.clone(),
            velocity: self.velocity,
            silhouette_reference: self.silhouette_reference,
        }
    }

    /// Puts back what [`Tracker::memory`] saved (of this tracker's model): the next frame
    /// goes on from there as if nothing had run in between. A state of the wrong length or
    /// one that cannot be posed is refused and nothing changes.
    pub fn restore(&mut self, memory: &TrackMemory) -> Result<(), TrackerError> {
        self.work
            .poses
            .update(&self.model, &memory.state)
            .map_err(TrackerError::State)?;
        self.state.clone_from(&memory.state);
        self.velocity = memory.velocity;
        self.silhouette_reference = memory.silhouette_reference;
        Ok(())
    }

    /// The normal equations of the last iteration of the last frame (`JᵀWJ` with the prior,
    /// without the conditioning): how well each direction of the state was observed.
    pub fn normal_equations(&self) -> &NormalEquations {
        &self.work.normal
    }

    /// The current state estimate (quaternion, mm, rad).
    pub fn state(&self) -> &[f32] {
        &self.state
    }

    /// The model tracked.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The cameras, in the order frames are given to [`Tracker::track`].
    pub fn cameras(&self) -> &[Camera] {
        &self.cameras
    }

    /// The states being estimated.
    pub fn free(&self) -> FreeMask {
        self.free
    }

    /// The parameters in use.
    pub fn config(&self) -> &TrackerConfig {
        &self.config
    }

    /// Tracks one instant: `frames[i]` is camera `i`'s frame. Updates the state and reports.
    /// A frame of the wrong size is an error and leaves the state unchanged.
    pub fn track(&mut self, frames: &[FrameView<'_>]) -> Result<FrameReport, TrackerError> {
        self.check_frames(frames)?;
        self.track_with(&mut LocalFrames::new(frames))
    }

    /// One frame per camera, each of its camera's size.
    fn check_frames(&self, frames: &[FrameView<'_>]) -> Result<(), TrackerError> {
        if frames.len() != self.cameras.len() {
            return Err(TrackerError::FrameCount);
        }
        for (f, c) in frames.iter().zip(self.cameras.iter()) {
            if f.width() != c.width as usize || f.height() != c.height as usize {
                return Err(TrackerError::Frame(FrameError::WrongSize {
                    expected_width: c.width,
                    expected_height: c.height,
                }));
            }
        }
        Ok(())
    }

    /// After a frame tracked and not lost: every [`ShadingRefineConfig::every_frames`] calls,
    /// [`ShadingRefineConfig::fingers_per_call`] fingers in turn are moved where the hand's
    /// shading in `frames` says it lies ([`crate::likelihood::shading_refine`]). The velocity
    /// is kept, so the next prediction goes on from the finger as moved. Off by default
    /// (`every_frames` 0: nothing happens, and nothing is counted). A frame of the wrong size
    /// is an error and moves nothing.
    pub fn refine_shading(
        &mut self,
        frames: &[FrameView<'_>],
    ) -> Result<RefineOutcome, TrackerError> {
        let config = self.config.shading_refine;
        let count = self.fingers.count() as u32;
        if config.every_frames == 0 || count == 0 {
            return Ok(RefineOutcome::default());
        }
        self.check_frames(frames)?;
        self.shading_calls = self.shading_calls.wrapping_add(1);
        let every = u32::from(config.every_frames);
        if !self.shading_calls.is_multiple_of(every) {
            return Ok(RefineOutcome::default());
        }
        let per_call = u32::from(config.fingers_per_call.max(1)).min(count);
        let first = (self.shading_calls / every).wrapping_mul(per_call);
        let mut q = self.state.clone();
        let mut outcome = RefineOutcome::default();
        for k in 0..per_call {
            let finger = (first.wrapping_add(k) % count) as usize;
            // The last iteration's first view is spent: the next frame projects afresh.
            let work = &mut self.work;
            let one = refine_finger(
                &self.model,
                &self.cameras,
                frames,
                &self.fingers,
                finger,
                &mut q,
                &mut work.poses,
                &mut work.views[0],
                &mut work.shading,
                &config,
            );
            outcome.moves = outcome.moves.saturating_add(one.moves);
            outcome.trials = outcome.trials.saturating_add(one.trials);
            outcome.uncached_cameras = outcome.uncached_cameras.max(one.uncached_cameras);
        }
        if outcome.moves > 0 {
            self.state = q;
        }
        Ok(outcome)
    }

    /// Tracks one instant with features from `measurer` (one camera per entry of
    /// [`Tracker::cameras`]): [`Tracker::track`] with the frames elsewhere, e.g. one board per
    /// camera. The same loop, so the same features give the same state.
    pub fn track_with<M: Measurer>(
        &mut self,
        measurer: &mut M,
    ) -> Result<FrameReport, TrackerError> {
        let start = self.state.clone();
        let predicted = self.predicted();
        let mut q = predicted.clone();
        let mut report = FrameReport::default();
        self.work.seen_by = [0; MAX_LINKS];
        for k in 0..self.config.iterations.max(1) {
            let Some(step) = self.iterate(&q, &predicted, measurer, k, &mut report) else {
                report.lost = true;
                break;
            };
            report.iterations += 1;
            let (angle, moved) = apply_step(&self.model, &mut q, &step, self.free);
            if angle < self.config.converged_rad && moved < self.config.converged_mm {
                break;
            }
        }
        report.silhouette_agreement = self.silhouette_agreement(measurer);
        let drop = self.config.lost_silhouette_drop;
        let mut silhouette_dropped = false;
        if drop > 0.0 && self.config.silhouette_grid > 0 {
            let reference = *self
                .silhouette_reference
                .get_or_insert(report.silhouette_agreement);
            silhouette_dropped = report.silhouette_agreement < reference - drop;
        }
        let found = f32::from(report.features_found);
        let expected = f32::from(report.features_expected).max(1.0);
        report.lost |= found < self.config.lost_min_found * expected
            || report.rms_px > self.config.lost_rms_px;
        let finite = q.iter().all(|v| v.is_finite());
        report.lost |= !finite;
        if finite && self.config.motion.hold_when_lost && !self.palm_in_view(&q) {
            report.lost = true;
        }
        let motion = &self.config.motion;
        // Lost on the silhouette check alone: the estimate may be kept, without velocity.
        let kept_unheld = motion.hold_when_lost
            && !motion.hold_on_silhouette_drop
            && silhouette_dropped
            && !report.lost;
        report.lost |= silhouette_dropped;
        if kept_unheld {
            self.velocity = None;
            self.state = q;
        } else if finite && !(report.lost && motion.hold_when_lost) {
            let trust = velocity_trust(
                found / expected,
                self.config.lost_min_found,
                motion.full_velocity_found,
            );
            let mut velocity = [0.0f32; MAX_STATES];
            for ((v, new), old) in velocity.iter_mut().zip(q.iter()).zip(start.iter()) {
                *v = *new - *old;
                if trust < 1.0 {
                    *v *= trust;
                }
            }
            if motion.prior.is_on() {
                self.observed_part(&mut velocity);
            }
            self.velocity = Some(velocity);
            self.state = q;
            // No check, no news of the images' level: the reference stays.
            if !report.lost && self.config.silhouette_grid > 0 {
                if let Some(reference) = self.silhouette_reference.as_mut() {
                    *reference +=
                        SILHOUETTE_REFERENCE_RATE * (report.silhouette_agreement - *reference);
                }
            }
        } else if motion.hold_when_lost {
            // Keep the last good state; a lost frame's motion is not evidence.
            self.velocity = None;
        }
        Ok(report)
    }

    /// Whether the palm's origin at `q` projects into some camera's frame, grown by
    /// [`VIEW_SLACK`] of its size on each side: a hand the cameras see cannot be out there.
    fn palm_in_view(&self, q: &[f32]) -> bool {
        let Some(&[x, y, z]) = q
            .get(TRANSLATION)
            .and_then(|t| <&[f32; 3]>::try_from(t).ok())
        else {
            return false;
        };
        let p = nalgebra::Vector3::new(x, y, z);
        self.cameras.iter().any(|c| {
            let (w, h) = (c.width as f32, c.height as f32);
            c.project(&p).is_some_and(|uv| {
                uv.x >= -VIEW_SLACK * w
                    && uv.x <= (1.0 + VIEW_SLACK) * w
                    && uv.y >= -VIEW_SLACK * h
                    && uv.y <= (1.0 + VIEW_SLACK) * h
            })
        })
    }

    /// Keeps only the part of `velocity` the images observed: `(H + P + S)⁻¹ H v`, with `H`
    /// the last iteration's `JᵀWJ` and `P` the prior. Along directions the images constrain
    /// (`H` ≫ `P + S`) the velocity stays; along those they do not (a finger seen end-on, the
    /// split of its bend among its joints) it vanishes, so estimation noise there is never
    /// extrapolated into the next prediction.
    fn observed_part(&self, velocity: &mut [f32; MAX_STATES]) {
        let v = nalgebra::SVector::<f32, MAX_STATES>::from_column_slice(velocity);
        let mut h_v = self.work.normal.times(self.free, &v);
        let prior = &self.config.motion.prior;
        for (i, hv) in h_v.iter_mut().enumerate() {
            if self.free.contains(i) {
                *hv -= prior.for_state(i) * v[i];
            }
        }
        let n = self.model.n_states();
        let conditioning = &self.config.estimator.conditioning;
        match self.work.normal.solve(n, self.free, conditioning, &h_v) {
            Some(x) => velocity.copy_from_slice(x.as_slice()),
            None => *velocity = [0.0; MAX_STATES],
        }
    }

    /// The smallest silhouette agreement over the cameras, with the views of the last
    /// iteration (1 when no camera can be scored or the check is off).
    fn silhouette_agreement<M: Measurer>(&self, measurer: &mut M) -> f32 {
        if self.config.silhouette_grid == 0 {
            return 1.0;
        }
        let mut least = 1.0f32;
        let grid = usize::from(self.config.silhouette_grid);
        for (index, (camera, view)) in self.cameras.iter().zip(&self.work.views).enumerate() {
            if let Some(agreement) = measurer.silhouette(index, camera, view, grid) {
                least = least.min(agreement);
            }
        }
        least
    }

    /// The start state of a frame: constant-velocity extrapolation of the free states.
    fn predicted(&self) -> Vec<f32, MAX_STATES> {
        let mut q = self.state.clone();
        if let (true, Some(velocity)) = (self.config.predict, &self.velocity) {
            for (i, v) in q.iter_mut().enumerate() {
                if self.free.contains(i) {
                    *v = clamp_to_limit(&self.model, i, *v + velocity[i]);
                }
            }
            renormalise_quaternion(&mut q);
        }
        q
    }

    /// One Gauss–Newton iteration at `q`: the step, or `None` when no step can be taken.
    fn iterate<M: Measurer>(
        &mut self,
        q: &[f32],
        predicted: &[f32],
        measurer: &mut M,
        iteration: u8,
        report: &mut FrameReport,
    ) -> Option<nalgebra::SVector<f32, MAX_STATES>> {
        let refine = iteration > 0;
        let work = &mut self.work;
        work.poses.update(&self.model, q).ok()?;
        measurer.begin_iteration(q, refine);
        work.normal.clear();
        report.features_found = 0;
        report.features_expected = 0;
        report.features_masked = 0;
        report.links_skipped = 0;
        let config = &self.config;
        let estimator = config.estimator.for_cameras(self.cameras.len());
        let mut single_view = estimator;
        single_view.width_weight = config.estimator.single_view_width_weight;
        let seen_before = work.seen_by;
        let mut seen_now = [0u8; MAX_LINKS];
        let fill_on = config.fill.is_on();
        for (camera_index, ((camera, view), fill)) in self
            .cameras
            .iter()
            .zip(work.views.iter_mut())
            .zip(work.fill.iter_mut())
            .enumerate()
        {
            view.update(
                &self.model,
                &work.poses,
                camera,
                config.features.min_link_px,
            );
            if fill_on && iteration < config.fill.gather_iterations.max(1) {
                measurer.fill(camera_index, camera, view, &config.fill, fill);
            }
            let skipped = view.skipped;
            report.links_skipped += skipped.behind + skipped.end_on + skipped.off_frame;
            for index in 0..view.links.len() {
                measurer.link_features(
                    camera_index,
                    camera,
                    view,
                    index,
                    &config.features,
                    refine,
                    &mut work.features,
                );
                let found =
                    work.features.edges.len() as u16 + u16::from(work.features.tip.is_some());
                report.features_found += found;
                report.features_expected += work.features.expected;
                report.features_masked += work.features.masked;
                let link = &view.links[index];
                let frame = usize::from(link.frame);
                if found > 0 {
                    if let Some(n) = seen_now.get_mut(frame) {
                        *n = n.saturating_add(1);
                    }
                }
                let mut samples = fill
                    .points
                    .iter()
                    .filter(|p| fill_on && p.frame == link.frame)
                    .map(|p| (fill.position(p), p.bright))
                    .peekable();
                let region = samples.peek().is_some();
                if found == 0 && !region {
                    continue;
                }
                work.jacobian
                    .compute(&self.model, &work.poses, camera, link);
                if found > 0 {
                    let alone = single_view.width_weight > 0.0
                        && self.cameras.len() > 1
                        && seen_before.get(frame) == Some(&1);
                    add_link_rows(
                        &mut work.normal,
                        link,
                        &work.features,
                        &work.jacobian,
                        if alone { &single_view } else { &estimator },
                        self.free,
                    );
                }
                if region {
                    add_region_rows(
                        &mut work.normal,
                        link,
                        samples,
                        &work.jacobian,
                        &config.estimator,
                        self.free,
                        config.fill.link_weight(link),
                    );
                }
            }
        }
        work.seen_by = seen_now;
        // The lost test weighs the fingers' fit alone: the palm's rows below count neither
        // towards the found share nor the residual. A palm the image does not show as the
        // model's bright box (a sleeve, a glove, a renderer's other palm) must not make every
        // frame lost, and on the sweep counting them bought nothing (lost recall 0.19 with
        // them, 0.18 without; docs/robustness.md).
        report.rms_px = work.normal.rms();
        if config.features.palm_edges {
            for (camera_index, (camera, view)) in
                self.cameras.iter().zip(work.views.iter()).enumerate()
            {
                work.outline
                    .update(view.palm.as_ref(), config.features.min_link_px);
                for edge in &work.outline.edges {
                    measurer.palm_edge_features(
                        camera_index,
                        camera,
                        view,
                        edge,
                        &config.features,
                        refine,
                        &mut work.features,
                    );
                    if work.features.edges.is_empty() {
                        continue;
                    }
                    work.jacobian
                        .compute(&self.model, &work.poses, camera, &edge.segment);
                    add_palm_edge_rows(
                        &mut work.normal,
                        edge,
                        &work.features,
                        &work.jacobian,
                        &config.estimator,
                        self.free,
                    );
                }
            }
        }
        if work.normal.rows() == 0 {
            return None;
        }
        let prior = &config.motion.prior;
        for (i, (now, centre)) in q.iter().zip(predicted).enumerate() {
            work.normal
                .add_prior(i, prior.for_state(i), *now - *centre, self.free);
        }
        let conditioning = &config.estimator.conditioning;
        if config.estimator.bounded_step {
            work.normal
                .bounded_step(&self.model, q, self.free, conditioning)
        } else {
            work.normal
                .step(self.model.n_states(), self.free, conditioning)
        }
    }
}
