//! Seeded random rigs and motions, so the tracker is judged on views nobody tuned it for, and
//! the thesis' own stereo rig (Sec. 4.3.3).
//!
//! The hand lies palm-down over the table of the *table* set-up (world z up, fingers along
//! +y). Each seed draws:
//! - one or two cameras anywhere on the upper hemisphere around the hand: elevation 20–90°
//!   above the table, any azimuth (beyond the fingertips, behind the wrist, either side),
//!   350–1500 mm away, the focal length set so the hand spans 120–350 px of the 640×480 image;
//!   a second camera 150–600 mm to the side of the first, both verging on the hand;
//! - a whole-hand motion, all 28 states free: every joint swings around a random mid-range
//!   pose across most of its range (curled fists, fingers crossing each other and the palm,
//!   fingers seen end-on as they curl toward a camera), the palm turning up to ±40° about its
//!   axes and moving up to ±60 mm;
//! - noise (σ 1–6 grey levels), blur (σ 0.3–1.2 px) and the fingertips' peak speed
//!   (3–8 px/frame);
//! - the lighting: a light beside the camera 5–60° off its axis, ambient 0.25–0.5 of an
//!   albedo of 150–230 grey levels (drawn after everything above, so a seed's rig, motion,
//!   noise and blur are those it had when the lighting was fixed).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::cameras::{look_at, resized};
use super::catalogue::Scenario;
use crate::render::Lighting;
use crate::sequence::CameraFile;

/// Names of the scenarios of this module.
pub const RANDOM_NAMES: [&str; 3] = ["random-mono", "random-stereo", "thesis-stereo"];

const DEG: f64 = std::f64::consts::PI / 180.0;

/// Where the cameras look: the centroid of the hand's frame origins at `q` (world, mm).
fn hand_centre(q: &[f64]) -> [f64; 3] {
    let qf: Vec<f32> = q.iter().map(|&v| v as f32).collect();
    let centre = digiteyes_core::model::Model::hand().ok().and_then(|model| {
        let poses = digiteyes_core::kinematics::Poses::compute(&model, &qf).ok()?;
        let points: Vec<_> = (0..model.links().len())
            .filter_map(|i| poses.origin(i))
            .collect();
        let n = points.len().max(1) as f32;
        let sum = points
            .iter()
            .fold(digiteyes_core::nalgebra::Vector3::zeros(), |a, p| a + p);
        Some([
            f64::from(sum.x / n),
            f64::from(sum.y / n),
            f64::from(sum.z / n),
        ])
    });
    centre.unwrap_or([0.0, 40.0, 35.0])
}

/// The hand's extent used to set the focal length (mm, wrist to fingertips).
const HAND_SPAN_MM: f64 = 190.0;

/// The palm-down pose of the table set-up, fingers in the given curl (MCP, PIP, DIP, rad).
fn palm_down(curl: [f64; 3], spread: f64) -> Vec<f64> {
    let mut q = vec![
        0.0,
        0.0,
        0.9975510002532796,
        -0.0699428473375328,
        0.0,
        0.0,
        45.0,
    ];
    for side in [-1.5f64, -0.5, 0.5, 1.5] {
        q.extend([spread * side, curl[0], curl[1], curl[2]]);
    }
    q.extend([0.3, -0.15, 0.0, -0.4, -0.5]);
    q
}

/// Joint ranges of the built-in hand (`models/hand.dh`), by state.
fn joint_range(state: usize) -> (f64, f64) {
    match state {
        7 | 11 | 15 | 19 => (-0.35, 0.35),
        8 | 12 | 16 | 20 => (0.0, 1.4),
        9 | 13 | 17 | 21 => (0.0, 1.6),
        10 | 14 | 18 | 22 => (0.0, 1.2),
        23 => (0.0, 0.8),
        24 => (-0.6, 0.3),
        25 => (-0.3, 0.3),
        26 => (-0.9, 0.1),
        _ => (-1.2, 0.1),
    }
}

/// A camera `distance` mm from [`TARGET`] at `azimuth` (0: beyond the fingertips, +y) and
/// `elevation` above the table, whose focal length makes the hand `span_px` wide.
fn hemisphere_camera(
    name: &str,
    target: [f64; 3],
    azimuth: f64,
    elevation: f64,
    distance: f64,
    span_px: f64,
) -> CameraFile {
    let [tx, ty, tz] = target;
    let eye = [
        tx + distance * elevation.cos() * azimuth.sin(),
        ty + distance * elevation.cos() * azimuth.cos(),
        tz + distance * elevation.sin(),
    ];
    camera_at(name, target, eye, span_px, distance)
}

fn camera_at(
    name: &str,
    target: [f64; 3],
    eye: [f64; 3],
    span_px: f64,
    distance: f64,
) -> CameraFile {
    let view = [target[0] - eye[0], target[1] - eye[1], target[2] - eye[2]];
    let horizontal = (view[0] * view[0] + view[1] * view[1]).sqrt();
    // Looking (nearly) straight down, "up the image" is the fingers' direction instead.
    let up = if horizontal < 0.05 * distance {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let mut camera = look_at(name, eye, target, up);
    let focal = span_px * distance / HAND_SPAN_MM;
    camera.fx = focal;
    camera.fy = focal;
    camera
}

/// A light beside the camera, 5–60° off its axis in any image direction; ambient 0.25–0.5 of
/// an albedo of 150–230 grey levels. The hand's darkest shade (37.5 at least) stays above the
/// plain background's grey, as the tracker's region evidence assumes of every rig it is
/// built for.
fn random_lighting(rng: &mut ChaCha8Rng) -> Lighting {
    let angle = rng.random_range(5.0..60.0) * DEG;
    let azimuth = rng.random_range(0.0..360.0) * DEG;
    let ambient = rng.random_range(0.25..0.5);
    let albedo = rng.random_range(150.0..230.0);
    Lighting::beside_camera(albedo, ambient, angle, azimuth)
}

/// The random scenario of `seed`, with one camera or two.
pub fn random_scenario(seed: u64, stereo: bool) -> Scenario {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x005e_ed0f_4a4d_u64);
    // A mid-range pose, and amplitudes across most of each joint's range.
    let mut base = palm_down([0.0; 3], 0.0);
    let mut amplitudes = vec![
        (4, rng.random_range(20.0..60.0)),
        (5, rng.random_range(20.0..60.0)),
        (6, rng.random_range(10.0..40.0)),
    ];
    for (s, value) in base.iter_mut().enumerate().skip(7) {
        let (lo, hi) = joint_range(s);
        let centre = lo + (hi - lo) * rng.random_range(0.35..0.65);
        *value = centre;
        let room = (centre - lo).min(hi - centre);
        amplitudes.push((s, room * rng.random_range(0.7..1.0)));
    }
    let target = hand_centre(&palm_down([0.3, 0.4, 0.3], 0.0));
    let azimuth = rng.random_range(0.0..360.0) * DEG;
    let elevation = rng.random_range(20.0..90.0) * DEG;
    let distance = rng.random_range(350.0..1500.0);
    let span_px = rng.random_range(120.0..350.0);
    let first = hemisphere_camera("cam0", target, azimuth, elevation, distance, span_px);
    let mut cameras = vec![first];
    if stereo {
        // The second camera sits `baseline` mm to the side of the first (across its view,
        // in the table plane), both verging on the hand.
        let baseline = rng.random_range(150.0..600.0);
        let [tx, ty, tz] = target;
        let side = [azimuth.cos(), -azimuth.sin(), 0.0];
        let eye0 = [
            tx + distance * elevation.cos() * azimuth.sin(),
            ty + distance * elevation.cos() * azimuth.cos(),
            tz + distance * elevation.sin(),
        ];
        let eye1 = [
            eye0[0] + baseline * side[0],
            eye0[1] + baseline * side[1],
            eye0[2],
        ];
        let d1 = ((eye1[0] - tx).powi(2) + (eye1[1] - ty).powi(2) + (eye1[2] - tz).powi(2)).sqrt();
        cameras.push(camera_at("cam1", target, eye1, span_px * distance / d1, d1));
    }
    let turn = rng.random_range(15.0..40.0) * DEG;
    Scenario {
        name: if stereo {
            "random-stereo"
        } else {
            "random-mono"
        },
        summary:
            "a seeded random rig (1 or 2 cameras on the upper hemisphere) and whole-hand motion",
        cameras,
        base,
        free: (0..28).collect(),
        amplitudes,
        rotation: Some([turn, turn, turn]),
        peak_tip_speed: rng.random_range(3.0..8.0),
        noise: rng.random_range(1.0..6.0),
        blur: rng.random_range(0.3..1.2),
        clutter: false,
        // Drawn last, so the rig, the motion, the noise and the blur of a seed are those it
        // had before the lighting was varied.
        lighting: random_lighting(&mut rng),
    }
}

/// The thesis' stereo rig (Sec. 4.3.3): two cameras behind the wrist, 60° above the table,
/// 200 mm apart, the fingers seen foreshortened; moderate motion from a flat, spread hand.
pub fn thesis_stereo() -> Scenario {
    let distance = 600.0;
    let (elevation, span_px) = (60.0 * DEG, 260.0);
    let base = palm_down([0.05, 0.05, 0.05], 0.12);
    let target = hand_centre(&base);
    let cameras = vec![
        hemisphere_camera("cam0", target, 170.5 * DEG, elevation, distance, span_px),
        hemisphere_camera("cam1", target, 189.5 * DEG, elevation, distance, span_px),
    ];
    let mut amplitudes = vec![(4, 20.0), (5, 20.0), (6, 10.0)];
    for finger in 0..4 {
        let s = 7 + 4 * finger;
        amplitudes.extend([(s, 0.1), (s + 1, 0.5), (s + 2, 0.6), (s + 3, 0.4)]);
    }
    amplitudes.extend([(23, 0.3), (24, 0.2), (25, 0.15), (26, 0.3), (27, 0.4)]);
    Scenario {
        name: "thesis-stereo",
        summary:
            "the thesis' stereo rig: two cameras behind the wrist, 60° up; a flat hand that curls",
        cameras,
        base,
        free: (0..28).collect(),
        amplitudes,
        rotation: Some([10.0 * DEG, 10.0 * DEG, 10.0 * DEG]),
        peak_tip_speed: 4.0,
        noise: 2.0,
        blur: 0.5,
        clutter: false,
        lighting: Lighting::default(),
    }
}

/// The scenario of this module called `name`, for `seed`.
pub fn by_name(name: &str, seed: u64) -> Option<Scenario> {
    match name {
        "random-mono" => Some(random_scenario(seed, false)),
        "random-stereo" => Some(random_scenario(seed, true)),
        "thesis-stereo" => Some(thesis_stereo()),
        _ => None,
    }
}

/// `scenario` with every camera's focal length times `factor` (a wider view).
pub fn zoomed(scenario: &Scenario, factor: f64) -> Scenario {
    let cameras = scenario
        .cameras
        .iter()
        .map(|c| {
            let mut c = resized(c, c.width, c.height);
            c.fx *= factor;
            c.fy *= factor;
            c
        })
        .collect();
    Scenario {
        cameras,
        ..scenario.clone()
    }
}
