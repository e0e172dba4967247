//! The hypotheses `track` and `stream` ask for, from their options: the count
//! (`--hypotheses`), the scoring period (`--score-every`), and what the hypotheses other than
//! the best may cost — caps on their Gauss–Newton iterations (`--sample-iterations`,
//! `--other-iterations`) and the finger-undo candidates (`--no-keep-fingers`). Both commands
//! map them to one [`HypothesesParams`]: `track` lays it over the tracker's configuration,
//! `stream` sends it in `Configure`.

use anyhow::{bail, Result};
use clap::Args;

use digiteyes_core::protocol::HypothesesParams;

/// `--hypotheses`' values: a whole number 1..=MAX_HYPOTHESES.
pub fn count(text: &str) -> Result<u8, String> {
    let max = digiteyes_core::config::MAX_HYPOTHESES;
    let range = format!("a whole number from 1 to {max} (1: the single tracker)");
    match text.trim().parse::<usize>() {
        Ok(k) if (1..=max).contains(&k) => u8::try_from(k).map_err(|_| range),
        _ => Err(format!("{} is not {range}", crate::text::quote_value(text))),
    }
}

/// The hypotheses asked for: `count` (left out: the default), scored one frame in
/// `score_every` (left out: the default), under `budget`. Refuses a scoring period or a budget
/// for a single hypothesis, where either would change nothing.
pub fn asked(
    count: Option<u8>,
    score_every: Option<u8>,
    budget: &HypothesisBudgetArgs,
) -> Result<HypothesesParams> {
    let defaults = HypothesesParams::default();
    let count = count.unwrap_or(defaults.count);
    if let Some(s) = score_every {
        check_score_every(count, s)?;
    }
    budget.check(count)?;
    Ok(budget.applied(HypothesesParams {
        count,
        score_every: score_every.unwrap_or(defaults.score_every),
        ..defaults
    }))
}

/// Refuses `--score-every` above 1 for a single hypothesis, where it would change nothing.
fn check_score_every(hypotheses: u8, score_every: u8) -> Result<()> {
    if score_every > 1 && hypotheses <= 1 {
        bail!(
            "--score-every {score_every}: only several hypotheses are scored; give \
             --hypotheses K with K > 1, or leave --score-every out"
        );
    }
    Ok(())
}

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
    fn check(&self, hypotheses: u8) -> Result<()> {
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

    /// `params` with these options applied (each left out: as in `params`).
    fn applied(&self, params: HypothesesParams) -> HypothesesParams {
        HypothesesParams {
            sample_iterations: self.sample_iterations.unwrap_or(params.sample_iterations),
            other_iterations: self.other_iterations.unwrap_or(params.other_iterations),
            keep_fingers: params.keep_fingers && !self.no_keep_fingers,
            ..params
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
            asked(None, None, &none).unwrap(),
            HypothesesParams::default()
        );
        assert!(asked(Some(1), Some(1), &none).is_ok());
        let all = HypothesisBudgetArgs {
            sample_iterations: Some(2),
            other_iterations: Some(3),
            no_keep_fingers: true,
        };
        assert_eq!(
            asked(Some(4), Some(5), &all).unwrap(),
            HypothesesParams {
                count: 4,
                score_every: 5,
                sample_iterations: 2,
                other_iterations: 3,
                keep_fingers: false,
            }
        );
        let err = asked(Some(1), None, &all).unwrap_err().to_string();
        assert!(err.starts_with("--sample-iterations 2:"), "{err}");
        let err = asked(None, Some(2), &none).unwrap_err().to_string();
        assert!(err.starts_with("--score-every 2:"), "{err}");
        let undo_only = HypothesisBudgetArgs {
            no_keep_fingers: true,
            ..HypothesisBudgetArgs::default()
        };
        assert!(undo_only.any());
        let err = asked(Some(1), Some(1), &undo_only).unwrap_err().to_string();
        assert!(err.starts_with("--no-keep-fingers:"), "{err}");
    }
}
