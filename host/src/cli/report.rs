//! `digiteyes report`: a tracking run as one self-contained HTML page.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

use crate::report::{write_report, ReportOptions};

/// Write an HTML report of a tracking run: states against time, errors, overlays.
///
/// One self-contained page (inline SVG plots and PNG thumbnails, no script, no external
/// link: it opens offline and can be mailed alone). It shows the sequence (folder, frames,
/// cameras, fps, model, free states); the accuracy against truth.csv when the sequence
/// has one (as `eval` prints it); the error over time (mean fingertip reprojection error
/// in px and free-joint RMS error in deg against the truth, and the tracker's rms_px
/// residual); one plot per free state against time (s; frames without fps) in the
/// state's unit (mm, rad), estimate and truth, with the frames flagged lost shaded and
/// the frames a board dropped (the `dropped` column of `stream`) marked; and the model
/// drawn over every Nth frame (--thumb-every); with --hypotheses FILE (`track
/// --hypotheses-out`), the hypotheses carried and the best's score against time. States that are not numbers are gaps in
/// the plots and a warning, not an error. Prints the path written and a summary.
#[derive(Args, Debug)]
pub struct ReportArgs {
    /// Sequence folder.
    pub seqdir: PathBuf,
    /// Estimated states (the output of `track` or `stream`).
    pub states: PathBuf,
    /// Output HTML path.
    #[arg(long, short, default_value = "report.html")]
    pub out: PathBuf,
    /// An overlay thumbnail of frames 0, N, 2N, ... (0: none).
    #[arg(long, value_name = "N",
          default_value_t = crate::report::DEFAULT_THUMB_EVERY)]
    pub thumb_every: usize,
    /// Thumbnail width in px (the height keeps the camera's aspect).
    #[arg(long, value_name = "PX",
          default_value_t = crate::report::DEFAULT_THUMB_WIDTH,
          value_parser = clap::value_parser!(u32).range(16..=4096))]
    pub thumb_width: u32,
    /// Thumbnails of this camera only (0-based; default: every camera).
    #[arg(long, value_name = "N")]
    pub camera_index: Option<usize>,
    /// Also plot the hypotheses carried and the best's score against time, from this CSV
    /// (`track --hypotheses-out`).
    #[arg(long, value_name = "FILE")]
    pub hypotheses: Option<PathBuf>,
}

/// Writes the report; prints its warnings on stderr and the summary.
pub fn run(args: ReportArgs) -> Result<()> {
    let options = ReportOptions {
        thumb_every: args.thumb_every,
        thumb_width: args.thumb_width,
        camera: args.camera_index,
        hypotheses: args.hypotheses,
        ..ReportOptions::default()
    };
    let summary = write_report(&args.seqdir, &args.states, &args.out, &options)?;
    for warning in &summary.warnings {
        eprintln!("digiteyes: warning: {warning}");
    }
    println!("{summary}");
    Ok(())
}
