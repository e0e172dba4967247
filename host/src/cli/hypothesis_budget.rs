//! What the hypotheses other than the best may cost, as options shared by `track` and
//! `stream`: caps on their Gauss–Newton iterations (`--sample-iterations`,
//! `--other-iterations`) and the finger-undo candidates (`--no-keep-fingers`).

use anyhow::{bail, Result};
use clap::Args;

use digiteyes_core::hypotheses::HypothesesConfig;

/// The hypotheses' budget as options (each left out: the tracker's default).
#[derive(Args, Debug, Clone, Copy, Default)]
pub struct HypothesisBudgetArgs {
    /// With --hypotheses K > 1: at most N Gauss–Newton iterations for each new sample on the
    /// frame it is drawn, 1 to 255 (default: the tracker's own number, as is any N at or
    /// above it).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(1..))]
    pub sample_iterations: Option<u8>,
    /// With --hypotheses K > 1: at most N Gauss–Newton iterations for each carried
    /// hypothesis other than the best, 1 to 255 (default: the tracker's own; the best always
    /// takes the tracker's own). Both at 2 cut K = 4's instructions a frame by a third
    /// (docs/hypotheses.md, "Fewer iterations for the hypotheses other than the best").
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(1..))]
    pub other_iterations: Option<u8>,
    /// With --hypotheses K > 1: do not also score the best with each finger's update undone
    /// (by default every scored frame weighs those candidates). Saves the scores of up to six
    /// candidates a scored frame: with K = 2 scored one frame in 4 and both caps at 1, a 480 MHz
    /// Cortex-M7 answered every frame of a whole-hand sequence within 33 ms (docs/hypotheses.md,
    /// "Two hypotheses within a board's frame budget").
    #[arg(long)]
    pub no_keep_fingers: bool,
}

impl HypothesisBudgetArgs {
    /// Refuses any of these options for a single hypothesis, where it would change nothing.
    pub fn check(&self, hypotheses: u8) -> Result<()> {
        if hypotheses > 1 {
            return Ok(());
        }
        let given = [
            (
                "--sample-iterations",
                self.sample_iterations.map(|n| n.to_string()),
            ),
            (
                "--other-iterations",
                self.other_iterations.map(|n| n.to_string()),
            ),
            ("--no-keep-fingers", self.no_keep_fingers.then(String::new)),
        ];
        for (option, value) in given {
            if let Some(value) = value {
                let shown = format!("{option} {value}");
                bail!(
                    "{}: only several hypotheses have a budget (the best always takes the \
                     tracker's own iterations); give --hypotheses K with K > 1, or leave \
                     {option} out",
                    shown.trim_end()
                );
            }
        }
        Ok(())
    }

    /// Whether any option was given.
    pub fn any(&self) -> bool {
        self.sample_iterations.is_some() || self.other_iterations.is_some() || self.no_keep_fingers
    }

    /// `config` with these options applied (the caps: 0, the tracker's own number, when left
    /// out).
    pub fn applied(&self, config: HypothesesConfig) -> HypothesesConfig {
        HypothesesConfig {
            sample_iterations: self.sample_iterations.unwrap_or(config.sample_iterations),
            other_iterations: self.other_iterations.unwrap_or(config.other_iterations),
            keep_fingers: config.keep_fingers && !self.no_keep_fingers,
            ..config
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_left_out_are_the_defaults_and_refused_for_one_hypothesis_only() {
        let none = HypothesisBudgetArgs::default();
        assert!(!none.any());
        assert_eq!(
            none.applied(HypothesesConfig::default()),
            HypothesesConfig::default()
        );
        assert!(none.check(1).is_ok());
        let all = HypothesisBudgetArgs {
            sample_iterations: Some(2),
            other_iterations: Some(3),
            no_keep_fingers: true,
        };
        let applied = all.applied(HypothesesConfig::default());
        assert_eq!(
            (
                applied.sample_iterations,
                applied.other_iterations,
                applied.keep_fingers
            ),
            (2, 3, false)
        );
        assert!(all.check(4).is_ok());
        let err = all.check(1).unwrap_err().to_string();
        assert!(err.starts_with("--sample-iterations 2:"), "{err}");
        let undo_only = HypothesisBudgetArgs {
            no_keep_fingers: true,
            ..HypothesisBudgetArgs::default()
        };
        assert!(undo_only.any());
        let err = undo_only.check(1).unwrap_err().to_string();
        assert!(err.starts_with("--no-keep-fingers:"), "{err}");
    }
}
