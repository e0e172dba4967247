//! The estimator's parameters: residual kind, robust weight, conditioning, free states.

use crate::state::{StateKind, QUATERNION_BITS};

/// Which residuals a link's edge points give.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ResidualKind {
    /// One row per edge point: its distance from the predicted silhouette line.
    EdgePoints,
    /// Two rows per link: the model axis' end points against the fitted axis line (Eq. 2.17).
    AxisLines,
    /// One row per slice: where both edges were found, the distance of their midpoint from the
    /// model axis (blind to a width bias, such as shading pulling both edges inward); a lone
    /// edge gives its edge-point row.
    AxisPoints,
}

/// Robust weighting of residuals (px).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Robust {
    /// Plain least squares.
    None,
    /// Huber: weight 1 up to `k` px, then `k / |r|`.
    Huber(f32),
    /// Tukey's biweight: `(1 − (r/c)²)²` up to `c` px, 0 beyond.
    Tukey(f32),
}

impl Robust {
    /// The weight of a residual `r` (px).
    #[inline]
    pub fn weight(&self, r: f32) -> f32 {
        let a = r.abs();
        match *self {
            Robust::None => 1.0,
            Robust::Huber(k) if a > k => k / a,
            Robust::Huber(_) => 1.0,
            Robust::Tukey(c) if a < c => {
                let u = 1.0 - (r / c) * (r / c);
                u * u
            }
            Robust::Tukey(_) => 0.0,
        }
    }
}

/// The diagonal of the conditioning matrix `S` per kind of state (Table 4.2).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Conditioning {
    /// For each quaternion state.
    pub quaternion: f32,
    /// For each translation state (per mm²).
    pub translation: f32,
    /// For each joint angle (per rad²).
    pub joint: f32,
}

impl Conditioning {
    /// The thesis' weights (Table 4.2): quaternion 1, translation 10, joint 1000.
    pub const THESIS: Conditioning = Conditioning {
        quaternion: 1.0,
        translation: 10.0,
        joint: 1000.0,
    };

    /// `S` for state `i`.
    #[inline]
    pub fn for_state(&self, i: usize) -> f32 {
        StateKind::of(i).pick(self.quaternion, self.translation, self.joint)
    }
}

/// Parameters of the estimator.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub struct EstimatorConfig {
    /// Which residuals edges give.
    pub residual: ResidualKind,
    /// Robust weighting of edge and tip residuals.
    pub robust: Robust,
    /// The conditioning matrix `S`.
    pub conditioning: Conditioning,
    /// Weight of a tip row relative to an edge row.
    pub tip_weight: f32,
    /// Weight of a palm outline edge row relative to a link's edge row
    /// ([`add_palm_edge_rows`](super::add_palm_edge_rows)).
    pub palm_edge_weight: f32,
    /// With [`ResidualKind::AxisPoints`], the weight of a second row per slice where both of
    /// its edges were found, relative to a lone edge's row: the mean of the two edges'
    /// residuals, which reads the link's width in the image, so its depth. 0: no such row.
    /// The rows use this weight; a tracker with one camera puts
    /// [`one_camera_width_weight`](Self::one_camera_width_weight) in its place.
    pub width_weight: f32,
    /// [`width_weight`](Self::width_weight) for a tracker with one camera, where a link's
    /// width is the one reading of its depth (two cameras triangulate it, and a width is
    /// biased by shading that pulls both edges inward). Default 0.5, measured on the
    /// robustness sweep (`docs/robustness.md`, "Stop 76: a link's width, with one camera").
    pub one_camera_width_weight: f32,
    /// With two or more cameras, [`width_weight`](Self::width_weight) for a link only one of
    /// them found features on in the frame's previous iteration (none on a frame's first):
    /// to that camera alone the link's width is its one reading of depth, as to a tracker with
    /// one camera. 0: no width rows there. Default 0.25, measured on the robustness sweep
    /// (`docs/robustness.md`, "Stop 77: a link one of two cameras sees").
    pub single_view_width_weight: f32,
    /// Solve each step with the joints it would carry out of their ranges held at their
    /// bounds and the other states solved again for it
    /// ([`NormalEquations::bounded_step`](super::NormalEquations::bounded_step)), instead of
    /// clamping them after the others moved as though they had gone on. Default off, measured
    /// (`docs/robustness.md`, "Joints at their bounds"): within noise on the sweep (its
    /// motions keep every joint off its bounds), +2.3 points of life on motions whose fingers
    /// lie straight part of the time, but it steadies a reading held at a bound as well, and a
    /// finger seen end-on read bent backwards (its MCP held at 0) is then given up by neither
    /// the single track nor the hypotheses (`tests/tests/hypotheses.rs`: K = 4 right on 2 of
    /// 10 noise seeds against 5 with the plain step).
    pub bounded_step: bool,
}

impl EstimatorConfig {
    /// The rows' parameters for a tracker with `cameras` cameras: with one camera its
    /// [`one_camera_width_weight`](Self::one_camera_width_weight) is the width rows' weight.
    pub fn for_cameras(&self, cameras: usize) -> EstimatorConfig {
        let mut config = *self;
        if cameras == 1 {
            config.width_weight = self.one_camera_width_weight;
        }
        config
    }
}

impl Default for EstimatorConfig {
    fn default() -> Self {
        EstimatorConfig {
            residual: ResidualKind::AxisPoints,
            robust: Robust::Huber(2.0),
            conditioning: Conditioning {
                quaternion: 1.0,
                translation: 1.0,
                joint: 1000.0,
            },
            tip_weight: 1.0,
            palm_edge_weight: 1.0,
            width_weight: 0.0,
            one_camera_width_weight: 0.5,
            single_view_width_weight: 0.25,
            bounded_step: false,
        }
    }
}

/// Which states the estimator may change: bit `i` for state `qi`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FreeMask(pub u32);

impl FreeMask {
    /// Every state of a model with `n` states.
    pub fn all(n: usize) -> Self {
        FreeMask(if n >= 32 { u32::MAX } else { (1u32 << n) - 1 })
    }

    /// The states listed, or the first listed that no mask can hold (32 or more).
    pub fn from_states(states: &[u8]) -> Result<Self, u8> {
        let mut mask = 0u32;
        for &s in states {
            mask |= 1u32.checked_shl(u32::from(s)).ok_or(s)?;
        }
        Ok(FreeMask(mask))
    }

    /// The same states with the whole quaternion free if any of its components is: its four
    /// components move together (a step renormalises them).
    #[inline]
    pub fn with_whole_quaternion(self) -> Self {
        if self.0 & QUATERNION_BITS != 0 {
            FreeMask(self.0 | QUATERNION_BITS)
        } else {
            self
        }
    }

    /// The first state named that a model with `n` states does not have, if any.
    #[inline]
    pub fn first_beyond(&self, n: usize) -> Option<u8> {
        let beyond = if n >= 32 { 0 } else { self.0 >> n };
        (beyond != 0).then(|| (n as u32 + beyond.trailing_zeros()) as u8)
    }

    /// Whether state `i` is free.
    #[inline]
    pub fn contains(&self, i: usize) -> bool {
        i < 32 && self.0 & (1 << i) != 0
    }

    /// Number of free states.
    pub fn count(&self) -> u32 {
        self.0.count_ones()
    }
}
