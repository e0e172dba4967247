//! The simulated board's frame tap: every frame the board tracks, with the state it sent for
//! it, handed to the host over a channel (for a debug overlay, a live view, a recorder).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{SyncSender, TrySendError};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use digiteyes_core::camera::Camera;
use digiteyes_core::features::FeatureConfig;
use digiteyes_core::status::Status;
use digiteyes_firmware::Tracked;

use super::SimReport;

/// How often a blocked [`TapMode::Every`] tap looks whether the board is being stopped.
const STOP_CHECK: Duration = Duration::from_millis(2);

/// One frame the simulated board tracked.
#[derive(Debug, Clone, PartialEq)]
pub struct SimFrame {
    /// The frame's number, as uploaded (the `State` message's `frame`).
    pub frame: u32,
    /// Width (px).
    pub width: u32,
    /// Height (px).
    pub height: u32,
    /// The frame: 8-bit grey, packed, row-major, `width × height` bytes.
    pub pixels: Vec<u8>,
    /// The state the board sent for it (the `State` message's `q`: quaternion, mm, rad), for
    /// the board's model, the built-in hand.
    pub q: Vec<f32>,
    /// The camera, as configured.
    pub camera: Camera,
    /// The slice-search parameters, as configured (what an overlay needs to redraw the search).
    pub features: FeatureConfig,
    /// The tracker flagged the state as not to be trusted (whenever `status` is not
    /// `Tracking`).
    pub lost: bool,
    /// What the board claimed of the frame (the `State` message's `status`).
    pub status: Status,
    /// RMS image residual of the frame's last iteration (px).
    pub rms_px: f32,
    /// Gauss–Newton iterations run.
    pub iterations: u8,
    /// Features found in the last iteration.
    pub features_found: u16,
    /// Features expected in the last iteration.
    pub features_expected: u16,
    /// How many times the board had been power-cycled when it tracked this frame.
    pub boot: u32,
}

/// What the tap does when the host has not taken the frames before it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TapMode {
    /// Wait until the channel has room: every frame arrives, and a slow receiver slows the
    /// board (its states come later). If the receiver is dropped, or the board is stopped
    /// while it waits, the frame is counted in [`SimReport::tap_skipped`].
    Every,
    /// Never wait: a frame the full channel has no room for is skipped and counted in
    /// [`SimReport::tap_skipped`] (a live view that only wants what it can show).
    Skip,
}

/// Where the simulated board hands its tracked frames ([`super::SimOptions::frame_tap`]).
#[derive(Debug, Clone)]
pub struct FrameTap {
    sender: SyncSender<SimFrame>,
    mode: TapMode,
}

impl FrameTap {
    /// Every frame into `sender`, waiting for room ([`TapMode::Every`]).
    pub fn every(sender: SyncSender<SimFrame>) -> Self {
        FrameTap {
            sender,
            mode: TapMode::Every,
        }
    }

    /// Frames into `sender` when it has room, the rest skipped and counted ([`TapMode::Skip`]).
    pub fn skipping(sender: SyncSender<SimFrame>) -> Self {
        FrameTap {
            sender,
            mode: TapMode::Skip,
        }
    }

    /// What it does when the channel is full.
    pub fn mode(&self) -> TapMode {
        self.mode
    }

    /// Hands `tracked` over; counts it in `report` as tapped or skipped.
    pub(super) fn hand(
        &self,
        tracked: &Tracked<'_>,
        boot: u32,
        stop: &AtomicBool,
        report: &Arc<Mutex<SimReport>>,
    ) {
        let (w, h) = (tracked.camera.width, tracked.camera.height);
        let mut frame = SimFrame {
            frame: tracked.frame,
            width: w,
            height: h,
            pixels: tracked
                .pixels
                .get(..w as usize * h as usize)
                .unwrap_or_default()
                .to_vec(),
            q: tracked.q.to_vec(),
            camera: *tracked.camera,
            features: tracked.config.features,
            lost: tracked.report.lost || !tracked.status.claims_hand(),
            status: tracked.status,
            rms_px: tracked.report.rms_px,
            iterations: tracked.report.iterations,
            features_found: tracked.report.features_found,
            features_expected: tracked.report.features_expected,
            boot,
        };
        let delivered = loop {
            match self.sender.try_send(frame) {
                Ok(()) => break true,
                Err(TrySendError::Disconnected(_)) => break false,
                Err(TrySendError::Full(back)) => {
                    if self.mode == TapMode::Skip || stop.load(Ordering::Relaxed) {
                        break false;
                    }
                    frame = back;
                    // The receiver is behind; std's SyncSender cannot wait with a timeout, so
                    // wait in short steps that still notice a stop.
                    std::thread::sleep(STOP_CHECK);
                }
            }
        };
        if let Ok(mut r) = report.lock() {
            if delivered {
                r.tapped += 1;
            } else {
                r.tap_skipped += 1;
            }
        }
    }
}
