//! The camera and tracker parameters as they cross the link.
//!
//! Wire types of their own, so the tracker's Rust types can change without changing the
//! protocol; each converts to the tracker's type only after checking its ranges.

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

use crate::camera::{Camera, CameraError};
use crate::config::{MAX_SLICES_PER_LINK, MAX_WINDOW};
use crate::estimator::{Conditioning, ResidualKind, Robust};
use crate::tracker::TrackerConfig;

/// A pinhole camera (`docs/sequence-format.md`): `p_c = R · p_w + t`, `u = fx · x/z + cx`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CameraParams {
    /// Image width (px).
    pub width: u16,
    /// Image height (px).
    pub height: u16,
    /// Focal lengths and principal point (px): `[fx, fy, cx, cy]`.
    pub intrinsics: [f32; 4],
    /// World-to-camera rotation, row-major.
    pub r: [f32; 9],
    /// World-to-camera translation (mm).
    pub t: [f32; 3],
}

impl CameraParams {
    /// The wire form of a camera; `None` when it is larger than 65535 px on a side.
    pub fn from_camera(camera: &Camera) -> Option<Self> {
        let mut r = [0.0; 9];
        for (i, v) in r.iter_mut().enumerate() {
            *v = camera.r[(i / 3, i % 3)];
        }
        Some(CameraParams {
            width: u16::try_from(camera.width).ok()?,
            height: u16::try_from(camera.height).ok()?,
            intrinsics: [camera.fx, camera.fy, camera.cx, camera.cy],
            r,
            t: [camera.t.x, camera.t.y, camera.t.z],
        })
    }

    /// The camera, checked by [`Camera::validate`].
    pub fn to_camera(&self) -> Result<Camera, CameraError> {
        let [fx, fy, cx, cy] = self.intrinsics;
        let camera = Camera {
            width: u32::from(self.width),
            height: u32::from(self.height),
            fx,
            fy,
            cx,
            cy,
            r: Matrix3::from_row_slice(&self.r),
            t: Vector3::from_column_slice(&self.t),
        };
        camera.validate()?;
        Ok(camera)
    }

    /// Bytes of one frame of this camera.
    pub fn frame_bytes(&self) -> usize {
        usize::from(self.width) * usize::from(self.height)
    }
}

/// Which residuals the estimator uses (see `estimator::ResidualKind`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WireResidual {
    /// One row per edge point.
    EdgePoints,
    /// Eq. 2.17 axis lines.
    AxisLines,
    /// One row per slice (the default).
    AxisPoints,
}

/// Robust weighting (see `estimator::Robust`); the parameter is in px.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WireRobust {
    /// Plain least squares.
    None,
    /// Huber with threshold `k` px.
    Huber(f32),
    /// Tukey with cut-off `c` px.
    Tukey(f32),
}

/// The tracker parameters a host may set; the rest keep the board's defaults.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TrackerParams {
    /// Gauss–Newton iterations per frame at most (1–50).
    pub iterations: u8,
    /// Constant-velocity prediction.
    pub predict: bool,
    /// Slices per link (1–[`MAX_SLICES_PER_LINK`]).
    pub slices_per_link: u8,
    /// Slice search window (px, 4–[`MAX_WINDOW`]).
    pub window_px: u8,
    /// Smallest accepted edge contrast (grey levels per px, > 0).
    pub min_contrast: f32,
    /// Residual form.
    pub residual: WireResidual,
    /// Robust weight.
    pub robust: WireRobust,
    /// Conditioning diagonal `[quaternion, translation, joint]` (each > 0).
    pub conditioning: [f32; 3],
    /// `lost` below this fraction of expected features found (0–1).
    pub lost_min_found: f32,
    /// `lost` above this residual RMS (px, > 0).
    pub lost_rms_px: f32,
    /// Slice across the palm box's own image outline too (version 6;
    /// `FeatureConfig::palm_edges`).
    pub palm_edges: bool,
    /// An edge found is kept only where the image's edge runs within this angle of the
    /// predicted one (rad, 0–π/2; π/2 keeps every edge; version 7;
    /// `FeatureConfig::max_edge_angle_rad`).
    pub max_edge_angle_rad: f32,
    /// Where the model says an edge lies against the background, the outermost edge at
    /// least this share of the window's strongest is taken (0–1; 0 takes the strongest;
    /// version 8; `FeatureConfig::outermost_share`).
    pub outermost_share: f32,
}

/// A tracker parameter out of range.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BadParameter(pub &'static str);

impl core::fmt::Display for BadParameter {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "tracker parameter `{}` out of range", self.0)
    }
}

impl TrackerParams {
    /// The wire form of a tracker configuration.
    pub fn from_config(config: &TrackerConfig) -> Self {
        let e = &config.estimator;
        TrackerParams {
            iterations: config.iterations,
            predict: config.predict,
            slices_per_link: config.features.slices_per_link,
            window_px: config.features.window_px,
            min_contrast: config.features.min_contrast,
            residual: match e.residual {
                ResidualKind::EdgePoints => WireResidual::EdgePoints,
                ResidualKind::AxisLines => WireResidual::AxisLines,
                ResidualKind::AxisPoints => WireResidual::AxisPoints,
            },
            robust: match e.robust {
                Robust::None => WireRobust::None,
                Robust::Huber(k) => WireRobust::Huber(k),
                Robust::Tukey(c) => WireRobust::Tukey(c),
            },
            conditioning: [
                e.conditioning.quaternion,
                e.conditioning.translation,
                e.conditioning.joint,
            ],
            lost_min_found: config.lost_min_found,
            lost_rms_px: config.lost_rms_px,
            palm_edges: config.features.palm_edges,
            max_edge_angle_rad: config.features.max_edge_angle_rad,
            outermost_share: config.features.outermost_share,
        }
    }

    /// The tracker configuration: `TrackerConfig::default()` with these parameters, after
    /// checking every range.
    pub fn to_config(&self) -> Result<TrackerConfig, BadParameter> {
        let positive = |v: f32| v.is_finite() && v > 0.0;
        check((1..=50).contains(&self.iterations), "iterations")?;
        check(
            (1..=MAX_SLICES_PER_LINK).contains(&usize::from(self.slices_per_link)),
            "slices_per_link",
        )?;
        check(
            (4..=MAX_WINDOW).contains(&usize::from(self.window_px)),
            "window_px",
        )?;
        check(positive(self.min_contrast), "min_contrast")?;
        check(
            self.conditioning.iter().all(|&v| positive(v)),
            "conditioning",
        )?;
        check((0.0..=1.0).contains(&self.lost_min_found), "lost_min_found")?;
        check(positive(self.lost_rms_px), "lost_rms_px")?;
        check(
            (0.0..=core::f32::consts::FRAC_PI_2).contains(&self.max_edge_angle_rad),
            "max_edge_angle_rad",
        )?;
        check(
            (0.0..=1.0).contains(&self.outermost_share),
            "outermost_share",
        )?;
        let robust = match self.robust {
            WireRobust::None => Robust::None,
            WireRobust::Huber(k) if positive(k) => Robust::Huber(k),
            WireRobust::Tukey(c) if positive(c) => Robust::Tukey(c),
            _ => return Err(BadParameter("robust")),
        };
        let defaults = TrackerConfig::default();
        let [quaternion, translation, joint] = self.conditioning;
        let mut features = defaults.features;
        features.slices_per_link = self.slices_per_link;
        features.window_px = self.window_px;
        features.min_contrast = self.min_contrast;
        features.palm_edges = self.palm_edges;
        features.max_edge_angle_rad = self.max_edge_angle_rad;
        features.outermost_share = self.outermost_share;
        let mut estimator = defaults.estimator;
        estimator.residual = match self.residual {
            WireResidual::EdgePoints => ResidualKind::EdgePoints,
            WireResidual::AxisLines => ResidualKind::AxisLines,
            WireResidual::AxisPoints => ResidualKind::AxisPoints,
        };
        estimator.robust = robust;
        estimator.conditioning = Conditioning {
            quaternion,
            translation,
            joint,
        };
        let config = TrackerConfig {
            iterations: self.iterations,
            predict: self.predict,
            lost_min_found: self.lost_min_found,
            lost_rms_px: self.lost_rms_px,
            features,
            estimator,
            ..defaults
        };
        Ok(config)
    }
}

impl Default for TrackerParams {
    fn default() -> Self {
        Self::from_config(&TrackerConfig::default())
    }
}

fn check(ok: bool, name: &'static str) -> Result<(), BadParameter> {
    if ok {
        Ok(())
    } else {
        Err(BadParameter(name))
    }
}
