//! The pinhole camera of `docs/sequence-format.md`: projections worked out by hand, the pixel-centre
//! convention, points that must not project, the projection Jacobian against finite
//! differences, and `validate`'s error paths.

mod common;

use common::Rng;
use digiteyes_core::camera::{palm_depth_mm, Camera, CameraError, MIN_DEPTH};
use digiteyes_core::nalgebra::{Matrix3, Vector2, Vector3};

/// The sequence-format example: 640×480, f = 1000, principal point at the image centre,
/// identity R, 600 mm in front of the world origin.
fn front_camera() -> Camera {
    Camera {
        width: 640,
        height: 480,
        fx: 1000.0,
        fy: 1000.0,
        cx: 319.5,
        cy: 239.5,
        r: Matrix3::identity(),
        t: Vector3::new(0.0, 0.0, 600.0),
    }
}

/// A camera looking along world +y: R = Rot_x(−90°) maps world (x, y, z) to camera
/// (x, −z, y), so world "up" (+z) is image up (−v).
fn side_camera() -> Camera {
    Camera {
        fx: 1200.0,
        fy: 1200.0,
        r: Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0),
        t: Vector3::new(0.0, 0.0, 500.0),
        ..front_camera()
    }
}

/// cam0 of the independent sample-mouse fixture, read from its `sequence.json`.
fn fixture_camera() -> (Camera, Vec<f64>) {
    let text = include_str!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../fixtures/sample-mouse/sequence.json"
    ));
    let json: serde_json::Value = serde_json::from_str(text).unwrap();
    let cam = &json["cameras"][0];
    let num = |v: &serde_json::Value| v.as_f64().unwrap();
    let r: Vec<f64> = cam["R"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|row| row.as_array().unwrap().iter().map(num).collect::<Vec<_>>())
        .collect();
    let t: Vec<f64> = cam["t"].as_array().unwrap().iter().map(num).collect();
    let camera = Camera {
        width: cam["width"].as_u64().unwrap() as u32,
        height: cam["height"].as_u64().unwrap() as u32,
        fx: num(&cam["fx"]) as f32,
        fy: num(&cam["fy"]) as f32,
        cx: num(&cam["cx"]) as f32,
        cy: num(&cam["cy"]) as f32,
        r: Matrix3::from_row_slice(&r.iter().map(|&v| v as f32).collect::<Vec<_>>()),
        t: Vector3::new(t[0] as f32, t[1] as f32, t[2] as f32),
    };
    let mut reference = r;
    reference.extend(t);
    (camera, reference)
}

#[track_caller]
fn assert_px(got: Option<Vector2<f32>>, u: f32, v: f32, tol: f32) {
    let got = got.expect("point should project");
    assert!(
        (got.x - u).abs() <= tol && (got.y - v).abs() <= tol,
        "got ({}, {}), expected ({u}, {v})",
        got.x,
        got.y
    );
}

#[test]
fn identity_camera_projects_by_hand() {
    let c = front_camera();
    c.validate().unwrap();
    // The world origin is on the optical axis: the principal point.
    assert_px(c.project(&Vector3::zeros()), 319.5, 239.5, 1e-4);
    // (60, −30, 0) at depth 600: u = 1000·60/600 + 319.5, v = 1000·(−30)/600 + 239.5.
    assert_px(
        c.project(&Vector3::new(60.0, -30.0, 0.0)),
        419.5,
        189.5,
        1e-3,
    );
    // (10, 20, 400) at depth 1000: 10 px right, 20 px down.
    assert_px(
        c.project(&Vector3::new(10.0, 20.0, 400.0)),
        329.5,
        259.5,
        1e-3,
    );
    assert_eq!(
        c.to_camera(&Vector3::new(1.0, 2.0, 3.0)),
        Vector3::new(1.0, 2.0, 603.0)
    );
    assert_eq!(c.centre(), Vector3::new(0.0, 0.0, -600.0));
}

#[test]
fn rotated_camera_projects_by_hand() {
    let c = side_camera();
    c.validate().unwrap();
    // World (10, 100, 20) -> camera (10, −20, 600): u = 1200·10/600 + 319.5 = 339.5,
    // v = 1200·(−20)/600 + 239.5 = 199.5.
    assert_eq!(
        c.to_camera(&Vector3::new(10.0, 100.0, 20.0)),
        Vector3::new(10.0, -20.0, 600.0)
    );
    assert_px(
        c.project(&Vector3::new(10.0, 100.0, 20.0)),
        339.5,
        199.5,
        1e-3,
    );
    // Higher in the world is higher in the image.
    let low = c.project(&Vector3::new(0.0, 0.0, 0.0)).unwrap();
    let high = c.project(&Vector3::new(0.0, 0.0, 10.0)).unwrap();
    assert!(high.y < low.y);
    // The camera sits at world y = −500 looking along +y.
    assert!((c.centre() - Vector3::new(0.0, -500.0, 0.0)).norm() < 1e-4);
}

#[test]
fn fixture_camera_projects_like_the_formula() {
    let (c, reference) = fixture_camera();
    c.validate().expect("the fixture's R is a rotation");
    assert_eq!((c.width, c.height), (640, 480));
    // The contract's formula in f64 with the file's full-precision numbers.
    let project64 = |p: [f64; 3]| {
        let r = &reference[..9];
        let t = &reference[9..];
        let pc: Vec<f64> = (0..3)
            .map(|i| r[3 * i] * p[0] + r[3 * i + 1] * p[1] + r[3 * i + 2] * p[2] + t[i])
            .collect();
        (
            1000.0 * pc[0] / pc[2] + 319.5,
            1000.0 * pc[1] / pc[2] + 239.5,
        )
    };
    // The fixture's palm origin (initial translation (0, 0, 45)), finger 1's zero-pose
    // knuckle and tip, and a point 100 mm off to the side.
    for p in [
        [0.0, 0.0, 45.0],
        [31.0, 38.0, 45.0],
        [31.0, 133.0, 45.0],
        [-100.0, 20.0, 0.0],
    ] {
        let (u, v) = project64(p);
        let got = c.project(&Vector3::new(p[0] as f32, p[1] as f32, p[2] as f32));
        // f32 rounding of R and t: ~1e-7 relative on ~500 mm, times f/z ≈ 2 px/mm.
        assert_px(got, u as f32, v as f32, 2e-3);
    }
    // The palm is in view.
    let palm = c.project(&Vector3::new(0.0, 0.0, 45.0)).unwrap();
    assert!(c.contains(&palm, 50.0));
    // Points on the optical axis project to the principal point; the camera centre and
    // points behind it do not project.
    let centre = c.centre();
    let axis = c.r.row(2).transpose();
    assert_px(c.project(&(centre + axis * 300.0)), 319.5, 239.5, 2e-3);
    assert!(c.project(&centre).is_none());
    assert!(c.project(&(centre - axis * 300.0)).is_none());
}

#[test]
fn pixel_zero_is_the_centre_of_the_top_left_pixel() {
    let c = front_camera();
    // The principal point 319.5 is the middle of 640 pixels centred at 0 … 639.
    assert_eq!(c.cx, (0.0 + (c.width - 1) as f32) / 2.0);
    assert!(c.contains(&Vector2::new(0.0, 0.0), 0.0));
    assert!(c.contains(&Vector2::new(639.0, 479.0), 0.0));
    assert!(!c.contains(&Vector2::new(-0.01, 0.0), 0.0));
    assert!(!c.contains(&Vector2::new(639.01, 0.0), 0.0));
    assert!(!c.contains(&Vector2::new(0.0, 479.01), 0.0));
    assert!(c.contains(&Vector2::new(10.0, 10.0), 10.0));
    assert!(!c.contains(&Vector2::new(9.9, 10.0), 10.0));
    assert!(!c.contains(&Vector2::new(f32::NAN, 10.0), 0.0));
    // The world point that lands on pixel (0, 0): x_c / z_c = −319.5 / 1000.
    assert_px(
        c.project(&Vector3::new(-191.7, -143.7, 0.0)),
        0.0,
        0.0,
        1e-3,
    );
}

#[test]
fn points_behind_or_at_the_camera_do_not_project() {
    let c = front_camera();
    // Camera z = world z + 600.
    for z in [-600.0, -700.0, -1e6, -600.0 + 0.5 * MIN_DEPTH] {
        let p = Vector3::new(1.0, 2.0, z);
        assert!(c.project(&p).is_none(), "z_c = {}", z + 600.0);
        assert!(c.project_with_jacobian(&p).is_none(), "z_c = {}", z + 600.0);
    }
    // At exactly MIN_DEPTH it does project.
    let p = Vector3::new(0.0, 0.0, -600.0 + MIN_DEPTH);
    assert_px(c.project(&p), 319.5, 239.5, 1e-3);
    // Non-finite points never give a pixel.
    for p in [
        Vector3::new(f32::NAN, 0.0, 0.0),
        Vector3::new(0.0, 0.0, f32::NAN),
        Vector3::new(f32::INFINITY, 0.0, 0.0),
        Vector3::new(0.0, 0.0, f32::INFINITY),
    ] {
        assert!(c.project(&p).is_none(), "{p:?}");
        assert!(c.project_with_jacobian(&p).is_none(), "{p:?}");
    }
}

#[test]
fn projection_jacobian_matches_finite_differences() {
    let mut rng = Rng::new(99);
    let (fixture, _) = fixture_camera();
    for c in [front_camera(), side_camera(), fixture] {
        for _ in 0..200 {
            let p = Vector3::new(
                rng.range(-150.0, 150.0),
                rng.range(-150.0, 150.0),
                rng.range(-150.0, 150.0),
            );
            let Some((uv, depth, j)) = c.project_with_jacobian(&p) else {
                continue;
            };
            // The same pixel as `project` (computed via 1/z there: within f32 rounding).
            assert!((uv - c.project(&p).unwrap()).norm() < 1e-3);
            assert!((depth - c.to_camera(&p).z).abs() < 1e-3);
            for axis in 0..3 {
                let h = 1e-2;
                let mut plus = p;
                plus[axis] += h;
                let mut minus = p;
                minus[axis] -= h;
                let fd = (c.project(&plus).unwrap() - c.project(&minus).unwrap())
                    / (plus[axis] - minus[axis]);
                let an = j.column(axis).into_owned();
                // Pixels of magnitude ≤ ~1000 carry ~6e-5 px of f32 rounding; over 2h = 0.02
                // that is ~6e-3 px/mm. Truncation h²/6 · f·2/z³ is ~1e-9. Derivatives are
                // ~f/z ≈ 2 px/mm, so a wrong term is off by ~1 px/mm.
                assert!(
                    (fd - an).norm() <= 1e-2 + 1e-3 * an.norm(),
                    "p {p:?} axis {axis}: analytic {an:?} fd {fd:?}"
                );
            }
        }
    }
}

#[test]
fn pixels_at_depth() {
    let c = front_camera();
    assert!((c.pixels_at_depth(10.0, 500.0) - 20.0).abs() < 1e-4);
    // Depths below MIN_DEPTH are clamped, never dividing by zero.
    assert!(c.pixels_at_depth(1.0, 0.0).is_finite());
    assert_eq!(
        c.pixels_at_depth(1.0, 0.0),
        c.pixels_at_depth(1.0, MIN_DEPTH)
    );
}

#[test]
fn validate_error_paths() {
    let good = front_camera();
    assert_eq!(good.validate(), Ok(()));
    assert_eq!(
        Camera { width: 0, ..good }.validate(),
        Err(CameraError::ZeroSize)
    );
    assert_eq!(
        Camera { height: 0, ..good }.validate(),
        Err(CameraError::ZeroSize)
    );
    assert_eq!(
        Camera { fx: 0.0, ..good }.validate(),
        Err(CameraError::BadFocalLength)
    );
    assert_eq!(
        Camera {
            fy: -1000.0,
            ..good
        }
        .validate(),
        Err(CameraError::BadFocalLength)
    );
    assert_eq!(
        Camera {
            cx: f32::NAN,
            ..good
        }
        .validate(),
        Err(CameraError::NotFinite)
    );
    assert_eq!(
        Camera {
            cy: f32::INFINITY,
            ..good
        }
        .validate(),
        Err(CameraError::NotFinite)
    );
    let t = Vector3::new(0.0, f32::NEG_INFINITY, 600.0);
    assert_eq!(Camera { t, ..good }.validate(), Err(CameraError::NotFinite));
    let mut r = Matrix3::identity();
    r[(1, 2)] = f32::NAN;
    assert_eq!(Camera { r, ..good }.validate(), Err(CameraError::NotFinite));
    // A NaN focal length is rejected (as non-finite or as a bad focal length).
    assert!(matches!(
        Camera {
            fx: f32::NAN,
            ..good
        }
        .validate(),
        Err(CameraError::NotFinite | CameraError::BadFocalLength)
    ));

    // Not rotations: scaled, sheared, reflected (det −1, though orthonormal), degenerate.
    let not_rotations = [
        Matrix3::identity() * 1.01,
        Matrix3::new(1.0, 0.1, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
        Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0)),
        -Matrix3::identity(),
        Matrix3::new(0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0), // swap x, y
        Matrix3::zeros(),
    ];
    for r in not_rotations {
        assert_eq!(
            Camera { r, ..good }.validate(),
            Err(CameraError::NotARotation),
            "{r}"
        );
    }
    // Rotations within the 1e-3 tolerance pass: the side camera and a slightly noisy identity.
    assert_eq!(side_camera().validate(), Ok(()));
    let mut r = Matrix3::identity();
    r[(0, 1)] = 2e-4;
    assert_eq!(Camera { r, ..good }.validate(), Ok(()));
    // Error texts say what is wrong.
    assert!(CameraError::NotARotation.to_string().contains("rotation"));
}

#[test]
fn a_camera_looking_along_a_direction_centres_it_with_up_upward() {
    let eye = Vector3::new(10.0, -300.0, 50.0);
    let forward = Vector3::new(0.0, 2.0, 0.0);
    let camera = Camera::looking_along(eye, forward, Vector3::z(), (640, 480), 800.0).unwrap();
    assert_eq!(camera.validate(), Ok(()));
    assert!((camera.centre() - eye).norm() < 1e-3);
    let ahead = camera
        .project(&(eye + Vector3::new(0.0, 500.0, 0.0)))
        .unwrap();
    assert!((ahead.x - 319.5).abs() < 1e-3 && (ahead.y - 239.5).abs() < 1e-3);
    let above = camera
        .project(&(eye + Vector3::new(0.0, 500.0, 40.0)))
        .unwrap();
    assert!(above.y < ahead.y - 60.0, "up is up the image: {above:?}");
    let right = camera
        .project(&(eye + Vector3::new(40.0, 500.0, 0.0)))
        .unwrap();
    assert!(right.x > ahead.x + 60.0, "world x to the right: {right:?}");
    // No direction, or a direction along `up`: no camera.
    assert!(
        Camera::looking_along(eye, Vector3::zeros(), Vector3::z(), (640, 480), 800.0).is_none()
    );
    assert!(Camera::looking_along(eye, Vector3::z(), Vector3::z(), (640, 480), 800.0).is_none());
    assert!(Camera::looking_along(eye, forward, Vector3::z(), (640, 480), 0.0).is_none());
}

#[test]
fn the_palms_depth_is_its_distance_from_the_first_camera() {
    let camera = Camera::looking_along(
        Vector3::new(300.0, 0.0, 400.0),
        Vector3::new(-3.0, 0.0, -4.0),
        Vector3::new(0.0, 1.0, 0.0),
        (640, 480),
        1000.0,
    )
    .expect("a valid camera");
    let mut state = [0.0f32; 7];
    state[0] = 1.0;
    // A palm at the world origin, 500 mm from the camera (a 3-4-5 triangle).
    let depth = palm_depth_mm(&[camera, front_camera()], &state).expect("a depth");
    assert!((depth - 500.0).abs() < 1e-3, "{depth}");
    state[6] = 400.0;
    let depth = palm_depth_mm(&[camera], &state).expect("a depth");
    assert!((depth - 300.0).abs() < 1e-3, "{depth}");
    assert_eq!(palm_depth_mm(&[], &state), None, "no camera");
    assert_eq!(
        palm_depth_mm(&[camera], &state[..5]),
        None,
        "no palm position"
    );
}
