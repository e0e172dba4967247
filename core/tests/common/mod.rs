//! Helpers shared by the core's integration tests.
#![allow(dead_code)]

/// SplitMix64: a tiny seeded generator, so every run draws the same "random" cases.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }

    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }
}

use digiteyes_core::camera::Camera;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::Model;
use digiteyes_core::projection::ProjectedModel;
use nalgebra::{Matrix3, Vector3};

const H: f32 = std::f32::consts::FRAC_1_SQRT_2;

/// The sample-mouse fixture's camera (~45° above a palm-down hand), 640×480.
pub fn table_camera() -> Camera {
    Camera {
        width: 640,
        height: 480,
        fx: 1000.0,
        fy: 1000.0,
        cx: 319.5,
        cy: 239.5,
        r: Matrix3::new(H, -H, 0.0, -0.5, -0.5, -H, 0.5, 0.5, -H),
        t: Vector3::new(26.15406, 25.07026, 520.0828),
    }
}

/// A palm-down pose with every joint bent a little, so no derivative is degenerate.
pub fn bent_pose() -> Vec<f32> {
    let mut q = vec![0.0f32; 28];
    q[..7].copy_from_slice(&[0.05, 0.02, 0.9975, -0.07, 3.0, -2.0, 45.0]);
    for (i, v) in q.iter_mut().enumerate().skip(7) {
        *v = 0.15 + 0.03 * (i % 5) as f32;
    }
    q
}

/// A 640×480 camera (f = 800 px) at `eye` looking along `forward`, world z up the image (y
/// when looking nearly straight down or up).
pub fn looking_along(eye: Vector3<f32>, forward: Vector3<f32>) -> Camera {
    let up = if forward.normalize().z.abs() > 0.9 {
        Vector3::y()
    } else {
        Vector3::z()
    };
    Camera::looking_along(eye, forward, up, (640, 480), 800.0).unwrap()
}

/// The model at `q` projected into `camera`, every link at least 1 px long kept.
pub fn view_at(model: &Model, q: &[f32], camera: &Camera) -> ProjectedModel {
    let poses = Poses::compute(model, q).unwrap();
    let mut view = ProjectedModel::new();
    view.update(model, &poses, camera, 1.0);
    view
}
