//! One finger's joints moved where the hand's shading says it lies: a pattern search on the
//! residual of the shading fit ([`super::shading`]), judged only around the finger.
//!
//! The shading is fitted once at the given state (one light, hand grey and background per
//! camera); each trial moves one of the finger's joint states by ± a step (clamped to its
//! range) and is scored by the residual of that same fit over the finger's image region (its
//! links' bounds at the start, widened), summed over the cameras. A trial that leaves less
//! than `1 − margin` of the best so far is kept at once; the steps shrink from the first to
//! the last of [`ShadingRefineConfig::steps_rad`]. The slice search's edges cannot pull back a
//! finger a few pixels off (they are found around the wrong state too); its shading can.
//!
//! Measured on the plain tracker (`host/examples/finger_research.rs`, `docs/robustness.md`,
//! "How often a finger must be put right"): one finger in turn after each frame.

use heapless::Vec;
use nalgebra::Vector2;

use super::shading::{fit_terms, residual_in, PixelCost, RegionResidual, RegionScoring};
use super::shading_cache::{moving_frames, CachedRegion, ShadingCache};
use crate::camera::Camera;
use crate::config::{MAX_CAMERAS, MAX_STATES};
use crate::frame::FrameView;
use crate::hypotheses::fingers::Fingers;
use crate::kinematics::Poses;
use crate::model::Model;
use crate::projection::{Bounds, ProjectedModel};

/// Most joint states of one finger the search moves.
pub const MAX_FINGER_JOINTS: usize = 8;

/// The search's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ShadingRefineConfig {
    /// Refine one finger (in turn) after every this many frames tracked (0: never, the
    /// default; the tracker as before, bit for bit).
    pub every_frames: u8,
    /// Fingers refined at each such frame, each in turn (at least 1; 1 by default: two or
    /// all five a frame measured worse on fresh seeds, `docs/robustness.md`).
    pub fingers_per_call: u8,
    /// The shading fit's lattice side (2..=[`super::shading::MAX_SHADING_GRID`]).
    pub grid: u8,
    /// The residual's pixel step over the finger's region (px, at least 1).
    pub region_step_px: f32,
    /// How far the finger's region reaches beyond its links' bounds (px).
    pub region_pad_px: f32,
    /// The steps tried on each joint, in order (rad; 0 skips one). 0.08 then 0.04 by default:
    /// a third step of 0.02 gained nothing on fresh seeds for a half more tries
    /// (`docs/robustness.md`, "Cheaper, and a margin").
    pub steps_rad: [f32; 3],
    /// Also try the finger's flexions (all its joint states but the first) moved together, a
    /// curl, before its joints one by one (false by default).
    pub curl: bool,
    /// Try each flexion alone (true by default; false leaves the first joint state alone and
    /// the flexions together, keeping how the bend is split among them).
    pub single_flexions: bool,
    /// A trial is kept when it leaves less than `1 − margin` of the best residual so far
    /// (0.005 by default: on fresh seeds a finger then moves only where its shading clearly
    /// says so, and fewer tracks are lost to a move than with none; `docs/robustness.md`).
    pub margin: f32,
    /// Each pixel's squared residual is capped at this many grey levels squared (0: no cap),
    /// so a highlight, a shadow or a part of another grey than the fit's counts no more than
    /// a pixel wholly wrong ([`PixelCost`]). 20 by default: on hands drawn with those
    /// (`render --surface varied`) the refinement without a cap lost life, with it less or
    /// none, and on the matte hands it kept its gain (`docs/robustness.md`, "A surface the
    /// shading fit does not model").
    pub residual_cap_grey: f32,
    /// Predict a surface facing away from the fitted light at the hand grey alone, as a
    /// Lambertian surface is lit ([`RegionScoring::clamp_light`]; false by default).
    pub clamp_light: bool,
}

impl Default for ShadingRefineConfig {
    fn default() -> Self {
        ShadingRefineConfig {
            every_frames: 0,
            fingers_per_call: 1,
            grid: 64,
            region_step_px: 2.0,
            region_pad_px: 20.0,
            steps_rad: [0.08, 0.04, 0.0],
            curl: false,
            single_flexions: true,
            margin: 0.005,
            residual_cap_grey: 20.0,
            clamp_light: false,
        }
    }
}

/// What one refinement did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RefineOutcome {
    /// Trials kept.
    pub moves: u8,
    /// Trials scored.
    pub trials: u8,
    /// Cameras whose region did not fit the cache ([`super::shading_cache::MAX_CACHED_PIXELS`]):
    /// scored the slow way, every ray against the whole hand (the same sums).
    pub uncached_cameras: u8,
}

/// One camera's shading fitted at the start, the finger's region, and that region's fixed
/// surfaces when they fit the cache.
#[derive(Clone, Copy)]
struct StartFit {
    scoring: RegionScoring,
    cached: Option<CachedRegion>,
}

/// Per camera: its [`StartFit`], `None` when that camera gives no fit or sees none of the
/// finger's links.
type Fits = [Option<StartFit>; MAX_CAMERAS];

/// Refines finger `finger` of `state` (one value per model state) on `frames` (one per
/// camera), in place. `poses`, `view` and `cache` are working memory. Nothing moves when the state
/// cannot be posed, a camera gives no fit or sees none of the finger, or no trial leaves less.
#[allow(clippy::too_many_arguments)] // the tracker's parts, lent for one call
pub fn refine_finger(
    model: &Model,
    cameras: &[Camera],
    frames: &[FrameView<'_>],
    fingers: &Fingers,
    finger: usize,
    state: &mut [f32],
    poses: &mut Poses,
    view: &mut ProjectedModel,
    cache: &mut ShadingCache,
    config: &ShadingRefineConfig,
) -> RefineOutcome {
    let mut outcome = RefineOutcome::default();
    let n = state.len().min(MAX_STATES);
    let joints: Vec<usize, MAX_FINGER_JOINTS> = (0..n)
        .filter(|&s| fingers.contains(finger, s))
        .take(MAX_FINGER_JOINTS)
        .collect();
    let moving = moving_frames(model, &joints);
    cache.clear();
    let Some(fits) = start_fits(
        model, cameras, frames, &joints, &moving, state, poses, view, cache, config,
    ) else {
        return outcome;
    };
    outcome.uncached_cameras = fits.iter().flatten().filter(|f| f.cached.is_none()).count() as u8;
    let score = |q: &[f32], poses: &mut Poses, view: &mut ProjectedModel| {
        if poses.update(model, q).is_err() {
            return f32::INFINITY;
        }
        let mut sum = 0.0f32;
        for ((camera, frame), fit) in cameras.iter().zip(frames).zip(&fits) {
            let Some(fit) = fit else {
                return f32::INFINITY;
            };
            view.update(model, poses, camera, 0.0);
            let residual: Option<RegionResidual> = match &fit.cached {
                Some(cached) => cache.residual(cached, view, camera, frame, &moving),
                None => residual_in(view, camera, frame, &fit.scoring),
            };
            match residual {
                Some(r) => sum += r.sum_sq,
                None => return f32::INFINITY,
            }
        }
        sum
    };
    let mut best = score(&state[..n], poses, view);
    if !best.is_finite() {
        return outcome;
    }
    let mut trial = [0.0f32; MAX_STATES];
    for &step in &config.steps_rad {
        if !(step.is_finite() && step > 0.0) {
            continue;
        }
        for (k, &s) in joints.iter().enumerate() {
            // The finger's flexions together (all its joints but the first), then each joint.
            if k == 0 && config.curl && joints.len() > 2 {
                let flexions = &joints[1..];
                for sign in [1.0f32, -1.0] {
                    trial[..n].copy_from_slice(&state[..n]);
                    for &f in flexions {
                        if let Some(limit) = model.limit(f) {
                            trial[f] = (state[f] + sign * step).clamp(limit.lo, limit.hi);
                        }
                    }
                    if flexions.iter().all(|&f| trial[f] == state[f]) {
                        continue;
                    }
                    outcome.trials = outcome.trials.saturating_add(1);
                    let residual = score(&trial[..n], poses, view);
                    if residual < best * (1.0 - config.margin) {
                        best = residual;
                        state[..n].copy_from_slice(&trial[..n]);
                        outcome.moves = outcome.moves.saturating_add(1);
                        break;
                    }
                }
            }
            if k > 0 && !config.single_flexions {
                continue;
            }
            let Some(limit) = model.limit(s) else {
                continue;
            };
            for sign in [1.0f32, -1.0] {
                trial[..n].copy_from_slice(&state[..n]);
                trial[s] = (state[s] + sign * step).clamp(limit.lo, limit.hi);
                if trial[s] == state[s] {
                    continue;
                }
                outcome.trials = outcome.trials.saturating_add(1);
                let residual = score(&trial[..n], poses, view);
                if residual < best * (1.0 - config.margin) {
                    best = residual;
                    state[s] = trial[s];
                    outcome.moves = outcome.moves.saturating_add(1);
                    break;
                }
            }
        }
    }
    // The caller's poses left at the state returned.
    let _ = poses.update(model, &state[..n]);
    outcome
}

/// Each camera's shading fitted at `state`, the region of the links that `joints` move,
/// widened, and that region's surfaces that stay put (the links not moving with `moving`, and
/// the palm) kept in `cache` while it has room; `None` when the state cannot be posed or some
/// camera has no fit or region.
#[allow(clippy::too_many_arguments)]
fn start_fits(
    model: &Model,
    cameras: &[Camera],
    frames: &[FrameView<'_>],
    joints: &[usize],
    moving: &super::shading_cache::MovingFrames,
    state: &[f32],
    poses: &mut Poses,
    view: &mut ProjectedModel,
    cache: &mut ShadingCache,
    config: &ShadingRefineConfig,
) -> Option<Fits> {
    poses.update(model, state).ok()?;
    let moved_by_finger = |frame: u8| {
        joints
            .iter()
            .any(|&s| model.joint_frame(s) == Some(usize::from(frame)))
    };
    let pad = Vector2::new(config.region_pad_px, config.region_pad_px);
    let mut fits: Fits = [None; MAX_CAMERAS];
    for ((camera, frame), slot) in cameras.iter().zip(frames).zip(fits.iter_mut()) {
        view.update(model, poses, camera, 0.0);
        let terms = fit_terms(view, camera, frame, usize::from(config.grid))?;
        let bounds = view
            .links
            .iter()
            .filter(|l| moved_by_finger(l.frame) || moved_by_finger(l.child))
            .map(|l| l.bounds)
            .reduce(|a, b| Bounds {
                min: a.min.inf(&b.min),
                max: a.max.sup(&b.max),
            })?;
        let scoring = RegionScoring {
            terms,
            region: Bounds {
                min: bounds.min - pad,
                max: bounds.max + pad,
            },
            step_px: config.region_step_px,
            cost: PixelCost::capped_at(config.residual_cap_grey),
            clamp_light: config.clamp_light,
        };
        let cached = cache.fill(view, camera, frame, &scoring, moving);
        *slot = Some(StartFit { scoring, cached });
    }
    Some(fits)
}
