//! The accuracy against `truth.csv`, through [`crate::eval::compare`], with per-frame series
//! for the error-over-time plot. Frames whose estimate has a NaN are left out of the
//! comparison and are gaps in the series.

use anyhow::{Context, Result};
use digiteyes_core::model::BASE_STATES;

use super::input::Inputs;
use crate::eval::{compare, EvalReport};
use crate::sequence::StateTable;

/// The evaluation of a report's states.
#[derive(Debug, Clone)]
pub struct Accuracy {
    /// The evaluation over the frames without NaN (`frames` says how many).
    pub report: EvalReport,
    /// Mean fingertip reprojection error of every frame over all tips and cameras (px); NaN
    /// for frames left out.
    pub fingertip_px: Vec<f64>,
    /// RMS error of the free revolute joints of every frame (deg); NaN for frames left out.
    /// Empty when no revolute joint is free.
    pub joint_deg: Vec<f64>,
}

/// Compares the estimate with `truth` over every frame whose estimate is all numbers; `None`
/// when there is no such frame.
pub fn accuracy(inputs: &Inputs, truth: &StateTable) -> Result<Option<Accuracy>> {
    let sequence = &inputs.sequence;
    let estimated = &inputs.estimate.table.rows;
    let kept: Vec<usize> = (0..estimated.len())
        .filter(|&k| estimated[k].iter().all(|v| v.is_finite()))
        .collect();
    if kept.is_empty() {
        return Ok(None);
    }
    let names: Vec<String> = (0..sequence.cameras.len())
        .map(|c| sequence.camera_name(c))
        .collect();
    let pick = |rows: &[Vec<f64>]| kept.iter().map(|&k| rows[k].clone()).collect::<Vec<_>>();
    let free = sequence.free_states();
    let mut report = compare(
        &sequence.model,
        &sequence.cameras,
        &names,
        &free,
        &pick(&truth.rows),
        &pick(estimated),
    )
    .with_context(|| format!("{}", inputs.states_path.display()))?;
    report.lost_frames = inputs
        .column("lost")
        .map(|_| inputs.lost.iter().filter(|&&l| l).count());
    let claimed = inputs.estimate.table.claimed();
    report.set_acquisitions(&kept.iter().map(|&k| claimed[k]).collect::<Vec<_>>());
    // The comparison ran over the kept frames: back to frame numbers.
    report.frames_to_acquire = report.frames_to_acquire.map(|i| kept[i]);
    for k in &mut report.reacquired_at {
        *k = kept[*k];
    }
    let mut fingertip_px = vec![f64::NAN; estimated.len()];
    for (&k, &e) in kept.iter().zip(&report.fingertip_mean_by_frame) {
        fingertip_px[k] = e;
    }
    let joints: Vec<usize> = free
        .iter()
        .copied()
        .filter(|&s| s >= BASE_STATES && s < sequence.n_states())
        .collect();
    let joint_deg = if joints.is_empty() {
        Vec::new()
    } else {
        truth
            .rows
            .iter()
            .zip(estimated)
            .map(|(t, e)| {
                let sum: f64 = joints.iter().map(|&s| (t[s] - e[s]).powi(2)).sum();
                (sum / joints.len() as f64).sqrt().to_degrees()
            })
            .collect()
    };
    Ok(Some(Accuracy {
        report,
        fingertip_px,
        joint_deg,
    }))
}
