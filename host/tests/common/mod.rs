//! Helpers shared by the host's integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use digiteyes_host::scenarios::{render_scenario, RenderOptions};

/// The conformance fixture from an independent renderer.
pub const FIXTURE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../fixtures/sample-mouse");

/// Renders `frames` frames of `scenario` at 160×120 into `dir/name` and returns that folder.
pub fn small_sequence(dir: &Path, scenario: &str, frames: usize) -> PathBuf {
    let seq = dir.join(scenario);
    let opts = RenderOptions {
        frames: Some(frames),
        size: Some((160, 120)),
        supersample: 2,
        ..RenderOptions::default()
    };
    render_scenario(scenario, &seq, &opts).unwrap();
    seq
}

/// The error's whole chain on one line.
pub fn message<T: std::fmt::Debug>(result: anyhow::Result<T>) -> String {
    format!("{:#}", result.unwrap_err())
}
