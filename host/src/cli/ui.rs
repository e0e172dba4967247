//! `digiteyes ui`: the hand live in a local web page.

use std::net::SocketAddr;
use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;

use crate::cli_values;
use crate::stream::DEFAULT_BAUD;
use crate::ui::{run_ui, UiOptions, UiSource, DEFAULT_BIND};

/// Show the hand live in a web page: 3D hand, camera overlay, 3D mouse, link figures.
///
/// Serves one page on this machine (default http://127.0.0.1:7878/; every asset is in
/// the binary, nothing is fetched from the internet) and feeds it from one source:
///   --port TTY        a board on a serial port (as `listen` reads it; --setup sets it up)
///   --udp ADDR:PORT   JSON lines of board messages, as `listen --forward udp://` sends
///   --replay SEQDIR   a tracked sequence played back at its frame rate, with its frames
///                     and the model drawn over them (states from --states, default
///                     SEQDIR/states.csv; --hypotheses CSV draws the other
///                     hypotheses of `track --hypotheses-out` ghosted behind the hand)
/// The page shows the 3D hand at the newest state (drag to orbit, wheel to zoom), the
/// camera frame with the back-projected model when the source has frames, the 3D mouse
/// (thesis Sec. 4.3.4: the pole's base follows the palm on the table, its height finger
/// 1's fingertip, finger 4 and thumb abduction are two buttons), every state's value,
/// states/s, drops, CRC and framing errors, and a lost-track / no-signal badge. Runs
/// until interrupted (Ctrl-C) or --seconds.
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
#[command(group = clap::ArgGroup::new("source").required(true).args(["port", "udp", "replay"]))]
pub struct UiArgs {
    /// The board's serial device (/dev/ttyUSB0, or the /dev/pts/N of `digiteyes sim`).
    #[arg(long, value_name = "TTY")]
    pub port: Option<String>,
    /// With --port: line speed in bits/s.
    #[arg(long, value_name = "B", default_value_t = DEFAULT_BAUD, requires = "port")]
    pub baud: u32,
    /// With --port: set the board up first (Configure + Reset) from this sequence.json or
    /// sequence folder.
    #[arg(long, value_name = "PATH", requires = "port")]
    pub setup: Option<PathBuf>,
    /// Receive board messages as JSON lines on this UDP address (port 0: any free port).
    #[arg(long, value_name = "ADDR:PORT")]
    pub udp: Option<SocketAddr>,
    /// Play back this tracked sequence folder.
    #[arg(long, value_name = "SEQDIR")]
    pub replay: Option<PathBuf>,
    /// With --replay: the states to show (default SEQDIR/states.csv).
    #[arg(long, value_name = "CSV", requires = "replay")]
    pub states: Option<PathBuf>,
    /// With --replay: the hypotheses tracked (`track --hypotheses-out`); the others than the
    /// best are drawn ghosted behind the hand.
    #[arg(long, value_name = "CSV", requires = "replay")]
    pub hypotheses: Option<PathBuf>,
    /// With --replay: frames/s, 0.01 to 1000 (default: the sequence's, else 15).
    #[arg(long, value_name = "FPS", requires = "replay", value_parser = cli_values::fps)]
    pub fps: Option<f64>,
    /// The camera of a multi-camera sequence (0-based; --replay and --setup).
    #[arg(long, value_name = "N")]
    pub camera_index: Option<usize>,
    /// Where to serve the page (port 0: any free port). Keep it on loopback unless you
    /// mean to show the hand to your network.
    #[arg(long, value_name = "ADDR:PORT", default_value = DEFAULT_BIND)]
    pub bind: SocketAddr,
    /// Stop after this many seconds (at most a week).
    #[arg(long, value_name = "S", value_parser = cli_values::positive_seconds)]
    pub seconds: Option<f64>,
}

/// Serves the page from the one source given, until interrupted or `--seconds`.
pub fn run(args: UiArgs) -> Result<()> {
    let source = match (args.port, args.udp, args.replay) {
        (Some(port), None, None) => UiSource::Serial {
            port,
            baud: args.baud,
            setup: args.setup,
            camera_index: args.camera_index,
        },
        (None, Some(addr), None) => UiSource::Udp(addr),
        (None, None, Some(seqdir)) => UiSource::Replay {
            states: args.states.unwrap_or_else(|| seqdir.join("states.csv")),
            hypotheses: args.hypotheses,
            seqdir,
            camera: args.camera_index.unwrap_or(0),
            fps: args.fps,
        },
        _ => bail!("give one of --port TTY, --udp ADDR:PORT or --replay SEQDIR"),
    };
    let options = UiOptions {
        bind: args.bind,
        source,
        duration: args.seconds.map(cli_values::duration),
    };
    run_ui(&options, &mut std::io::stdout())
}
