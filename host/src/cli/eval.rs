//! `digiteyes eval`: estimated states against a sequence's truth.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

use crate::eval::evaluate_at;

/// Compare estimated states with a sequence's truth.csv.
///
/// Per camera: fingertip and joint-centre reprojection error (px, mean and 95th
/// percentile). Free-joint RMS error (deg), palm rotation (deg) and translation (mm)
/// errors, and track life: the fraction of frames before the mean fingertip error stays
/// above 10 px (`--lost-px`) for 5 frames, and the frames held: the share of all frames
/// whose mean fingertip error is within that threshold, also after the life ends. With a
/// `status` column (`track`'s output): the frames to acquire (the first frame from which the
/// hand is claimed with the error under that threshold for 5 frames) and the
/// re-acquisitions.
#[derive(Args, Debug)]
pub struct EvalArgs {
    /// Sequence folder (with truth.csv).
    pub seqdir: PathBuf,
    /// Estimated states (the output of `track`).
    pub states: PathBuf,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// The mean fingertip error (px) above which a frame counts as lost and below which the
    /// hand counts as held. The default suits 640-px-wide frames; scale it with the width to
    /// compare sizes (5 at 320×240).
    #[arg(long, value_name = "PX", default_value_t = crate::eval::LOST_ERROR_PX)]
    pub lost_px: f64,
}

/// Evaluates and prints the report (a table, or JSON).
pub fn run(args: EvalArgs) -> Result<()> {
    let report = evaluate_at(&args.seqdir, &args.states, args.lost_px)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{report}");
    }
    Ok(())
}
