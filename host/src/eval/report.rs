//! The evaluation as a readable table.

use std::fmt;

use super::{EvalReport, LOST_RUN};

impl fmt::Display for EvalReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "reprojection error (px), {} frames", self.frames)?;
        writeln!(
            f,
            "  {:<12} {:>14} {:>13} {:>11} {:>10}",
            "camera", "fingertip mean", "fingertip p95", "joint mean", "joint p95"
        )?;
        for c in &self.cameras {
            writeln!(
                f,
                "  {:<12} {:>14.2} {:>13.2} {:>11.2} {:>10.2}",
                c.name, c.fingertip_mean_px, c.fingertip_p95_px, c.joint_mean_px, c.joint_p95_px
            )?;
        }
        if self.free_joints > 0 {
            writeln!(
                f,
                "free-joint RMS error     {:8.2} deg  ({} joints)",
                self.joint_rms_deg, self.free_joints
            )?;
        } else {
            writeln!(f, "free-joint RMS error          n/a  (no free joint)")?;
        }
        writeln!(
            f,
            "palm rotation error      {:8.2} deg  mean, {:.2} deg max",
            self.palm_rotation_deg, self.palm_rotation_max_deg
        )?;
        writeln!(
            f,
            "palm translation error   {:8.2} mm   mean, {:.2} mm max",
            self.palm_translation_mm, self.palm_translation_max_mm
        )?;
        let kept = (self.track_life * self.frames as f64).round() as usize;
        writeln!(
            f,
            "track life               {:8.1} %    ({kept} of {} frames before the fingertip error stays > {} px for {LOST_RUN} frames)",
            100.0 * self.track_life,
            self.frames,
            self.lost_error_px
        )?;
        writeln!(
            f,
            "frames held              {:8.1} %    (every frame with the fingertip error <= {} px, also after the track life ends)",
            100.0 * self.held_share,
            self.lost_error_px
        )?;
        if let Some(lost) = self.lost_frames {
            writeln!(f, "frames flagged lost      {lost:8}")?;
        }
        match self.frames_to_acquire {
            Some(k) => writeln!(
                f,
                "frames to acquire        {k:8}       (first frame from which the hand is claimed with the fingertip error < {} px for {LOST_RUN} frames)",
                self.lost_error_px
            )?,
            None => writeln!(
                f,
                "frames to acquire        never    (the hand is never claimed with the fingertip error < {} px for {LOST_RUN} frames)",
                self.lost_error_px
            )?,
        }
        let again = self
            .reacquired_at
            .iter()
            .map(|k| k.to_string())
            .collect::<Vec<_>>();
        writeln!(
            f,
            "re-acquisitions          {:8}{}",
            again.len(),
            if again.is_empty() {
                String::new()
            } else {
                format!("       (at frame {})", again.join(", "))
            }
        )?;
        if let Some(status) = &self.status {
            writeln!(f, "{status}")?;
        }
        Ok(())
    }
}
