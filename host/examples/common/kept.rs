//! The sequences `bench robustness --keep DIR` kept, as the study examples read them.
#![allow(dead_code)] // each example uses part of it

use std::path::{Path, PathBuf};

use anyhow::{anyhow, Result};
use digiteyes_core::frame::FrameView;
use digiteyes_host::sequence::Sequence;
use image::GrayImage;

/// The kept seeds' folders in `dir` (each with a `sequence.json`), in name order.
pub fn seed_dirs(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(dir)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("sequence.json").exists())
        .collect();
    dirs.sort();
    Ok(dirs)
}

/// Every camera's frame `k` of `sequence`.
pub fn read_instant(sequence: &Sequence, k: usize) -> Result<Vec<GrayImage>> {
    (0..sequence.cameras.len())
        .map(|c| sequence.read_frame(c, k))
        .collect()
}

/// The tracker's views of `images`.
pub fn views(images: &[GrayImage]) -> Result<Vec<FrameView<'_>>> {
    images
        .iter()
        .map(|img| {
            FrameView::packed(img.as_raw(), img.width() as usize, img.height() as usize)
                .map_err(|e| anyhow!("{e}"))
        })
        .collect()
}
