//! What each of the hand model's 28 states means, for labels in reports, plots and the UI.
//!
//! Numbering follows `hand.dh` (see `docs/hand-model.md`): q0..q3 the palm's unit quaternion
//! (w, x, y, z), q4..q6 its translation (mm, world), then four joints per finger (abduction,
//! MCP, PIP and DIP flexion; rad) and five for the thumb (q23..q27, rad).

use digiteyes_core::state::StateKind;

/// States of the whole-hand model.
pub const HAND_STATES: usize = 28;

/// Short description of state `i` of the whole-hand model, e.g. "finger 1 MCP flexion";
/// "state N" beyond it (a model with more states).
pub fn state_meaning(i: usize) -> String {
    const PALM: [&str; 7] = [
        "palm rotation w",
        "palm rotation x",
        "palm rotation y",
        "palm rotation z",
        "palm x",
        "palm y",
        "palm z",
    ];
    const FINGER_JOINTS: [&str; 4] = ["abduction", "MCP flexion", "PIP flexion", "DIP flexion"];
    const THUMB_JOINTS: [&str; 5] = [
        "trapeziometacarpal 1",
        "trapeziometacarpal 2",
        "opposition",
        "MP flexion",
        "IP flexion",
    ];
    match i {
        0..=6 => PALM[i].to_string(),
        7..=22 => format!("finger {} {}", (i - 7) / 4 + 1, FINGER_JOINTS[(i - 7) % 4]),
        23..=27 => format!("thumb {}", THUMB_JOINTS[i - 23]),
        _ => format!("state {i}"),
    }
}

/// The unit of state `i`: "" for the quaternion, "mm" for the translation, "rad" for joints.
pub fn state_unit(i: usize) -> &'static str {
    match StateKind::of(i) {
        StateKind::Quaternion => "",
        StateKind::Translation => "mm",
        StateKind::Joint => "rad",
    }
}

/// `q{i}` with its meaning and unit, e.g. "q8 finger 1 MCP flexion (rad)".
pub fn state_label(i: usize) -> String {
    match state_unit(i) {
        "" => format!("q{i} {}", state_meaning(i)),
        unit => format!("q{i} {} ({unit})", state_meaning(i)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_follow_the_dh_table() {
        assert_eq!(state_label(0), "q0 palm rotation w");
        assert_eq!(state_label(5), "q5 palm y (mm)");
        assert_eq!(state_label(7), "q7 finger 1 abduction (rad)");
        assert_eq!(state_label(10), "q10 finger 1 DIP flexion (rad)");
        assert_eq!(state_label(19), "q19 finger 4 abduction (rad)");
        assert_eq!(state_label(22), "q22 finger 4 DIP flexion (rad)");
        assert_eq!(state_label(24), "q24 thumb trapeziometacarpal 2 (rad)");
        assert_eq!(state_label(27), "q27 thumb IP flexion (rad)");
        assert_eq!(state_label(28), "q28 state 28 (rad)");
    }
}
