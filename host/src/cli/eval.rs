//! `digiteyes eval`: estimated states against a sequence's truth.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

use crate::eval::evaluate;

/// Compare estimated states with a sequence's truth.csv.
///
/// Per camera: fingertip and joint-centre reprojection error (px, mean and 95th
/// percentile). Free-joint RMS error (deg), palm rotation (deg) and translation (mm)
/// errors, and track life: the fraction of frames before the mean fingertip error stays
/// above 10 px for 5 frames.
#[derive(Args, Debug)]
pub struct EvalArgs {
    /// Sequence folder (with truth.csv).
    pub seqdir: PathBuf,
    /// Estimated states (the output of `track`).
    pub states: PathBuf,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Evaluates and prints the report (a table, or JSON).
pub fn run(args: EvalArgs) -> Result<()> {
    let report = evaluate(&args.seqdir, &args.states)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{report}");
    }
    Ok(())
}
