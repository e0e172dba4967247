//! Evaluation: estimated states against the ground truth of a sequence.
//!
//! Per camera, the reprojection error (px) of the fingertips (origins of the `tip` frames) and
//! of the joint centres (origins of the `cyl` frames), true state against estimated state,
//! over every frame: mean and 95th percentile. Over the sequence: the RMS error of the free
//! revolute joints (deg), the palm's rotation error (deg, angle between the quaternions) and
//! translation error (mm), and the track life. All geometry goes through the core's
//! kinematics and camera.

pub mod report;
pub mod stats;

use std::path::Path;

use anyhow::{anyhow, ensure, Context, Result};
use digiteyes_core::camera::Camera;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::{Model, Shape, BASE_STATES};
use digiteyes_core::nalgebra::Vector2;
use digiteyes_core::quaternion;
use serde::Serialize;

use crate::sequence::status::{Status, StatusCounts};
use crate::sequence::{read_states, Sequence};

/// A frame's mean fingertip error above this (px) counts towards losing the track.
pub const LOST_ERROR_PX: f64 = 10.0;
/// Consecutive frames above [`LOST_ERROR_PX`] that mean the track is lost.
pub const LOST_RUN: usize = 5;

/// Reprojection errors seen by one camera, over every frame and point (px).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CameraErrors {
    /// The camera's name.
    pub name: String,
    /// Mean fingertip error (px).
    pub fingertip_mean_px: f64,
    /// 95th percentile of the fingertip error (px).
    pub fingertip_p95_px: f64,
    /// Mean joint-centre error (px).
    pub joint_mean_px: f64,
    /// 95th percentile of the joint-centre error (px).
    pub joint_p95_px: f64,
}

/// How well estimated states follow the truth.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EvalReport {
    /// Frames compared.
    pub frames: usize,
    /// Reprojection errors, one entry per camera in sequence order.
    pub cameras: Vec<CameraErrors>,
    /// Free revolute joints compared.
    pub free_joints: usize,
    /// RMS error of the free revolute joints over every frame (deg); 0 when none is free.
    pub joint_rms_deg: f64,
    /// Mean angle between the true and estimated palm rotations (deg).
    pub palm_rotation_deg: f64,
    /// Largest such angle (deg).
    pub palm_rotation_max_deg: f64,
    /// Mean distance between the true and estimated palm positions (mm).
    pub palm_translation_mm: f64,
    /// Largest such distance (mm).
    pub palm_translation_max_mm: f64,
    /// The mean fingertip error (px) above which a frame counts towards losing the track, and
    /// below which it counts towards holding it ([`LOST_ERROR_PX`] unless asked otherwise:
    /// `eval --lost-px`).
    pub lost_error_px: f64,
    /// Fraction (0–1) of the frames before the track is lost: before the first frame from
    /// which the mean fingertip error stays above `lost_error_px` for [`LOST_RUN`] frames;
    /// 1 if that never happens.
    pub track_life: f64,
    /// Fraction (0–1) of all frames whose mean fingertip error is at most `lost_error_px`,
    /// wherever they fall: unlike the track life, a hand that strays over the threshold and
    /// comes back is counted for the frames it is held again.
    pub held_share: f64,
    /// Mean fingertip error of every frame, over all tips and cameras (px).
    pub fingertip_mean_by_frame: Vec<f64>,
    /// Frames the tracker flagged `lost`, when the states file has that column.
    pub lost_frames: Option<usize>,
    /// The first frame from which the hand is held: claimed (when the file says which frames
    /// claim it) and the mean fingertip error below `lost_error_px` for [`LOST_RUN`] frames;
    /// `None` if never.
    pub frames_to_acquire: Option<usize>,
    /// The frames where the hand was held again (as for `frames_to_acquire`) after it had
    /// been held and then not for [`LOST_RUN`] frames in a row.
    pub reacquired_at: Vec<usize>,
    /// Frames per status and where the status changed, when the file has a `status` column.
    pub status: Option<StatusCounts>,
}

/// Compares the states in `states_csv` (the tracker's output, or any CSV starting with
/// `frame,q0,...`) with `seq/truth.csv`. Errors if either file's frame or state count does not
/// match the sequence.
pub fn evaluate(seq: &Path, states_csv: &Path) -> Result<EvalReport> {
    evaluate_at(seq, states_csv, LOST_ERROR_PX)
}

/// [`evaluate`] with a frame lost above `lost_error_px` (px) of mean fingertip error, and
/// held below it: a threshold for another image size (10 px at 640 px wide is 5 px at 320).
pub fn evaluate_at(seq: &Path, states_csv: &Path, lost_error_px: f64) -> Result<EvalReport> {
    ensure!(
        lost_error_px.is_finite() && lost_error_px > 0.0,
        "the lost threshold must be a positive number of px, not {lost_error_px}"
    );
    let sequence = Sequence::open(seq)?;
    let truth = sequence.read_truth()?;
    let estimated = read_states(states_csv, sequence.n_states())?;
    sequence.check_state_rows(states_csv, estimated.rows.len())?;
    let names = (0..sequence.cameras.len())
        .map(|c| sequence.camera_name(c))
        .collect::<Vec<_>>();
    let mut report = compare(
        &sequence.model,
        &sequence.cameras,
        &names,
        &sequence.free_states(),
        &truth.rows,
        &estimated.rows,
    )
    .with_context(|| {
        format!(
            "comparing {} with {}",
            states_csv.display(),
            sequence.dir.join(crate::sequence::TRUTH_CSV).display()
        )
    })?;
    report.lost_error_px = lost_error_px;
    report.track_life = track_life_at(&report.fingertip_mean_by_frame, lost_error_px);
    report.held_share = held_share_at(&report.fingertip_mean_by_frame, lost_error_px);
    report.lost_frames = estimated
        .extra("lost")
        .map(|lost| lost.iter().filter(|&&v| v != 0.0).count());
    report.set_acquisitions(&estimated.claimed());
    report.status = estimated.status.as_ref().map(|column| {
        // A frame with no status (a board's dropped frame) claims nothing: counted as lost.
        let statuses: Vec<Status> = column.iter().map(|s| s.unwrap_or(Status::Lost)).collect();
        StatusCounts::of(&statuses)
    });
    Ok(report)
}

/// Compares `estimated` with `truth` (one state vector per frame each).
pub fn compare(
    model: &Model,
    cameras: &[Camera],
    camera_names: &[String],
    free: &[usize],
    truth: &[Vec<f64>],
    estimated: &[Vec<f64>],
) -> Result<EvalReport> {
    ensure!(
        truth.len() == estimated.len(),
        "{} estimated frames, {} true",
        estimated.len(),
        truth.len()
    );
    let links = model.links();
    let tips: Vec<usize> = (0..links.len())
        .filter(|&i| matches!(links[i].shape, Shape::Tip { .. }))
        .collect();
    let joints: Vec<usize> = (0..links.len())
        .filter(|&i| matches!(links[i].shape, Shape::Cylinder { .. }))
        .collect();
    let free_joints: Vec<usize> = free
        .iter()
        .copied()
        .filter(|&s| s >= BASE_STATES && s < model.n_states())
        .collect();
    let mut tip_errors = vec![Vec::new(); cameras.len()];
    let mut joint_errors = vec![Vec::new(); cameras.len()];
    let mut by_frame = Vec::with_capacity(truth.len());
    let (mut rotation, mut translation) = (Vec::new(), Vec::new());
    let mut joint_square_sum = 0.0;
    for (k, (t, e)) in truth.iter().zip(estimated).enumerate() {
        let qt = to_f32(t);
        let qe = to_f32(e);
        let pt = Poses::compute(model, &qt).map_err(|err| anyhow!("frame {k}: truth: {err}"))?;
        let pe = Poses::compute(model, &qe).map_err(|err| anyhow!("frame {k}: estimate: {err}"))?;
        let mut frame_tips = Vec::new();
        for (c, cam) in cameras.iter().enumerate() {
            for &i in &tips {
                let err = reprojection_error(cam, &pt, &pe, i);
                frame_tips.push(err);
                tip_errors[c].push(err);
            }
            for &i in &joints {
                joint_errors[c].push(reprojection_error(cam, &pt, &pe, i));
            }
        }
        by_frame.push(stats::mean(&frame_tips));
        let angle = quaternion::angle_between(unit(&qt), unit(&qe));
        rotation.push(f64::from(angle).to_degrees());
        let dt = (0..3).map(|i| (t[4 + i] - e[4 + i]).powi(2)).sum::<f64>();
        translation.push(dt.sqrt());
        for &s in &free_joints {
            joint_square_sum += (t[s] - e[s]).powi(2);
        }
    }
    let samples = (free_joints.len() * truth.len()).max(1) as f64;
    let cameras = cameras
        .iter()
        .enumerate()
        .map(|(c, _)| CameraErrors {
            name: camera_names
                .get(c)
                .cloned()
                .unwrap_or_else(|| format!("cam{c}")),
            fingertip_mean_px: stats::mean(&tip_errors[c]),
            fingertip_p95_px: stats::percentile(&tip_errors[c], 0.95),
            joint_mean_px: stats::mean(&joint_errors[c]),
            joint_p95_px: stats::percentile(&joint_errors[c], 0.95),
        })
        .collect();
    Ok(EvalReport {
        frames: truth.len(),
        cameras,
        free_joints: free_joints.len(),
        joint_rms_deg: (joint_square_sum / samples).sqrt().to_degrees(),
        palm_rotation_deg: stats::mean(&rotation),
        palm_rotation_max_deg: rotation.iter().copied().fold(0.0, f64::max),
        palm_translation_mm: stats::mean(&translation),
        palm_translation_max_mm: translation.iter().copied().fold(0.0, f64::max),
        lost_error_px: LOST_ERROR_PX,
        track_life: track_life(&by_frame),
        held_share: held_share_at(&by_frame, LOST_ERROR_PX),
        frames_to_acquire: acquisitions(&by_frame, &vec![true; truth.len()]).0,
        reacquired_at: acquisitions(&by_frame, &vec![true; truth.len()]).1,
        fingertip_mean_by_frame: by_frame,
        lost_frames: None,
        status: None,
    })
}

impl EvalReport {
    /// Sets [`EvalReport::frames_to_acquire`] and [`EvalReport::reacquired_at`] from the
    /// fingertip errors and which frames claim the hand (one flag per frame).
    pub fn set_acquisitions(&mut self, claimed: &[bool]) {
        let (first, again) =
            acquisitions_at(&self.fingertip_mean_by_frame, claimed, self.lost_error_px);
        self.frames_to_acquire = first;
        self.reacquired_at = again;
    }
}

/// The first frame from which the hand is held — claimed and the error (px) below
/// [`LOST_ERROR_PX`] for [`LOST_RUN`] frames — and every frame it is held again after
/// [`LOST_RUN`] frames in a row not held. A frame past the end of `claimed` counts as claimed.
pub fn acquisitions(errors: &[f64], claimed: &[bool]) -> (Option<usize>, Vec<usize>) {
    acquisitions_at(errors, claimed, LOST_ERROR_PX)
}

/// [`acquisitions`] with the error held below `lost_error_px` (px).
pub fn acquisitions_at(
    errors: &[f64],
    claimed: &[bool],
    lost_error_px: f64,
) -> (Option<usize>, Vec<usize>) {
    let good = |k: usize| claimed.get(k).copied().unwrap_or(true) && errors[k] < lost_error_px;
    let mut first = None;
    let mut again = Vec::new();
    let mut held = false;
    let (mut good_run, mut bad_run) = (0, 0);
    for k in 0..errors.len() {
        if good(k) {
            good_run += 1;
            bad_run = 0;
        } else {
            bad_run += 1;
            good_run = 0;
        }
        if !held && good_run == LOST_RUN {
            let start = k + 1 - LOST_RUN;
            if first.is_none() {
                first = Some(start);
            } else {
                again.push(start);
            }
            held = true;
        }
        if held && bad_run == LOST_RUN {
            held = false;
        }
    }
    (first, again)
}

/// Fraction of frames before the first run of [`LOST_RUN`] frames whose error (px) all exceed
/// [`LOST_ERROR_PX`]; 1 if there is no such run.
pub fn track_life(errors: &[f64]) -> f64 {
    track_life_at(errors, LOST_ERROR_PX)
}

/// [`track_life`] with a frame lost above `lost_error_px` (px).
pub fn track_life_at(errors: &[f64], lost_error_px: f64) -> f64 {
    if errors.is_empty() {
        return 1.0;
    }
    let mut run = 0;
    for (k, &e) in errors.iter().enumerate() {
        run = if e > lost_error_px { run + 1 } else { 0 };
        if run == LOST_RUN {
            return (k + 1 - LOST_RUN) as f64 / errors.len() as f64;
        }
    }
    1.0
}

/// Fraction of frames whose error (px) is at most `lost_error_px` (a NaN error is not held);
/// 1 with no frame.
pub fn held_share_at(errors: &[f64], lost_error_px: f64) -> f64 {
    if errors.is_empty() {
        return 1.0;
    }
    let held = errors.iter().filter(|&&e| e <= lost_error_px).count();
    held as f64 / errors.len() as f64
}

/// Image distance (px) between frame `i`'s origin at the true and at the estimated state.
/// A point that does not project (at or behind the camera) counts as the image diagonal.
pub fn reprojection_error(cam: &Camera, truth: &Poses, estimate: &Poses, i: usize) -> f64 {
    let project = |p: &Poses| p.origin(i).and_then(|o| cam.project(&o));
    match (project(truth), project(estimate)) {
        (Some(a), Some(b)) => f64::from((a - b).norm()),
        _ => f64::from(Vector2::new(cam.width as f32, cam.height as f32).norm()),
    }
}

fn to_f32(q: &[f64]) -> Vec<f32> {
    q.iter().map(|&v| v as f32).collect()
}

fn unit(q: &[f32]) -> [f32; 4] {
    quaternion::normalised([q[0], q[1], q[2], q[3]]).unwrap_or([1.0, 0.0, 0.0, 0.0])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn acquisitions_need_five_good_claimed_frames() {
        let e = |v: &[f64]| v.to_vec();
        // Held from frame 2; a 5-frame loss; held again from frame 12.
        let errors = e(&[
            50., 50., 1., 1., 1., 1., 1., 50., 50., 50., 50., 50., 1., 1., 1., 1., 1.,
        ]);
        let all = vec![true; errors.len()];
        assert_eq!(acquisitions(&errors, &all), (Some(2), vec![12]));
        // Unclaimed frames are not held, whatever their error.
        let errors = e(&[50., 50., 1., 1., 1., 1., 1., 1., 1.]);
        let mut claimed = vec![true; errors.len()];
        assert_eq!(acquisitions(&errors, &claimed).0, Some(2));
        claimed[3] = false;
        assert_eq!(acquisitions(&errors, &claimed).0, Some(4));
        // A loss shorter than five frames is no re-acquisition.
        let errors = e(&[1., 1., 1., 1., 1., 50., 50., 1., 1., 1., 1., 1.]);
        assert_eq!(acquisitions(&errors, &[true; 12]), (Some(0), vec![]));
        assert_eq!(acquisitions(&[50.; 8], &[true; 8]), (None, vec![]));
    }

    #[test]
    fn the_held_share_counts_frames_held_again_after_the_life_ends() {
        // Lost for 5 frames from frame 2, then held again to the end.
        let errors = [1., 1., 50., 50., 50., 50., 50., 1., 1., 1.];
        assert_eq!(track_life(&errors), 0.2);
        assert_eq!(held_share_at(&errors, LOST_ERROR_PX), 0.5);
        // At the threshold is held; over it, or not a number, is not.
        assert_eq!(held_share_at(&[10.0, 10.01, f64::NAN, 0.0], 10.0), 0.5);
        assert_eq!(held_share_at(&[], 10.0), 1.0);
    }
}
