//! `digiteyes track`: a sequence tracked, its states as CSV, optionally overlays.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

use super::tracker_config;
use crate::track::track_sequence_with;

/// Track a sequence and write the estimated states as CSV.
///
/// Starts from the sequence's initial_state and estimates its free states from every
/// frame of every camera. Output columns: frame, q0..q{n-1} (unit quaternion, mm, rad),
/// rms_px, iterations, features_found, features_expected, lost (0/1). Prints a summary
/// (frames, lost frames, mean RMS residual, frames/s). Exits non-zero, naming the file or
/// frame, on bad input or a tracker error.
///
/// With --overlay DIR, each frame of each camera is also written as DIR/camN/NNNNNN.png,
/// drawn at the state tracked for it, like the IC40's video overlay: the frame dimmed,
/// each link's axis (orange) and silhouette lines (cyan), the slices searched (blue;
/// purple where masked as hidden), the edge points found (red squares) and the
/// fingertips found (green crosses). See docs/overlay.md.
#[derive(Args, Debug)]
pub struct TrackArgs {
    /// Sequence folder.
    pub seqdir: PathBuf,
    /// Output CSV path (default: states.csv in the current folder).
    #[arg(long, short, default_value = "states.csv", hide_default_value = true)]
    pub out: PathBuf,
    /// Gauss–Newton iterations per frame (default: the tracker's).
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..))]
    pub iterations: Option<u8>,
    /// Start each frame from the last estimate instead of a constant-velocity prediction.
    #[arg(long)]
    pub no_predict: bool,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
    /// Also draw every frame at its tracked state into DIR/camN/NNNNNN.png.
    #[arg(long, value_name = "DIR")]
    pub overlay: Option<PathBuf>,
}

/// Tracks the sequence and prints the summary; `progress`: a progress bar on stderr.
pub fn run(args: TrackArgs, progress: bool) -> Result<()> {
    let config = tracker_config(args.iterations, args.no_predict);
    let summary = track_sequence_with(
        &args.seqdir,
        &args.out,
        config,
        progress && !args.quiet,
        args.overlay.as_deref(),
    )?;
    println!("{summary}");
    Ok(())
}
