//! `--sample-iterations` and `--other-iterations`: caps on the Gauss–Newton iterations of the
//! hypotheses other than the best, shared by `track` and `stream`.

use anyhow::{bail, Result};
use clap::Args;

/// The hypotheses' iteration caps as options (each left out: the tracker's own number).
#[derive(Args, Debug, Clone, Copy, Default)]
pub struct HypothesisIterationArgs {
    /// With --hypotheses K > 1: at most N Gauss–Newton iterations for each new sample on the
    /// frame it is drawn, 1 to 255 (default: the tracker's own number, as is any N at or
    /// above it).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(1..))]
    pub sample_iterations: Option<u8>,
    /// With --hypotheses K > 1: at most N Gauss–Newton iterations for each carried
    /// hypothesis other than the best, 1 to 255 (default: the tracker's own; the best always
    /// takes the tracker's own). Both at 2 cut K = 4's instructions a frame by a third and
    /// give back part of its gain (docs/hypotheses.md, "Fewer iterations for the hypotheses
    /// other than the best").
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(1..))]
    pub other_iterations: Option<u8>,
}

impl HypothesisIterationArgs {
    /// Refuses a cap for a single hypothesis, where it would change nothing.
    pub fn check(&self, hypotheses: u8) -> Result<()> {
        for (option, given) in [
            ("--sample-iterations", self.sample_iterations),
            ("--other-iterations", self.other_iterations),
        ] {
            if let (Some(n), true) = (given, hypotheses <= 1) {
                bail!(
                    "{option} {n}: only several hypotheses are capped (the best always takes \
                     the tracker's own iterations); give --hypotheses K with K > 1, or leave \
                     {option} out"
                );
            }
        }
        Ok(())
    }

    /// The caps as `HypothesesConfig` and `Configure` take them, `[sample, other]` (0: the
    /// tracker's own number).
    pub fn caps(&self) -> [u8; 2] {
        [
            self.sample_iterations.unwrap_or(0),
            self.other_iterations.unwrap_or(0),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn caps_left_out_are_the_trackers_own_and_refused_for_one_hypothesis_only() {
        let none = HypothesisIterationArgs::default();
        assert_eq!(none.caps(), [0, 0]);
        assert!(none.check(1).is_ok());
        let both = HypothesisIterationArgs {
            sample_iterations: Some(2),
            other_iterations: Some(3),
        };
        assert_eq!(both.caps(), [2, 3]);
        assert!(both.check(4).is_ok());
        let err = both.check(1).unwrap_err().to_string();
        assert!(err.contains("--sample-iterations 2"), "{err}");
        let others_only = HypothesisIterationArgs {
            sample_iterations: None,
            other_iterations: Some(3),
        };
        let err = others_only.check(1).unwrap_err().to_string();
        assert!(err.contains("--other-iterations 3"), "{err}");
    }
}
