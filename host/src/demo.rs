//! The demo: render the `mouse` scenario, stream it to a simulated Linux board over a real
//! pseudo-terminal serial link, evaluate the states the board sent back, write the HTML
//! report, and show the run in the UI.
//!
//! ```text
//! renderer ─▶ camN/*.pgm ─▶ host (stream) ═══ PTY ═══ board (firmware loop, tracker)
//!                               ▲                          │
//!                               └──── State per frame ◀────┘ ─▶ states.csv ─▶ eval
//!                                                                     ├─▶ report.html
//!                                                                     └─▶ ui (replay)
//! ```

use std::io::Write;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{Context, Result};
use digiteyes_board_linux::{SimOptions, SimReport};
use digiteyes_core::protocol::TrackerParams;

use crate::eval::{evaluate, EvalReport};
use crate::report::{write_report, ReportOptions, ReportSummary};
use crate::scenarios::{render_scenario, RenderOptions};
use crate::stream::{stream_sequence, StreamOptions, StreamSummary};
use crate::ui::{run_ui, UiOptions, UiSource, DEFAULT_BIND};
use crate::TrackerConfig;

/// The scenario the demo runs.
pub const DEMO_SCENARIO: &str = "mouse";

/// Where the demo writes its run unless told otherwise (relative to the current folder).
pub const DEFAULT_DEMO_DIR: &str = "digiteyes-demo";

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
    /// The HTML report of the run.
    pub report: ReportSummary,
}

/// Renders `frames` frames of the `mouse` scenario into `dir`, streams them to a simulated
/// board running `config`, evaluates the states it sent back (written to `dir/states.csv`)
/// and writes the HTML report `dir/report.html`.
pub fn run_demo(
    frames: usize,
    dir: &Path,
    config: TrackerConfig,
    progress: bool,
) -> Result<DemoResult> {
    let opts = RenderOptions {
        frames: Some(frames),
        progress,
        ..RenderOptions::default()
    };
    render_scenario(DEMO_SCENARIO, dir, &opts)?;
    let board = crate::sim::start(SimOptions::default())?;
    let port = board.path().display().to_string();
    let states = dir.join("states.csv");
    let mut options = StreamOptions::new(port).progress(progress);
    options.tracker = TrackerParams::from_config(&config);
    let stream = stream_sequence(dir, &states, &options)?;
    let board = board.stop().context("the simulated board failed")?;
    let eval = evaluate(dir, &states)?;
    let report = write_report(
        dir,
        &states,
        &dir.join(REPORT_HTML),
        &ReportOptions::default(),
    )?;
    Ok(DemoResult {
        sequence: dir.to_path_buf(),
        stream,
        board,
        eval,
        report,
    })
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
            camera: 0,
            fps: None,
        },
        duration,
    };
    run_ui(&options, out)
}
