//! The report's 3D-mouse section, after the thesis' Fig. 4.12 (and the buttons of Fig. 4.11):
//! the pole read off the states over time — its base x and y on the table, its height, the
//! palm's yaw about the table's normal, the two buttons — each with the pole read off the
//! truth, and the mouse's accuracy (height and base errors, clicks detected).
//!
//! It appears for a 3D-mouse sub-model (see [`is_mouse_sub_model`]); the pole is
//! [`crate::mouse_pole`]'s, its buttons resting at the sequence's initial state.

use anyhow::Result;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

use super::input::Inputs;
use super::plots::{decorate, entry, estimate_plot, new_chart};
use crate::mouse_pole::accuracy::{compare, poles, MouseAccuracy, BUTTON_NAMES};
use crate::mouse_pole::{MouseConfig, MousePole, POLE_BASE_STATES};

/// The palm's height above the table (world z, q6): fixed in a 3D-mouse sub-model.
const PALM_HEIGHT_STATE: usize = 6;
/// Finger 1's MCP flexion: free in a 3D-mouse sub-model (it lifts the pole).
const FINGER1_MCP_STATE: usize = 8;
/// The buttons' plot draws button `b` between `b * BUTTON_SPACING` (up) and one above (down).
const BUTTON_SPACING: f64 = 1.5;

/// One number read off a pole (mm).
type Reading = fn(&MousePole) -> f32;

/// The 3D-mouse section of a report.
#[derive(Debug, Clone)]
pub struct MouseSection {
    /// The plots: `<svg class="mouse-plot" data-series="base-x|base-y|height|yaw|buttons">`.
    pub plots: Vec<String>,
    /// The mouse read off the estimate against the truth, when there is a truth.
    pub accuracy: Option<MouseAccuracy>,
}

/// Whether a sequence estimating `free` drives the thesis' 3D mouse: the palm slides on the
/// table (its x and y free, its height fixed) and finger 1 lifts the pole (its MCP free).
pub fn is_mouse_sub_model(free: &[usize]) -> bool {
    POLE_BASE_STATES.iter().all(|s| free.contains(s))
        && free.contains(&FINGER1_MCP_STATE)
        && !free.contains(&PALM_HEIGHT_STATE)
}

/// The section for `inputs`, or `None` when the sequence is no 3D-mouse sub-model or its model
/// cannot carry the mouse (no `finger1.tip`, too few states).
pub fn mouse_section(inputs: &Inputs) -> Result<Option<MouseSection>> {
    let sequence = &inputs.sequence;
    if !is_mouse_sub_model(&sequence.free_states()) {
        return Ok(None);
    }
    let rest: Vec<f32> = sequence.initial_state.iter().map(|&v| v as f32).collect();
    let config = MouseConfig::default();
    let Ok(estimate) = poles(&sequence.model, &rest, config, &inputs.estimate.table.rows) else {
        return Ok(None);
    };
    let truth = match &inputs.truth {
        Some(t) => Some(poles(&sequence.model, &rest, config, &t.rows)?),
        None => None,
    };
    let accuracy = match &inputs.truth {
        Some(t) => compare(
            &sequence.model,
            &rest,
            config,
            &t.rows,
            &inputs.estimate.table.rows,
        )
        .ok(),
        None => None,
    };
    let heading = |rows: &[Vec<f64>]| -> Vec<f64> {
        let rest = palm_heading(&sequence.initial_state);
        rows.iter()
            .map(|q| wrap_deg((palm_heading(q) - rest).to_degrees()))
            .collect()
    };
    let series = |poles: &[Option<MousePole>], f: Reading| -> Vec<f64> {
        poles
            .iter()
            .map(|p| p.as_ref().map_or(f64::NAN, |p| f64::from(f(p))))
            .collect()
    };
    let mut plots = Vec::new();
    let kinds: [(&str, &str, Reading); 3] = [
        (
            "base-x",
            "pole base x: the palm's x on the table (mm)",
            |p| p.x_mm,
        ),
        (
            "base-y",
            "pole base y: the palm's y on the table (mm)",
            |p| p.y_mm,
        ),
        (
            "height",
            "pole height: finger 1's fingertip above the table (mm)",
            |p| p.height_mm,
        ),
    ];
    for (name, title, f) in kinds {
        let t = truth.as_ref().map(|t| series(t, f));
        plots.push(estimate_plot(
            inputs,
            &series(&estimate, f),
            t.as_deref(),
            &format!(r#" class="mouse-plot" data-series="{name}""#),
            title,
            "mm",
        ));
    }
    let yaw_truth = inputs.truth.as_ref().map(|t| heading(&t.rows));
    plots.push(estimate_plot(
        inputs,
        &heading(&inputs.estimate.table.rows),
        yaw_truth.as_deref(),
        r#" class="mouse-plot" data-series="yaw""#,
        "palm yaw about the table's normal (deg)",
        "deg",
    ));
    plots.push(buttons_plot(inputs, &estimate, truth.as_deref()));
    Ok(Some(MouseSection { plots, accuracy }))
}

/// The buttons against time: button `b` is a step between `b · 1.5` (up) and one above it
/// (pressed), estimate solid, truth dashed.
fn buttons_plot(
    inputs: &Inputs,
    estimate: &[Option<MousePole>],
    truth: Option<&[Option<MousePole>]>,
) -> String {
    let top = BUTTON_SPACING * (BUTTON_NAMES.len() - 1) as f64 + 1.0;
    let mut chart = new_chart(inputs, (0.0, top));
    let mut legend = decorate(&mut chart, inputs);
    let level = |poles: &[Option<MousePole>], b: usize| -> Vec<f64> {
        poles
            .iter()
            .map(|p| match p {
                Some(p) => BUTTON_SPACING * b as f64 + f64::from(u8::from(p.buttons[b])),
                None => f64::NAN,
            })
            .collect()
    };
    for b in 0..BUTTON_NAMES.len() {
        if let Some(truth) = truth {
            chart.line(&inputs.times, &level(truth, b), "truth");
        }
        chart.line(&inputs.times, &level(estimate, b), "estimate");
    }
    if truth.is_some() {
        legend.insert(0, entry("truth", "truth"));
    }
    legend.insert(0, entry("estimate", "estimate"));
    let title = format!(
        "buttons pressed: {} 0–1, {} {}–{}",
        BUTTON_NAMES[0],
        BUTTON_NAMES[1],
        BUTTON_SPACING,
        BUTTON_SPACING + 1.0
    );
    chart.finish(
        r#" class="mouse-plot" data-series="buttons""#,
        &title,
        inputs.time_label(),
        "pressed",
        &legend,
    )
}

/// The heading of the palm's finger direction (its y axis) on the table: its angle from
/// world x about world z (rad), from the quaternion `q[0..4]`; NaN if it is not a number.
fn palm_heading(q: &[f64]) -> f64 {
    if q.len() < 4 || q[..4].iter().any(|v| !v.is_finite()) {
        return f64::NAN;
    }
    let r = UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]));
    let fingers = r * Vector3::y();
    fingers.y.atan2(fingers.x)
}

/// An angle in degrees brought into (−180, 180].
fn wrap_deg(a: f64) -> f64 {
    let w = a.rem_euclid(360.0);
    if w > 180.0 {
        w - 360.0
    } else {
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mouse_sub_models_are_recognised() {
        assert!(is_mouse_sub_model(&[4, 5, 8, 9, 10, 19, 24]));
        assert!(is_mouse_sub_model(&[0, 1, 2, 3, 4, 5, 8, 9, 10, 19, 24]));
        // Two fingers move the palm in 3D; the rigid palm has no finger; the whole hand
        // moves in depth.
        assert!(!is_mouse_sub_model(&[4, 5, 6, 8, 9, 10, 12, 13, 14]));
        assert!(!is_mouse_sub_model(&[0, 1, 2, 3, 4, 5, 6]));
        assert!(!is_mouse_sub_model(&(0..28).collect::<Vec<_>>()));
    }

    #[test]
    fn heading_is_the_yaw_about_world_z() {
        let base = UnitQuaternion::from_quaternion(Quaternion::new(
            0.0,
            0.0,
            0.9975510002532796,
            -0.0699428473375328,
        ));
        let q = |r: UnitQuaternion<f64>| vec![r.w, r.i, r.j, r.k];
        let rest = palm_heading(&q(base));
        for yaw in [-0.3f64, 0.0, 0.2, 3.0] {
            let turned = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw) * base;
            let got = wrap_deg((palm_heading(&q(turned)) - rest).to_degrees());
            assert!((got - yaw.to_degrees()).abs() < 1e-9, "{yaw}: {got}");
        }
        assert!(palm_heading(&[f64::NAN, 0.0, 0.0, 1.0]).is_nan());
        assert_eq!(wrap_deg(270.0), -90.0);
        assert_eq!(wrap_deg(-180.0), 180.0);
    }
}
