//! The tracking report: one self-contained HTML page judging a run the way the thesis did —
//! each free state plotted against time with its ground truth (Figs. 4.7, 4.8, 4.11, 4.12),
//! the error over time, and overlay snapshots of the model on the frames (Fig. 4.5).
//!
//! ```text
//! sequence + states.csv (+ truth.csv) ─▶ input ─▶ accuracy (crate::eval)
//!                                          │  ─▶ plots (svg)  ─▶ html ─▶ report.html
//!                                          └──▶ thumbnails (crate::overlay, PNG data: URIs)
//! ```
//!
//! The page holds no script and names no external resource: it opens offline, alone. See
//! `docs/report.md`.

pub mod accuracy;
pub mod html;
pub mod hypotheses;
pub mod input;
pub mod mouse;
pub mod plots;
pub mod svg;
pub mod thumbnails;

use std::fmt;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Result;
use digiteyes_core::features::FeatureConfig;

use crate::eval::EvalReport;
use crate::mouse_pole::accuracy::MouseAccuracy;
use crate::state_names::state_label;
use accuracy::{accuracy, Accuracy};
use html::Page;
use input::Inputs;

/// A thumbnail every this many frames unless asked otherwise.
pub const DEFAULT_THUMB_EVERY: usize = 10;
/// Thumbnail width (px) unless asked otherwise.
pub const DEFAULT_THUMB_WIDTH: u32 = 320;

/// What goes into a report.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ReportOptions {
    /// An overlay thumbnail of frames 0, N, 2N, ... (0: no thumbnails).
    pub thumb_every: usize,
    /// Thumbnail width (px); the height keeps the camera's aspect. Frames narrower than this
    /// are shown at their own size.
    pub thumb_width: u32,
    /// The camera whose frames get thumbnails (0-based); `None`: every camera.
    pub camera: Option<usize>,
    /// The feature search the overlay draws (the tracker's default).
    pub features: FeatureConfig,
    /// `track --hypotheses-out`'s CSV: its count and best score plotted against time.
    pub hypotheses: Option<PathBuf>,
}

impl Default for ReportOptions {
    fn default() -> Self {
        ReportOptions {
            thumb_every: DEFAULT_THUMB_EVERY,
            thumb_width: DEFAULT_THUMB_WIDTH,
            camera: None,
            features: FeatureConfig::default(),
            hypotheses: None,
        }
    }
}

/// What a report holds.
#[derive(Debug, Clone)]
pub struct ReportSummary {
    /// Where the report was written.
    pub out: PathBuf,
    /// Frames per camera.
    pub frames: usize,
    /// Cameras in the sequence.
    pub cameras: usize,
    /// State plots (one per free state).
    pub state_plots: usize,
    /// Error-over-time plots.
    pub error_plots: usize,
    /// 3D-mouse plots (the thesis' Fig. 4.12), for a 3D-mouse sub-model.
    pub mouse_plots: usize,
    /// The 3D mouse read off the estimate against the truth's, for a 3D-mouse sub-model with a
    /// truth.
    pub mouse: Option<MouseAccuracy>,
    /// Hypotheses plots (count and best score), with `--hypotheses`.
    pub hypotheses_plots: usize,
    /// Overlay thumbnails.
    pub thumbnails: usize,
    /// Size of the page (bytes).
    pub bytes: usize,
    /// Frames the tracker flagged lost.
    pub lost_frames: usize,
    /// Frames the board dropped (`dropped` column not empty).
    pub dropped_frames: usize,
    /// Frames with a state that is not a number (gaps in the plots).
    pub nan_frames: Vec<usize>,
    /// The accuracy against `truth.csv` (over the frames without NaN), when there is a truth.
    pub eval: Option<EvalReport>,
    /// The problems the page warns about (also in [`ReportSummary::nan_frames`] etc.).
    pub warnings: Vec<String>,
    /// Time taken to read, draw and write (s).
    pub seconds: f64,
}

impl fmt::Display for ReportSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "report written to {} ({:.0} KB): {} frames, {} state plots, {} error plots, {} thumbnails",
            self.out.display(),
            self.bytes as f64 / 1024.0,
            self.frames,
            self.state_plots,
            self.error_plots,
            self.thumbnails
        )?;
        if self.hypotheses_plots > 0 {
            write!(f, ", {} hypotheses plots", self.hypotheses_plots)?;
        }
        match &self.eval {
            Some(e) => {
                let tips = e.fingertip_mean_by_frame.iter().sum::<f64>()
                    / e.fingertip_mean_by_frame.len().max(1) as f64;
                write!(
                    f,
                    "; fingertips {tips:.2} px mean, track life {:.0} %",
                    100.0 * e.track_life
                )?;
            }
            None => write!(f, "; no truth.csv")?,
        }
        if let Some(m) = &self.mouse {
            write!(
                f,
                "; 3D mouse: pole height {:.2} mm RMS, base {:.2} mm RMS",
                m.height_rms_mm, m.base_rms_mm
            )?;
        }
        write!(
            f,
            "; {} lost, {} dropped, {} with NaN; {:.2} s",
            self.lost_frames,
            self.dropped_frames,
            self.nan_frames.len(),
            self.seconds
        )
    }
}

/// Writes the report of `states_csv` (the output of `track` or `stream`) on the sequence in
/// folder `seq` to `out` as one self-contained HTML file. Errors name the file at fault: an
/// unreadable sequence, a states file with the wrong columns or frame count, a malformed
/// `truth.csv`, an unreadable frame, an unwritable `out`. States that are not numbers do not
/// fail: they are gaps in the plots, and the page and summary warn about them.
pub fn write_report(
    seq: &Path,
    states_csv: &Path,
    out: &Path,
    options: &ReportOptions,
) -> Result<ReportSummary> {
    let start = Instant::now();
    let (page, mut summary) = build_report(seq, states_csv, options)?;
    crate::atomic_file::write_atomic(out, page.as_bytes())?;
    summary.out = out.to_path_buf();
    summary.seconds = start.elapsed().as_secs_f64();
    Ok(summary)
}

/// The report page as text and its summary (with an empty `out`), without writing it.
pub fn build_report(
    seq: &Path,
    states_csv: &Path,
    options: &ReportOptions,
) -> Result<(String, ReportSummary)> {
    let start = Instant::now();
    let inputs = Inputs::read(seq, states_csv)?;
    let cameras = thumbnails::thumbnail_cameras(&inputs, options)?;
    let accuracy = match &inputs.truth {
        Some(truth) => accuracy(&inputs, truth)?,
        None => None,
    };
    let hypotheses = options
        .hypotheses
        .as_deref()
        .map(|path| hypotheses::HypothesesSeries::read(&inputs, path))
        .transpose()?;
    let warnings = warnings(&inputs, accuracy.as_ref());
    let free = inputs.sequence.free_states();
    let mut page = Page::new();
    header(&mut page, &inputs, &free);
    for w in &warnings {
        page.warning(w);
    }
    page.heading("Accuracy");
    match (&accuracy, &inputs.truth) {
        (Some(acc), _) => page.pre(&acc.report.to_string()),
        (None, Some(_)) => page.paragraph("No frame with a complete estimate to compare."),
        (None, None) => page.paragraph(
            "The sequence has no truth.csv: the plots show the estimate and the tracker's own \
             residual only.",
        ),
    }
    page.heading("Error over time");
    let error_plots = plots::error_plots(&inputs, accuracy.as_ref());
    page.raw(&grid(&error_plots));
    let hypotheses_plots = match &hypotheses {
        Some(series) => {
            page.heading("Hypotheses");
            page.paragraph(&series.summary());
            let plots = series.plots(&inputs);
            page.raw(&grid(&plots));
            plots.len()
        }
        None => 0,
    };
    let mouse = mouse::mouse_section(&inputs)?;
    if let Some(section) = &mouse {
        page.heading("3D mouse (the thesis' Fig. 4.12)");
        page.paragraph(
            "The 3D mouse's pole read off the states (thesis Sec. 4.3.4): its base is the \
             palm's position on the table, its height finger 1's fingertip above the table; \
             finger 4's and the thumb's abduction are its buttons, pressed beyond 0.15 rad \
             from their rest at the first frame.",
        );
        if let Some(acc) = &section.accuracy {
            page.pre(&acc.to_string());
        }
        page.raw(&grid(&section.plots));
    }
    page.heading(&format!("Free states ({})", free.len()));
    page.paragraph(legend_note(&inputs));
    let state_plots: Vec<String> = free
        .iter()
        .map(|&s| plots::state_plot(&inputs, s))
        .collect();
    page.raw(&grid(&state_plots));
    let frames = thumbnails::thumbnail_frames(inputs.frames(), options.thumb_every);
    let thumbs = thumbnails::thumbnails(&inputs, options, &frames, &cameras)?;
    if !thumbs.is_empty() {
        page.heading(&format!(
            "Overlays every {} frames (model at the estimate, searched slices, edges, tips)",
            options.thumb_every
        ));
        let tips = accuracy.as_ref().map(|a| a.fingertip_px.as_slice());
        page.raw(&thumbnails::thumbnails_html(&inputs, &thumbs, tips));
    }
    let title = format!("digiteyes report: {}", sequence_name(&inputs.sequence.dir));
    let html = page.finish(&title);
    let summary = ReportSummary {
        out: PathBuf::new(),
        frames: inputs.frames(),
        cameras: inputs.sequence.cameras.len(),
        state_plots: state_plots.len(),
        error_plots: error_plots.len(),
        mouse_plots: mouse.as_ref().map_or(0, |m| m.plots.len()),
        mouse: mouse.and_then(|m| m.accuracy),
        hypotheses_plots,
        thumbnails: thumbs.len(),
        bytes: html.len(),
        lost_frames: inputs.lost.iter().filter(|&&l| l).count(),
        dropped_frames: inputs.dropped.iter().flatten().count(),
        nan_frames: inputs.gaps.clone(),
        eval: accuracy.map(|a| a.report),
        warnings,
        seconds: start.elapsed().as_secs_f64(),
    };
    Ok((html, summary))
}

/// The header table: sequence, states file, frames, cameras, fps, model, free states.
fn header(page: &mut Page, inputs: &Inputs, free: &[usize]) {
    let seq = &inputs.sequence;
    let cameras = (0..seq.cameras.len())
        .map(|c| {
            let cam = &seq.cameras[c];
            format!("{} ({}x{} px)", seq.camera_name(c), cam.width, cam.height)
        })
        .collect::<Vec<_>>()
        .join(", ");
    let frames = match seq.fps() {
        Some(fps) if fps > 0.0 => format!(
            "{} ({:.2} s at {fps} frames/s)",
            inputs.frames(),
            inputs.frames() as f64 / fps
        ),
        _ => format!("{} (no fps in sequence.json)", inputs.frames()),
    };
    let free_text = free
        .iter()
        .map(|&s| state_label(s))
        .collect::<Vec<_>>()
        .join("; ");
    let truth = if inputs.truth.is_some() {
        "truth.csv"
    } else {
        "none"
    };
    page.table(&[
        ("sequence", sequence_name(&seq.dir)),
        ("folder", seq.dir.display().to_string()),
        ("states", inputs.states_path.display().to_string()),
        ("ground truth", truth.to_string()),
        ("frames", frames),
        ("cameras", cameras),
        ("model", seq.file.model.clone()),
        ("free states", free_text),
        (
            "tracker flags",
            format!(
                "{} lost, {} dropped by the board",
                inputs.lost.iter().filter(|&&l| l).count(),
                inputs.dropped.iter().flatten().count()
            ),
        ),
        ("status", status_text(inputs)),
        (
            "made by",
            format!("digiteyes {}", env!("CARGO_PKG_VERSION")),
        ),
    ]);
}

/// The status row of the header: frames per status and where it changed, from the states'
/// `status` column.
fn status_text(inputs: &Inputs) -> String {
    match &inputs.estimate.table.status {
        Some(column) => {
            let statuses: Vec<crate::sequence::status::Status> = column
                .iter()
                .map(|s| s.unwrap_or(crate::sequence::status::Status::Lost))
                .collect();
            let counts = crate::sequence::status::StatusCounts::of(&statuses).to_string();
            counts
                .strip_prefix("status: ")
                .unwrap_or(&counts)
                .to_string()
        }
        None => "no status column (a file from before the status machine)".to_string(),
    }
}

/// The page's warnings: NaN states (naming the file and frames), an accuracy over fewer frames.
fn warnings(inputs: &Inputs, accuracy: Option<&Accuracy>) -> Vec<String> {
    let mut warnings = Vec::new();
    if !inputs.gaps.is_empty() {
        warnings.push(format!(
            "{}: {} frame(s) with a state that is not a number (frames {}): gaps in the plots, \
             left out of the accuracy",
            inputs.states_path.display(),
            inputs.gaps.len(),
            list_frames(&inputs.gaps)
        ));
    }
    if let Some(acc) = accuracy {
        if acc.report.frames < inputs.frames() {
            warnings.push(format!(
                "accuracy over {} of {} frames",
                acc.report.frames,
                inputs.frames()
            ));
        }
    }
    warnings
}

/// Up to 20 frame numbers, then "…".
fn list_frames(frames: &[usize]) -> String {
    let mut text = frames
        .iter()
        .take(20)
        .map(|k| k.to_string())
        .collect::<Vec<_>>()
        .join(", ");
    if frames.len() > 20 {
        text.push_str(", …");
    }
    text
}

fn legend_note(inputs: &Inputs) -> &'static str {
    match inputs.truth {
        Some(_) => {
            "Estimate (solid) and truth (dashed) in each state's unit; the strip along the top: \
             the tracker's status (blue searching, green tracking, orange lost); grey bands: \
             frames flagged lost (no hand claimed); red markers: frames the board dropped (hover for the reason); \
             orange: frames with no number."
        }
        None => {
            "Estimate in each state's unit; the strip along the top: the tracker's status (blue \
             searching, green tracking, orange lost); grey bands: frames flagged lost (no hand \
             claimed); red markers: frames \
             the board dropped (hover for the reason); orange: frames with no number."
        }
    }
}

fn grid(plots: &[String]) -> String {
    let mut s = String::from("<div class=\"plots\">\n");
    for p in plots {
        s.push_str(p);
        s.push('\n');
    }
    s.push_str("</div>");
    s
}

/// The sequence folder's name ("." resolved when possible).
fn sequence_name(dir: &Path) -> String {
    let dir = dir.canonicalize().unwrap_or_else(|_| dir.to_path_buf());
    dir.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| dir.display().to_string())
}
