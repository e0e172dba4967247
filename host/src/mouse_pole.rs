//! The 3D mouse of the thesis (Rehg 1995, Sec. 4.3.4): the mouse sub-model's states read as a
//! pole standing on the table, with two buttons.
//!
//! The thesis' mouse sub-model (scenario `mouse-thesis`) frees the palm's 3 DOF in the table
//! plane — its translation (q4, q5) and its rotation about the table's normal, through the
//! quaternion (q0..q3, free together) — finger 1's three flexions (q8, q9, q10), finger 4's
//! abduction (q19) and the thumb's (q24); the `mouse` scenario (the `sample-mouse` fixture's
//! sub-model) keeps the palm's rotation fixed. In the table set-up (world z up, the table is
//! z = 0, the hand palm-down above it):
//!
//! - the pole's **base** follows the palm across the table: `(x, y) = (q4, q5)` mm, world
//!   (the palm's yaw moves the hand, not the base);
//! - its **height** follows finger 1's fingertip: the world z of the `finger1.tip` frame's
//!   origin minus the fingertip radius, i.e. the gap between the fingertip's surface and the
//!   table (mm, clamped at 0). Raising finger 1 (its MCP extended, q8 < 0) lifts the pole;
//!   flexing it curls it towards the palm side — down, for a palm-down hand — and lowers it;
//! - its two **buttons** are finger 4's and the thumb's abduction: a button is pressed when
//!   its angle is more than [`MouseConfig::press_rad`] from its rest value (the sequence's
//!   initial state) and released again only once back within [`MouseConfig::release_rad`] —
//!   hysteresis, so a noisy angle near the threshold does not chatter.

pub mod accuracy;

use anyhow::{anyhow, bail, Context, Result};
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::{Model, Shape};
use serde::Serialize;

/// The model frame whose origin gives the pole's height: finger 1's fingertip.
pub const HEIGHT_TIP: &str = "finger1.tip";

/// States of the pole's base: the palm's world x and y (mm) (not the model's
/// `model::BASE_STATES`, the count of palm states).
pub const POLE_BASE_STATES: [usize; 2] = [4, 5];

/// The state driving each button by default: finger 4's abduction (q19) and the thumb's
/// first trapeziometacarpal joint, its abduction (q24) (rad).
pub const BUTTON_STATES: [usize; 2] = [19, 24];

/// One reading of the 3D mouse.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct MousePole {
    /// The pole's base on the table: world x (mm), the palm's q4.
    pub x_mm: f32,
    /// The pole's base on the table: world y (mm), the palm's q5.
    pub y_mm: f32,
    /// The pole's height: finger 1's fingertip surface above the table (mm, >= 0).
    pub height_mm: f32,
    /// Finger 1's fingertip surface: its world z (mm), not clamped. Below 0 the fingertip is
    /// below the table plane — possible in synthetic scenes, which have no table to stop it
    /// (the `mouse` scenario's curled finger 1 reaches a few mm below z = 0), so the pole
    /// stays at 0 while this still follows the finger.
    pub tip_z_mm: f32,
    /// The buttons: `[finger 4 abduction, thumb abduction]` by default; `true` = pressed.
    pub buttons: [bool; 2],
}

/// The thresholds of the buttons.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct MouseConfig {
    /// A released button is pressed when its angle is more than this from rest (rad).
    pub press_rad: f32,
    /// A pressed button is released when its angle is less than this from rest (rad); below
    /// `press_rad`, so the gap between them is the hysteresis.
    pub release_rad: f32,
    /// The state driving each button (default [`BUTTON_STATES`]).
    pub button_states: [usize; 2],
}

impl Default for MouseConfig {
    fn default() -> Self {
        MouseConfig {
            press_rad: 0.15,
            release_rad: 0.10,
            button_states: BUTTON_STATES,
        }
    }
}

/// Turns hand states into [`MousePole`] readings, remembering which buttons are down.
#[derive(Debug, Clone)]
pub struct MouseMapper {
    model: Model,
    poses: Poses,
    tip: usize,
    tip_radius_mm: f32,
    rest: [f32; 2],
    config: MouseConfig,
    pressed: [bool; 2],
}

impl MouseMapper {
    /// A mapper for `model` (the built-in hand or any model with a `finger1.tip` frame and
    /// the button states), with the buttons' angles at rest taken from `rest`, a whole state
    /// vector (quaternion, mm, rad) — usually the sequence's initial state. Both buttons start
    /// released.
    pub fn new(model: &Model, rest: &[f32], config: MouseConfig) -> Result<MouseMapper> {
        let valid = |v: f32| v.is_finite() && v >= 0.0;
        if !valid(config.press_rad) || !valid(config.release_rad) {
            bail!(
                "mouse: button thresholds must be finite and >= 0 rad (press {}, release {})",
                config.press_rad,
                config.release_rad
            );
        }
        if config.release_rad > config.press_rad {
            bail!(
                "mouse: the release threshold ({} rad) is above the press threshold ({} rad)",
                config.release_rad,
                config.press_rad
            );
        }
        let n = model.n_states();
        for s in POLE_BASE_STATES.iter().chain(&config.button_states) {
            if *s >= n {
                bail!("mouse: the model has {n} states, no q{s}");
            }
        }
        let tip = model
            .find(HEIGHT_TIP)
            .ok_or_else(|| anyhow!("mouse: the model has no frame `{HEIGHT_TIP}`"))?;
        let tip_radius_mm = match model.links()[tip].shape {
            Shape::Tip { radius } => radius,
            _ => 0.0,
        };
        let poses = Poses::compute(model, rest).map_err(|e| anyhow!("mouse: rest state: {e}"))?;
        let [a, b] = config.button_states;
        Ok(MouseMapper {
            model: model.clone(),
            poses,
            tip,
            tip_radius_mm,
            rest: [rest[a], rest[b]],
            config,
            pressed: [false; 2],
        })
    }

    /// The pole for states `q` (the model's whole state vector: quaternion, mm, rad). Fails,
    /// leaving the buttons as they were, when `q` has the wrong length or a value that is not
    /// finite.
    pub fn update(&mut self, q: &[f32]) -> Result<MousePole> {
        self.poses
            .update(&self.model, q)
            .map_err(|e| anyhow!("{e}"))
            .context("mouse: cannot place the hand")?;
        let tip_z = self
            .poses
            .origin(self.tip)
            .ok_or_else(|| anyhow!("mouse: no pose for `{HEIGHT_TIP}`"))?
            .z;
        for (k, &s) in self.config.button_states.iter().enumerate() {
            let deviation = (q[s] - self.rest[k]).abs();
            self.pressed[k] = if self.pressed[k] {
                deviation >= self.config.release_rad
            } else {
                deviation > self.config.press_rad
            };
        }
        Ok(MousePole {
            x_mm: q[POLE_BASE_STATES[0]],
            y_mm: q[POLE_BASE_STATES[1]],
            height_mm: (tip_z - self.tip_radius_mm).max(0.0),
            tip_z_mm: tip_z - self.tip_radius_mm,
            buttons: self.pressed,
        })
    }

    /// The buttons as they are now (`true` = pressed).
    pub fn buttons(&self) -> [bool; 2] {
        self.pressed
    }

    /// The thresholds in use.
    pub fn config(&self) -> &MouseConfig {
        &self.config
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The `mouse` scenario's initial state: palm-down, 45 mm above the table.
    fn table_pose() -> Vec<f32> {
        crate::scenarios::scenario("mouse")
            .unwrap()
            .base
            .iter()
            .map(|&v| v as f32)
            .collect()
    }

    fn mapper(rest: &[f32]) -> MouseMapper {
        MouseMapper::new(&Model::hand().unwrap(), rest, MouseConfig::default()).unwrap()
    }

    /// Finger 1's fingertip in world coordinates (mm), composed in f64 from the DH rows of
    /// `docs/hand-model.md` written out here, apart from the core's kinematics: the palm's rotation
    /// from its quaternion, then rows 1..6 of the table.
    fn finger1_tip_f64(q: &[f32]) -> [f64; 3] {
        type M = [[f64; 4]; 4];
        fn mul(a: &M, b: &M) -> M {
            let mut c = [[0.0; 4]; 4];
            for (i, row) in c.iter_mut().enumerate() {
                for (j, v) in row.iter_mut().enumerate() {
                    *v = (0..4).map(|k| a[i][k] * b[k][j]).sum();
                }
            }
            c
        }
        fn dh(theta: f64, d: f64, a: f64, alpha: f64) -> M {
            let (s, c) = theta.sin_cos();
            let (sa, ca) = alpha.sin_cos();
            [
                [c, -s * ca, s * sa, a * c],
                [s, c * ca, -c * sa, a * s],
                [0.0, sa, ca, d],
                [0.0, 0.0, 0.0, 1.0],
            ]
        }
        let q: Vec<f64> = q.iter().map(|&v| f64::from(v)).collect();
        let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
        let (w, x, y, z) = (q[0] / n, q[1] / n, q[2] / n, q[3] / n);
        let palm: M = [
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y - w * z),
                2.0 * (x * z + w * y),
                q[4],
            ],
            [
                2.0 * (x * y + w * z),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z - w * x),
                q[5],
            ],
            [
                2.0 * (x * z - w * y),
                2.0 * (y * z + w * x),
                1.0 - 2.0 * (x * x + y * y),
                q[6],
            ],
            [0.0, 0.0, 0.0, 1.0],
        ];
        use std::f64::consts::FRAC_PI_2;
        let rows = [
            dh(FRAC_PI_2, 0.0, 38.0, -FRAC_PI_2),
            dh(0.0, -31.0, 0.0, FRAC_PI_2),
            dh(q[7], 0.0, 0.0, FRAC_PI_2),
            dh(q[8], 0.0, 45.0, 0.0),
            dh(q[9], 0.0, 26.0, 0.0),
            dh(q[10], 0.0, 24.0, 0.0),
        ];
        let w = rows.iter().fold(palm, |acc, row| mul(&acc, row));
        [w[0][3], w[1][3], w[2][3]]
    }

    /// Finger 1's fingertip radius in `hand.dh` (mm).
    const TIP_RADIUS: f64 = 9.0;

    #[test]
    fn the_base_follows_the_palm_on_the_table() {
        let rest = table_pose();
        let mut mouse = mapper(&rest);
        let mut q = rest.clone();
        q[4] = 12.5;
        q[5] = -30.25;
        let pole = mouse.update(&q).unwrap();
        assert_eq!((pole.x_mm, pole.y_mm), (12.5, -30.25));
        assert_eq!(pole.buttons, [false, false]);
    }

    #[test]
    fn the_height_is_analytic_for_a_palm_up_hand() {
        // Palm frame = world moved up 50 mm; finger 1 flexes in the palm frame's y-z plane:
        // its tip is at z = 50 + 45 sin a + 26 sin(a + b) + 24 sin(a + b + c) (docs/hand-model.md:
        // rows 1–3 turn the finger's flexion axis to the palm's x axis, 31 mm out, 38 mm up).
        let mut q = vec![0.0f32; 28];
        q[0] = 1.0;
        q[6] = 50.0;
        let mut mouse = mapper(&q);
        for (a, b, c) in [
            (0.0, 0.0, 0.0),
            (0.3, 0.0, 0.0),
            (0.2, 0.4, 0.3),
            (1.0, 1.2, 0.9),
        ] {
            (q[8], q[9], q[10]) = (a, b, c);
            let (a, b, c) = (f64::from(a), f64::from(b), f64::from(c));
            let z = 50.0 + 45.0 * a.sin() + 26.0 * (a + b).sin() + 24.0 * (a + b + c).sin();
            let pole = mouse.update(&q).unwrap();
            let expected = (z - TIP_RADIUS).max(0.0);
            assert!(
                (f64::from(pole.height_mm) - expected).abs() < 1e-3,
                "q8..q10 = {a} {b} {c}: {} mm, expected {expected}",
                pole.height_mm
            );
            let tip = finger1_tip_f64(&q);
            assert!((tip[2] - z).abs() < 1e-9, "{tip:?} vs z {z}");
            assert!((tip[0] - 31.0).abs() < 1e-9, "{tip:?}");
        }
    }

    #[test]
    fn flexing_finger_1_lowers_the_pole_of_a_palm_down_hand() {
        let rest = table_pose();
        let mut mouse = mapper(&rest);
        let mut q = rest.clone();
        let mut last = f32::INFINITY;
        for step in 0..=6 {
            q[8] = 0.2 * step as f32; // MCP flexion 0 .. 1.2 rad
            let pole = mouse.update(&q).unwrap();
            let tip = finger1_tip_f64(&q);
            let expected = (tip[2] - TIP_RADIUS).max(0.0);
            assert!(
                (f64::from(pole.height_mm) - expected).abs() < 1e-3,
                "q8 = {}: {} mm, the f64 DH chain says {expected}",
                q[8],
                pole.height_mm
            );
            assert!(pole.height_mm >= 0.0);
            assert!(
                (f64::from(pole.tip_z_mm) - (tip[2] - TIP_RADIUS)).abs() < 1e-3,
                "q8 = {}: fingertip surface at {} mm",
                q[8],
                pole.tip_z_mm
            );
            if expected > 0.0 {
                assert!(
                    pole.height_mm < last,
                    "q8 = {}: {} mm",
                    q[8],
                    pole.height_mm
                );
            }
            last = pole.height_mm;
        }
        // Curled far enough, the fingertip reaches the table: the pole stops at 0.
        (q[8], q[9], q[10]) = (1.4, 1.2, 0.6);
        assert!(finger1_tip_f64(&q)[2] < TIP_RADIUS);
        let pole = mouse.update(&q).unwrap();
        assert_eq!(pole.height_mm, 0.0);
        // ... while the fingertip's own height goes on following the finger below it.
        assert!(pole.tip_z_mm < 0.0, "{}", pole.tip_z_mm);
    }

    #[test]
    fn buttons_press_beyond_the_threshold_and_hold_with_hysteresis() {
        let rest = table_pose();
        let mut mouse = mapper(&rest);
        let mut q = rest.clone();
        let mut press = |mouse: &mut MouseMapper, d19: f32, d24: f32| {
            q[19] = rest[19] + d19;
            q[24] = rest[24] + d24;
            mouse.update(&q).unwrap().buttons
        };
        assert_eq!(press(&mut mouse, 0.14, -0.14), [false, false]);
        assert_eq!(press(&mut mouse, 0.16, 0.0), [true, false]);
        assert_eq!(press(&mut mouse, 0.0, -0.16), [false, true]);
        // Between the thresholds a pressed button stays down and a released one stays up.
        assert_eq!(press(&mut mouse, 0.12, -0.12), [false, true]);
        assert_eq!(press(&mut mouse, 0.16, -0.16), [true, true]);
        for d in [0.14, 0.11, 0.13, 0.101, 0.149] {
            assert_eq!(press(&mut mouse, d, -d), [true, true], "{d}");
        }
        assert_eq!(press(&mut mouse, 0.09, -0.05), [false, false]);
        assert_eq!(press(&mut mouse, 0.149, -0.149), [false, false]);
    }

    #[test]
    fn noise_around_the_threshold_does_not_chatter() {
        let rest = table_pose();
        let mut mouse = mapper(&rest);
        let mut q = rest.clone();
        let mut changes = 0;
        let mut last = [false; 2];
        // ±0.03 rad of alternating noise around 0.15 rad: one press, no release.
        for i in 0..40 {
            let noise = if i % 2 == 0 { 0.03 } else { -0.03 };
            q[19] = rest[19] + 0.15 + noise;
            let buttons = mouse.update(&q).unwrap().buttons;
            changes += usize::from(buttons != last);
            last = buttons;
        }
        assert_eq!(changes, 1);
        assert_eq!(last, [true, false]);
    }

    #[test]
    fn bad_states_are_errors_that_keep_the_buttons() {
        let rest = table_pose();
        let mut mouse = mapper(&rest);
        let mut q = rest.clone();
        q[19] += 0.2;
        assert_eq!(mouse.update(&q).unwrap().buttons, [true, false]);
        let mut bad = q.clone();
        bad[24] = f32::NAN;
        let err = format!("{:#}", mouse.update(&bad).unwrap_err());
        assert!(err.contains("q24") && err.contains("not finite"), "{err}");
        let err = format!("{:#}", mouse.update(&q[..7]).unwrap_err());
        assert!(err.contains("7 states"), "{err}");
        assert_eq!(mouse.buttons(), [true, false]);
    }

    #[test]
    fn bad_set_ups_are_refused() {
        let hand = Model::hand().unwrap();
        let rest = table_pose();
        for release_rad in [0.2, f32::NAN, -0.01] {
            let config = MouseConfig {
                release_rad,
                ..MouseConfig::default()
            };
            assert!(
                MouseMapper::new(&hand, &rest, config).is_err(),
                "{release_rad}"
            );
        }
        let err = format!(
            "{:#}",
            MouseMapper::new(&hand, &rest[..20], MouseConfig::default()).unwrap_err()
        );
        assert!(err.contains("20 states"), "{err}");
        let mut rest_nan = rest.clone();
        rest_nan[2] = f32::NAN;
        assert!(MouseMapper::new(&hand, &rest_nan, MouseConfig::default()).is_err());
    }

    #[test]
    fn the_pole_is_json() {
        let pole = MousePole {
            x_mm: 1.5,
            y_mm: -2.0,
            height_mm: 30.0,
            tip_z_mm: 30.0,
            buttons: [true, false],
        };
        assert_eq!(
            serde_json::to_string(&pole).unwrap(),
            r#"{"x_mm":1.5,"y_mm":-2.0,"height_mm":30.0,"tip_z_mm":30.0,"buttons":[true,false]}"#
        );
    }
}
