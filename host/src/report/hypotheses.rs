//! The report's hypotheses section (`report --hypotheses FILE`): from `track
//! --hypotheses-out`'s CSV, the count of hypotheses carried and the best's score against time.

use std::path::Path;

use anyhow::{bail, Result};

use super::input::Inputs;
use super::plots::{decorate, entry, new_chart};
use super::svg::finite_range;
use crate::sequence::hypotheses::read_hypotheses;

/// Per frame, what the hypotheses CSV says.
#[derive(Debug, Clone, PartialEq)]
pub struct HypothesesSeries {
    /// Hypotheses carried after each frame (0: none, searching).
    pub count: Vec<f64>,
    /// The best's score (rank 0) after each frame; NaN on a frame with none.
    pub best_score: Vec<f64>,
}

impl HypothesesSeries {
    /// Reads `path` for the frames of `inputs`. Fails, naming the file, on a malformed file or
    /// one with rows past the sequence's last frame.
    pub fn read(inputs: &Inputs, path: &Path) -> Result<HypothesesSeries> {
        let table = read_hypotheses(path, inputs.sequence.n_states())?;
        let frames = inputs.frames();
        if let Some(last) = table.last_frame().filter(|&f| f >= frames) {
            bail!(
                "{}: frame {last} is past the states' last frame ({} frames): the hypotheses of \
                 another run?",
                path.display(),
                frames
            );
        }
        let by_frame = table.by_frame(frames);
        Ok(HypothesesSeries {
            count: by_frame.iter().map(|rows| rows.len() as f64).collect(),
            best_score: by_frame
                .iter()
                .map(|rows| rows.first().map_or(f64::NAN, |r| r.score))
                .collect(),
        })
    }

    /// The two plots: `<svg class="hypotheses-plot" data-series="count">` (hypotheses carried)
    /// and `data-series="best-score"` (the best's likelihood score), with the status band and
    /// lost frames as on the other plots.
    pub fn plots(&self, inputs: &Inputs) -> Vec<String> {
        // Headroom above the lines: the status band runs along the top of the plot.
        let top = finite_range(self.count.iter()).map_or(1.0, |(_, hi)| hi.max(1.0));
        let mut chart = new_chart(inputs, (0.0, top + 0.5));
        let mut legend = decorate(&mut chart, inputs);
        chart.line(&inputs.times, &self.count, "hyp-count");
        legend.insert(0, entry("hyp-count", "carried"));
        let count = chart.finish(
            r#" class="hypotheses-plot" data-series="count""#,
            "hypotheses carried",
            inputs.time_label(),
            "hypotheses",
            &legend,
        );
        let (lo, hi) = finite_range(self.best_score.iter()).unwrap_or((0.0, 1.0));
        let mut chart = new_chart(inputs, (lo.min(0.0), hi.max(1.0) + 0.1));
        let mut legend = decorate(&mut chart, inputs);
        chart.line(&inputs.times, &self.best_score, "hyp-score");
        legend.insert(0, entry("hyp-score", "best"));
        let score = chart.finish(
            r#" class="hypotheses-plot" data-series="best-score""#,
            "the best hypothesis' score",
            inputs.time_label(),
            "score",
            &legend,
        );
        vec![count, score]
    }

    /// A line of text: frames with hypotheses, the mean count, the best's mean score.
    pub fn summary(&self) -> String {
        let with: Vec<usize> = (0..self.count.len())
            .filter(|&k| self.count[k] > 0.0)
            .collect();
        let n = with.len().max(1) as f64;
        let mean_count = with.iter().map(|&k| self.count[k]).sum::<f64>() / n;
        let mean_score = with.iter().map(|&k| self.best_score[k]).sum::<f64>() / n;
        format!(
            "{} of {} frames carry hypotheses (a searching frame carries none): {:.2} on \
             average; the best's score {:.3} on average (0 throughout with a single hypothesis).",
            with.len(),
            self.count.len(),
            mean_count,
            mean_score
        )
    }
}
