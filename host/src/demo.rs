//! The demo: render the thesis' four-phase 3D-mouse trial (`mouse-thesis`), stream it to a
//! simulated Linux board over a real pseudo-terminal serial link, evaluate the states the board
//! sent back (as a tracker and as a 3D mouse), write the HTML report, and show the run in the
//! UI, whose mouse pole rises twice, holds while the thumb clicks, and slides.
//!
//! ```text
//! renderer ─▶ camN/*.pgm ─▶ host (stream) ═══ PTY ═══ board (firmware loop, tracker)
//!                               ▲                          │
//!                               └──── State per frame ◀────┘ ─▶ states.csv ─▶ eval (+ mouse)
//!                                                                     ├─▶ report.html
//!                                                                     └─▶ ui (replay)
//! ```

use std::io::Write;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::time::Duration;

use crate::sim::{SimOptions, SimReport};
use anyhow::{Context, Result};
use digiteyes_core::protocol::TrackerParams;

use crate::eval::{evaluate, EvalReport};
use crate::mouse_pole::accuracy::{compare, MouseAccuracy};
use crate::mouse_pole::MouseConfig;
use crate::report::{write_report, ReportOptions, ReportSummary};
use crate::scenarios::{render_scenario, RenderOptions};
use crate::sequence::{read_states, Sequence};
use crate::stereo::{stream_stereo, StereoOptions, StereoSummary};
use crate::stream::{stream_sequence, StreamOptions, StreamSummary};
use crate::ui::{run_ui, UiOptions, UiSource, DEFAULT_BIND};
use crate::TrackerConfig;

/// The scenario the demo runs: the thesis' 3D-mouse trial.
pub const DEMO_SCENARIO: &str = crate::scenarios::mouse_thesis::NAME;

/// Frames the demo renders unless told otherwise: the thesis' 500, its pace (about 25 s of
/// render, upload and tracking on a 2-core machine at 640×480; `docs/ui.md`).
pub const DEMO_FRAMES: usize = crate::scenarios::mouse_thesis::THESIS_FRAMES;

/// Where the demo writes its run unless told otherwise (relative to the current folder).
pub const DEFAULT_DEMO_DIR: &str = "digiteyes-demo";

/// About this many overlay thumbnails in the demo's report, whatever its length.
pub const DEMO_THUMBNAILS: usize = 20;

/// The report's file name in the demo's folder.
pub const REPORT_HTML: &str = "report.html";

/// What the demo produced.
#[derive(Debug, Clone)]
pub struct DemoResult {
    /// The rendered sequence's folder, with `states.csv` and `report.html`.
    pub sequence: PathBuf,
    /// The stream to the simulated board (its link figures included).
    pub stream: StreamSummary,
    /// The simulated board's side of the line.
    pub board: SimReport,
    /// The evaluation of the board's states.
    pub eval: EvalReport,
    /// The board's states as a 3D mouse, against the truth's.
    pub mouse: MouseAccuracy,
    /// The HTML report of the run.
    pub report: ReportSummary,
}

/// Renders the [`DEMO_SCENARIO`] into `dir` in `frames` frames (its four phases shrink in
/// proportion below [`DEMO_FRAMES`]), streams them to a simulated board running `config`,
/// evaluates the states it sent back (written to `dir/states.csv`), as a tracker and as a 3D
/// mouse, and writes the HTML report `dir/report.html`.
pub fn run_demo(
    frames: usize,
    dir: &Path,
    config: TrackerConfig,
    progress: bool,
) -> Result<DemoResult> {
    render_demo(DEMO_SCENARIO, frames, dir, progress)?;
    let board = crate::sim::start(SimOptions::default())?;
    let port = board.path().display().to_string();
    let states = dir.join("states.csv");
    let mut options = StreamOptions::new(port).progress(progress);
    options.tracker = TrackerParams::from_config(&config);
    let stream = stream_sequence(dir, &states, &options)?;
    let board = board.stop().context("the simulated board failed")?;
    let eval = evaluate(dir, &states)?;
    let mouse = mouse_accuracy(dir, &states)?;
    let report = write_demo_report(dir, &states, frames)?;
    Ok(DemoResult {
        sequence: dir.to_path_buf(),
        stream,
        board,
        eval,
        mouse,
        report,
    })
}

/// The scenario `demo --stereo` runs: the whole hand seen by two cameras.
pub const STEREO_DEMO_SCENARIO: &str = "fullhand-stereo";

/// Frames `demo --stereo` renders unless told otherwise.
pub const STEREO_DEMO_FRAMES: usize = 120;

/// What `demo --stereo` produced.
#[derive(Debug, Clone)]
pub struct StereoDemoResult {
    /// The rendered sequence's folder, with `states.csv` and `report.html`.
    pub sequence: PathBuf,
    /// The run on the two boards (each board's figures included).
    pub stream: StereoSummary,
    /// Each simulated board's side of its line.
    pub boards: Vec<SimReport>,
    /// The evaluation of the states.
    pub eval: EvalReport,
    /// The HTML report of the run.
    pub report: ReportSummary,
}

/// Renders [`STEREO_DEMO_SCENARIO`] into `dir` in `frames` frames and tracks it with one
/// simulated board per camera, as the thesis' stereo system ran (`stream --port A --port
/// B`): the host solves once per iteration with what both boards found. Evaluates the
/// states (`dir/states.csv`) and writes `dir/report.html`.
pub fn run_stereo_demo(
    frames: usize,
    dir: &Path,
    config: TrackerConfig,
    progress: bool,
) -> Result<StereoDemoResult> {
    render_demo(STEREO_DEMO_SCENARIO, frames, dir, progress)?;
    let n_cameras = Sequence::open(dir)?.cameras.len();
    let boards = (0..n_cameras)
        .map(|_| crate::sim::start(SimOptions::default()))
        .collect::<Result<Vec<_>>>()?;
    let ports = boards
        .iter()
        .map(|b| b.path().display().to_string())
        .collect();
    let states = dir.join("states.csv");
    let mut options = StereoOptions::new(ports);
    options.tracker = TrackerParams::from_config(&config);
    options.progress = progress;
    let stream = stream_stereo(dir, &states, &options)?;
    let boards = boards
        .into_iter()
        .map(|b| b.stop().context("a simulated board failed"))
        .collect::<Result<Vec<_>>>()?;
    let eval = evaluate(dir, &states)?;
    let report = write_demo_report(dir, &states, frames)?;
    Ok(StereoDemoResult {
        sequence: dir.to_path_buf(),
        stream,
        boards,
        eval,
        report,
    })
}

/// Renders `scenario` into `dir` in `frames` frames, as the demos do.
fn render_demo(scenario: &str, frames: usize, dir: &Path, progress: bool) -> Result<()> {
    let options = RenderOptions {
        frames: Some(frames),
        progress,
        ..RenderOptions::default()
    };
    render_scenario(scenario, dir, &options)
}

/// The demo's HTML report `dir/report.html`, with about [`DEMO_THUMBNAILS`] overlays.
fn write_demo_report(dir: &Path, states_csv: &Path, frames: usize) -> Result<ReportSummary> {
    let options = ReportOptions {
        thumb_every: frames.div_ceil(DEMO_THUMBNAILS).max(1),
        ..ReportOptions::default()
    };
    write_report(dir, states_csv, &dir.join(REPORT_HTML), &options)
}

/// The states in `states_csv` as a 3D mouse against the truth of the sequence in `dir`.
fn mouse_accuracy(dir: &Path, states_csv: &Path) -> Result<MouseAccuracy> {
    let sequence = Sequence::open(dir)?;
    let truth = sequence.read_truth()?;
    let estimate = read_states(states_csv, sequence.n_states())?;
    let rest: Vec<f32> = sequence.initial_state.iter().map(|&v| v as f32).collect();
    compare(
        &sequence.model,
        &rest,
        MouseConfig::default(),
        &truth.rows,
        &estimate.rows,
    )
    .with_context(|| format!("{}", states_csv.display()))
}

/// Shows the demo's run in the UI: replays `dir`'s frames and states, served on
/// [`DEFAULT_BIND`] (or any free loopback port if that one is taken), for `duration` or until
/// the process is interrupted. Prints the page's address to `out`.
pub fn serve_demo_ui(dir: &Path, duration: Option<Duration>, out: &mut dyn Write) -> Result<()> {
    let preferred: SocketAddr = DEFAULT_BIND.parse().context("default UI address")?;
    let bind = if std::net::TcpListener::bind(preferred).is_ok() {
        preferred
    } else {
        SocketAddr::from(([127, 0, 0, 1], 0))
    };
    let options = UiOptions {
        bind,
        source: UiSource::Replay {
            seqdir: dir.to_path_buf(),
            states: dir.join("states.csv"),
            hypotheses: None,
            camera: 0,
            fps: None,
        },
        duration,
    };
    run_ui(&options, out)
}
