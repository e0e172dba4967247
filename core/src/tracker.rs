//! The per-frame tracking loop (Sec. 4.3.2) and its report. (API stub; being written.)

use core::fmt;

use heapless::Vec;

use crate::camera::{Camera, CameraError};
use crate::config::{MAX_CAMERAS, MAX_STATES};
use crate::frame::{FrameError, FrameView};
use crate::kinematics::KinematicsError;
use crate::model::Model;

/// Tracker parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct TrackerConfig {
    /// Gauss–Newton iterations per frame; features are found again at every one.
    pub iterations: u8,
    /// Predict each frame's start state by constant velocity from the last two.
    pub predict: bool,
}

impl Default for TrackerConfig {
    fn default() -> Self {
        TrackerConfig {
            iterations: 6,
            predict: true,
        }
    }
}

/// What the tracker did with one frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameReport {
    /// Root-mean-square image residual after the last iteration (px).
    pub rms_px: f32,
    /// Features found in the last iteration (edge points and tips).
    pub features_found: u16,
    /// Features the model predicted should be visible in the last iteration.
    pub features_expected: u16,
    /// Iterations run.
    pub iterations: u8,
    /// Too few features, or the residual exploded: the state is not to be trusted.
    pub lost: bool,
}

/// Why the tracker could not be set up or could not use a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
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
    /// A `free` entry names no state of the model.
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

/// Tracks one hand over frames from one or more calibrated cameras.
#[derive(Debug, Clone)]
pub struct Tracker {
    model: Model,
    cameras: Vec<Camera, MAX_CAMERAS>,
    state: Vec<f32, MAX_STATES>,
    config: TrackerConfig,
}

impl Tracker {
    /// A tracker starting from `initial` (one value per model state), estimating the states
    /// listed in `free` (all when `None`).
    pub fn new(
        model: Model,
        cameras: &[Camera],
        initial: &[f32],
        free: Option<&[u8]>,
        config: TrackerConfig,
    ) -> Result<Self, TrackerError> {
        let _ = free;
        let cameras = Vec::from_slice(cameras).map_err(|_| TrackerError::CameraCount)?;
        let state = Vec::from_slice(initial).map_err(|_| {
            TrackerError::State(KinematicsError::WrongStateCount {
                expected: model.n_states() as u8,
                got: 255,
            })
        })?;
        Ok(Tracker {
            model,
            cameras,
            state,
            config,
        })
    }

    /// Tracks one instant: `frames[i]` is camera `i`'s frame. Updates and returns the state.
    pub fn track(&mut self, frames: &[FrameView<'_>]) -> Result<FrameReport, TrackerError> {
        let _ = (frames, &self.cameras, self.config);
        Ok(FrameReport::default())
    }

    /// The current state estimate (quaternion, mm, rad).
    pub fn state(&self) -> &[f32] {
        &self.state
    }

    /// The model tracked.
    pub fn model(&self) -> &Model {
        &self.model
    }
}
