//! The measurement behind the estimator's defaults: every residual form, robust weight and
//! conditioning matrix on the same rendered scenarios, scored against ground truth.
//!
//! `cargo run --release -p digiteyes-tests --example residual_study [FRAMES]`

use digiteyes_core::estimator::{Conditioning, ResidualKind, Robust};
use digiteyes_host::{evaluate, render_scenario, track_sequence, RenderOptions, TrackerConfig};

/// The axis points' width rows (`EstimatorConfig::width_weight`) compared besides, with one
/// camera or two; the forms above run without them (one camera's default is 0.5).
const WIDTH_WEIGHTS: [f32; 2] = [0.5, 1.0];

fn main() -> anyhow::Result<()> {
    let frames: usize = std::env::args().nth(1).map_or(Ok(40), |s| s.parse())?;
    let dir = tempfile::tempdir()?;
    let scenarios = [
        "mouse",
        "rigid",
        "fullhand-mono",
        "fullhand-stereo",
        "fast",
        "clutter",
    ];
    let variants: [(&str, ResidualKind, Robust, Conditioning); 9] = [
        (
            "axis points + Tukey 5 px",
            ResidualKind::AxisPoints,
            Robust::Tukey(5.0),
            TrackerConfig::default().estimator.conditioning,
        ),
        (
            "axis points + Huber 2 px (default, no width rows)",
            ResidualKind::AxisPoints,
            Robust::Huber(2.0),
            TrackerConfig::default().estimator.conditioning,
        ),
        (
            "axis points + Tukey 4 px",
            ResidualKind::AxisPoints,
            Robust::Tukey(4.0),
            TrackerConfig::default().estimator.conditioning,
        ),
        (
            "edge points + Huber 2 px",
            ResidualKind::EdgePoints,
            Robust::Huber(2.0),
            TrackerConfig::default().estimator.conditioning,
        ),
        (
            "edge points, plain least squares",
            ResidualKind::EdgePoints,
            Robust::None,
            TrackerConfig::default().estimator.conditioning,
        ),
        (
            "edge points + Tukey 4 px",
            ResidualKind::EdgePoints,
            Robust::Tukey(4.0),
            TrackerConfig::default().estimator.conditioning,
        ),
        (
            "axis lines (Eq. 2.17, thesis)",
            ResidualKind::AxisLines,
            Robust::Huber(2.0),
            TrackerConfig::default().estimator.conditioning,
        ),
        (
            "edge points, thesis S (1/10/1000)",
            ResidualKind::EdgePoints,
            Robust::Huber(2.0),
            Conditioning::THESIS,
        ),
        (
            "axis lines, thesis S (the thesis' tracker)",
            ResidualKind::AxisLines,
            Robust::None,
            Conditioning::THESIS,
        ),
    ];
    println!("| scenario | variant | fingertip mean px (worst camera) | free-joint RMS deg | palm rot deg | palm mm | track life |");
    println!("| --- | --- | --- | --- | --- | --- | --- |");
    for scenario in scenarios {
        let seq = dir.path().join(scenario);
        let options = RenderOptions {
            seed: 1,
            frames: Some(frames),
            ..RenderOptions::default()
        };
        render_scenario(scenario, &seq, &options)?;
        let widths = WIDTH_WEIGHTS.map(|w| {
            let name = format!("axis points + Huber 2 px, width rows at {w}");
            let default = TrackerConfig::default().estimator;
            (
                name,
                default.residual,
                default.robust,
                default.conditioning,
                w,
            )
        });
        let plain = variants.map(|(name, residual, robust, conditioning)| {
            (name.to_string(), residual, robust, conditioning, 0.0)
        });
        for (name, residual, robust, conditioning, width) in plain.into_iter().chain(widths) {
            let mut config = TrackerConfig::default();
            config.estimator.residual = residual;
            config.estimator.robust = robust;
            config.estimator.conditioning = conditioning;
            config.estimator.width_weight = width;
            config.estimator.one_camera_width_weight = width;
            let out = dir.path().join("states.csv");
            track_sequence(&seq, &out, config, false)?;
            let r = evaluate(&seq, &out)?;
            let tip = r
                .cameras
                .iter()
                .map(|c| c.fingertip_mean_px)
                .fold(0.0, f64::max);
            println!(
                "| {scenario} | {name} | {tip:.2} | {:.2} | {:.2} | {:.2} | {:.0}% |",
                r.joint_rms_deg,
                r.palm_rotation_deg,
                r.palm_translation_mm,
                r.track_life * 100.0
            );
        }
    }
    Ok(())
}
