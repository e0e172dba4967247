//! `digiteyes bench`: measurements beyond what a test should make.

use anyhow::Result;
use clap::Subcommand;

use crate::bench::robustness::{self, RobustnessArgs};

/// What `digiteyes bench` measures.
#[derive(Subcommand, Debug)]
pub enum BenchCommand {
    /// Render and track a randomised sweep of rigs and motions and print the distribution.
    ///
    /// Odd seeds are `random-mono`, even ones `random-stereo` (see `render --help`). Per
    /// group (mono, stereo, all): median and 10th-percentile track life, the share of seeds
    /// at >= 95 %, the median and 10th percentile of the share of frames held (the fingertip
    /// error within `eval`'s 10 px, also after the life ends), median fingertip px, joint
    /// RMS deg, palm deg and mm, the lost flag's precision and recall against frames truly
    /// lost (fingertips > 20 px at 640 px wide or palm > 30 mm), non-finite states, frames
    /// with the palm > 100 mm away and not flagged, and tracker ms per frame. See
    /// docs/robustness.md.
    Robustness(RobustnessArgs),
}

/// Runs the measurement and prints what it found.
pub fn run(command: BenchCommand) -> Result<()> {
    match command {
        BenchCommand::Robustness(args) => {
            let sweep = robustness::run(&args)?;
            print!("{sweep}");
        }
    }
    Ok(())
}
