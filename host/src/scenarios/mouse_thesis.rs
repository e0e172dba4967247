//! The thesis' 3D-mouse trial (Rehg 1995, Sec. 4.3.4, Figs. 4.11–4.13) as a scripted motion:
//! scenario `mouse-thesis`.
//!
//! The thesis' mouse sub-model is the palm with 3 DOF in the table plane (two translations and
//! the rotation about the table's normal), finger 1's three flexion joints, and finger 4's and
//! the thumb's abduction as two buttons, seen by one camera at about 45° to the table. Its
//! 500-frame trial had four phases, which this script replays (in *thesis frames* `t`, 0..500):
//!
//! | phase | thesis frames | what moves |
//! | --- | --- | --- |
//! | 1 | 0–150 | finger 1 is raised and lowered twice (two peaks of the pole's height) |
//! | 2 | 150–200 | finger 1 is raised and held up while the thumb clicks twice |
//! | 3 | 200–350 | the palm slides and yaws on the table, the finger held up (height constant) |
//! | 4 | 350–500 | everything at once: the finger lowers and rises twice, the palm slides and yaws, the thumb clicks once and finger 4 twice |
//!
//! A sequence of `N` frames plays the whole script: frame `k` is thesis frame `500 k / N`, so
//! `--frames 500` is the thesis' pace and a shorter sequence is the same trial, faster (its
//! phases shrink in proportion). The motion is deterministic; the seed only changes the noise.
//!
//! The palm keeps the table set-up's height (q6 fixed) and tilt: its rotation is the base
//! rotation turned about the world's z axis (the table's normal), so only yaw changes. The
//! tracker estimates it through the free quaternion (all four states, as they are free
//! together), so it is free to tilt the palm too; the script never does.
//!
//! The pole ([`crate::mouse_pole`]) reads: base = palm (q4, q5); height = finger 1's fingertip
//! above the table — about 1 mm with the finger lowered, about 48 mm raised.

use anyhow::{bail, Result};
use digiteyes_core::camera::Camera;
use digiteyes_core::model::Model;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use super::{measure, VIEW_MARGIN_PX};

/// The scenario's name.
pub const NAME: &str = "mouse-thesis";

/// Frames of the thesis' trial: a sequence of this many frames plays the script at its pace.
pub const THESIS_FRAMES: usize = 500;

/// Where each phase ends (thesis frames); phase 1 starts at 0.
pub const PHASE_ENDS: [f64; 4] = [150.0, 200.0, 350.0, 500.0];

/// The free states: the palm's quaternion (all four, for the yaw), its x and y on the table,
/// finger 1's three flexions, finger 4's abduction and the thumb's (the two buttons).
pub const FREE: [usize; 11] = [0, 1, 2, 3, 4, 5, 8, 9, 10, 19, 24];

/// Finger 1's flexion states (MCP, PIP, DIP).
const FINGER1: [usize; 3] = [8, 9, 10];
/// Finger 1 lowered (rad): the fingertip just above the table (~1 mm).
const FINGER1_LOWERED: [f64; 3] = [-0.05, 0.3, 0.3];
/// Finger 1 raised (rad): the MCP extended above the palm's plane, the fingertip ~48 mm up.
const FINGER1_RAISED: [f64; 3] = [-0.4, 0.1, 0.1];

/// Finger 4's abduction (a button).
const FINGER4_ABDUCTION: usize = 19;
/// The thumb's abduction (a button).
const THUMB_ABDUCTION: usize = 24;
/// How far a click turns its joint from rest (rad): well beyond the mouse's press threshold
/// (0.15 rad), well inside the joint's range.
pub const CLICK_RAD: f64 = 0.25;
/// The thumb clicks outwards, from under the palm towards finger 1's side (q24 increasing).
const THUMB_CLICK_SIGN: f64 = 1.0;
/// Finger 4 clicks away from finger 3 (q19 increasing).
const FINGER4_CLICK_SIGN: f64 = 1.0;

/// Thumb clicks: (start, end) in thesis frames.
pub const THUMB_CLICKS: [(f64, f64); 3] = [(166.0, 182.0), (184.0, 200.0), (410.0, 430.0)];
/// Finger 4 clicks: (start, end) in thesis frames.
pub const FINGER4_CLICKS: [(f64, f64); 2] = [(365.0, 385.0), (455.0, 475.0)];

/// Phase 2 raises the finger over these thesis frames, before the thumb clicks.
const RAISE: (f64, f64) = (150.0, 166.0);
/// Phase 1's raise-and-lower period (thesis frames): two in 150.
const PHASE1_PERIOD: f64 = 75.0;
/// Phase 4's lower-and-raise period (thesis frames): the finger starts up, is down at 400,
/// up at 450 and down at 500.
const PHASE4_PERIOD: f64 = 100.0;

/// Phase 3's palm path: x and y amplitude (mm) and yaw amplitude (rad).
const PHASE3_PATH: (f64, f64, f64) = (30.0, 15.0, 0.2);
/// Phase 4's palm path: x and y amplitude (mm) and yaw amplitude (rad).
const PHASE4_PATH: (f64, f64, f64) = (-25.0, 12.0, -0.15);

/// The base pose of the trial, from the table set-up's `table_pose` (quaternion, mm, rad):
/// finger 1 lowered, the rest as given.
pub fn base_pose(mut table_pose: Vec<f64>) -> Vec<f64> {
    for (s, v) in FINGER1.iter().zip(FINGER1_LOWERED) {
        table_pose[*s] = v;
    }
    table_pose
}

/// The thesis frame shown by frame `k` of an `n`-frame sequence.
pub fn thesis_time(k: usize, n: usize) -> f64 {
    k as f64 * THESIS_FRAMES as f64 / n.max(1) as f64
}

/// The phase (1..=4) of thesis frame `t`.
pub fn phase(t: f64) -> usize {
    PHASE_ENDS.iter().position(|&end| t < end).unwrap_or(3) + 1
}

/// The first frame of each phase in an `n`-frame sequence, and `n`: phase `p` (1..=4) is
/// frames `bounds[p - 1]..bounds[p]`.
pub fn phase_frames(n: usize) -> [usize; 5] {
    let mut bounds = [0, 0, 0, 0, n];
    for (p, b) in bounds.iter_mut().enumerate().skip(1).take(3) {
        *b = (0..n).find(|&k| phase(thesis_time(k, n)) > p).unwrap_or(n);
    }
    bounds
}

/// 0 at `u <= 0`, 1 at `u >= 1`, smooth with zero slope at both ends.
fn smoothstep(u: f64) -> f64 {
    let u = u.clamp(0.0, 1.0);
    u * u * (3.0 - 2.0 * u)
}

/// A click's deflection in 0..=1 at thesis frame `t`: a sin² bump over each window.
fn clicks(t: f64, windows: &[(f64, f64)]) -> f64 {
    windows
        .iter()
        .filter(|(a, b)| (*a..*b).contains(&t))
        .map(|(a, b)| (std::f64::consts::PI * (t - a) / (b - a)).sin().powi(2))
        .sum()
}

/// How far finger 1 is raised at thesis frame `t`: 0 lowered, 1 raised.
fn raise(t: f64) -> f64 {
    use std::f64::consts::PI;
    let [p1, _, p3, _] = PHASE_ENDS;
    if t < p1 {
        (PI * t / PHASE1_PERIOD).sin().powi(2)
    } else if t < RAISE.1 {
        smoothstep((t - RAISE.0) / (RAISE.1 - RAISE.0))
    } else if t < p3 {
        1.0
    } else {
        (PI * (t - p3) / PHASE4_PERIOD).cos().powi(2)
    }
}

/// The palm on the table at thesis frame `t`: x, y (mm) and yaw (rad) from the base pose.
fn palm(t: f64) -> (f64, f64, f64) {
    use std::f64::consts::TAU;
    let [_, p2, p3, p4] = PHASE_ENDS;
    let path = |e: f64, (ax, ay, ayaw): (f64, f64, f64)| {
        let (s, c) = (TAU * e).sin_cos();
        (ax * s, ay * (1.0 - c), ayaw * s)
    };
    if t < p2 {
        (0.0, 0.0, 0.0)
    } else if t < p3 {
        path(smoothstep((t - p2) / (p3 - p2)), PHASE3_PATH)
    } else {
        path(smoothstep((t - p3) / (p4 - p3)), PHASE4_PATH)
    }
}

/// The whole state at thesis frame `t` (quaternion, mm, rad), from `base` ([`base_pose`]).
pub fn state_at(base: &[f64], t: f64) -> Vec<f64> {
    let mut q = base.to_vec();
    let r = raise(t);
    for (k, &s) in FINGER1.iter().enumerate() {
        q[s] = FINGER1_LOWERED[k] + r * (FINGER1_RAISED[k] - FINGER1_LOWERED[k]);
    }
    let (x, y, yaw) = palm(t);
    q[4] += x;
    q[5] += y;
    let turned = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw)
        * UnitQuaternion::from_quaternion(Quaternion::new(base[0], base[1], base[2], base[3]));
    (q[0], q[1], q[2], q[3]) = (turned.w, turned.i, turned.j, turned.k);
    q[THUMB_ABDUCTION] += THUMB_CLICK_SIGN * CLICK_RAD * clicks(t, &THUMB_CLICKS);
    q[FINGER4_ABDUCTION] += FINGER4_CLICK_SIGN * CLICK_RAD * clicks(t, &FINGER4_CLICKS);
    q
}

/// The `frames` states of the trial from `base`, checked to keep every joint in the model's
/// range and the hand in view of `cameras` (at their full size).
pub fn sample(
    model: &Model,
    cameras: &[Camera],
    base: &[f64],
    frames: usize,
) -> Result<Vec<Vec<f64>>> {
    let truth: Vec<Vec<f64>> = (0..frames)
        .map(|k| state_at(base, thesis_time(k, frames)))
        .collect();
    for (k, q) in truth.iter().enumerate() {
        for (s, &v) in q.iter().enumerate() {
            if let Some(l) = model.limit(s) {
                if !(f64::from(l.lo)..=f64::from(l.hi)).contains(&v) {
                    bail!(
                        "{NAME}: frame {k}: q{s} = {v} rad leaves its range {} .. {} rad",
                        l.lo,
                        l.hi
                    );
                }
            }
        }
    }
    measure::check_in_view(model, cameras, &truth, VIEW_MARGIN_PX)?;
    Ok(truth)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mouse_pole::{MouseConfig, MouseMapper};
    use crate::scenarios::scenario;

    fn base() -> Vec<f64> {
        scenario(NAME).unwrap().base
    }

    fn f32s(q: &[f64]) -> Vec<f32> {
        q.iter().map(|&v| v as f32).collect()
    }

    /// The pole at every thesis frame 0..500 (one per frame).
    fn poles() -> Vec<crate::mouse_pole::MousePole> {
        let base = base();
        let model = Model::hand().unwrap();
        let mut mouse = MouseMapper::new(&model, &f32s(&base), MouseConfig::default()).unwrap();
        (0..THESIS_FRAMES)
            .map(|k| mouse.update(&f32s(&state_at(&base, k as f64))).unwrap())
            .collect()
    }

    #[test]
    fn phases_cover_the_sequence_in_the_thesis_proportions() {
        assert_eq!(phase_frames(500), [0, 150, 200, 350, 500]);
        assert_eq!(phase_frames(250), [0, 75, 100, 175, 250]);
        assert_eq!(phase_frames(4), [0, 2, 2, 3, 4]);
        assert_eq!(phase(0.0), 1);
        assert_eq!(phase(199.9), 2);
        assert_eq!(phase(499.0), 4);
    }

    #[test]
    fn phase_1_raises_the_pole_twice_and_lowers_it_to_the_table() {
        let poles = poles();
        let h = |k: usize| poles[k].height_mm;
        assert!(h(0) < 3.0, "lowered: {} mm", h(0));
        for peak in [37, 112] {
            assert!(
                (40.0..60.0).contains(&h(peak)),
                "frame {peak}: {} mm",
                h(peak)
            );
        }
        assert!(h(75) < 3.0 && h(149) < 3.0, "{} {}", h(75), h(149));
        // The base stays and no button is pressed.
        for p in &poles[..150] {
            assert_eq!((p.x_mm, p.y_mm, p.buttons), (0.0, 0.0, [false, false]));
        }
    }

    #[test]
    fn phase_2_holds_the_finger_up_while_the_thumb_clicks_twice() {
        let poles = poles();
        let held: Vec<f32> = poles[166..200].iter().map(|p| p.height_mm).collect();
        assert!(held.iter().all(|&h| (h - held[0]).abs() < 0.01 && h > 40.0));
        let thumb: Vec<bool> = poles[150..200].iter().map(|p| p.buttons[1]).collect();
        let presses = thumb.windows(2).filter(|w| !w[0] && w[1]).count();
        assert_eq!(presses, 2, "{thumb:?}");
        assert!(poles[150..200].iter().all(|p| !p.buttons[0]));
    }

    #[test]
    fn phase_3_slides_and_yaws_the_palm_at_a_constant_height() {
        let base = base();
        let poles = poles();
        let h0 = poles[200].height_mm;
        assert!(poles[200..350]
            .iter()
            .all(|p| (p.height_mm - h0).abs() < 0.01 && p.buttons == [false, false]));
        let reach = poles[200..350]
            .iter()
            .map(|p| p.x_mm.hypot(p.y_mm))
            .fold(0.0, f32::max);
        assert!(reach > 25.0, "the base moved {reach} mm");
        // Pure yaw: the palm's normal keeps its angle to the table.
        let normal = |q: &[f64]| {
            let r = UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]));
            r * Vector3::z()
        };
        let n0 = normal(&base);
        let mut yaw_max = 0.0f64;
        for t in 200..350 {
            let q = state_at(&base, t as f64);
            assert!((normal(&q).z - n0.z).abs() < 1e-12, "frame {t} tilts");
            assert_eq!(q[6], base[6]);
            let a = UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]));
            let b = UnitQuaternion::from_quaternion(Quaternion::new(
                base[0], base[1], base[2], base[3],
            ));
            yaw_max = yaw_max.max(a.angle_to(&b));
        }
        assert!(yaw_max > 0.15, "yaw {yaw_max} rad");
    }

    #[test]
    fn phase_4_moves_everything_and_both_buttons_click() {
        let poles = poles();
        let part = &poles[350..500];
        let presses = |b: usize| {
            part.windows(2)
                .filter(|w| !w[0].buttons[b] && w[1].buttons[b])
                .count()
        };
        assert_eq!((presses(0), presses(1)), (2, 1));
        let heights: Vec<f32> = part.iter().map(|p| p.height_mm).collect();
        assert!(heights.iter().any(|&h| h < 3.0) && heights.iter().any(|&h| h > 40.0));
        assert!(part.iter().any(|p| p.x_mm.hypot(p.y_mm) > 15.0));
    }

    #[test]
    fn the_trial_stays_in_range_and_in_view_and_ends_at_rest() {
        let s = scenario(NAME).unwrap();
        let model = Model::hand().unwrap();
        let cameras = crate::sequence::check_cameras(&s.cameras).unwrap();
        let truth = sample(&model, &cameras, &s.base, THESIS_FRAMES).unwrap();
        assert_eq!(truth[0], s.base);
        let end = state_at(&s.base, 500.0);
        for (a, b) in end.iter().zip(&s.base) {
            assert!((a - b).abs() < 1e-9, "{end:?}");
        }
    }

    #[test]
    fn shorter_sequences_play_the_same_trial_faster() {
        let s = scenario(NAME).unwrap();
        let model = Model::hand().unwrap();
        let cameras = crate::sequence::check_cameras(&s.cameras).unwrap();
        let full = sample(&model, &cameras, &s.base, 500).unwrap();
        let half = sample(&model, &cameras, &s.base, 250).unwrap();
        for k in 0..250 {
            assert_eq!(half[k], full[2 * k]);
        }
    }
}
