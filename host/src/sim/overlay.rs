//! `sim --overlay`: every frame the simulated board tracks drawn at the state it sent back,
//! as PNGs written in the background by the one [`PngWriter`] `track --overlay` uses too.

use std::path::Path;

use anyhow::{anyhow, Result};
use digiteyes_core::model::Model;
use image::GrayImage;

use super::{FrameTap, SimFrame};
use crate::overlay::{draw_overlay, overlay_path, PngWriter};

/// Tracked frames the overlay writer may fall behind the board by before the board waits.
pub const OVERLAY_QUEUE: usize = 32;

/// A frame tap for [`super::SimOptions::frame_tap`] and the writer that draws what it hands
/// over: each tracked frame at the state the board sent for it, with the board's model (the
/// built-in hand) and search parameters, into `dir/cam0/NNNNNN.png`, NNNNNN the frame's
/// number as uploaded (a board sees one camera). Every frame is drawn: the board waits when
/// [`OVERLAY_QUEUE`] frames are pending. A frame that cannot be drawn is reported on stderr
/// and skipped (counted in [`crate::overlay::PngStats::undrawable`]); a write failure stops
/// the writer (reported on stderr and by [`PngWriter::finish`], which waits until the board
/// is gone) and the board counts the frames after it as skipped.
pub fn overlay_tap(dir: &Path) -> Result<(FrameTap, PngWriter<SimFrame>)> {
    let model = Model::hand().map_err(|e| anyhow!("built-in hand model: {e}"))?;
    let dir = dir.to_path_buf();
    let writer = PngWriter::drawing(
        OVERLAY_QUEUE,
        "digiteyes sim: overlays stopped",
        move |f: SimFrame| {
            let bytes = f.pixels.len();
            let drawn = GrayImage::from_raw(f.width, f.height, f.pixels)
                .ok_or_else(|| anyhow!("{bytes} bytes is not a {}x{} frame", f.width, f.height))
                .and_then(|frame| draw_overlay(&model, &f.camera, &f.q, &frame, &f.features));
            match drawn {
                Ok(image) => Some((overlay_path(&dir, 0, f.frame as usize), image)),
                Err(e) => {
                    eprintln!("digiteyes sim: frame {}: no overlay: {e:#}", f.frame);
                    None
                }
            }
        },
    )?;
    let sender = writer
        .sender()
        .ok_or_else(|| anyhow!("the overlay writer has already stopped"))?;
    Ok((FrameTap::every(sender), writer))
}
