//! The report's plots against time, after the thesis' Figs. 4.7, 4.8, 4.11 and 4.12: one per
//! free state (estimate, truth, lost frames shaded, dropped frames and NaN gaps marked) and the
//! error over time.

use super::accuracy::Accuracy;
use super::input::Inputs;
use super::svg::{finite_range, Chart, LegendEntry};
use crate::eval::LOST_ERROR_PX;
use crate::sequence::status::Status;
use crate::state_names::{state_label, state_unit};

/// The plot of state `state` (model index) against time: `<svg class="state-plot"
/// data-state="{state}">`, the estimate as `polyline.estimate`, the truth (when there is one)
/// as `polyline.truth`, in the state's unit.
pub fn state_plot(inputs: &Inputs, state: usize) -> String {
    let estimate: Vec<f64> = inputs
        .estimate
        .table
        .rows
        .iter()
        .map(|r| r[state])
        .collect();
    let truth: Option<Vec<f64>> = inputs
        .truth
        .as_ref()
        .map(|t| t.rows.iter().map(|r| r[state]).collect());
    estimate_plot(
        inputs,
        &estimate,
        truth.as_deref(),
        &format!(r#" class="state-plot" data-state="{state}""#),
        &state_label(state),
        state_unit(state),
    )
}

/// A series derived from the states against time, one value per frame (NaN: a gap): the
/// estimate as `polyline.estimate`, the truth (when given) as `polyline.truth`, lost frames,
/// dropped frames and gaps marked as on the state plots; `attributes` go on the `<svg>`.
pub fn estimate_plot(
    inputs: &Inputs,
    estimate: &[f64],
    truth: Option<&[f64]>,
    attributes: &str,
    title: &str,
    unit: &str,
) -> String {
    let range =
        finite_range(estimate.iter().chain(truth.iter().copied().flatten())).unwrap_or((0.0, 1.0));
    let mut chart = new_chart(inputs, range);
    let mut legend = decorate(&mut chart, inputs);
    if let Some(truth) = truth {
        chart.line(&inputs.times, truth, "truth");
        legend.insert(0, entry("truth", "truth"));
    }
    chart.line(&inputs.times, estimate, "estimate");
    legend.insert(0, entry("estimate", "estimate"));
    chart.finish(attributes, title, inputs.time_label(), unit, &legend)
}

/// The error-over-time plots: with an accuracy, the mean fingertip reprojection error (px,
/// with the track-loss threshold) and the free joints' RMS error (deg); and the tracker's own
/// RMS image residual (px) when the states file has `rms_px`. Each is `<svg
/// class="error-plot" data-series="...">`.
pub fn error_plots(inputs: &Inputs, accuracy: Option<&Accuracy>) -> Vec<String> {
    let mut plots = Vec::new();
    if let Some(acc) = accuracy {
        plots.push(series_plot(
            inputs,
            &acc.fingertip_px,
            "fingertip",
            "estimate",
            "mean fingertip reprojection error vs truth",
            "px",
            Some(LOST_ERROR_PX),
        ));
        if !acc.joint_deg.is_empty() {
            plots.push(series_plot(
                inputs,
                &acc.joint_deg,
                "joint",
                "joint",
                "free-joint RMS error vs truth",
                "deg",
                None,
            ));
        }
    }
    if let Some(rms) = inputs.column("rms_px") {
        plots.push(series_plot(
            inputs,
            &rms,
            "rms",
            "rms",
            "tracker RMS image residual",
            "px",
            None,
        ));
    }
    plots
}

/// One non-negative series against time, from 0, with an optional threshold line.
fn series_plot(
    inputs: &Inputs,
    values: &[f64],
    name: &str,
    class: &'static str,
    title: &str,
    unit: &str,
    threshold: Option<f64>,
) -> String {
    let top = finite_range(values.iter()).map_or(1.0, |(_, hi)| hi.max(1e-9));
    let mut chart = new_chart(inputs, (0.0, top));
    let mut legend = decorate(&mut chart, inputs);
    if let Some(t) = threshold {
        chart.rule(t, "threshold", &format!("{t} {unit}"));
    }
    chart.line(&inputs.times, values, class);
    legend.insert(0, entry(class, unit));
    chart.finish(
        &format!(r#" class="error-plot" data-series="{name}""#),
        title,
        inputs.time_label(),
        unit,
        &legend,
    )
}

pub(super) fn new_chart(inputs: &Inputs, y_range: (f64, f64)) -> Chart {
    let first = inputs.times.first().copied().unwrap_or(0.0);
    let last = inputs.times.last().copied().unwrap_or(1.0);
    Chart::new((first, last), y_range)
}

/// Shades the lost frames, draws the status band (when the states file has a `status`
/// column) and marks the dropped frames and NaN gaps; returns the legend entries of what was
/// drawn.
pub(super) fn decorate(chart: &mut Chart, inputs: &Inputs) -> Vec<LegendEntry> {
    let mut legend = Vec::new();
    let half = inputs.half_frame();
    if let Some(column) = &inputs.estimate.table.status {
        for status in Status::ALL {
            let flags: Vec<bool> = column.iter().map(|s| *s == Some(status)).collect();
            let runs = Inputs::runs(&flags);
            let class = status_class(status);
            for &(a, b) in &runs {
                let title = if a == b {
                    format!("frame {a} {status}")
                } else {
                    format!("frames {a}–{b} {status}")
                };
                chart.strip(
                    inputs.times[a] - half,
                    inputs.times[b] + half,
                    class,
                    &title,
                );
            }
            if !runs.is_empty() {
                legend.push(entry(class, status.as_str()));
            }
        }
    }
    let runs = Inputs::runs(&inputs.lost);
    for &(a, b) in &runs {
        let title = if a == b {
            format!("frame {a} lost")
        } else {
            format!("frames {a}–{b} lost")
        };
        chart.band(
            inputs.times[a] - half,
            inputs.times[b] + half,
            "lost",
            &title,
        );
    }
    if !runs.is_empty() {
        legend.push(entry("lost", "lost"));
    }
    let mut any_dropped = false;
    for (k, reason) in inputs.dropped.iter().enumerate() {
        if let Some(reason) = reason {
            let attributes = format!(r#" data-frame="{k}""#);
            let title = format!("frame {k} dropped: {reason}");
            chart.marker(inputs.times[k], "dropped", &attributes, &title);
            any_dropped = true;
        }
    }
    if any_dropped {
        legend.push(entry("dropped", "dropped"));
    }
    for &k in &inputs.gaps {
        let attributes = format!(r#" data-frame="{k}""#);
        let title = format!("frame {k}: a state is not a number");
        chart.marker(inputs.times[k], "gap", &attributes, &title);
    }
    if !inputs.gaps.is_empty() {
        legend.push(entry("gap", "no number"));
    }
    legend
}

/// The class of a status's stretch of the status band (`status-searching`, ...).
pub fn status_class(status: Status) -> &'static str {
    match status {
        Status::Searching => "status-searching",
        Status::Tracking => "status-tracking",
        Status::Lost => "status-lost",
    }
}

pub(super) fn entry(class: &'static str, text: &str) -> LegendEntry {
    LegendEntry {
        class,
        text: text.to_string(),
    }
}
