//! Helpers shared by the end-to-end tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use digiteyes_host::{render_scenario, RenderOptions};

/// A short `mouse` sequence at 320×240 in `dir/mouse` (quick to render, upload and track).
pub fn mouse(dir: &Path, frames: usize) -> PathBuf {
    let seq = dir.join("mouse");
    let options = RenderOptions {
        frames: Some(frames),
        size: Some((320, 240)),
        supersample: 2,
        ..RenderOptions::default()
    };
    render_scenario("mouse", &seq, &options).unwrap();
    seq
}
