//! `digiteyes-board`: the digiteyes board on Linux, serving a host over a tty.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::Parser;
use digiteyes_board_linux::{Source, StatusLed, BOARD_NAME};
use digiteyes_firmware::{edge_map_bytes, Board, Buffers, NoLed, Uploads};
use digiteyes_platform_linux::camera::V4l2Camera;
use digiteyes_platform_linux::{parse_frame_size, MonotonicClock, TtySerial};
use linux_embedded_hal::Delay;

/// The digiteyes board on a Linux computer (Raspberry-Pi class).
///
/// Listens on a serial port for a host (`digiteyes stream`, `digiteyes listen --setup`):
/// it announces itself with Hello, takes Configure (camera, tracker parameters) and Reset
/// (initial state, free states), then tracks every frame — uploaded by the host as
/// FrameChunks, or captured from a V4L2 camera with --camera — and sends a State for each
/// (Dropped, with the reason, for each frame it cannot track). Runs until killed.
#[derive(Parser, Debug)]
#[command(name = "digiteyes-board", version, about, long_about)]
struct Args {
    /// Serial device to the host: a UART (/dev/ttyAMA0, /dev/serial0), a USB serial adapter
    /// (/dev/ttyUSB0) or a pseudo-terminal (/dev/pts/N).
    #[arg(long, value_name = "TTY")]
    port: String,
    /// Line speed (bits/s, 8N1). Ignored by pseudo-terminals.
    #[arg(long, default_value_t = 115_200, value_name = "B")]
    baud: u32,
    /// Capture frames from this V4L2 camera (GREY, YUYV or MJPEG; converted to 8-bit grey)
    /// instead of taking frames uploaded by the host.
    #[arg(long, value_name = "/dev/videoN")]
    camera: Option<PathBuf>,
    /// Frame size in px, e.g. 320x240: the camera's capture size, and the largest frame the
    /// board accepts (its frame buffer). Default: the camera's current size, or 640x480
    /// without a camera.
    #[arg(long, value_name = "WxH", value_parser = parse_frame_size)]
    size: Option<(u32, u32)>,
    /// GPIO chip of a status LED (lit while the board is tracking), e.g. /dev/gpiochip0.
    #[arg(long, value_name = "/dev/gpiochipN", requires = "led_line")]
    led_chip: Option<String>,
    /// Line offset of the status LED on --led-chip (e.g. 17 for BCM GPIO 17 on a Pi).
    #[arg(long, value_name = "L", requires = "led_chip")]
    led_line: Option<u32>,
    /// Sleep this long (µs) when there is nothing to do.
    #[arg(long, default_value_t = 200, value_name = "US")]
    idle_us: u32,
}

fn main() -> ExitCode {
    match run(Args::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("digiteyes-board: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(args: Args) -> Result<()> {
    let serial = TtySerial::open(&args.port, args.baud)?;
    let source = match &args.camera {
        Some(path) => Source::Camera(Box::new(V4l2Camera::open(path, args.size)?)),
        None => Source::Uploads(Uploads),
    };
    let (width, height) = match &source {
        Source::Camera(camera) => camera.size(),
        Source::Uploads(_) => args.size.unwrap_or((640, 480)),
    };
    let led = match (&args.led_chip, args.led_line) {
        (Some(chip), Some(line)) => StatusLed::gpio(chip, line)?,
        _ => StatusLed::None(NoLed),
    };
    let mut frame_buffer = vec![0u8; width as usize * height as usize];
    eprintln!(
        "digiteyes-board: serving on {} at {} baud, frames up to {width}x{height} px from {}",
        args.port,
        args.baud,
        match &args.camera {
            Some(path) => format!("camera {}", path.display()),
            None => "host uploads".to_string(),
        }
    );
    let mut edge_map = vec![0u8; edge_map_bytes(width as usize, height as usize)];
    let mut board = Board::new(
        BOARD_NAME,
        Buffers {
            frame: &mut frame_buffer,
            overlay: None,
            edge_map: &mut edge_map,
        },
        serial,
        source,
        led,
        MonotonicClock::new(),
    );
    match board.run(&mut Delay, args.idle_us) {
        Ok(never) => match never {},
        Err(e) => Err(e).with_context(|| format!("serial port {}", args.port)),
    }
}
