//! How well a tracked run drives the 3D mouse: the pole read off the estimated states against
//! the pole read off the truth — height and base errors (mm), and whether every click of a
//! button was detected once and none while it rested.
//!
//! Both poles come from a [`MouseMapper`] with the same rest state (the sequence's initial
//! state) and thresholds, so a click is what the mouse reports: a press (released → pressed)
//! and the release after it.

use std::fmt;

use anyhow::{ensure, Result};
use digiteyes_core::model::Model;

use super::{MouseConfig, MouseMapper, MousePole};

/// An estimated press counts for a true click when it comes at most this many frames before
/// the true press or after the true release (the tracker may lag a frame or two).
pub const CLICK_SLACK_FRAMES: usize = 3;

/// The names of the two buttons, in [`MousePole::buttons`] order.
pub const BUTTON_NAMES: [&str; 2] = ["finger 4", "thumb"];

/// The pole of every frame of `states` (quaternion, mm, rad per row), read by one mapper that
/// rests at `rest`: `None` where a row cannot be placed (a state that is not a number); the
/// buttons then keep their last reading.
pub fn poles(
    model: &Model,
    rest: &[f32],
    config: MouseConfig,
    states: &[Vec<f64>],
) -> Result<Vec<Option<MousePole>>> {
    let mut mouse = MouseMapper::new(model, rest, config)?;
    Ok(states
        .iter()
        .map(|row| {
            let q: Vec<f32> = row.iter().map(|&v| v as f32).collect();
            mouse.update(&q).ok()
        })
        .collect())
}

/// The clicks of button `b` in `poles`: `(press frame, last pressed frame)`, a press still
/// held at the end lasting to the last frame. Frames without a pole are skipped.
pub fn clicks(poles: &[Option<MousePole>], b: usize) -> Vec<(usize, usize)> {
    let mut clicks = Vec::new();
    let mut down: Option<usize> = None;
    let mut last = 0;
    for (k, pole) in poles.iter().enumerate() {
        let Some(pole) = pole else { continue };
        match (down, pole.buttons[b]) {
            (None, true) => down = Some(k),
            (Some(start), false) => {
                clicks.push((start, last));
                down = None;
            }
            _ => {}
        }
        last = k;
    }
    if let Some(start) = down {
        clicks.push((start, last));
    }
    clicks
}

/// One button's clicks, estimated against true.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ClickCount {
    /// Clicks in the truth.
    pub truth: usize,
    /// True clicks the estimate pressed exactly once for.
    pub detected_once: usize,
    /// True clicks with no estimated press.
    pub missed: usize,
    /// True clicks with more than one estimated press (a chattering button).
    pub repeated: usize,
    /// Estimated presses near no true click: clicks while the button rested.
    pub spurious: usize,
}

impl ClickCount {
    /// Every true click detected once and nothing else pressed.
    pub fn perfect(&self) -> bool {
        self.detected_once == self.truth && self.spurious == 0
    }
}

/// Matches the estimated presses to the true clicks: a press belongs to the first true click
/// whose pressed frames, widened by [`CLICK_SLACK_FRAMES`] each side, contain it.
pub fn count_clicks(truth: &[(usize, usize)], estimate: &[(usize, usize)]) -> ClickCount {
    let mut presses = vec![0usize; truth.len()];
    let mut spurious = 0;
    for &(press, _) in estimate {
        let owner = truth
            .iter()
            .position(|&(a, b)| press + CLICK_SLACK_FRAMES >= a && press <= b + CLICK_SLACK_FRAMES);
        match owner {
            Some(i) => presses[i] += 1,
            None => spurious += 1,
        }
    }
    ClickCount {
        truth: truth.len(),
        detected_once: presses.iter().filter(|&&n| n == 1).count(),
        missed: presses.iter().filter(|&&n| n == 0).count(),
        repeated: presses.iter().filter(|&&n| n > 1).count(),
        spurious,
    }
}

/// The 3D mouse of a run against its truth.
#[derive(Debug, Clone, PartialEq)]
pub struct MouseAccuracy {
    /// Frames compared (those whose estimate is all numbers).
    pub frames: usize,
    /// RMS error of the pole's height (mm; both clamped at the table, as the pole is).
    pub height_rms_mm: f64,
    /// Largest error of the pole's height (mm).
    pub height_max_mm: f64,
    /// RMS error of finger 1's fingertip height, not clamped (mm).
    pub tip_z_rms_mm: f64,
    /// RMS distance between the estimated and true base on the table (mm).
    pub base_rms_mm: f64,
    /// Largest such distance (mm).
    pub base_max_mm: f64,
    /// The clicks of each button, in [`BUTTON_NAMES`] order.
    pub buttons: [ClickCount; 2],
}

/// Reads the pole off `truth` and `estimate` (the same number of rows; quaternion, mm, rad)
/// with one mapper each resting at `rest`, and compares them. Rows of `estimate` that are not
/// all numbers are left out of the errors (their buttons hold).
pub fn compare(
    model: &Model,
    rest: &[f32],
    config: MouseConfig,
    truth: &[Vec<f64>],
    estimate: &[Vec<f64>],
) -> Result<MouseAccuracy> {
    ensure!(
        truth.len() == estimate.len(),
        "mouse: {} estimated frames, {} true",
        estimate.len(),
        truth.len()
    );
    let true_poles = poles(model, rest, config, truth)?;
    let estimated = poles(model, rest, config, estimate)?;
    let (mut n, mut h2, mut hmax, mut z2, mut b2, mut bmax) =
        (0usize, 0.0, 0.0f64, 0.0, 0.0, 0.0f64);
    for (t, e) in true_poles.iter().zip(&estimated) {
        let (Some(t), Some(e)) = (t, e) else { continue };
        let dh = f64::from(e.height_mm - t.height_mm);
        let dz = f64::from(e.tip_z_mm - t.tip_z_mm);
        let db = f64::from(e.x_mm - t.x_mm).hypot(f64::from(e.y_mm - t.y_mm));
        n += 1;
        h2 += dh * dh;
        z2 += dz * dz;
        b2 += db * db;
        hmax = hmax.max(dh.abs());
        bmax = bmax.max(db);
    }
    ensure!(n > 0, "mouse: no frame with a complete estimate to compare");
    let rms = |sum: f64| (sum / n as f64).sqrt();
    let buttons = [0, 1].map(|b| count_clicks(&clicks(&true_poles, b), &clicks(&estimated, b)));
    Ok(MouseAccuracy {
        frames: n,
        height_rms_mm: rms(h2),
        height_max_mm: hmax,
        tip_z_rms_mm: rms(z2),
        base_rms_mm: rms(b2),
        base_max_mm: bmax,
        buttons,
    })
}

impl fmt::Display for MouseAccuracy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "3D mouse, {} frames: pole height {:.2} mm RMS (max {:.2}; fingertip {:.2} mm RMS), \
             base {:.2} mm RMS (max {:.2})",
            self.frames,
            self.height_rms_mm,
            self.height_max_mm,
            self.tip_z_rms_mm,
            self.base_rms_mm,
            self.base_max_mm
        )?;
        for (name, c) in BUTTON_NAMES.iter().zip(&self.buttons) {
            write!(
                f,
                "; {name} clicks: {} of {} detected once",
                c.detected_once, c.truth
            )?;
            for (n, what) in [
                (c.missed, "missed"),
                (c.repeated, "repeated"),
                (c.spurious, "while resting"),
            ] {
                if n > 0 {
                    write!(f, ", {n} {what}")?;
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pole(buttons: [bool; 2]) -> Option<MousePole> {
        Some(MousePole {
            buttons,
            ..MousePole::default()
        })
    }

    #[test]
    fn clicks_are_press_to_release_and_skip_gaps() {
        let t = [false, true, true, false, false, true];
        let mut poles: Vec<Option<MousePole>> = t.iter().map(|&b| pole([b, false])).collect();
        assert_eq!(clicks(&poles, 0), vec![(1, 2), (5, 5)]);
        assert!(clicks(&poles, 1).is_empty());
        // A gap inside a press does not split it.
        poles[2] = None;
        assert_eq!(clicks(&poles, 0), vec![(1, 1), (5, 5)]);
        poles[3] = pole([true, false]);
        assert_eq!(clicks(&poles, 0), vec![(1, 3), (5, 5)]);
    }

    #[test]
    fn each_true_click_wants_one_press_and_rest_wants_none() {
        let truth = [(10, 20), (40, 50)];
        let perfect = count_clicks(&truth, &[(12, 21), (39, 52)]);
        assert!(perfect.perfect(), "{perfect:?}");
        // Within the slack either side.
        assert!(count_clicks(&truth, &[(7, 9), (53, 55)]).perfect());
        let late = count_clicks(&truth, &[(24, 30), (40, 50)]);
        assert_eq!((late.detected_once, late.missed, late.spurious), (1, 1, 1));
        let chatter = count_clicks(&truth, &[(12, 13), (15, 20), (41, 50)]);
        assert_eq!((chatter.detected_once, chatter.repeated), (1, 1));
        assert!(!chatter.perfect());
        let resting = count_clicks(&[], &[(3, 4)]);
        assert_eq!((resting.truth, resting.spurious), (0, 1));
        assert!(count_clicks(&[], &[]).perfect());
    }
}
