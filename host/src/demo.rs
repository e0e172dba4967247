//! The demo: render the `mouse` scenario, stream it to a simulated Linux board over a real
//! pseudo-terminal serial link, and evaluate the states the board sent back.
//!
//! ```text
//! renderer ─▶ camN/*.pgm ─▶ host (stream) ═══ PTY ═══ board (firmware loop, tracker)
//!                               ▲                          │
//!                               └──── State per frame ◀────┘ ─▶ states.csv ─▶ eval
//! ```

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use digiteyes_board_linux::{SimOptions, SimReport};
use digiteyes_core::protocol::TrackerParams;

use crate::eval::{evaluate, EvalReport};
use crate::scenarios::{render_scenario, RenderOptions};
use crate::stream::{stream_sequence, StreamOptions, StreamSummary};
use crate::TrackerConfig;

/// The scenario the demo runs.
pub const DEMO_SCENARIO: &str = "mouse";

/// What the demo produced.
#[derive(Debug, Clone)]
pub struct DemoResult {
    /// The rendered sequence's folder (gone after return unless kept).
    pub sequence: PathBuf,
    /// The stream to the simulated board (its link figures included).
    pub stream: StreamSummary,
    /// The simulated board's side of the line.
    pub board: SimReport,
    /// The evaluation of the board's states.
    pub eval: EvalReport,
}

/// Renders `frames` frames of the `mouse` scenario into `keep` (or a temporary folder that is
/// removed afterwards), streams them to a simulated board running `config`, and evaluates the
/// states it sent back (written to `states.csv` in the sequence folder).
pub fn run_demo(
    frames: usize,
    keep: Option<&Path>,
    config: TrackerConfig,
    progress: bool,
) -> Result<DemoResult> {
    let temp;
    let dir = match keep {
        Some(dir) => dir.to_path_buf(),
        None => {
            temp = tempfile::tempdir().context("cannot create a temporary folder")?;
            temp.path().to_path_buf()
        }
    };
    let opts = RenderOptions {
        frames: Some(frames),
        progress,
        ..RenderOptions::default()
    };
    render_scenario(DEMO_SCENARIO, &dir, &opts)?;
    let board = crate::sim::start(SimOptions::default())?;
    let port = board.path().display().to_string();
    let states = dir.join("states.csv");
    let mut options = StreamOptions::new(port).progress(progress);
    options.tracker = TrackerParams::from_config(&config);
    let stream = stream_sequence(&dir, &states, &options)?;
    let board = board.stop().context("the simulated board failed")?;
    let eval = evaluate(&dir, &states)?;
    Ok(DemoResult {
        sequence: dir,
        stream,
        board,
        eval,
    })
}
