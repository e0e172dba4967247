//! The named scenarios: which states move, how far, how fast, and who watches.
//!
//! Two set-ups share the world frames:
//! - *table* (`mouse`, `mouse-thesis`, `fast`, `clutter`, `twofinger`): world z up, the table is z = 0; the
//!   hand lies palm-down 45 mm above it, fingers along +y. The mouse camera looks down at 45°
//!   from behind the wrist (camera and pose copied from the conformance fixture
//!   `sample-mouse`); the two-finger camera looks down at 50° from in front of the fingertips.
//! - *facing* (`rigid`, `fullhand-*`): the world is the palm frame at rest (fingers along +y,
//!   palm side +z); cameras 550–650 mm away on the palm side look at the hand, fingers up.

use anyhow::{bail, Result};

use super::cameras::look_at;
use super::mouse_thesis;
use crate::render::Lighting;
use crate::sequence::CameraFile;

/// Every scenario name, in the order `--help` lists them.
pub const NAMES: [&str; 8] = [
    "mouse",
    "mouse-thesis",
    "rigid",
    "twofinger",
    "fullhand-stereo",
    "fullhand-mono",
    "fast",
    "clutter",
];

/// One scenario's definition.
#[derive(Debug, Clone, PartialEq)]
pub struct Scenario {
    /// Its name.
    pub name: &'static str,
    /// One line for `--help` and reports.
    pub summary: &'static str,
    /// The cameras (default size 640×480).
    pub cameras: Vec<CameraFile>,
    /// The pose at frame 0 (quaternion, mm, rad).
    pub base: Vec<f64>,
    /// The states the tracker estimates.
    pub free: Vec<usize>,
    /// `(state, amplitude)` of the moving states other than the quaternion (mm or rad);
    /// amplitudes are cut to keep joints inside the model's ranges.
    pub amplitudes: Vec<(usize, f64)>,
    /// Palm rotation amplitudes about its own x, y, z axes (rad), when it turns.
    pub rotation: Option<[f64; 3]>,
    /// The fastest fingertip's image speed at its peak (px/frame, at 640×480); 0 for a
    /// scripted scenario, whose pace the script and the frame count set.
    pub peak_tip_speed: f64,
    /// Noise standard deviation (grey levels).
    pub noise: f32,
    /// Blur standard deviation (px).
    pub blur: f32,
    /// Whether the background is cluttered.
    pub clutter: bool,
    /// How the hand is lit.
    pub lighting: Lighting,
}

/// The fixture's camera: 45° above the table, looking at the hand.
fn table_camera() -> CameraFile {
    CameraFile {
        name: Some("cam0".into()),
        width: 640,
        height: 480,
        fx: 1000.0,
        fy: 1000.0,
        cx: 319.5,
        cy: 239.5,
        r: [
            [0.7071067811865475, -0.7071067811865477, 0.0],
            [
                -0.5000000000000001,
                -0.4999999999999999,
                -0.7071067811865477,
            ],
            [0.5000000000000001, 0.5, -0.7071067811865475],
        ],
        t: [26.154060882418502, 25.070263925050817, 520.0828363140029],
    }
}

/// The fixture's initial state: palm-down, 45 mm above the table, fingers slightly curled.
fn table_pose() -> Vec<f64> {
    vec![
        0.0,
        0.0,
        0.9975510002532796,
        -0.0699428473375328,
        0.0,
        0.0,
        45.0,
        0.0,
        0.3,
        0.4,
        0.3,
        0.0,
        0.3,
        0.4,
        0.3,
        0.0,
        0.3,
        0.4,
        0.3,
        0.0,
        0.3,
        0.4,
        0.3,
        0.3,
        -0.15,
        0.0,
        -0.4,
        -0.5,
    ]
}

/// A camera in front of the fingertips, 50° above the table: the fingers lie side by side
/// in the image and their flexion moves them up and down it.
fn fingertip_camera() -> CameraFile {
    let target = [-15.0, 45.0, 25.0];
    let (azimuth, elevation, distance) = (-25.0 * DEG, 50.0 * DEG, 520.0);
    let eye = [
        target[0] + distance * elevation.cos() * azimuth.sin(),
        target[1] + distance * elevation.cos() * azimuth.cos(),
        target[2] + distance * elevation.sin(),
    ];
    look_at("cam0", eye, target, [0.0, 0.0, 1.0])
}

/// Fingers point up the image.
const FINGERS_UP: [f64; 3] = [0.0, 1.0, 0.0];
/// The hand lies across the (landscape) image, fingers right, thumb down.
const THUMB_DOWN: [f64; 3] = [-1.0, 0.0, 0.0];

/// Where the facing cameras look: the middle of the hand at rest (palm frame, mm).
const FACING_TARGET: [f64; 3] = [8.0, 50.0, 0.0];

/// A camera on the palm side, `azimuth` rad around the palm's y axis (towards finger 1 for
/// positive angles) and `elevation` rad towards the fingertips (below the wrist if negative),
/// `distance` mm from [`FACING_TARGET`], with world direction `up` pointing up the image.
fn facing_camera(
    name: &str,
    azimuth: f64,
    elevation: f64,
    distance: f64,
    up: [f64; 3],
) -> CameraFile {
    let [tx, ty, tz] = FACING_TARGET;
    let eye = [
        tx + distance * elevation.cos() * azimuth.sin(),
        ty + distance * elevation.sin(),
        tz + distance * elevation.cos() * azimuth.cos(),
    ];
    look_at(name, eye, [tx, ty, tz], up)
}

/// A pose of the facing set-up: palm at the origin, fingers spread (abduction of fingers
/// 1..4, rad; negative spreads finger 1 away from finger 2) and curled (MCP, PIP, DIP, rad).
fn facing_pose(spread: [f64; 4], curl: [f64; 3]) -> Vec<f64> {
    let mut q = vec![1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    for spread in spread {
        q.extend([spread, curl[0], curl[1], curl[2]]);
    }
    q.extend([0.3, -0.15, 0.0, -0.3, -0.3]);
    q
}

const DEG: f64 = std::f64::consts::PI / 180.0;

/// The 3D-mouse sub-model's free states (as in the fixture).
const MOUSE_FREE: [usize; 7] = [4, 5, 8, 9, 10, 19, 24];

fn mouse(name: &'static str, summary: &'static str, speed: f64) -> Scenario {
    Scenario {
        name,
        summary,
        cameras: vec![table_camera()],
        base: table_pose(),
        free: MOUSE_FREE.to_vec(),
        amplitudes: vec![
            (4, 30.0),
            (5, 25.0),
            (8, 0.3),
            (9, 0.4),
            (10, 0.3),
            (19, 0.3),
            (24, 0.3),
        ],
        rotation: None,
        peak_tip_speed: speed,
        noise: 2.0,
        blur: 0.5,
        clutter: false,
        lighting: Lighting::default(),
    }
}

fn fullhand(name: &'static str, summary: &'static str, cameras: Vec<CameraFile>) -> Scenario {
    let mut amplitudes = vec![(4, 15.0), (5, 15.0), (6, 15.0)];
    for finger in 0..4 {
        let s = 7 + 4 * finger;
        amplitudes.extend([(s, 0.1), (s + 1, 0.25), (s + 2, 0.3), (s + 3, 0.2)]);
    }
    amplitudes.extend([(23, 0.2), (24, 0.2), (25, 0.15), (26, 0.25), (27, 0.3)]);
    Scenario {
        name,
        summary,
        cameras,
        base: facing_pose([-0.22, -0.08, 0.08, 0.22], [0.3, 0.35, 0.25]),
        free: (0..28).collect(),
        amplitudes,
        rotation: Some([10.0 * DEG, 10.0 * DEG, 10.0 * DEG]),
        peak_tip_speed: 5.0,
        noise: 2.0,
        blur: 0.5,
        clutter: false,
        lighting: Lighting::default(),
    }
}

/// The scenario called `name`.
pub fn scenario(name: &str) -> Result<Scenario> {
    Ok(match name {
        "mouse" => mouse(
            "mouse",
            "3D-mouse sub-model: palm slides on the table, finger 1 flexes, finger 4 and thumb abduct; one camera at 45°",
            4.0,
        ),
        "mouse-thesis" => Scenario {
            name: mouse_thesis::NAME,
            summary: "the thesis' 3D-mouse trial in four phases: finger 1 raised and lowered twice, held up while the thumb clicks, palm slides and yaws, all at once (--frames 500: the thesis' pace); one camera at 45°",
            cameras: vec![table_camera()],
            base: mouse_thesis::base_pose(table_pose()),
            free: mouse_thesis::FREE.to_vec(),
            amplitudes: Vec::new(),
            rotation: None,
            peak_tip_speed: 0.0,
            noise: 2.0,
            blur: 0.5,
            clutter: false,
            lighting: Lighting::default(),
        },
        "fast" => mouse(
            "fast",
            "the mouse motion, fingertips moving 20 px/frame at the peak",
            20.0,
        ),
        "clutter" => Scenario {
            noise: 8.0,
            clutter: true,
            ..mouse(
                "clutter",
                "the mouse motion over a cluttered, textured background with noise σ 8",
                4.0,
            )
        },
        "rigid" => Scenario {
            name: "rigid",
            summary: "palm pose only (q0..q6): ±20° rotation, ±30 mm translation; fingers fixed",
            cameras: vec![facing_camera("cam0", 35.0 * DEG, 20.0 * DEG, 520.0, THUMB_DOWN)],
            base: facing_pose([-0.12, -0.04, 0.04, 0.12], [0.15, 0.2, 0.1]),
            free: (0..7).collect(),
            amplitudes: vec![(4, 30.0), (5, 30.0), (6, 20.0)],
            rotation: Some([20.0 * DEG, 20.0 * DEG, 20.0 * DEG]),
            peak_tip_speed: 6.0,
            noise: 2.0,
            blur: 0.5,
            clutter: false,
            lighting: Lighting::default(),
        },
        "twofinger" => {
            let mut base = table_pose();
            base[8..11].copy_from_slice(&[0.5, 0.6, 0.4]);
            base[12..15].copy_from_slice(&[0.5, 0.6, 0.4]);
            // Fingers 3 and 4 curled under the palm, out of the way.
            base[16..19].copy_from_slice(&[1.3, 1.5, 1.1]);
            base[20..23].copy_from_slice(&[1.3, 1.5, 1.1]);
            Scenario {
                name: "twofinger",
                summary: "two-finger sub-model: fingers 1 and 2 flex (3 joints each), palm translates in 3D",
                cameras: vec![fingertip_camera()],
                base,
                free: vec![4, 5, 6, 8, 9, 10, 12, 13, 14],
                amplitudes: vec![
                    (4, 25.0),
                    (5, 25.0),
                    (6, 15.0),
                    (8, 0.4),
                    (9, 0.5),
                    (10, 0.35),
                    (12, 0.4),
                    (13, 0.5),
                    (14, 0.35),
                ],
                rotation: None,
                peak_tip_speed: 5.0,
                noise: 2.0,
                blur: 0.5,
                clutter: false,
                lighting: Lighting::default(),
            }
        }
        "fullhand-stereo" => fullhand(
            "fullhand-stereo",
            "all 28 states move; two cameras 35° apart face the palm",
            vec![
                facing_camera("cam0", -17.5 * DEG, -8.5 * DEG, 650.0, FINGERS_UP),
                facing_camera("cam1", 17.5 * DEG, -8.5 * DEG, 650.0, FINGERS_UP),
            ],
        ),
        "fullhand-mono" => fullhand(
            "fullhand-mono",
            "the fullhand-stereo motion seen by its first camera only",
            vec![facing_camera("cam0", -17.5 * DEG, -8.5 * DEG, 650.0, FINGERS_UP)],
        ),
        other => bail!(
            "unknown scenario `{other}`; scenarios are: {}",
            NAMES.join(", ")
        ),
    })
}
