//! `digiteyes sim`: simulated boards on pseudo-terminals for a host to connect to, with line
//! noise, a power cycle or a deaf spell on request, and `--overlay` or `--ui` to watch one.

use std::net::SocketAddr;
use std::ops::Range;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use digiteyes_core::model::Model;
use digiteyes_platform_linux::parse_frame_size;

use crate::cli_values;
use crate::sim::ui_tap::ui_tap;
use crate::sim::{overlay_tap, start, Corruption, SimBoard, SimOptions, Window};
use crate::ui::{attach_mouse, Hub, UiServer, DEFAULT_BIND};

/// Run a simulated digiteyes board on a pseudo-terminal; prints the device to connect to.
///
/// The board is the firmware's loop (the same code as on a Linux board or a
/// microcontroller) in this process, on one side of a PTY pair; connect `digiteyes
/// stream --port` or `digiteyes listen --port` to the printed /dev/pts/N. It tracks the
/// built-in hand model (or any sub-model of it, such as the mouse scenarios'). Runs until
/// interrupted (Ctrl-C).
///
/// With --overlay DIR, every frame the board tracks is drawn at the state it sent back,
/// into DIR/cam0/NNNNNN.png (NNNNNN: the frame number as uploaded), with the colours of
/// `track --overlay` (docs/overlay.md). The PNGs are written on a thread of their own; if
/// it falls 32 frames behind, the board waits for it.
///
/// With --ui, this process also serves the UI page (docs/ui.md): the newest frame the
/// board tracked with the model drawn over it, the 3D hand, the 3D mouse. The board never
/// waits for the page; frames it was too slow for are counted as skipped.
#[derive(Args, Debug)]
pub struct SimArgs {
    /// Flip one random bit in this fraction of the bytes crossing the line, both ways
    /// (0.01 = 1%; 0 to 1): line noise, to see the link recover.
    #[arg(long, value_name = "RATE", default_value_t = 0.0, value_parser = cli_values::share)]
    pub corrupt: f64,
    /// Only corrupt while these frames are uploaded (A..B: frames A to B-1).
    #[arg(long, value_name = "A..B", value_parser = parse_range,
          requires = "corrupt")]
    pub corrupt_frames: Option<Range<u32>>,
    /// Seed of the line noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Power-cycle the board once, after N frames were uploaded (it reboots mid-upload of
    /// frame N, announcing itself with a new Hello).
    #[arg(long, value_name = "N")]
    pub restart_after: Option<u32>,
    /// Stand up this many boards (1 to 4), one per camera of a stereo sequence, each on
    /// its own pseudo-terminal: `digiteyes stream --port A --port B --seq DIR`.
    #[arg(long, value_name = "N", default_value_t = 1,
          value_parser = clap::value_parser!(u8).range(1..=4))]
    pub boards: u8,
    /// The last board hears nothing while frames A..B are uploaded (frames A to B-1,
    /// counted from 0), as if its cable were pulled, then hears again: to see a host
    /// carry on without it and take it back.
    #[arg(long, value_name = "A..B", value_parser = parse_range)]
    pub deaf_frames: Option<Range<u32>>,
    /// The board's frame buffer: the largest frame it accepts, WxH px.
    #[arg(long, value_name = "WxH", value_parser = parse_frame_size, default_value = "640x480")]
    pub max_frame: (u32, u32),
    /// Print the line's byte and error counts every this many seconds (0: never; at most a
    /// week).
    #[arg(long, value_name = "S", default_value_t = 0.0, value_parser = cli_values::seconds_or_zero)]
    pub report_every: f64,
    /// Draw every tracked frame at its state into DIR/cam0/NNNNNN.png.
    #[arg(long, value_name = "DIR")]
    pub overlay: Option<PathBuf>,
    /// Also serve the UI page (docs/ui.md) on ADDR:PORT (default 127.0.0.1:7878): every
    /// frame the board tracks with the model drawn over it, the 3D hand, the 3D mouse.
    #[arg(long, value_name = "ADDR:PORT", num_args = 0..=1,
          default_missing_value = DEFAULT_BIND, conflicts_with = "overlay")]
    pub ui: Option<SocketAddr>,
}

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

/// Starts the boards and serves them until the process is interrupted (or one stops).
pub fn run(args: SimArgs) -> Result<()> {
    let boards = args.boards;
    // Before any watcher starts: a watcher holds on until the board it watches is gone.
    if boards > 1 && (args.overlay.is_some() || args.ui.is_some()) {
        bail!("--overlay and --ui watch one board: leave them out with --boards {boards}");
    }
    let mut options = SimOptions::default().max_frame(args.max_frame.0, args.max_frame.1);
    if args.corrupt > 0.0 || args.corrupt_frames.is_some() {
        options = options.corruption(corruption(
            args.corrupt,
            args.corrupt_frames.clone(),
            args.seed,
        )?);
    }
    if let Some(n) = args.restart_after {
        options = options.restart_after(n);
    }
    // The writer runs until the process is interrupted, like the board.
    let _overlays = match &args.overlay {
        Some(dir) => {
            let (tap, writer) = overlay_tap(dir)?;
            options = options.frame_tap(tap);
            println!("overlays of the tracked frames go to {}", dir.display());
            Some(writer)
        }
        None => None,
    };
    // The UI server and its feeding thread live as long as the board.
    let _ui = match args.ui {
        Some(bind) => {
            let model = Model::hand().map_err(|e| anyhow!("built-in hand model: {e}"))?;
            let hub = Hub::new(model, Vec::new(), "simulated board");
            attach_mouse(&hub, None);
            let (tap, feeder) = ui_tap(Arc::clone(&hub))?;
            options = options.frame_tap(tap);
            let server = UiServer::start(bind, hub)?;
            println!("UI: {}", server.url());
            Some((server, feeder))
        }
        None => None,
    };
    let mut started = Vec::new();
    for b in 0..boards {
        let mut options = options.clone();
        if let (Some(deaf), true) = (&args.deaf_frames, b + 1 == boards) {
            options = options.deaf(deaf.start, deaf.end.saturating_sub(deaf.start));
        }
        let board = start(options)?;
        println!("simulated board on {}", board.path().display());
        started.push(board);
    }
    // The boards hold the taps now: once they stop, the watchers can finish.
    drop(options);
    let ports: Vec<String> = started
        .iter()
        .map(|b| format!("--port {}", b.path().display()))
        .collect();
    println!(
        "connect with: digiteyes stream {} --seq DIR   (Ctrl-C stops the board{})",
        ports.join(" "),
        if boards > 1 { "s" } else { "" }
    );
    let every = (args.report_every > 0.0).then(|| cli_values::duration(args.report_every));
    serve(started, every)
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
