//! `digiteyes track`: a sequence tracked, its states as CSV, optionally overlays.

use std::path::PathBuf;

use anyhow::Result;
use clap::{Args, ValueEnum};

use super::hypotheses::{self, HypothesisBudgetArgs};
use super::tracker_config;
use crate::acquire::Recovery;
use crate::track::{track_sequence_to, Init, TrackOptions, TrackOutputs};
use digiteyes_core::hypotheses::HypothesesConfig;

/// Track a sequence and write the estimated states as CSV.
///
/// Estimates the sequence's free states from every frame of every camera, inside a status
/// machine: searching (no hand claimed) -> tracking -> lost -> searching. With --init
/// given (the default when sequence.json has initial_state) it tracks from the initial
/// state; with --init auto (the default when it has none) it searches for the hand
/// itself, ignoring the free states' given values (fixed states keep theirs). A track
/// lost for 10 frames in a row searches again (--recover search, the default): first
/// locally around the last tracked state, then over the whole view. --recover never
/// keeps the plain tracker's behaviour: a lost track is never searched for, and the
/// output is the same as before the status machine existed (plus the status column).
///
/// Output columns: frame, q0..q{n-1} (unit quaternion, mm, rad), rms_px, iterations,
/// features_found, features_expected, lost (0/1: 1 on every frame that claims no hand,
/// searching or lost), status (searching, tracking or lost; a hand found shows as searching
/// until it is confirmed). While searching, the states are the last tracked ones (the
/// search's base state before the first acquisition).
/// Prints a summary (frames, lost frames, mean RMS residual, frames per status, the
/// frames where the hand was acquired, lost and re-acquired, frames/s). Exits non-zero,
/// naming the file or frame, on bad input or a tracker error.
///
/// With --overlay DIR, each frame of each camera is also written as DIR/camN/NNNNNN.png,
/// drawn at the state tracked for it, like the IC40's video overlay: the frame dimmed,
/// each link's axis (orange) and silhouette lines (cyan), the slices searched (blue;
/// purple where masked as hidden), the edge points found (red squares) and the
/// fingertips found (green crosses). See docs/overlay.md.
///
/// With --hypotheses K (1 to 8; 1, the default, is the single tracker, bit for bit) the
/// tracker carries up to K hypotheses through ambiguous frames and outputs the best; the
/// summary then says how many were carried on average and how often the best switched.
/// --hypotheses-out FILE writes every hypothesis carried: one row per hypothesis per frame,
/// `frame,rank,score,age,q0..` (rank 0 is the best, the output; a searching frame has no
/// row). With --score-every S the hypotheses are scored, sampled around and merged on one
/// frame in S only (and after a lost frame), and only tracked between: K = 2 at S = 4 costs
/// about half of K = 2's instructions a frame on the mean (docs/hypotheses.md, "Scoring one
/// frame in S"). --sample-iterations and --other-iterations cap the Gauss–Newton iterations
/// of the new samples and of the carried hypotheses other than the best; --no-keep-fingers
/// drops the candidates that undo each finger's update.
#[derive(Args, Debug)]
pub struct TrackArgs {
    /// Sequence folder.
    pub seqdir: PathBuf,
    /// Output CSV path (default: states.csv in the current folder).
    #[arg(long, short, default_value = "states.csv", hide_default_value = true)]
    pub out: PathBuf,
    /// Gauss–Newton iterations per tracked frame (default: the tracker's, 8). The search's
    /// refinements of its leaves keep their own 8, which its acceptance was set on.
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..))]
    pub iterations: Option<u8>,
    /// Start each frame from the last estimate instead of a constant-velocity prediction.
    #[arg(long)]
    pub no_predict: bool,
    /// After every N-th frame tracked, move one finger in turn where the hand's shading
    /// says it lies (0: never, the default). Costs up to 16 residuals over a finger a frame.
    /// It models the hand as one matte grey: on glossy, shadowed hands of uneven grey it
    /// helped two cameras a little and one camera not at all, and under the tracker's
    /// defaults since stop 77 neither; docs/robustness.md, "The shading pulls a finger back",
    /// "A surface the shading fit does not model" and "Stop 78".
    #[arg(long, value_name = "N")]
    pub shading_refine: Option<u8>,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
    /// Also draw every frame at its tracked state into DIR/camN/NNNNNN.png.
    #[arg(long, value_name = "DIR")]
    pub overlay: Option<PathBuf>,
    /// How to start: `given` tracks from the sequence's initial_state, `auto` searches for
    /// the hand (default: given when sequence.json has initial_state, else auto).
    #[arg(long, value_enum, value_name = "HOW")]
    pub init: Option<InitArg>,
    /// After 10 lost frames in a row: `search` for the hand again (locally, then over the
    /// view), or `never` (stay lost, as the plain tracker did).
    #[arg(long, value_enum, value_name = "HOW", default_value = "search")]
    pub recover: RecoverArg,
    /// Hypotheses carried through ambiguous frames, 1 to 8 (1: the single tracker, the
    /// board's budget). On the randomised sweep 4 kept the hand longer than 1 (+3.7 points of
    /// track life over 360 seeds, though 24 seeds did worse) at about 7 times the cost per
    /// frame; docs/hypotheses.md.
    #[arg(long, value_name = "K", default_value_t = 1, value_parser = hypotheses::count)]
    pub hypotheses: u8,
    /// Also write every hypothesis carried, one row per hypothesis per frame, to FILE.
    #[arg(long, value_name = "FILE")]
    pub hypotheses_out: Option<PathBuf>,
    /// With --hypotheses K > 1: score the hypotheses on one frame in S, 1 to 255 (default 1:
    /// every frame).
    #[arg(long, value_name = "S", default_value_t = 1, value_parser = clap::value_parser!(u8).range(1..))]
    pub score_every: u8,
    /// What the hypotheses other than the best may cost.
    #[command(flatten)]
    pub hypothesis_budget: HypothesisBudgetArgs,
}

/// `--init`'s values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum InitArg {
    /// Track from the sequence's initial_state.
    Given,
    /// Search for the hand.
    Auto,
}

/// `--recover`'s values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RecoverArg {
    /// Search again after a loss.
    Search,
    /// Never search: stay lost.
    Never,
}

/// Tracks the sequence and prints the summary; `progress`: a progress bar on stderr.
pub fn run(args: TrackArgs, progress: bool) -> Result<()> {
    let asked = hypotheses::asked(
        Some(args.hypotheses),
        Some(args.score_every),
        &args.hypothesis_budget,
    )?;
    let mut config = tracker_config(args.iterations, args.no_predict);
    if let Some(every) = args.shading_refine {
        config.shading_refine.every_frames = every;
    }
    let options = TrackOptions {
        init: args.init.map(|i| match i {
            InitArg::Given => Init::Given,
            InitArg::Auto => Init::Auto,
        }),
        recovery: match args.recover {
            RecoverArg::Search => Recovery::Search,
            RecoverArg::Never => Recovery::Never,
        },
        hypotheses: asked.over(HypothesesConfig::default()),
        ..TrackOptions::default()
    };
    let outputs = TrackOutputs {
        overlay_dir: args.overlay.as_deref(),
        hypotheses_out: args.hypotheses_out.as_deref(),
    };
    let summary = track_sequence_to(
        &args.seqdir,
        &args.out,
        config,
        progress && !args.quiet,
        &outputs,
        &options,
    )?;
    println!("{summary}");
    Ok(())
}
