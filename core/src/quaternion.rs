//! Unit quaternions `(w, x, y, z)` as used by the palm's spatial transform (states q0..q3).

use nalgebra::{Matrix3, Vector3};

use crate::float::Length;

/// Rotation matrix of the unit quaternion `(w, x, y, z)`; the caller normalises.
pub fn rotation(w: f32, x: f32, y: f32, z: f32) -> Matrix3<f32> {
    Matrix3::new(
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y - w * z),
        2.0 * (x * z + w * y),
        2.0 * (x * y + w * z),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z - w * x),
        2.0 * (x * z - w * y),
        2.0 * (y * z + w * x),
        1.0 - 2.0 * (x * x + y * y),
    )
}

/// Euclidean norm of a 4-vector.
pub fn norm4(q: [f32; 4]) -> f32 {
    crate::float::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
}

/// `q / |q|`, or `None` when `q` is zero or not finite.
pub fn normalised(q: [f32; 4]) -> Option<[f32; 4]> {
    let n = norm4(q);
    if !(n.is_finite() && n > 1e-12) {
        return None;
    }
    Some([q[0] / n, q[1] / n, q[2] / n, q[3] / n])
}

/// Derivatives of `R(q / |q|) · v` with respect to the four (unnormalised) components of `q`.
///
/// `q` is the raw state; `v` is a vector in the rotated (palm) frame. Column `k` is
/// `∂(R v)/∂q_k`; the radial direction has zero derivative, so a Gauss–Newton step never
/// tries to scale the hand.
pub fn rotation_derivatives(q: [f32; 4], v: &Vector3<f32>) -> Option<[Vector3<f32>; 4]> {
    let n = norm4(q);
    let u = normalised(q)?;
    let (w, x, y, z) = (u[0], u[1], u[2], u[3]);
    let axis = Vector3::new(x, y, z);
    let cross = axis.cross(v);
    let dot = axis.dot(v);
    // R v = v + 2w (u × v) + 2 (u (u·v) − v |u|²), differentiated at the unit quaternion.
    let d_w = cross * 2.0;
    let mut d = [d_w, Vector3::zeros(), Vector3::zeros(), Vector3::zeros()];
    for j in 0..3 {
        let mut e = Vector3::zeros();
        e[j] = 1.0;
        d[j + 1] = e.cross(v) * (2.0 * w) + (e * dot + axis * v[j] - v * (2.0 * axis[j])) * 2.0;
    }
    // Chain through normalisation: ∂u/∂q = (I − u uᵀ) / |q|.
    let mut out = [Vector3::zeros(); 4];
    for (k, o) in out.iter_mut().enumerate() {
        let mut acc = d[k];
        for (m, dm) in d.iter().enumerate() {
            acc -= dm * (u[m] * u[k]);
        }
        *o = acc / n;
    }
    Some(out)
}

/// Angle in radians between two unit quaternions' rotations (sign-invariant): `2·atan2(|v|, |w|)`
/// of the relative rotation `a⁻¹ b`, exact near zero where `acos` of the dot product is not.
pub fn angle_between(a: [f32; 4], b: [f32; 4]) -> f32 {
    let (aw, av) = (a[0], Vector3::new(a[1], a[2], a[3]));
    let (bw, bv) = (b[0], Vector3::new(b[1], b[2], b[3]));
    let w = aw * bw + av.dot(&bv);
    let v = bv * aw - av * bw - av.cross(&bv);
    2.0 * libm::atan2f(v.length(), w.abs())
}

/// The unit quaternion `(w, x, y, z)` of a rotation matrix (Shepperd's method).
pub fn from_rotation(m: &Matrix3<f32>) -> [f32; 4] {
    let tr = m[(0, 0)] + m[(1, 1)] + m[(2, 2)];
    let q = if tr > 0.0 {
        let s = crate::float::sqrt(tr + 1.0) * 2.0;
        [
            0.25 * s,
            (m[(2, 1)] - m[(1, 2)]) / s,
            (m[(0, 2)] - m[(2, 0)]) / s,
            (m[(1, 0)] - m[(0, 1)]) / s,
        ]
    } else if m[(0, 0)] > m[(1, 1)] && m[(0, 0)] > m[(2, 2)] {
        let s = crate::float::sqrt(1.0 + m[(0, 0)] - m[(1, 1)] - m[(2, 2)]) * 2.0;
        [
            (m[(2, 1)] - m[(1, 2)]) / s,
            0.25 * s,
            (m[(0, 1)] + m[(1, 0)]) / s,
            (m[(0, 2)] + m[(2, 0)]) / s,
        ]
    } else if m[(1, 1)] > m[(2, 2)] {
        let s = crate::float::sqrt(1.0 + m[(1, 1)] - m[(0, 0)] - m[(2, 2)]) * 2.0;
        [
            (m[(0, 2)] - m[(2, 0)]) / s,
            (m[(0, 1)] + m[(1, 0)]) / s,
            0.25 * s,
            (m[(1, 2)] + m[(2, 1)]) / s,
        ]
    } else {
        let s = crate::float::sqrt(1.0 + m[(2, 2)] - m[(0, 0)] - m[(1, 1)]) * 2.0;
        [
            (m[(1, 0)] - m[(0, 1)]) / s,
            (m[(0, 2)] + m[(2, 0)]) / s,
            (m[(1, 2)] + m[(2, 1)]) / s,
            0.25 * s,
        ]
    };
    normalised(q).unwrap_or([1.0, 0.0, 0.0, 0.0])
}
