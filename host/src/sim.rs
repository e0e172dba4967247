//! `digiteyes sim`: a simulated Linux board on a pseudo-terminal, for a host to connect to;
//! with `--overlay`, every frame it tracks drawn at the state it sent ([`overlay_tap`]).

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{sync_channel, Receiver};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Context, Result};
use digiteyes_board_linux::{Corruption, FrameTap, SimBoard, SimFrame, SimOptions, Window};
use digiteyes_core::model::Model;
use image::GrayImage;

use crate::overlay::{draw_overlay, overlay_path, write_png};

/// Tracked frames the overlay writer may fall behind the board by before the board waits.
pub const OVERLAY_QUEUE: usize = 32;

/// Line noise from the command line: `rate` of the bytes, in `frames` (all when `None`).
pub fn corruption(rate: f64, frames: Option<Range<u32>>, seed: u64) -> Result<Corruption> {
    if !(0.0..=1.0).contains(&rate) {
        bail!("--corrupt {rate}: the rate is a fraction of the bytes, 0 to 1 (0.01 = 1%)");
    }
    Ok(Corruption {
        rate,
        window: frames.map_or(Window::Always, Window::Frames),
        seed,
    })
}

/// Parses `A..B` (frames A to B-1).
pub fn parse_range(text: &str) -> Result<Range<u32>, String> {
    let (a, b) = text
        .split_once("..")
        .ok_or_else(|| format!("`{text}` is not a range A..B, e.g. 10..20"))?;
    let parse = |s: &str| {
        s.trim()
            .parse::<u32>()
            .map_err(|_| format!("`{s}` is not a frame number"))
    };
    let (a, b) = (parse(a)?, parse(b)?);
    if a >= b {
        return Err(format!("`{text}` is empty: A must be below B"));
    }
    Ok(a..b)
}

/// Starts the simulated board and returns it (its [`SimBoard::path`] is the device to
/// connect to).
pub fn start(options: SimOptions) -> Result<SimBoard> {
    SimBoard::start(options).context("cannot start the simulated board on a pseudo-terminal")
}

/// Runs `boards` until the process is interrupted (or one stops), printing each line's
/// figures every `every` (never when `None`).
pub fn serve(boards: Vec<SimBoard>, every: Option<Duration>) -> Result<()> {
    // How often a quiet server looks whether every board still runs.
    const CHECK: Duration = Duration::from_millis(200);
    let mut since_report = Duration::ZERO;
    loop {
        std::thread::sleep(CHECK);
        if let Some(stopped) = boards.iter().position(|b| !b.is_running()) {
            let mut boards = boards;
            boards
                .swap_remove(stopped)
                .wait()
                .context("a simulated board stopped")?;
            return Ok(());
        }
        since_report += CHECK;
        if every.is_some_and(|e| since_report >= e) {
            since_report = Duration::ZERO;
            for b in &boards {
                eprintln!("{}: {}", b.path().display(), b.report());
            }
        }
    }
}

/// What an [`OverlayWriter`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct OverlayStats {
    /// PNGs written.
    pub files: usize,
    /// Frames that could not be drawn (each reported on stderr).
    pub undrawable: usize,
    /// Time spent drawing, encoding and writing (s), on the writer's thread.
    pub seconds: f64,
}

/// The thread that draws a simulated board's tracked frames as overlay PNGs.
#[derive(Debug)]
pub struct OverlayWriter {
    thread: JoinHandle<Result<OverlayStats>>,
}

impl OverlayWriter {
    /// Waits until the board is gone (its tap closed) and every frame is written; what was
    /// written, or the first write failure.
    pub fn finish(self) -> Result<OverlayStats> {
        self.thread
            .join()
            .map_err(|_| anyhow!("the overlay writer panicked"))?
    }
}

/// A frame tap for [`SimOptions::frame_tap`] and the thread that draws what it hands over:
/// each tracked frame at the state the board sent for it, with the board's model (the
/// built-in hand) and search parameters, into `dir/cam0/NNNNNN.png`, NNNNNN the frame's
/// number as uploaded (a board sees one camera). Every frame is drawn: the board waits when
/// [`OVERLAY_QUEUE`] frames are pending. A frame that cannot be drawn is reported on stderr
/// and skipped; a write failure stops the writer (reported on stderr and by
/// [`OverlayWriter::finish`]) and the board counts the frames after it as skipped.
pub fn overlay_tap(dir: &Path) -> Result<(FrameTap, OverlayWriter)> {
    let model = Model::hand().map_err(|e| anyhow!("built-in hand model: {e}"))?;
    let (sender, receiver) = sync_channel(OVERLAY_QUEUE);
    let dir = dir.to_path_buf();
    let thread = std::thread::Builder::new()
        .name("digiteyes-sim-overlay".into())
        .spawn(move || {
            let result = write_overlays(&model, &dir, &receiver);
            if let Err(e) = &result {
                eprintln!("digiteyes sim: overlays stopped: {e:#}");
            }
            result
        })
        .context("cannot start the overlay writer thread")?;
    Ok((FrameTap::every(sender), OverlayWriter { thread }))
}

fn write_overlays(model: &Model, dir: &Path, frames: &Receiver<SimFrame>) -> Result<OverlayStats> {
    let mut stats = OverlayStats::default();
    let mut busy = Duration::ZERO;
    let mut made: Option<PathBuf> = None;
    for f in frames {
        let t0 = Instant::now();
        let bytes = f.pixels.len();
        let drawn = GrayImage::from_raw(f.width, f.height, f.pixels)
            .ok_or_else(|| anyhow!("{bytes} bytes is not a {}x{} frame", f.width, f.height))
            .and_then(|frame| draw_overlay(model, &f.camera, &f.q, &frame, &f.features));
        match drawn {
            Ok(image) => {
                write_png(&overlay_path(dir, 0, f.frame as usize), &image, &mut made)?;
                stats.files += 1;
            }
            Err(e) => {
                eprintln!("digiteyes sim: frame {}: no overlay: {e:#}", f.frame);
                stats.undrawable += 1;
            }
        }
        busy += t0.elapsed();
    }
    stats.seconds = busy.as_secs_f64();
    Ok(stats)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_and_rates() {
        assert_eq!(parse_range("3..7").unwrap(), 3..7);
        assert!(parse_range("7..3").is_err());
        assert!(parse_range("3-7").is_err());
        assert!(corruption(1.5, None, 1).is_err());
        assert_eq!(
            corruption(0.01, Some(2..4), 9).unwrap().window,
            Window::Frames(2..4)
        );
    }
}
