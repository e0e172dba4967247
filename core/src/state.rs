//! The layout of a state vector: the palm's unit quaternion `(w, x, y, z)` (`q0..q3`), its
//! translation (`q4..q6`, mm), then the joint angles in model order (rad). One home for the
//! ranges, the quaternion's renormalisation and the clamp to a joint's range, used by the
//! estimator, the tracker and the host.

use core::ops::Range;

use crate::model::{Model, BASE_STATES};
use crate::quaternion;

/// The palm quaternion's states, `q0..q3`.
pub const QUATERNION: Range<usize> = 0..4;

/// The palm translation's states, `q4..q6` (mm).
pub const TRANSLATION: Range<usize> = 4..BASE_STATES;

/// The quaternion's states as a [`FreeMask`](crate::estimator::FreeMask) bit set.
pub const QUATERNION_BITS: u32 = (1 << QUATERNION.end) - 1;

/// What a state is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum StateKind {
    /// A component of the palm quaternion (unitless).
    Quaternion,
    /// A component of the palm translation (mm).
    Translation,
    /// A joint angle (rad).
    Joint,
}

impl StateKind {
    /// The kind of state `i`.
    #[inline]
    pub fn of(i: usize) -> StateKind {
        // Joints first: most states are joints, and the estimator asks for every free state.
        if i >= TRANSLATION.end {
            StateKind::Joint
        } else if i >= QUATERNION.end {
            StateKind::Translation
        } else {
            StateKind::Quaternion
        }
    }
}

impl StateKind {
    /// The one of three per-kind values (weights, units, …) that applies to this kind.
    #[inline]
    pub fn pick<T>(self, quaternion: T, translation: T, joint: T) -> T {
        match self {
            StateKind::Quaternion => quaternion,
            StateKind::Translation => translation,
            StateKind::Joint => joint,
        }
    }
}

/// Scales the quaternion at the head of `q` to unit length; leaves `q` as it is when it is
/// shorter than a quaternion or the quaternion is zero or not finite.
#[inline]
pub fn renormalise_quaternion(q: &mut [f32]) {
    if let Some(head) = q.get_mut(QUATERNION) {
        if let Some(u) = quaternion::normalised([head[0], head[1], head[2], head[3]]) {
            head.copy_from_slice(&u);
        }
    }
}

/// `v` clamped to the range of state `i` in `model` (unchanged for a state without one).
#[inline]
pub fn clamp_to_limit(model: &Model, i: usize, v: f32) -> f32 {
    match model.limit(i) {
        Some(limit) => v.clamp(limit.lo, limit.hi),
        None => v,
    }
}
