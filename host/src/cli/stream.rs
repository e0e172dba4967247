//! `digiteyes stream`: frames to one board, or to one board per camera, and the states back.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::{Args, ValueEnum};
use digiteyes_core::protocol::{Start, TrackerParams};

use super::hypotheses::{self, HypothesisBudgetArgs};
use super::tracker_config;
use crate::cli_values;
use crate::stereo::{stream_stereo, StereoOptions};
use crate::stream::{stream_camera, stream_sequence, StreamOptions, DEFAULT_BAUD};

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
/// last state with lost = 1 — and then a column `status`: what the board claimed of the
/// frame, searching, tracking or lost (lost for a dropped frame; lost = 1 on every row
/// that is not tracking) — and last `board_ticks`: the board's own count of its work on
/// the frame, in ticks of its clock (empty for a dropped frame). With --init auto the board searches for the hand instead of
/// starting from initial_state; either way it searches again after losing the hand.
/// Prints a summary (with the statuses) and the link's figures (states/s, bytes,
/// CRC/framing errors on both ends, the board's drops by reason). A board tracks one
/// camera: a stereo sequence needs --camera-index, or one board per camera.
///
/// One board per camera (--port given once per camera of --seq, in camera order), as the
/// thesis' stereo system ran: each board holds its camera's frames (Hold); per
/// Gauss–Newton iteration the host sends the state to every board (Measure), each
/// searches its own frame at it and answers with the edges and tips it found, and the
/// host solves once with all of them — the same states as `track` on the sequence with
/// the same --iterations. A board that does not answer within --reply-timeout is left
/// out (the other cameras carry on, and the summary says so) and taken back as soon as
/// it answers again. docs/link.md has the bytes per iteration and the rates they allow.
#[derive(Args, Debug)]
pub struct StreamArgs {
    /// The board or boards.
    #[command(flatten)]
    pub port: StreamPorts,
    /// Sequence folder whose frames to upload.
    #[arg(
        long,
        value_name = "DIR",
        required_unless_present = "camera",
        conflicts_with = "camera"
    )]
    pub seq: Option<PathBuf>,
    /// Capture the frames from this V4L2 camera on the host instead (GREY, YUYV or MJPEG);
    /// needs --setup.
    #[arg(long, value_name = "/dev/videoN", requires = "setup")]
    pub camera: Option<PathBuf>,
    /// With --camera: a sequence.json giving the model, the camera's calibration (its
    /// size is the capture size), the initial state and the free states.
    #[arg(long, value_name = "FILE")]
    pub setup: Option<PathBuf>,
    /// With --camera: frames to capture.
    #[arg(long, value_name = "N", default_value_t = 300)]
    pub frames: usize,
    /// The camera of a multi-camera sequence to track (0-based).
    #[arg(long, value_name = "N")]
    pub camera_index: Option<usize>,
    /// Gauss–Newton iterations per tracked frame, 1 to 50 (default: the tracker's, 8; the
    /// thesis ran one per frame). The search's refinements keep their own 8.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(1..=50))]
    pub iterations: Option<u8>,
    /// How the board starts: `given` tracks from sequence.json's initial_state; `auto`
    /// searches for the hand (the free states' initial values are ignored, the fixed ones
    /// kept). Default: `given` when sequence.json has an initial_state, `auto` when it has
    /// none. One board per camera (the host's own tracker) supports `given` only.
    #[arg(long, value_enum)]
    pub init: Option<InitArg>,
    /// The board's search budget: evaluations per frame and camera at most while it searches, 1 to
    /// 65535 (default: the search's, 100). Lower keeps a searching frame's time nearer a
    /// tracking frame's; the search then takes more frames.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub search_evaluations: Option<u16>,
    /// Hypotheses the board's tracker carries, 1 to 8 (default: the tracker's). 1 is the
    /// single tracker; with more the board sends them after every state (protocol version
    /// 5) and the summary counts them (carried on average, the best's mean score). A single
    /// board only: with one board per camera the host tracks.
    #[arg(long, value_name = "K", value_parser = hypotheses::count)]
    pub hypotheses: Option<u8>,
    /// With --hypotheses K > 1: the board scores its hypotheses on one frame in S, 1 to 255
    /// (default 1: every frame; protocol version 9): K = 2 at S = 4 fits 30 frames/s on a
    /// 480 MHz M7 on the mean, not on the frames it scores (docs/hypotheses.md, "Scoring one
    /// frame in S").
    #[arg(long, value_name = "S", value_parser = clap::value_parser!(u8).range(1..))]
    pub score_every: Option<u8>,
    /// What the board's hypotheses other than the best may cost (protocol version 10).
    #[command(flatten)]
    pub hypothesis_budget: HypothesisBudgetArgs,
    /// With --hypotheses K > 1: also write every hypothesis the board sends, one row per
    /// hypothesis per frame, best first, to FILE: the file `track --hypotheses-out` writes
    /// (`digiteyes report` and `ui` read it).
    #[arg(long, value_name = "FILE")]
    pub hypotheses_out: Option<PathBuf>,
    /// Output CSV path (default: states.csv in the current folder).
    #[arg(long, short, default_value = "states.csv", hide_default_value = true)]
    pub out: PathBuf,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
}

/// The boards `stream` talks to: one, or one per camera.
#[derive(Args, Debug)]
pub struct StreamPorts {
    /// A board's serial device: a UART or USB serial adapter (/dev/ttyUSB0), or a
    /// pseudo-terminal `digiteyes sim` printed (/dev/pts/N). Give it once per camera of a
    /// stereo --seq (in camera order) for one board per camera.
    #[arg(long, value_name = "TTY", required = true, num_args = 1)]
    pub port: Vec<String>,
    /// Line speed in bits/s (8N1; ignored by pseudo-terminals).
    #[arg(long, value_name = "B", default_value_t = DEFAULT_BAUD)]
    pub baud: u32,
    /// Seconds to wait for each answer of a board (a frame's State or Dropped, an Ack, the
    /// answer to a Measure). Without a frame's answer by then, a Ping probes for as long
    /// again (a slow answer still counts); then the frame counts as dropped, "no reply
    /// (timeout)". With one board per camera, a board that does not answer a Measure in time
    /// is left out until it answers again. At most a week.
    #[arg(long, value_name = "S", default_value_t = 2.0, value_parser = cli_values::positive_seconds)]
    pub reply_timeout: f64,
}

/// How a board starts (`--init`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum InitArg {
    /// From the sequence's initial state.
    Given,
    /// Searching for the hand.
    Auto,
}

impl From<InitArg> for Start {
    fn from(init: InitArg) -> Self {
        match init {
            InitArg::Given => Start::Given,
            InitArg::Auto => Start::Search,
        }
    }
}

/// What a single board is told, as `args` ask: the port, the tracker, how to start, the
/// search's budget and the hypotheses. Refuses hypotheses' options that mean nothing with one.
fn single_board_options(
    args: &StreamArgs,
    tracker: TrackerParams,
    progress: bool,
) -> Result<StreamOptions> {
    let port = &args.port;
    let port_path = port.port.first().cloned().unwrap_or_default();
    let mut options = StreamOptions::new(&port_path)
        .baud(port.baud)
        .reply_timeout(cli_values::duration(port.reply_timeout))
        .camera_index(args.camera_index)
        .start(args.init.map(Start::from))
        .progress(progress && !args.quiet);
    options.tracker = tracker;
    if let Some(n) = args.search_evaluations {
        options.search_evaluations_per_frame = n;
    }
    options.hypotheses =
        hypotheses::asked(args.hypotheses, args.score_every, &args.hypothesis_budget)?;
    if let Some(path) = &args.hypotheses_out {
        if options.hypotheses.count <= 1 {
            bail!(
                "--hypotheses-out {}: a board sends its hypotheses only when it carries \
                 several; give --hypotheses K with K > 1 (with one, the states file is all \
                 there is)",
                path.display()
            );
        }
        options.hypotheses_out = Some(path.clone());
    }
    Ok(options)
}

/// Streams to the board(s), writes the CSV and prints the summary; fails when no frame was
/// tracked.
pub fn run(args: StreamArgs, progress: bool) -> Result<()> {
    let port = &args.port;
    let tracker = TrackerParams::from_config(&tracker_config(args.iterations, false));
    if port.port.len() > 1 {
        let Some(seq) = args.seq else {
            bail!(
                "one board per camera (--port given {} times) needs --seq DIR: a \
                 sequence with that many cameras",
                port.port.len()
            );
        };
        if args.init == Some(InitArg::Auto) {
            bail!(
                "--init auto: with one board per camera the host tracks, from the sequence's \
                 initial_state only (accepted: --init given); a single board searches itself"
            );
        }
        if args.hypotheses.is_some()
            || args.score_every.is_some()
            || args.hypothesis_budget.any()
            || args.hypotheses_out.is_some()
        {
            bail!(
                "--hypotheses, --score-every, --sample-iterations, --other-iterations, \
                 --no-keep-fingers, --hypotheses-out: with one board per camera the host tracks, and its stereo \
                 tracker carries one hypothesis; leave them out, or stream one camera to one \
                 board (--camera-index)"
            );
        }
        if args.camera_index.is_some() {
            bail!("--camera-index picks the one camera of a single board; with one --port per camera leave it out");
        }
        let mut options = StereoOptions::new(port.port.clone());
        options.baud = port.baud;
        options.reply_timeout = cli_values::duration(port.reply_timeout);
        options.tracker = tracker;
        options.progress = progress && !args.quiet;
        let summary = stream_stereo(&seq, &args.out, &options)?;
        print!("{summary}");
        if summary.frames == summary.lost_frames {
            bail!("every frame was lost: no board measured the hand");
        }
        return Ok(());
    }
    let options = single_board_options(&args, tracker, progress)?;
    let summary = match (args.seq, args.camera, args.setup) {
        (Some(seq), None, _) => stream_sequence(&seq, &args.out, &options)?,
        (None, Some(camera), Some(setup)) => {
            stream_camera(&camera, &setup, args.frames, &args.out, &options)?
        }
        _ => bail!("give --seq DIR, or --camera /dev/videoN with --setup FILE"),
    };
    println!("{summary}");
    summary.ensure_some_tracked()
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;
    use digiteyes_core::protocol::HypothesesParams;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        stream: StreamArgs,
    }

    fn options(args: &[&str]) -> Result<StreamOptions> {
        let base = ["stream", "--port", "/dev/null", "--seq", "seq"];
        let cli = Cli::try_parse_from([&base[..], args].concat())?;
        single_board_options(&cli.stream, TrackerParams::default(), false)
    }

    /// What `Configure` then carries: the hypotheses' count, scoring period and budget as
    /// given, the defaults otherwise (the board applies each: `firmware/tests/hypotheses.rs`).
    #[test]
    fn the_hypotheses_options_reach_what_the_board_is_configured_with() {
        let defaults = options(&[]).unwrap();
        assert_eq!(defaults.hypotheses, HypothesesParams::default());
        assert_eq!(
            (
                defaults.port.as_str(),
                defaults.search_evaluations_per_frame
            ),
            (
                "/dev/null",
                StreamOptions::new("x").search_evaluations_per_frame
            )
        );
        let asked = options(&[
            "--hypotheses",
            "2",
            "--score-every",
            "4",
            "--sample-iterations",
            "2",
            "--other-iterations",
            "3",
            "--no-keep-fingers",
            "--search-evaluations",
            "7",
        ])
        .unwrap();
        assert_eq!(
            asked.hypotheses,
            HypothesesParams {
                count: 2,
                score_every: 4,
                sample_iterations: 2,
                other_iterations: 3,
                keep_fingers: false,
            }
        );
        assert_eq!(asked.search_evaluations_per_frame, 7);
        let err = options(&["--no-keep-fingers"]).unwrap_err().to_string();
        assert!(err.contains("--no-keep-fingers"), "{err}");
        let written = options(&["--hypotheses", "2", "--hypotheses-out", "h.csv"]).unwrap();
        assert_eq!(written.hypotheses_out, Some(PathBuf::from("h.csv")));
        assert_eq!(options(&[]).unwrap().hypotheses_out, None);
        let err = options(&["--hypotheses-out", "h.csv"])
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("--hypotheses-out h.csv:"), "{err}");
    }
}
