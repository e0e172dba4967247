//! The demo: render the `mouse` scenario, track it, evaluate it.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::eval::{evaluate, EvalReport};
use crate::scenarios::{render_scenario, RenderOptions};
use crate::track::{track_sequence, TrackSummary};
use crate::TrackerConfig;

/// The scenario the demo runs.
pub const DEMO_SCENARIO: &str = "mouse";

/// What the demo produced.
#[derive(Debug, Clone)]
pub struct DemoResult {
    /// The rendered sequence's folder (gone after return unless kept).
    pub sequence: PathBuf,
    /// The tracking run.
    pub track: TrackSummary,
    /// The evaluation.
    pub eval: EvalReport,
}

/// Renders `frames` frames of the `mouse` scenario into `keep` (or a temporary folder that is
/// removed afterwards), tracks them with `config` and evaluates the result. The states go to
/// `states.csv` in the sequence folder.
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
    let states = dir.join("states.csv");
    let track = track_sequence(&dir, &states, config, progress)?;
    let eval = evaluate(&dir, &states)?;
    Ok(DemoResult {
        sequence: dir,
        track,
        eval,
    })
}
