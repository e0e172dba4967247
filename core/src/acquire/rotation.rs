//! Palm rotations for the search: quaternion turns, and a lattice spread over SO(3).

/// Quaternion (w, x, y, z) of a turn of `angle` rad about unit `axis`.
pub(crate) fn axis_angle(axis: [f32; 3], angle: f32) -> [f32; 4] {
    let (s, c) = crate::float::sin_cos(angle / 2.0);
    [c, axis[0] * s, axis[1] * s, axis[2] * s]
}

/// `a ⊗ b`: turn by `b` in `a`'s frame.
pub(crate) fn compose(a: &[f32; 4], b: &[f32; 4]) -> [f32; 4] {
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
pub(crate) fn coarse_rotation(k: u32, normals: u32, j: u32, spins: u32) -> [f32; 4] {
    const GOLDEN_ANGLE: f32 = 2.399_963;
    let z = 1.0 - 2.0 * (k as f32 + 0.5) / normals as f32;
    let r = crate::float::sqrt((1.0 - z * z).max(0.0));
    let phi = k as f32 * GOLDEN_ANGLE;
    let (sin_phi, cos_phi) = crate::float::sin_cos(phi);
    let n = [r * cos_phi, r * sin_phi, z];
    // Turn e_z onto n: about e_z × n by acos(n_z).
    let axis = [-n[1], n[0], 0.0];
    let len = crate::float::sqrt(axis[0] * axis[0] + axis[1] * axis[1]);
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
    use heapless::Vec;

    #[test]
    fn coarse_rotations_are_unit_and_spread() {
        let all: Vec<[f32; 4], 120> = (0..20)
            .flat_map(|k| (0..6).map(move |j| coarse_rotation(k, 20, j, 6)))
            .collect();
        for q in &all {
            let n = crate::float::sqrt(q.iter().map(|v| v * v).sum::<f32>());
            assert!((n - 1.0).abs() < 1e-5);
        }
        // Every rotation of a fine random set lies within 50° of some coarse one.
        let mut worst = 0.0f32;
        for i in 0..500 {
            let t = i as f32 * 0.618_034;
            let axis = [
                crate::float::cos(t * 7.0),
                crate::float::sin(t * 7.0),
                crate::float::cos(t * 3.0),
            ];
            let len = crate::float::sqrt(axis.iter().map(|v| v * v).sum::<f32>());
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
