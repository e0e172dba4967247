//! Forward kinematics against `docs/hand-model.md`'s geometry, and the analytic point derivatives
//! (Eq. 2.16 and the quaternion chain rule) against central finite differences.

mod common;

use common::Rng;
use digiteyes_core::kinematics::{KinematicsError, Pose, Poses};
use digiteyes_core::model::{Model, Shape, Theta};
use digiteyes_core::nalgebra::{Matrix3, Vector3};
use digiteyes_core::quaternion;

fn hand() -> Model {
    Model::hand().unwrap()
}

/// The whole hand at all states zero with the identity palm.
fn zero_state() -> Vec<f32> {
    let mut q = vec![0.0; 28];
    q[0] = 1.0;
    q
}

#[track_caller]
fn assert_close(a: Vector3<f32>, b: Vector3<f32>, tol: f32, what: &str) {
    assert!(
        (a - b).norm() <= tol,
        "{what}: got {a:?}, expected {b:?} (|diff| = {})",
        (a - b).norm()
    );
}

// ---------------------------------------------------------------------------------------------
// Geometry at all states zero (docs/hand-model.md, "The whole hand"). The expected
// origins follow from the table by hand: each finger's constant frames move `a` along +y and
// then `d` along the (world −x) z axis of the second frame, then the link lengths run along +y.

#[test]
fn finger_and_thumb_origins_at_zero() {
    let m = hand();
    let p = Poses::compute(&m, &zero_state()).unwrap();
    let o = |f: usize| p.origin(f).unwrap();
    // Frames 1, 8, 15, 22, 29 start at the palm frame.
    for f in [0, 1, 8, 15, 22, 29] {
        assert_close(o(f), Vector3::zeros(), 1e-5, &format!("frame {f}"));
    }
    // (x of the finger, y of its MCP joint, link lengths a of link0..link2)
    let fingers = [
        (31.0, 38.0, [45.0, 26.0, 24.0]),
        (9.0, 37.0, [56.0, 27.0, 22.0]),
        (-6.0, 33.0, [53.0, 25.0, 20.0]),
        (-26.0, 30.0, [38.0, 19.0, 17.0]),
    ];
    for (k, (x, y0, lengths)) in fingers.into_iter().enumerate() {
        let base = 7 * k;
        // Abduction and MCP frames share the knuckle.
        assert_close(
            o(base + 3),
            Vector3::new(x, y0, 0.0),
            1e-4,
            "abduction frame",
        );
        let mut y = y0;
        assert_close(o(base + 4), Vector3::new(x, y, 0.0), 1e-4, "link0 origin");
        for (j, len) in lengths.into_iter().enumerate() {
            y += len;
            assert_close(o(base + 5 + j), Vector3::new(x, y, 0.0), 1e-4, "link end");
        }
    }
    // Finger 1 at x = 31, finger 4 at x = −26 (docs/hand-model.md).
    assert!((o(7).x - 31.0).abs() < 1e-4 && (o(28).x + 26.0).abs() < 1e-4);
    // The thumb along +y at x = 38, z = 15: frame 31 at y = −43 (a = 43 along −y), then
    // link0 (46), the opposition frame, link1 (34), link2 (25).
    assert_close(o(31), Vector3::new(38.0, -43.0, 15.0), 1e-4, "thumb base");
    assert_close(o(32), Vector3::new(38.0, -43.0, 15.0), 1e-4, "thumb link0");
    assert_close(o(33), Vector3::new(38.0, 3.0, 15.0), 1e-4, "thumb MP");
    assert_close(o(34), Vector3::new(38.0, 3.0, 15.0), 1e-4, "thumb link1");
    assert_close(o(35), Vector3::new(38.0, 37.0, 15.0), 1e-4, "thumb link2");
    assert_close(o(36), Vector3::new(38.0, 62.0, 15.0), 1e-4, "thumb tip");
    assert!(p.origin(37).is_none());
    assert!(p.frame(37).is_none());
}

#[test]
fn palm_pose_moves_the_whole_hand() {
    let m = hand();
    // 90° about +z, written as a non-unit quaternion (scaled by 3): x -> y, y -> −x.
    let h = core::f32::consts::FRAC_1_SQRT_2 * 3.0;
    let mut q = zero_state();
    q[..7].copy_from_slice(&[h, 0.0, 0.0, h, 10.0, -20.0, 30.0]);
    let p = Poses::compute(&m, &q).unwrap();
    let t = Vector3::new(10.0, -20.0, 30.0);
    assert_close(p.palm().t, t, 1e-5, "palm origin");
    // finger 1 tip (31, 133, 0) -> (−133, 31, 0); thumb tip (38, 62, 15) -> (−62, 38, 15).
    assert_close(
        p.origin(7).unwrap(),
        Vector3::new(-133.0, 31.0, 0.0) + t,
        1e-3,
        "tip 1",
    );
    assert_close(
        p.origin(36).unwrap(),
        Vector3::new(-62.0, 38.0, 15.0) + t,
        1e-3,
        "thumb",
    );
}

#[test]
fn positive_flexion_curls_fingers_toward_plus_z() {
    let m = hand();
    for k in 0..4 {
        let tip = 7 * k + 7;
        for j in 1..4 {
            let s = 7 + 4 * k + j; // MCP, PIP, DIP of finger k+1
            let mut q = zero_state();
            q[s] = 0.4;
            let p = Poses::compute(&m, &q).unwrap();
            assert!(
                p.origin(tip).unwrap().z > 1.0,
                "q{s} = 0.4 lifts tip {tip} to +z"
            );
            q[s] = -0.4;
            let p = Poses::compute(&m, &q).unwrap();
            assert!(
                p.origin(tip).unwrap().z < -1.0,
                "q{s} = -0.4 moves tip {tip} to -z"
            );
        }
    }
    // Exactly: d(tip)/d(MCP) at zero is z × (tip − knuckle) = (0, 0, finger length).
    let p = Poses::compute(&m, &zero_state()).unwrap();
    let tip = p.origin(7).unwrap();
    let d = p.point_derivatives(&m, 7, &tip);
    let (_, d8) = d.iter().find(|(s, _)| *s == 8).unwrap();
    assert_close(*d8, Vector3::new(0.0, 0.0, 95.0), 1e-3, "d tip1 / d q8");
}

#[test]
fn positive_thumb_flexion_moves_it_toward_plus_x() {
    let m = hand();
    for s in [26, 27] {
        let mut q = zero_state();
        q[s] = 0.3;
        let p = Poses::compute(&m, &q).unwrap();
        let tip = p.origin(36).unwrap();
        assert!(
            tip.x > 38.0 + 1.0,
            "q{s} = 0.3: thumb tip {tip:?} should move to +x"
        );
        assert!((tip.z - 15.0).abs() < 1e-3, "q{s} bends in the palm plane");
    }
    let p = Poses::compute(&m, &zero_state()).unwrap();
    let tip = p.origin(36).unwrap();
    let d = p.point_derivatives(&m, 36, &tip);
    let (_, d26) = d.iter().find(|(s, _)| *s == 26).unwrap();
    // Lever arm from the MP joint (38, 3, 15) to the tip is 59 mm along +y.
    assert_close(
        *d26,
        Vector3::new(59.0, 0.0, 0.0),
        1e-3,
        "d thumb tip / d q26",
    );
}

// ---------------------------------------------------------------------------------------------
// Analytic derivatives against central finite differences.

/// A model point fixed to frame `frame`'s shape: `local` in the shape frame
/// `W_frame · Rot_z(theta_frame)`.
#[derive(Clone, Copy, Debug)]
struct ShapePoint {
    frame: usize,
    local: Vector3<f32>,
    what: &'static str,
}

fn shape_point_world(m: &Model, poses: &Poses, q: &[f32], sp: &ShapePoint) -> Vector3<f32> {
    let w = poses.frame(sp.frame).unwrap();
    let theta = match m.links()[sp.frame].theta {
        Theta::State(s) => q[usize::from(s)],
        Theta::Const(v) => v,
        Theta::Base => 0.0,
    };
    let shape = w.compose(&Pose::dh(theta, 0.0, 0.0, 0.0));
    shape.apply(&sp.local)
}

/// Origin, midpoint and an off-axis point of every cylinder, and every tip's centre.
fn shape_points(m: &Model) -> Vec<ShapePoint> {
    let mut points = Vec::new();
    for (f, link) in m.links().iter().enumerate() {
        match link.shape {
            Shape::Cylinder { radius } => {
                // In the shape frame the axis runs from 0 to (a, 0, d).
                let end = Vector3::new(link.a, 0.0, link.d);
                points.push(ShapePoint {
                    frame: f,
                    local: Vector3::zeros(),
                    what: "cyl origin",
                });
                points.push(ShapePoint {
                    frame: f,
                    local: end * 0.5,
                    what: "cyl midpoint",
                });
                points.push(ShapePoint {
                    frame: f,
                    local: end * 0.7 + Vector3::new(0.0, 0.6 * radius, -0.8 * radius),
                    what: "cyl surface",
                });
            }
            Shape::Tip { .. } => points.push(ShapePoint {
                frame: f,
                local: Vector3::zeros(),
                what: "tip",
            }),
            _ => {}
        }
    }
    points
}

/// A random state: a non-unit quaternion (norm 0.5 … 2), translation within ±60 mm, joints
/// within ±1.6 rad (wider than the limits: the derivatives hold everywhere).
fn random_state(rng: &mut Rng) -> Vec<f32> {
    let mut q = vec![0.0; 28];
    loop {
        for v in &mut q[..4] {
            *v = rng.range(-1.0, 1.0);
        }
        if quaternion::norm4([q[0], q[1], q[2], q[3]]) > 0.3 {
            break;
        }
    }
    let scale = rng.range(0.5, 2.0) / quaternion::norm4([q[0], q[1], q[2], q[3]]);
    for v in &mut q[..4] {
        *v *= scale;
    }
    for v in &mut q[4..7] {
        *v = rng.range(-60.0, 60.0);
    }
    for v in &mut q[7..] {
        *v = rng.range(-1.6, 1.6);
    }
    q
}

/// Finite-difference steps: 1e-3 for the quaternion (unitless, |q| ≥ 0.5) and the joint
/// angles (rad), 1e-2 mm for the translation.
fn step(state: usize) -> f32 {
    if (4..7).contains(&state) {
        1e-2
    } else {
        1e-3
    }
}

/// Tolerance for comparing an f32 central difference with the analytic derivative.
///
/// Truncation: a central difference errs by h²/6 · |p⁽³⁾|. Points move on circles of radius
/// r ≤ ~200 mm (hand length plus palm translation), and |q| ≥ 0.5 scales the quaternion's
/// sensitivity by ≤ 2 per order, so |p⁽³⁾| ≲ 8r and the error is ≲ 1e-6/6 · 1600 ≈ 3e-4 —
/// negligible. Rounding dominates: a point of magnitude up to ~260 mm is computed through
/// ~10 composed f32 transforms, so each evaluation is off by a few ulps (ulp(256) ≈ 3e-5 mm,
/// say 3 ulps ≈ 1e-4 mm); the difference of two such points over 2h = 2e-3 gives ~0.05 mm per
/// unit state. We allow exactly that, plus 0.05 % of the derivative's size for the relative
/// error of the analytic side. For the translation (h = 1e-2, derivative exactly 1) the
/// rounding term is 10× smaller: 0.005. (Observed worst: ~0.03 for quaternion states, ~0.013
/// for joints, ~6e-4 for translation.) A wrong axis, sign, lever arm or state index is off by
/// mm per unit state or more, far outside this.
fn tolerance(state: usize, analytic: f32) -> f32 {
    let abs = if (4..7).contains(&state) { 5e-3 } else { 5e-2 };
    abs + 5e-4 * analytic
}

#[test]
fn point_derivatives_match_finite_differences() {
    let m = hand();
    let points = shape_points(&m);
    assert_eq!(points.len(), 15 * 3 + 5, "15 cylinders, 5 tips");
    let mut rng = Rng::new(0x00D1_617E_7E55);
    let mut worst = (0.0f32, String::new());
    let poses_count = 60;
    for pose in 0..poses_count {
        let q = random_state(&mut rng);
        let poses = Poses::compute(&m, &q).unwrap();
        for sp in &points {
            let p = shape_point_world(&m, &poses, &q, sp);
            let analytic = poses.point_derivatives(&m, sp.frame, &p);
            // The list: the 7 palm states in order, then the frame's chain, root first.
            let listed: Vec<u8> = analytic.iter().map(|(s, _)| *s).collect();
            let mut expected: Vec<u8> = (0..7).collect();
            expected.extend_from_slice(&m.chain(sp.frame).unwrap());
            assert_eq!(listed, expected, "frame {}", sp.frame);
            for state in 0..28 {
                let h = step(state);
                let mut plus = q.clone();
                plus[state] += h;
                let mut minus = q.clone();
                minus[state] -= h;
                let pp = shape_point_world(&m, &Poses::compute(&m, &plus).unwrap(), &plus, sp);
                let pm = shape_point_world(&m, &Poses::compute(&m, &minus).unwrap(), &minus, sp);
                // The actual step (q ± h is rounded in f32).
                let fd = (pp - pm) / (plus[state] - minus[state]);
                let an = analytic
                    .iter()
                    .find(|(s, _)| usize::from(*s) == state)
                    .map(|(_, d)| *d)
                    .unwrap_or_else(Vector3::zeros);
                let err = (fd - an).norm();
                let tol = tolerance(state, an.norm());
                if err / tol > worst.0 {
                    worst = (
                        err / tol,
                        format!("pose {pose} q{state} {} frame {}", sp.what, sp.frame),
                    );
                }
                assert!(
                    err <= tol,
                    "pose {pose}, {} on frame {}, q{state}: analytic {an:?}, \
                     finite difference {fd:?}, |err| {err} > {tol}",
                    sp.what,
                    sp.frame
                );
            }
        }
    }
    eprintln!("worst error/tolerance: {} at {}", worst.0, worst.1);
}

#[test]
fn quaternion_derivatives_have_no_radial_part() {
    // Scaling the raw quaternion does not move the hand: Σ_k q_k ∂p/∂q_k = 0.
    let m = hand();
    let mut rng = Rng::new(7);
    for _ in 0..50 {
        let q = random_state(&mut rng);
        let poses = Poses::compute(&m, &q).unwrap();
        let tip = poses.origin(21).unwrap();
        let d = poses.point_derivatives(&m, 21, &tip);
        let radial: Vector3<f32> = (0..4).map(|k| d[k].1 * q[k]).sum();
        let scale: f32 = (0..4).map(|k| d[k].1.norm() * q[k].abs()).sum::<f32>();
        assert!(radial.norm() <= 1e-4 * scale + 1e-4, "radial {radial:?}");

        let v = Vector3::new(rng.range(-50.0, 50.0), rng.range(-50.0, 50.0), 20.0);
        let raw = [q[0], q[1], q[2], q[3]];
        let cols = quaternion::rotation_derivatives(raw, &v).unwrap();
        let radial: Vector3<f32> = (0..4).map(|k| cols[k] * raw[k]).sum();
        assert!(radial.norm() <= 1e-4 * v.norm(), "radial {radial:?}");
    }
}

#[test]
fn rotation_derivatives_match_finite_differences_at_non_unit_quaternions() {
    let mut rng = Rng::new(11);
    let rotated = |q: [f32; 4], v: &Vector3<f32>| {
        let u = quaternion::normalised(q).unwrap();
        quaternion::rotation(u[0], u[1], u[2], u[3]) * v
    };
    for _ in 0..200 {
        let mut q = [0.0f32; 4];
        for c in &mut q {
            *c = rng.range(-2.0, 2.0);
        }
        if quaternion::norm4(q) < 0.3 {
            continue;
        }
        let v = Vector3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        );
        let cols = quaternion::rotation_derivatives(q, &v).unwrap();
        for (k, col) in cols.iter().enumerate() {
            let h = 1e-3;
            let mut plus = q;
            plus[k] += h;
            let mut minus = q;
            minus[k] -= h;
            let fd = (rotated(plus, &v) - rotated(minus, &v)) / (plus[k] - minus[k]);
            // |v| ≤ √3, so rounding of ~1e-7 over 2e-3 gives ~1e-4; 2e-3 leaves headroom and
            // still catches any mistake (the derivatives are O(|v| / |q|)).
            assert!(
                (fd - col).norm() <= 2e-3 + 1e-3 * col.norm(),
                "q {q:?} k {k}: analytic {col:?}, fd {fd:?}"
            );
        }
    }
    assert!(quaternion::rotation_derivatives([0.0; 4], &Vector3::x()).is_none());
    assert!(quaternion::rotation_derivatives([f32::NAN, 1.0, 0.0, 0.0], &Vector3::x()).is_none());
}

#[test]
fn rotation_matches_hand_computed_matrices() {
    let h = core::f32::consts::FRAC_1_SQRT_2;
    // 90° about z: x -> y.
    let r = quaternion::rotation(h, 0.0, 0.0, h);
    let expected = Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0);
    assert!((r - expected).norm() < 1e-6, "{r}");
    // 180° about x.
    let r = quaternion::rotation(0.0, 1.0, 0.0, 0.0);
    assert_eq!(r, Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, -1.0)));
    assert_eq!(
        quaternion::rotation(1.0, 0.0, 0.0, 0.0),
        Matrix3::identity()
    );
}

#[test]
fn from_rotation_inverts_rotation() {
    let mut rng = Rng::new(3);
    let check = |q: [f32; 4]| {
        let u = quaternion::normalised(q).unwrap();
        let back = quaternion::from_rotation(&quaternion::rotation(u[0], u[1], u[2], u[3]));
        // q and −q are the same rotation.
        let dot: f32 = (0..4).map(|k| u[k] * back[k]).sum();
        assert!(dot.abs() > 1.0 - 1e-5, "{u:?} -> {back:?}");
        assert!((quaternion::norm4(back) - 1.0).abs() < 1e-5);
        assert!(quaternion::angle_between(u, back) < 1e-2);
    };
    for _ in 0..500 {
        check([
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        ]);
    }
    // Each branch of Shepperd's method: positive trace, and 180° turns about x, y, z.
    check([1.0, 0.0, 0.0, 0.0]);
    check([0.0, 1.0, 0.0, 0.0]);
    check([0.0, 0.0, 1.0, 0.0]);
    check([0.0, 0.0, 0.0, 1.0]);
    check([0.01, 0.3, 0.9, -0.2]);
}

#[test]
fn angle_between_is_sign_invariant() {
    let h = core::f32::consts::FRAC_1_SQRT_2;
    let a = [1.0, 0.0, 0.0, 0.0];
    let b = [h, 0.0, 0.0, h]; // 90° about z
    assert!((quaternion::angle_between(a, b) - core::f32::consts::FRAC_PI_2).abs() < 1e-3);
    assert!((quaternion::angle_between(a, [-1.0, 0.0, 0.0, 0.0])).abs() < 1e-3);
    assert!((quaternion::angle_between(b, [-h, 0.0, 0.0, -h])).abs() < 1e-3);
}

#[test]
fn normalised_rejects_zero_and_non_finite() {
    assert_eq!(quaternion::normalised([0.0; 4]), None);
    assert_eq!(quaternion::normalised([f32::NAN, 0.0, 0.0, 0.0]), None);
    assert_eq!(quaternion::normalised([f32::INFINITY, 0.0, 0.0, 0.0]), None);
    assert_eq!(
        quaternion::normalised([0.0, 0.0, 2.0, 0.0]),
        Some([0.0, 0.0, 1.0, 0.0])
    );
}

// ---------------------------------------------------------------------------------------------
// Error paths.

#[test]
fn compute_rejects_bad_state_vectors() {
    let m = hand();
    let mut q = zero_state();
    q.pop();
    assert_eq!(
        Poses::compute(&m, &q).unwrap_err(),
        KinematicsError::WrongStateCount {
            expected: 28,
            got: 27
        }
    );
    assert_eq!(
        Poses::compute(&m, &[1.0; 29]).unwrap_err(),
        KinematicsError::WrongStateCount {
            expected: 28,
            got: 29
        }
    );
    assert!(matches!(
        Poses::compute(&m, &[]).unwrap_err(),
        KinematicsError::WrongStateCount { got: 0, .. }
    ));
    // A length that does not fit the error's u8 saturates instead of wrapping.
    assert!(matches!(
        Poses::compute(&m, &[1.0; 300]).unwrap_err(),
        KinematicsError::WrongStateCount { got: 255, .. }
    ));

    let mut q = zero_state();
    q[10] = f32::NAN;
    assert_eq!(
        Poses::compute(&m, &q).unwrap_err(),
        KinematicsError::NotFinite { state: 10 }
    );
    let mut q = zero_state();
    q[5] = f32::INFINITY;
    q[20] = f32::NEG_INFINITY;
    assert_eq!(
        Poses::compute(&m, &q).unwrap_err(),
        KinematicsError::NotFinite { state: 5 }
    );
    let mut q = zero_state();
    q[0] = 0.0;
    assert_eq!(
        Poses::compute(&m, &q).unwrap_err(),
        KinematicsError::ZeroQuaternion
    );
    // A quaternion far below unit scale (norm < 1e-12, here its square underflows) is zero.
    q[2] = 1e-30;
    assert_eq!(
        Poses::compute(&m, &q).unwrap_err(),
        KinematicsError::ZeroQuaternion
    );
    // Error texts name the state.
    assert!(KinematicsError::NotFinite { state: 10 }
        .to_string()
        .contains("q10"));
}

#[test]
fn update_reuses_poses() {
    let m = hand();
    let mut rng = Rng::new(5);
    let a = random_state(&mut rng);
    let b = random_state(&mut rng);
    let mut poses = Poses::compute(&m, &a).unwrap();
    poses.update(&m, &b).unwrap();
    let fresh = Poses::compute(&m, &b).unwrap();
    for f in 0..37 {
        assert_eq!(poses.frame(f), fresh.frame(f));
    }
    // A failed update reports the error.
    let mut bad = b.clone();
    bad[3] = f32::NAN;
    assert!(poses.update(&m, &bad).is_err());
}

#[test]
fn dh_transform_matches_its_definition() {
    // Rot_z(theta) · Trans_z(d) · Trans_x(a) · Rot_x(alpha), composed from its factors.
    let (theta, d, a, alpha) = (0.7f32, -3.0f32, 12.0f32, -1.1f32);
    let rz = Pose::dh(theta, 0.0, 0.0, 0.0);
    let tz = Pose {
        r: Matrix3::identity(),
        t: Vector3::new(0.0, 0.0, d),
    };
    let tx = Pose {
        r: Matrix3::identity(),
        t: Vector3::new(a, 0.0, 0.0),
    };
    let rx = Pose::dh(0.0, 0.0, 0.0, alpha);
    let composed = rz.compose(&tz).compose(&tx).compose(&rx);
    let dh = Pose::dh(theta, d, a, alpha);
    assert!((composed.r - dh.r).norm() < 1e-6);
    assert!((composed.t - dh.t).norm() < 1e-5);
    // The factors themselves: Rot_z turns x toward y, Rot_x turns y toward z.
    assert!(
        (rz.apply(&Vector3::x()) - Vector3::new(0.7f32.cos(), 0.7f32.sin(), 0.0)).norm() < 1e-6
    );
    let y = rx.apply(&Vector3::y());
    assert!((y - Vector3::new(0.0, (-1.1f32).cos(), (-1.1f32).sin())).norm() < 1e-6);
}

#[test]
fn angle_between_is_exact_for_small_and_large_turns() {
    use digiteyes_core::quaternion::angle_between;
    for &angle in &[1e-4f32, 0.01, 0.5, 3.0] {
        let (s, c) = (angle * 0.5).sin_cos();
        let a = [0.6f32, 0.0, 0.8, 0.0];
        // b = a · (turn about x by `angle`)
        let t = [c, s, 0.0, 0.0];
        let b = [
            a[0] * t[0] - a[1] * t[1] - a[2] * t[2] - a[3] * t[3],
            a[0] * t[1] + a[1] * t[0] + a[2] * t[3] - a[3] * t[2],
            a[0] * t[2] - a[1] * t[3] + a[2] * t[0] + a[3] * t[1],
            a[0] * t[3] + a[1] * t[2] - a[2] * t[1] + a[3] * t[0],
        ];
        let got = angle_between(a, b);
        assert!((got - angle).abs() < 1e-3 * angle + 1e-6, "{angle}: {got}");
        let neg = [-b[0], -b[1], -b[2], -b[3]];
        assert!((angle_between(a, neg) - got).abs() < 1e-6, "sign-invariant");
    }
}
