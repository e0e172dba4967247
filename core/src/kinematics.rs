//! Forward kinematics: link poses for a state vector, and derivatives of model points.
//!
//! A [`Pose`] maps coordinates of a frame to world coordinates (mm). The palm (frame 0) is
//! placed by states q0..q6 — the quaternion is normalised before use, so its derivative has no
//! radial part — and each child by its row's DH transform
//! `Rot_z(theta) · Trans_z(d) · Trans_x(a) · Rot_x(alpha)`.
//!
//! A point fixed to frame `i`'s shape (which turns with `theta_i`) moves with revolute joint
//! `j` on its chain at velocity `n_j × (p − o_j)` (Eq. 2.16), where `n_j` and `o_j` are frame
//! `j`'s z axis and origin in the world.

use core::fmt;

use heapless::Vec;
use nalgebra::{Matrix3, Vector3};

use crate::config::{MAX_LINKS, MAX_ROW_NONZEROS};
use crate::model::{Model, Theta, BASE_STATES};
use crate::quaternion;

/// A rigid transform from a frame's coordinates to world coordinates (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Rotation: columns are the frame's axes in the world.
    pub r: Matrix3<f32>,
    /// Origin of the frame in the world (mm).
    pub t: Vector3<f32>,
}

impl Pose {
    /// The identity transform.
    pub fn identity() -> Self {
        Pose {
            r: Matrix3::identity(),
            t: Vector3::zeros(),
        }
    }

    /// `self ∘ other`: first `other`, then `self`.
    pub fn compose(&self, other: &Pose) -> Pose {
        Pose {
            r: self.r * other.r,
            t: self.r * other.t + self.t,
        }
    }

    /// A point given in this frame, in world coordinates (mm).
    pub fn apply(&self, p: &Vector3<f32>) -> Vector3<f32> {
        self.r * p + self.t
    }

    /// The DH transform `Rot_z(theta) · Trans_z(d) · Trans_x(a) · Rot_x(alpha)`.
    pub fn dh(theta: f32, d: f32, a: f32, alpha: f32) -> Pose {
        Pose::dh_twisted(theta, d, a, crate::float::sin_cos(alpha))
    }

    /// [`Pose::dh`] with the twist given by its sine and cosine.
    pub fn dh_twisted(theta: f32, d: f32, a: f32, (sa, ca): (f32, f32)) -> Pose {
        let (s, c) = crate::float::sin_cos(theta);
        Pose {
            r: Matrix3::new(c, -s * ca, s * sa, s, c * ca, -c * sa, 0.0, sa, ca),
            t: Vector3::new(a * c, a * s, d),
        }
    }
}

/// Why poses could not be computed for a state vector.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum KinematicsError {
    /// The state vector's length is not the model's state count.
    WrongStateCount {
        /// States the model has.
        expected: u8,
        /// States given.
        got: u8,
    },
    /// A state is NaN or infinite.
    NotFinite {
        /// The first such state.
        state: u8,
    },
    /// The palm quaternion q0..q3 is zero.
    ZeroQuaternion,
}

impl fmt::Display for KinematicsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::WrongStateCount { expected, got } => {
                write!(f, "state vector has {got} states, the model {expected}")
            }
            Self::NotFinite { state } => write!(f, "state q{state} is not finite"),
            Self::ZeroQuaternion => write!(f, "palm quaternion q0..q3 is zero"),
        }
    }
}

impl core::error::Error for KinematicsError {}

/// The world pose of every frame for one state vector, plus what derivatives need.
#[derive(Debug, Clone)]
pub struct Poses {
    /// `frame[i]`: frame `i` in the world (`W_i`).
    frame: [Pose; MAX_LINKS],
    /// `E_k = D_k · Rᵀ`: `∂p/∂q_k = E_k (p − t_palm)` for the quaternion states k = 0..3.
    quat_derivative: [Matrix3<f32>; 4],
    n_frames: usize,
}

impl Poses {
    /// Poses of every frame of `model` for states `q` (quaternion, mm, rad).
    pub fn compute(model: &Model, q: &[f32]) -> Result<Poses, KinematicsError> {
        let mut poses = Poses {
            frame: [Pose::identity(); MAX_LINKS],
            quat_derivative: [Matrix3::zeros(); 4],
            n_frames: model.links().len(),
        };
        poses.update(model, q)?;
        Ok(poses)
    }

    /// Recomputes the poses in place for new states `q`.
    #[inline(never)] // a stage of Table 4.1: kept whole so profiles can attribute its cost
    pub fn update(&mut self, model: &Model, q: &[f32]) -> Result<(), KinematicsError> {
        if q.len() != model.n_states() {
            return Err(KinematicsError::WrongStateCount {
                expected: model.n_states() as u8,
                got: q.len().min(255) as u8,
            });
        }
        if let Some(i) = q.iter().position(|v| !v.is_finite()) {
            return Err(KinematicsError::NotFinite { state: i as u8 });
        }
        let raw = [q[0], q[1], q[2], q[3]];
        let u = quaternion::normalised(raw).ok_or(KinematicsError::ZeroQuaternion)?;
        let palm = Pose {
            r: quaternion::rotation(u[0], u[1], u[2], u[3]),
            t: Vector3::new(q[4], q[5], q[6]),
        };
        // D_k's column `axis` is ∂(R e_axis)/∂q_k: one call per axis gives all four k.
        let mut d = [Matrix3::zeros(); 4];
        for axis in 0..3 {
            let mut v = Vector3::zeros();
            v[axis] = 1.0;
            if let Some(cols) = quaternion::rotation_derivatives(raw, &v) {
                for (dk, col) in d.iter_mut().zip(&cols) {
                    dk.set_column(axis, col);
                }
            }
        }
        for (e, dk) in self.quat_derivative.iter_mut().zip(&d) {
            *e = dk * palm.r.transpose();
        }
        let links = model.links();
        self.n_frames = links.len();
        for &f in model.order() {
            let f = usize::from(f);
            let link = &links[f];
            let parent = match link.parent {
                Some(p) => self.frame[usize::from(p)].compose(&self.local(model, f, q)),
                None => palm,
            };
            self.frame[f] = parent;
        }
        // `frame[f]` above is W_f = W_parent · T_parent; T_parent is the parent's row.
        Ok(())
    }

    /// The DH transform from frame `parent(f)` to frame `f`: the parent row's transform.
    fn local(&self, model: &Model, f: usize, q: &[f32]) -> Pose {
        let links = model.links();
        let Some(p) = links[f].parent else {
            return Pose::identity();
        };
        row_transform(&links[usize::from(p)], q)
    }

    /// World pose of frame `i` (`W_i`).
    pub fn frame(&self, i: usize) -> Option<&Pose> {
        self.frame[..self.n_frames].get(i)
    }

    /// Origin of frame `i` in the world (mm).
    pub fn origin(&self, i: usize) -> Option<Vector3<f32>> {
        self.frame(i).map(|p| p.t)
    }

    /// The palm pose (frame 0).
    pub fn palm(&self) -> &Pose {
        &self.frame[0]
    }

    /// Derivatives of a world point `p` (mm) fixed to frame `shape_frame`'s shape, with respect
    /// to every state that moves it: the 7 palm states, then the joints of its chain.
    /// Entries are `(state, ∂p/∂q_state)` in mm per unit state.
    pub fn point_derivatives(
        &self,
        model: &Model,
        shape_frame: usize,
        p: &Vector3<f32>,
    ) -> Vec<(u8, Vector3<f32>), MAX_ROW_NONZEROS> {
        let mut out = Vec::new();
        let rel = p - self.frame[0].t;
        for (k, e) in self.quat_derivative.iter().enumerate() {
            let _ = out.push((k as u8, e * rel));
        }
        for axis in 0..3 {
            let mut v = Vector3::zeros();
            v[axis] = 1.0;
            let _ = out.push(((4 + axis) as u8, v));
        }
        let mut cursor = Some(shape_frame);
        let start = out.len();
        while let Some(f) = cursor {
            let Some(link) = model.links().get(f) else {
                break;
            };
            if let Theta::State(s) = link.theta {
                let w = &self.frame[f];
                let n = w.r.column(2).into_owned();
                if out.push((s, n.cross(&(p - w.t)))).is_err() {
                    break;
                }
            }
            cursor = link.parent.map(usize::from);
        }
        out[start..].reverse();
        debug_assert!(out.len() <= BASE_STATES + crate::config::MAX_CHAIN);
        out
    }
}

/// The transform of one row, `Rot_z(theta) · Trans_z(d) · Trans_x(a) · Rot_x(alpha)`, with
/// `theta` read from `q` for a joint; the `base` row contributes its constant part only.
pub fn row_transform(link: &crate::model::Link, q: &[f32]) -> Pose {
    let theta = match link.theta {
        Theta::Base => 0.0,
        Theta::Const(v) => v,
        Theta::State(s) => q.get(usize::from(s)).copied().unwrap_or(0.0),
    };
    Pose::dh_twisted(theta, link.d, link.a, link.alpha_sin_cos())
}
