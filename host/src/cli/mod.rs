//! The `digiteyes` command line: one module per command, each with its `clap::Args` and its
//! `run`, so the binary only parses and dispatches. Every option is declared once, where the
//! command that reads it lives.

pub mod bench;
pub mod demo;
pub mod eval;
pub mod hypotheses;
pub mod listen;
pub mod render;
pub mod report;
pub mod sim;
pub mod stream;
pub mod track;
pub mod ui;

use crate::TrackerConfig;

/// The tracker's configuration with `--iterations` and `--no-predict` applied.
pub fn tracker_config(iterations: Option<u8>, no_predict: bool) -> TrackerConfig {
    let mut config = TrackerConfig::default();
    if let Some(n) = iterations {
        config.iterations = n;
    }
    if no_predict {
        config.predict = false;
    }
    config
}
