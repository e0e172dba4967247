//! The UI beside a simulated board (`digiteyes sim --ui`): every frame the board tracks, with
//! the state it sent for it, straight from the board's frame tap — the IC40's video overlay
//! and the workstation's 3D hand, on one page.

use std::sync::mpsc::{sync_channel, Receiver};
use std::sync::Arc;
use std::thread::JoinHandle;

use super::{FrameTap, SimFrame};
use anyhow::{Context, Result};
use image::GrayImage;

use crate::ui::hub::{CameraFrame, Hub, ShownState};

/// Frames waiting for the UI before the board skips handing it more (a live view needs the
/// newest frame, not every one; the board never waits for the UI).
pub const UI_TAP_QUEUE: usize = 2;

/// A frame tap for `SimOptions::frame_tap` that feeds `hub`, and the thread doing it (it ends
/// when the board is gone). Frames the UI was too slow for are counted by the board as
/// `tap_skipped`.
pub fn ui_tap(hub: Arc<Hub>) -> Result<(FrameTap, JoinHandle<()>)> {
    let (sender, receiver) = sync_channel(UI_TAP_QUEUE);
    let thread = std::thread::Builder::new()
        .name("ui-board-tap".into())
        .spawn(move || feed(&hub, &receiver))
        .context("cannot start the UI's board-tap thread")?;
    Ok((FrameTap::skipping(sender), thread))
}

fn feed(hub: &Hub, frames: &Receiver<SimFrame>) {
    for f in frames {
        if let Some(image) = GrayImage::from_raw(f.width, f.height, f.pixels) {
            hub.push_frame(CameraFrame {
                frame: f.frame,
                camera: f.camera,
                image,
                q: f.q.clone(),
            });
        }
        hub.push_state(ShownState {
            frame: f.frame,
            q: f.q,
            lost: f.lost,
            status: f.status,
            rms_px: f.rms_px,
            features_found: f.features_found,
            features_expected: f.features_expected,
            iterations: f.iterations,
        });
    }
}
