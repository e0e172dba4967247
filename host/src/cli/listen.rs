//! `digiteyes listen`: what a board sends, printed and forwarded over UDP.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

use super::stream::InitArg;
use crate::cli_values;
use crate::forward::one_euro::{self, Smoothing};
use crate::forward::parse_forward;
use crate::link::Link;
use crate::listen::{listen, ListenOptions};
use crate::stream::DEFAULT_BAUD;

/// Print what a board sends (states, drops, counters) and forward it over UDP.
///
/// Decodes every message on the serial port and prints one line each: text by default,
/// JSON with --json (e.g. {"State":{"frame":12,"timestamp":…,"q":[…],"rms_px":…,…,
/// "status":"Tracking",…}}). Each state's line names the board's status (searching,
/// tracking or lost); the summary on stderr counts them. A board tracking several
/// hypotheses follows each state with its hypotheses (their scores and ages, best first);
/// the summary counts how many were carried on average.
/// With --forward, messages also go to the machines that show the hand, as JSON lines
/// (udp://) or Open Sound Control (osc://: /digiteyes/state, /digiteyes/q/N,
/// /digiteyes/mouse, /digiteyes/dropped, /digiteyes/stats; see docs/forwarding.md).
/// With --smooth, forwarded states pass through a one-euro filter (what is printed stays
/// raw). Runs until interrupted, or --states/--seconds. A board with its own camera needs
/// setting up first: --setup.
#[derive(Args, Debug)]
pub struct ListenArgs {
    /// The serial port.
    #[command(flatten)]
    pub port: PortArgs,
    /// Print JSON lines instead of text.
    #[arg(long)]
    pub json: bool,
    /// Forward to this address; may be given several times. udp://HOST:PORT sends every
    /// message as one JSON line per datagram (e.g. udp://192.168.1.20:5005);
    /// osc://HOST:PORT sends states (one OSC bundle each, with the 3D mouse for the
    /// built-in hand: its buttons rest at --setup's initial state, else at the first
    /// state), drops and counters as Open Sound Control.
    #[arg(long, value_name = "udp://HOST:PORT|osc://HOST:PORT")]
    pub forward: Vec<String>,
    /// Smooth forwarded states with the one-euro filter (Casiez et al. 2012), timed by
    /// the board's clock once its Hello is known (--setup, or a board booting while
    /// listened to), else by the host's receive time. Quaternions are renormalised.
    #[arg(long, requires = "forward")]
    pub smooth: bool,
    /// With --smooth: the lowest cutoff, at rest (Hz); lower = less jitter, more lag.
    #[arg(long, value_name = "HZ", requires = "smooth",
          default_value_t = one_euro::DEFAULT_MIN_CUTOFF_HZ, value_parser = cli_values::positive)]
    pub min_cutoff: f32,
    /// With --smooth: cutoff added per mm/s of the palm's translation (q4..q6); higher =
    /// less lag in fast motion.
    #[arg(long, value_name = "PER_MM", requires = "smooth",
          default_value_t = one_euro::DEFAULT_BETA_MM, value_parser = cli_values::non_negative)]
    pub beta: f32,
    /// With --smooth: cutoff added per rad/s of the quaternion and the joints.
    #[arg(long, value_name = "PER_RAD", requires = "smooth",
          default_value_t = one_euro::DEFAULT_BETA_RAD, value_parser = cli_values::non_negative)]
    pub beta_rad: f32,
    /// With --smooth: the cutoff of the speed estimate (Hz).
    #[arg(long, value_name = "HZ", requires = "smooth",
          default_value_t = one_euro::DEFAULT_D_CUTOFF_HZ, value_parser = cli_values::positive)]
    pub d_cutoff: f32,
    /// Set the board up first (Configure + Reset) from this sequence.json or sequence
    /// folder: camera calibration, initial state, free states.
    #[arg(long, value_name = "PATH")]
    pub setup: Option<PathBuf>,
    /// With --setup: how the board starts: `given` tracks from initial_state; `auto`
    /// searches for the hand (the free states' initial values ignored, the fixed ones kept).
    #[arg(long, value_enum, requires = "setup", default_value_t = InitArg::Given)]
    pub init: InitArg,
    /// With --setup: the camera of a multi-camera description (0-based).
    #[arg(long, value_name = "N")]
    pub camera_index: Option<usize>,
    /// Stop after this many states.
    #[arg(long, value_name = "N")]
    pub states: Option<usize>,
    /// Stop after this many seconds (at most a week).
    #[arg(long, value_name = "S", value_parser = cli_values::positive_seconds)]
    pub seconds: Option<f64>,
}

/// The serial port options of `listen`.
#[derive(Args, Debug)]
pub struct PortArgs {
    /// The board's serial device: a UART or USB serial adapter (/dev/ttyUSB0), or the
    /// pseudo-terminal `digiteyes sim` printed (/dev/pts/N).
    #[arg(long, value_name = "TTY")]
    pub port: String,
    /// Line speed in bits/s (8N1; ignored by pseudo-terminals).
    #[arg(long, value_name = "B", default_value_t = DEFAULT_BAUD)]
    pub baud: u32,
    /// Seconds to wait for each answer of the board (a frame's State or Dropped, an Ack).
    /// Without a frame's answer by then, a Ping probes for as long again (a slow answer still
    /// counts); then the frame counts as dropped, "no reply (timeout)". At most a week.
    #[arg(long, value_name = "S", default_value_t = 2.0, value_parser = cli_values::positive_seconds)]
    pub reply_timeout: f64,
}

/// Listens until interrupted, `--states` or `--seconds`; prints the figures on stderr.
pub fn run(args: ListenArgs) -> Result<()> {
    let port = args.port;
    let options = ListenOptions {
        json: args.json,
        forward: args
            .forward
            .iter()
            .map(|url| parse_forward(url))
            .collect::<Result<_>>()?,
        smoothing: match args.smooth {
            true => Some(Smoothing::new(
                args.min_cutoff,
                args.beta,
                args.beta_rad,
                args.d_cutoff,
            )?),
            false => None,
        },
        setup: args.setup,
        camera_index: args.camera_index,
        start: Some(args.init.into()),
        states: args.states,
        duration: args.seconds.map(cli_values::duration),
    };
    let link = Link::open(&port.port, port.baud)?;
    eprintln!("listening on {}", port.port);
    let summary = listen(link, &options, &mut std::io::stdout().lock())?;
    let [searching, tracking, lost] = summary.statuses;
    let hypotheses = match summary.hypotheses_messages {
        0 => String::new(),
        n => format!(
            "; {n} hypotheses messages, {:.2} carried on average",
            summary.hypotheses_carried as f64 / n as f64
        ),
    };
    eprintln!(
        "{} messages ({} states: {tracking} tracking, {lost} lost, {searching} \
         searching{hypotheses}), {} forwarded; {} CRC errors, {} framing errors",
        summary.messages,
        summary.states,
        summary.forwarded,
        summary.link.crc_errors,
        summary.link.framing_errors
    );
    Ok(())
}
