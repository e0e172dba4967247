//! What a report is made from: the sequence, the estimated states (NaN kept as gaps), the
//! tracker's per-frame columns, the truth when there is one, and the time of every frame.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::sequence::states::{read_states_with_gaps, StatesWithGaps};
use crate::sequence::{Sequence, StateTable, TRUTH_CSV};

/// The `stream` output's column of dropped frames' reasons (empty for a tracked frame).
pub const DROPPED_COLUMN: &str = "dropped";

/// Everything read from disk for a report, checked against the sequence.
#[derive(Debug, Clone)]
pub struct Inputs {
    /// The sequence, opened.
    pub sequence: Sequence,
    /// The states file.
    pub states_path: PathBuf,
    /// The estimated states (NaN where the file has no number) and their extra columns.
    pub estimate: StatesWithGaps,
    /// `truth.csv`, when the sequence has one.
    pub truth: Option<StateTable>,
    /// The time of every frame: seconds when the sequence gives its fps, else frame numbers.
    pub times: Vec<f64>,
    /// Whether [`Inputs::times`] are seconds (else frame numbers).
    pub in_seconds: bool,
    /// Frames the tracker flagged lost (`lost` column not 0; all false without the column).
    pub lost: Vec<bool>,
    /// Per frame, the reason the board dropped it (`dropped` column), `None` if tracked.
    pub dropped: Vec<Option<String>>,
    /// Frames with a state that is not a number, in order.
    pub gaps: Vec<usize>,
}

impl Inputs {
    /// Opens the sequence `seq` and reads `states_csv` (and `seq/truth.csv` if present).
    /// Errors name the file: an unreadable sequence, a states file whose columns do not fit
    /// the model or whose frame count is not the sequence's, a malformed truth.
    pub fn read(seq: &Path, states_csv: &Path) -> Result<Inputs> {
        let sequence = Sequence::open(seq)
            .with_context(|| format!("cannot open the sequence {}", seq.display()))?;
        let estimate = read_states_with_gaps(states_csv, sequence.n_states())?;
        let frames = estimate.table.rows.len();
        sequence.check_state_rows(states_csv, frames)?;
        let truth = if seq.join(TRUTH_CSV).exists() {
            Some(sequence.read_truth()?)
        } else {
            None
        };
        let fps = sequence.fps().filter(|f| f.is_finite() && *f > 0.0);
        let times = (0..frames)
            .map(|k| fps.map_or(k as f64, |f| k as f64 / f))
            .collect();
        let lost = match estimate.table.extra("lost") {
            Some(column) => column.iter().map(|&v| v.is_finite() && v != 0.0).collect(),
            None => vec![false; frames],
        };
        let dropped = match estimate.extra_text(DROPPED_COLUMN) {
            Some(column) => column
                .iter()
                .map(|r| (!r.is_empty()).then(|| r.to_string()))
                .collect(),
            None => vec![None; frames],
        };
        let gaps = estimate.gap_frames();
        Ok(Inputs {
            sequence,
            states_path: states_csv.to_path_buf(),
            estimate,
            truth,
            times,
            in_seconds: fps.is_some(),
            lost,
            dropped,
            gaps,
        })
    }

    /// Frames per camera.
    pub fn frames(&self) -> usize {
        self.times.len()
    }

    /// The x-axis label: "time (s)" or "frame".
    pub fn time_label(&self) -> &'static str {
        if self.in_seconds {
            "time (s)"
        } else {
            "frame"
        }
    }

    /// Frame `k`'s time as text: "1.233 s" or "frame 37".
    pub fn time_text(&self, k: usize) -> String {
        if self.in_seconds {
            format!("{:.3} s", self.times[k])
        } else {
            format!("frame {k}")
        }
    }

    /// Half the spacing between frames in time units, so a frame's span is `t ± half`.
    pub fn half_frame(&self) -> f64 {
        match self.times.get(1) {
            Some(t1) => (t1 - self.times[0]) / 2.0,
            None => 0.5,
        }
    }

    /// The tracker's column `name`, one value per frame (NaN where not a number).
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        self.estimate.table.extra(name)
    }

    /// Runs of consecutive frames where `flag` holds, as (first, last) frame pairs.
    pub fn runs(flags: &[bool]) -> Vec<(usize, usize)> {
        let mut runs = Vec::new();
        let mut start = None;
        for (k, &f) in flags.iter().enumerate() {
            match (f, start) {
                (true, None) => start = Some(k),
                (false, Some(s)) => {
                    runs.push((s, k - 1));
                    start = None;
                }
                _ => {}
            }
        }
        if let Some(s) = start {
            runs.push((s, flags.len() - 1));
        }
        runs
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_group_consecutive_frames() {
        let f = [true, true, false, true, false, false, true];
        assert_eq!(Inputs::runs(&f), vec![(0, 1), (3, 3), (6, 6)]);
        assert!(Inputs::runs(&[false, false]).is_empty());
        assert!(Inputs::runs(&[]).is_empty());
    }
}
