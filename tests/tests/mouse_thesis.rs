//! The thesis' 3D-mouse trial end to end: render all 500 frames of `mouse-thesis` (four
//! phases, the thesis' pace) at 480×360, track them with the default tracker, and judge the
//! states as a 3D mouse against the truth: the pole's height within 3 mm RMS, its base within
//! 2 mm RMS, every click of either button detected exactly once, no click while a button
//! rests; and the report draws the pole over time (the thesis' Fig. 4.12).
//!
//! 480×360 keeps the test near 10 s on two cores; the full-size figures (640×480, several
//! seeds) are in docs/ui.md, from `cargo run --release -p digiteyes-tests --example
//! mouse_thesis_study`.

use digiteyes_host::mouse_pole::accuracy::{
    clicks, compare, poles, BUTTON_NAMES, CLICK_SLACK_FRAMES,
};
use digiteyes_host::mouse_pole::MouseConfig;
use digiteyes_host::report::{build_report, ReportOptions};
use digiteyes_host::scenarios::mouse_thesis::{self, NAME, THESIS_FRAMES};
use digiteyes_host::sequence::{read_states, Sequence};
use digiteyes_host::{evaluate, render_scenario, track_sequence, RenderOptions, TrackerConfig};

/// The targets of the 3D mouse on this trial.
const HEIGHT_RMS_MM: f64 = 3.0;
const BASE_RMS_MM: f64 = 2.0;

#[test]
fn the_four_phase_trial_drives_the_mouse_within_its_targets() {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join(NAME);
    let options = RenderOptions {
        seed: 1,
        frames: Some(THESIS_FRAMES),
        size: Some((480, 360)),
        ..RenderOptions::default()
    };
    render_scenario(NAME, &seq, &options).unwrap();
    let states = dir.path().join("states.csv");
    let summary = track_sequence(&seq, &states, TrackerConfig::default(), false).unwrap();
    assert_eq!(summary.frames, THESIS_FRAMES);
    let eval = evaluate(&seq, &states).unwrap();
    assert_eq!(eval.track_life, 1.0, "{eval}");

    let sequence = Sequence::open(&seq).unwrap();
    let truth = sequence.read_truth().unwrap().rows;
    let estimate = read_states(&states, sequence.n_states()).unwrap().rows;
    let rest: Vec<f32> = sequence.initial_state.iter().map(|&v| v as f32).collect();
    let config = MouseConfig::default();
    let mouse = compare(&sequence.model, &rest, config, &truth, &estimate).unwrap();
    println!("{mouse}");
    assert_eq!(mouse.frames, THESIS_FRAMES);
    assert!(
        mouse.height_rms_mm <= HEIGHT_RMS_MM,
        "pole height {:.2} mm RMS, target {HEIGHT_RMS_MM}",
        mouse.height_rms_mm
    );
    assert!(
        mouse.base_rms_mm <= BASE_RMS_MM,
        "pole base {:.2} mm RMS, target {BASE_RMS_MM}",
        mouse.base_rms_mm
    );

    // Every click detected once: the trial's 3 thumb and 2 finger-4 clicks.
    let [finger4, thumb] = mouse.buttons;
    assert_eq!(
        (thumb.truth, finger4.truth),
        (
            mouse_thesis::THUMB_CLICKS.len(),
            mouse_thesis::FINGER4_CLICKS.len()
        )
    );
    for (name, count) in BUTTON_NAMES.iter().zip(mouse.buttons) {
        assert!(count.perfect(), "{name}: {count:?}");
    }
    // No click while a button rests: every frame the estimate holds a button down lies within
    // a true click (give or take the slack).
    let true_poles = poles(&sequence.model, &rest, config, &truth).unwrap();
    let est_poles = poles(&sequence.model, &rest, config, &estimate).unwrap();
    for (b, name) in BUTTON_NAMES.iter().enumerate() {
        let true_clicks = clicks(&true_poles, b);
        for (press, release) in clicks(&est_poles, b) {
            let inside = true_clicks.iter().any(|&(a, z)| {
                press + CLICK_SLACK_FRAMES >= a && release <= z + CLICK_SLACK_FRAMES
            });
            assert!(
                inside,
                "{name} pressed at frames {press}..={release}, true clicks {true_clicks:?}"
            );
        }
    }

    // The report draws Fig. 4.12: the pole's base x, y and height (estimate and truth), the
    // palm's yaw and the buttons, and states the same accuracy.
    let (html, report) = build_report(&seq, &states, &ReportOptions::default()).unwrap();
    assert_eq!(report.mouse_plots, 5);
    assert_eq!(report.mouse.as_ref(), Some(&mouse));
    for series in ["base-x", "base-y", "height", "yaw", "buttons"] {
        let tag = format!(r#"class="mouse-plot" data-series="{series}""#);
        let start = html
            .find(&tag)
            .unwrap_or_else(|| panic!("no {series} plot"));
        let svg = &html[start..start + html[start..].find("</svg>").unwrap()];
        for class in ["estimate", "truth"] {
            let line = format!(r#"<polyline class="{class}" points=""#);
            let points = svg.find(&line).map(|i| {
                let s = &svg[i + line.len()..];
                s[..s.find('"').unwrap()].split(' ').count()
            });
            assert_eq!(points, Some(THESIS_FRAMES), "{series} {class}");
        }
    }
    assert!(html.contains(&mouse.to_string()));
}
