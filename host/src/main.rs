//! `digiteyes`: render, track and evaluate hand sequences. A thin layer over the library.

use digiteyes_board_linux::parse_frame_size;
use std::io::IsTerminal;
use std::ops::Range;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::{bail, Result};
use clap::{Args, Parser, Subcommand};
use digiteyes_board_linux::SimOptions;
use digiteyes_host::demo::run_demo;
use digiteyes_host::link::{reply_timeout, Link};
use digiteyes_host::listen::{listen, parse_forward, ListenOptions};
use digiteyes_host::scenarios::{render_scenario, RenderOptions, DEFAULT_FRAMES, NAMES};
use digiteyes_host::stream::{stream_camera, DEFAULT_BAUD};
use digiteyes_host::{evaluate, stream_sequence, track_sequence, StreamOptions, TrackerConfig};

/// Model-based 3D hand tracking after DigitEyes (Rehg 1995).
///
/// Sequences are folders in the format of `sequence-format.md`: `sequence.json`, frames
/// `camN/NNNNNN.pgm` (8-bit P5) and optionally `truth.csv`. Units: mm, rad, px.
#[derive(Parser, Debug)]
#[command(name = "digiteyes", version, about, long_about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Render a synthetic scenario to a sequence folder.
    ///
    /// Writes OUTDIR/sequence.json (model `builtin:hand`, cameras, initial state = truth at
    /// frame 0, free states), the frames OUTDIR/camN/NNNNNN.pgm and OUTDIR/truth.csv (every
    /// state at every frame). The motion is smooth and seeded; the hand stays in view.
    ///
    /// Scenarios:
    ///   mouse            3D-mouse sub-model (free q4 q5 q8 q9 q10 q19 q24): palm slides on the
    ///                    table, finger 1 flexes, finger 4 and thumb abduct; one camera at 45°;
    ///                    fingertips <= 4 px/frame
    ///   rigid            palm pose only (q0..q6): ±20° rotation, ±30 mm translation
    ///   twofinger        fingers 1 and 2 (3 joints each) + palm translation (q4 q5 q6)
    ///   fullhand-stereo  all 28 states, two cameras 35° apart facing the palm
    ///   fullhand-mono    the same motion, first camera only
    ///   fast             the mouse motion at 20 px/frame fingertip speed (peak)
    ///   clutter          the mouse motion over a cluttered background, noise σ 8
    #[command(verbatim_doc_comment)]
    Render {
        /// Scenario name (see above).
        #[arg(value_parser = clap::builder::PossibleValuesParser::new(NAMES))]
        scenario: String,
        /// Output sequence folder (created if missing; existing files are overwritten).
        outdir: PathBuf,
        /// Seed of the motion, noise and clutter.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Number of frames.
        #[arg(long, default_value_t = DEFAULT_FRAMES)]
        frames: usize,
        /// Gaussian noise standard deviation in grey levels (default: the scenario's, 2; 8 for
        /// `clutter`).
        #[arg(long, value_name = "SIGMA")]
        noise: Option<f32>,
        /// Gaussian blur standard deviation in px (default: the scenario's, 0.5).
        #[arg(long, value_name = "SIGMA")]
        blur: Option<f32>,
        /// Cluttered, textured background (default: only for `clutter`).
        #[arg(long)]
        clutter: bool,
        /// Image size in px, e.g. 320x240 (default 640x480); the view stays the same.
        #[arg(long, value_name = "WxH", value_parser = parse_frame_size)]
        size: Option<(u32, u32)>,
        /// Rays per pixel along each axis (3 = 9 rays per pixel).
        #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=8))]
        supersample: u32,
    },
    /// Track a sequence and write the estimated states as CSV.
    ///
    /// Starts from the sequence's initial_state and estimates its free states from every
    /// frame of every camera. Output columns: frame, q0..q{n-1} (unit quaternion, mm, rad),
    /// rms_px, iterations, features_found, features_expected, lost (0/1). Prints a summary
    /// (frames, lost frames, mean RMS residual, frames/s). Exits non-zero, naming the file or
    /// frame, on bad input or a tracker error.
    Track {
        /// Sequence folder.
        seqdir: PathBuf,
        /// Output CSV path (default: states.csv in the current folder).
        #[arg(long, short, default_value = "states.csv", hide_default_value = true)]
        out: PathBuf,
        /// Gauss–Newton iterations per frame (default: the tracker's).
        #[arg(long, value_parser = clap::value_parser!(u8).range(1..))]
        iterations: Option<u8>,
        /// Start each frame from the last estimate instead of a constant-velocity prediction.
        #[arg(long)]
        no_predict: bool,
        /// No progress bar.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Compare estimated states with a sequence's truth.csv.
    ///
    /// Per camera: fingertip and joint-centre reprojection error (px, mean and 95th
    /// percentile). Free-joint RMS error (deg), palm rotation (deg) and translation (mm)
    /// errors, and track life: the fraction of frames before the mean fingertip error stays
    /// above 10 px for 5 frames.
    Eval {
        /// Sequence folder (with truth.csv).
        seqdir: PathBuf,
        /// Estimated states (the output of `track`).
        states: PathBuf,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// Run a simulated digiteyes board on a pseudo-terminal; prints the device to connect to.
    ///
    /// The board is the firmware's loop (the same code as on a Linux board or a
    /// microcontroller) in this process, on one side of a PTY pair; connect `digiteyes
    /// stream --port` or `digiteyes listen --port` to the printed /dev/pts/N. It tracks the
    /// built-in hand model (or any sub-model of it, such as the mouse scenarios'). Runs until
    /// interrupted (Ctrl-C).
    Sim {
        /// Flip one random bit in this fraction of the bytes crossing the line, both ways
        /// (0.01 = 1%): line noise, to see the link recover.
        #[arg(long, value_name = "RATE", default_value_t = 0.0)]
        corrupt: f64,
        /// Only corrupt while these frames are uploaded (A..B: frames A to B-1).
        #[arg(long, value_name = "A..B", value_parser = digiteyes_host::sim::parse_range,
              requires = "corrupt")]
        corrupt_frames: Option<Range<u32>>,
        /// Seed of the line noise.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Power-cycle the board once, after N frames were uploaded (it reboots mid-upload of
        /// frame N, announcing itself with a new Hello).
        #[arg(long, value_name = "N")]
        restart_after: Option<u32>,
        /// The board's frame buffer: the largest frame it accepts, WxH px.
        #[arg(long, value_name = "WxH", value_parser = parse_frame_size, default_value = "640x480")]
        max_frame: (u32, u32),
        /// Print the line's byte and error counts every this many seconds (0: never).
        #[arg(long, value_name = "S", default_value_t = 0.0)]
        report_every: f64,
    },
    /// Stream frames to a board over a serial link and write the states it sends back.
    ///
    /// Sets the board up (Configure: the camera from sequence.json and the default tracker
    /// parameters; Reset: initial_state and free from sequence.json), checks its Hello
    /// (protocol version; the board's model must be the sequence's), then uploads each frame
    /// as FrameChunks and waits for its State or Dropped. A board that reboots mid-stream is
    /// set up again from the last state. Writes the same CSV as `track` (every frame, in
    /// order) plus a last column `dropped`: empty for tracked frames; for a frame the board
    /// did not track, the reason (incomplete, wrong size WxH, too large, not ready,
    /// superseded, tracker error, no reply (timeout), board restarted) — its row repeats the
    /// last state with lost = 1. Prints a summary and the link's figures (states/s, bytes,
    /// CRC/framing errors on both ends, the board's drops by reason). A board tracks one
    /// camera: a stereo sequence needs --camera-index.
    Stream {
        #[command(flatten)]
        port: PortArgs,
        /// Sequence folder whose frames to upload.
        #[arg(
            long,
            value_name = "DIR",
            required_unless_present = "camera",
            conflicts_with = "camera"
        )]
        seq: Option<PathBuf>,
        /// Capture the frames from this V4L2 camera on the host instead (GREY, YUYV or MJPEG);
        /// needs --setup.
        #[arg(long, value_name = "/dev/videoN", requires = "setup")]
        camera: Option<PathBuf>,
        /// With --camera: a sequence.json giving the model, the camera's calibration (its
        /// size is the capture size), the initial state and the free states.
        #[arg(long, value_name = "FILE")]
        setup: Option<PathBuf>,
        /// With --camera: frames to capture.
        #[arg(long, value_name = "N", default_value_t = 300)]
        frames: usize,
        /// The camera of a multi-camera sequence to track (0-based).
        #[arg(long, value_name = "N")]
        camera_index: Option<usize>,
        /// Output CSV path (default: states.csv in the current folder).
        #[arg(long, short, default_value = "states.csv", hide_default_value = true)]
        out: PathBuf,
        /// No progress bar.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Print what a board sends (states, drops, counters) and forward it over UDP.
    ///
    /// Decodes every message on the serial port and prints one line each: text by default,
    /// JSON with --json (e.g. {"State":{"frame":12,"timestamp":…,"q":[…],"rms_px":…,…}}).
    /// With --forward, every message also goes as one JSON line per UDP datagram to the
    /// machine that shows the hand. Runs until interrupted, or --states/--seconds. A board
    /// with its own camera needs setting up first: --setup.
    Listen {
        #[command(flatten)]
        port: PortArgs,
        /// Print JSON lines instead of text.
        #[arg(long)]
        json: bool,
        /// Send every message as a JSON line to this UDP address, e.g. udp://192.168.1.20:5005.
        #[arg(long, value_name = "udp://HOST:PORT")]
        forward: Option<String>,
        /// Set the board up first (Configure + Reset) from this sequence.json or sequence
        /// folder: camera calibration, initial state, free states.
        #[arg(long, value_name = "PATH")]
        setup: Option<PathBuf>,
        /// With --setup: the camera of a multi-camera description (0-based).
        #[arg(long, value_name = "N")]
        camera_index: Option<usize>,
        /// Stop after this many states.
        #[arg(long, value_name = "N")]
        states: Option<usize>,
        /// Stop after this many seconds.
        #[arg(long, value_name = "S")]
        seconds: Option<f64>,
    },
    /// Render the `mouse` scenario, stream it to a simulated board, and evaluate.
    ///
    /// The rendered camera's frames go to a simulated Linux board (the firmware loop on a
    /// pseudo-terminal, as `digiteyes sim` runs it) over a real serial link; the states it
    /// sends back are evaluated against the ground truth. Prints the accuracy and the link's
    /// figures.
    Demo {
        /// Number of frames.
        #[arg(long, default_value_t = DEFAULT_FRAMES)]
        frames: usize,
        /// Keep the sequence (and states.csv) in this folder instead of a temporary one.
        #[arg(long, value_name = "DIR")]
        keep: Option<PathBuf>,
    },
}

/// The serial port options of `stream` and `listen`.
#[derive(Args, Debug)]
struct PortArgs {
    /// The board's serial device: a UART or USB serial adapter (/dev/ttyUSB0), or the
    /// pseudo-terminal `digiteyes sim` printed (/dev/pts/N).
    #[arg(long, value_name = "TTY")]
    port: String,
    /// Line speed in bits/s (8N1; ignored by pseudo-terminals).
    #[arg(long, value_name = "B", default_value_t = DEFAULT_BAUD)]
    baud: u32,
    /// Seconds to wait for each answer of the board (a frame's State or Dropped, an Ack).
    /// Without a frame's answer by then, a Ping probes for as long again (a slow answer still
    /// counts); then the frame counts as dropped, "no reply (timeout)".
    #[arg(long, value_name = "S", default_value_t = 2.0)]
    reply_timeout: f64,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("digiteyes: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    let progress = std::io::stderr().is_terminal();
    match cli.command {
        Command::Render {
            scenario,
            outdir,
            seed,
            frames,
            noise,
            blur,
            clutter,
            size,
            supersample,
        } => {
            let opts = RenderOptions {
                seed,
                frames: Some(frames),
                noise,
                blur,
                clutter: clutter.then_some(true),
                size,
                supersample,
                progress,
            };
            render_scenario(&scenario, &outdir, &opts)?;
            println!(
                "rendered {scenario}: {frames} frames to {}",
                outdir.display()
            );
        }
        Command::Track {
            seqdir,
            out,
            iterations,
            no_predict,
            quiet,
        } => {
            let config = tracker_config(iterations, no_predict);
            let summary = track_sequence(&seqdir, &out, config, progress && !quiet)?;
            println!("{summary}");
        }
        Command::Eval {
            seqdir,
            states,
            json,
        } => {
            let report = evaluate(&seqdir, &states)?;
            if json {
                println!("{}", serde_json::to_string_pretty(&report)?);
            } else {
                print!("{report}");
            }
        }
        Command::Sim {
            corrupt,
            corrupt_frames,
            seed,
            restart_after,
            max_frame,
            report_every,
        } => {
            let mut options = SimOptions::default()
                .frame_buffer_bytes(max_frame.0 as usize * max_frame.1 as usize);
            if corrupt > 0.0 || corrupt_frames.is_some() {
                options = options.corruption(digiteyes_host::sim::corruption(
                    corrupt,
                    corrupt_frames,
                    seed,
                )?);
            }
            if let Some(n) = restart_after {
                options = options.restart_after(n);
            }
            let board = digiteyes_host::sim::start(options)?;
            println!("simulated board on {}", board.path().display());
            println!(
                "connect with: digiteyes stream --port {} --seq DIR   (Ctrl-C stops the board)",
                board.path().display()
            );
            let every = (report_every > 0.0).then(|| Duration::from_secs_f64(report_every));
            digiteyes_host::sim::serve(board, every)?;
        }
        Command::Stream {
            port,
            seq,
            camera,
            setup,
            frames,
            camera_index,
            out,
            quiet,
        } => {
            let mut options = StreamOptions::new(&port.port)
                .baud(port.baud)
                .reply_timeout(reply_timeout(port.reply_timeout)?)
                .camera_index(camera_index)
                .progress(progress && !quiet);
            options.tracker = Default::default();
            let summary = match (seq, camera, setup) {
                (Some(seq), None, _) => stream_sequence(&seq, &out, &options)?,
                (None, Some(camera), Some(setup)) => {
                    stream_camera(&camera, &setup, frames, &out, &options)?
                }
                _ => bail!("give --seq DIR, or --camera /dev/videoN with --setup FILE"),
            };
            println!("{summary}");
        }
        Command::Listen {
            port,
            json,
            forward,
            setup,
            camera_index,
            states,
            seconds,
        } => {
            let mut options = ListenOptions::default();
            options.json = json;
            options.forward = forward.as_deref().map(parse_forward).transpose()?;
            options.setup = setup;
            options.camera_index = camera_index;
            options.states = states;
            options.duration = match seconds {
                Some(s) => Some(reply_timeout(s)?),
                None => None,
            };
            let link = Link::open(&port.port, port.baud)?;
            eprintln!("listening on {}", port.port);
            let summary = listen(link, &options, &mut std::io::stdout().lock())?;
            eprintln!(
                "{} messages ({} states), {} forwarded; {} CRC errors, {} framing errors",
                summary.messages,
                summary.states,
                summary.forwarded,
                summary.link.crc_errors,
                summary.link.framing_errors
            );
        }
        Command::Demo { frames, keep } => {
            let result = run_demo(frames, keep.as_deref(), TrackerConfig::default(), progress)?;
            println!("{}", result.stream);
            println!("{}", result.board);
            print!("{}", result.eval);
            match keep {
                Some(_) => println!("sequence kept in {}", result.sequence.display()),
                None => println!(
                    "(the sequence was in a temporary folder, now removed; --keep DIR keeps it)"
                ),
            }
        }
    }
    Ok(())
}

fn tracker_config(iterations: Option<u8>, no_predict: bool) -> TrackerConfig {
    let mut config = TrackerConfig::default();
    if let Some(n) = iterations {
        config.iterations = n;
    }
    if no_predict {
        config.predict = false;
    }
    config
}
