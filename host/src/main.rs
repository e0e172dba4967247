//! `digiteyes`: render, track and evaluate hand sequences. A thin layer over the library.

use std::io::IsTerminal;
use std::net::SocketAddr;
use std::ops::Range;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{bail, Result};
use clap::{Args, Parser, Subcommand};
use digiteyes_platform_linux::parse_frame_size;
use digiteyes_core::protocol::TrackerParams;
use digiteyes_host::cli_values;
use digiteyes_host::demo::{
    run_demo, run_stereo_demo, serve_demo_ui, DEFAULT_DEMO_DIR, DEMO_FRAMES, REPORT_HTML,
    STEREO_DEMO_FRAMES,
};
use digiteyes_host::forward::one_euro::{self, Smoothing};
use digiteyes_host::forward::parse_forward;
use digiteyes_host::link::Link;
use digiteyes_host::listen::{listen, ListenOptions};
use digiteyes_host::scenarios::{
    render_scenario, RenderOptions, DEFAULT_FRAMES, NAMES, RANDOM_NAMES,
};
use digiteyes_host::stereo::{stream_stereo, StereoOptions};
use digiteyes_host::stream::{stream_camera, DEFAULT_BAUD};
use digiteyes_host::sim::ui_tap::ui_tap;
use digiteyes_host::sim::SimOptions;
use digiteyes_host::ui::{attach_mouse, run_ui, Hub, UiOptions, UiServer, UiSource, DEFAULT_BIND};
use digiteyes_host::{
    evaluate, stream_sequence, track_sequence_with, StreamOptions, TrackerConfig,
};

/// Model-based 3D hand tracking after DigitEyes (Rehg 1995).
///
/// Sequences are folders in the format of `docs/sequence-format.md`: `sequence.json`, frames
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
    ///   mouse-thesis     the thesis' 3D-mouse trial (free q0..q5 q8 q9 q10 q19 q24), scripted in
    ///                    four phases: finger 1 raised and lowered twice; held up while the thumb
    ///                    clicks; palm slides and yaws; all at once. --frames 500 is the thesis'
    ///                    pace (fewer frames: the same trial, faster)
    ///   rigid            palm pose only (q0..q6): ±20° rotation, ±30 mm translation
    ///   twofinger        fingers 1 and 2 (3 joints each) + palm translation (q4 q5 q6)
    ///   fullhand-stereo  all 28 states, two cameras 35° apart facing the palm
    ///   fullhand-mono    the same motion, first camera only
    ///   fast             the mouse motion at 20 px/frame fingertip speed (peak)
    ///   clutter          the mouse motion over a cluttered background, noise σ 8
    ///   random-mono      a random rig from --seed: one camera anywhere on the upper
    ///                    hemisphere (elevation 20-90°, any azimuth, 350-1500 mm, hand
    ///                    120-350 px wide) and a random whole-hand motion through fists,
    ///                    crossing fingers and end-on fingers (docs/robustness.md)
    ///   random-stereo    the same with a second camera 150-600 mm beside the first
    ///   thesis-stereo    the thesis' stereo rig: two cameras behind the wrist, 60° up
    #[command(verbatim_doc_comment)]
    Render {
        /// Scenario name (see above).
        #[arg(value_parser = clap::builder::PossibleValuesParser::new(
            NAMES.iter().chain(RANDOM_NAMES.iter()).copied()
        ))]
        scenario: String,
        /// Output sequence folder (created if missing; existing files are overwritten).
        outdir: PathBuf,
        /// Seed of the motion, noise and clutter.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Number of frames (1 to 100000).
        #[arg(long, default_value_t = DEFAULT_FRAMES, value_parser = cli_values::frame_count)]
        frames: usize,
        /// Gaussian noise standard deviation in grey levels, 0 to 128 (default: the
        /// scenario's, 2; 8 for `clutter`).
        #[arg(long, value_name = "SIGMA", value_parser = cli_values::noise_sigma)]
        noise: Option<f32>,
        /// Gaussian blur standard deviation in px, 0 to 20 (default: the scenario's, 0.5).
        #[arg(long, value_name = "SIGMA", value_parser = cli_values::blur_sigma)]
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
    ///
    /// With --overlay DIR, each frame of each camera is also written as DIR/camN/NNNNNN.png,
    /// drawn at the state tracked for it, like the IC40's video overlay: the frame dimmed,
    /// each link's axis (orange) and silhouette lines (cyan), the slices searched (blue;
    /// purple where masked as hidden), the edge points found (red squares) and the
    /// fingertips found (green crosses). See docs/overlay.md.
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
        /// Also draw every frame at its tracked state into DIR/camN/NNNNNN.png.
        #[arg(long, value_name = "DIR")]
        overlay: Option<PathBuf>,
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
    /// Write an HTML report of a tracking run: states against time, errors, overlays.
    ///
    /// One self-contained page (inline SVG plots and PNG thumbnails, no script, no external
    /// link: it opens offline and can be mailed alone). It shows the sequence (folder, frames,
    /// cameras, fps, model, free states); the accuracy against truth.csv when the sequence
    /// has one (as `eval` prints it); the error over time (mean fingertip reprojection error
    /// in px and free-joint RMS error in deg against the truth, and the tracker's rms_px
    /// residual); one plot per free state against time (s; frames without fps) in the
    /// state's unit (mm, rad), estimate and truth, with the frames flagged lost shaded and
    /// the frames a board dropped (the `dropped` column of `stream`) marked; and the model
    /// drawn over every Nth frame (--thumb-every). States that are not numbers are gaps in
    /// the plots and a warning, not an error. Prints the path written and a summary.
    Report {
        /// Sequence folder.
        seqdir: PathBuf,
        /// Estimated states (the output of `track` or `stream`).
        states: PathBuf,
        /// Output HTML path.
        #[arg(long, short, default_value = "report.html")]
        out: PathBuf,
        /// An overlay thumbnail of frames 0, N, 2N, ... (0: none).
        #[arg(long, value_name = "N",
              default_value_t = digiteyes_host::report::DEFAULT_THUMB_EVERY)]
        thumb_every: usize,
        /// Thumbnail width in px (the height keeps the camera's aspect).
        #[arg(long, value_name = "PX",
              default_value_t = digiteyes_host::report::DEFAULT_THUMB_WIDTH,
              value_parser = clap::value_parser!(u32).range(16..=4096))]
        thumb_width: u32,
        /// Thumbnails of this camera only (0-based; default: every camera).
        #[arg(long, value_name = "N")]
        camera_index: Option<usize>,
    },
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
    Sim {
        /// Flip one random bit in this fraction of the bytes crossing the line, both ways
        /// (0.01 = 1%; 0 to 1): line noise, to see the link recover.
        #[arg(long, value_name = "RATE", default_value_t = 0.0, value_parser = cli_values::share)]
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
        /// Stand up this many boards (1 to 4), one per camera of a stereo sequence, each on
        /// its own pseudo-terminal: `digiteyes stream --port A --port B --seq DIR`.
        #[arg(long, value_name = "N", default_value_t = 1,
              value_parser = clap::value_parser!(u8).range(1..=4))]
        boards: u8,
        /// The last board hears nothing while frames A..B are uploaded (frames A to B-1,
        /// counted from 0), as if its cable were pulled, then hears again: to see a host
        /// carry on without it and take it back.
        #[arg(long, value_name = "A..B", value_parser = digiteyes_host::sim::parse_range)]
        deaf_frames: Option<Range<u32>>,
        /// The board's frame buffer: the largest frame it accepts, WxH px.
        #[arg(long, value_name = "WxH", value_parser = parse_frame_size, default_value = "640x480")]
        max_frame: (u32, u32),
        /// Print the line's byte and error counts every this many seconds (0: never; at most a
        /// week).
        #[arg(long, value_name = "S", default_value_t = 0.0, value_parser = cli_values::seconds_or_zero)]
        report_every: f64,
        /// Draw every tracked frame at its state into DIR/cam0/NNNNNN.png.
        #[arg(long, value_name = "DIR")]
        overlay: Option<PathBuf>,
        /// Also serve the UI page (docs/ui.md) on ADDR:PORT (default 127.0.0.1:7878): every
        /// frame the board tracks with the model drawn over it, the 3D hand, the 3D mouse.
        #[arg(long, value_name = "ADDR:PORT", num_args = 0..=1,
              default_missing_value = DEFAULT_BIND, conflicts_with = "overlay")]
        ui: Option<SocketAddr>,
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
    Stream {
        #[command(flatten)]
        port: StreamPorts,
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
        /// Gauss–Newton iterations per frame, 1 to 50 (default: the tracker's, 8; the thesis
        /// ran one per frame).
        #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(1..=50))]
        iterations: Option<u8>,
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
    /// With --forward, messages also go to the machines that show the hand, as JSON lines
    /// (udp://) or Open Sound Control (osc://: /digiteyes/state, /digiteyes/q/N,
    /// /digiteyes/mouse, /digiteyes/dropped, /digiteyes/stats; see docs/forwarding.md).
    /// With --smooth, forwarded states pass through a one-euro filter (what is printed stays
    /// raw). Runs until interrupted, or --states/--seconds. A board with its own camera needs
    /// setting up first: --setup.
    Listen {
        #[command(flatten)]
        port: PortArgs,
        /// Print JSON lines instead of text.
        #[arg(long)]
        json: bool,
        /// Forward to this address; may be given several times. udp://HOST:PORT sends every
        /// message as one JSON line per datagram (e.g. udp://192.168.1.20:5005);
        /// osc://HOST:PORT sends states (one OSC bundle each, with the 3D mouse for the
        /// built-in hand: its buttons rest at --setup's initial state, else at the first
        /// state), drops and counters as Open Sound Control.
        #[arg(long, value_name = "udp://HOST:PORT|osc://HOST:PORT")]
        forward: Vec<String>,
        /// Smooth forwarded states with the one-euro filter (Casiez et al. 2012), timed by
        /// the board's clock once its Hello is known (--setup, or a board booting while
        /// listened to), else by the host's receive time. Quaternions are renormalised.
        #[arg(long, requires = "forward")]
        smooth: bool,
        /// With --smooth: the lowest cutoff, at rest (Hz); lower = less jitter, more lag.
        #[arg(long, value_name = "HZ", requires = "smooth",
              default_value_t = one_euro::DEFAULT_MIN_CUTOFF_HZ, value_parser = cli_values::positive)]
        min_cutoff: f32,
        /// With --smooth: cutoff added per mm/s of the palm's translation (q4..q6); higher =
        /// less lag in fast motion.
        #[arg(long, value_name = "PER_MM", requires = "smooth",
              default_value_t = one_euro::DEFAULT_BETA_MM, value_parser = cli_values::non_negative)]
        beta: f32,
        /// With --smooth: cutoff added per rad/s of the quaternion and the joints.
        #[arg(long, value_name = "PER_RAD", requires = "smooth",
              default_value_t = one_euro::DEFAULT_BETA_RAD, value_parser = cli_values::non_negative)]
        beta_rad: f32,
        /// With --smooth: the cutoff of the speed estimate (Hz).
        #[arg(long, value_name = "HZ", requires = "smooth",
              default_value_t = one_euro::DEFAULT_D_CUTOFF_HZ, value_parser = cli_values::positive)]
        d_cutoff: f32,
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
        /// Stop after this many seconds (at most a week).
        #[arg(long, value_name = "S", value_parser = cli_values::positive_seconds)]
        seconds: Option<f64>,
    },
    /// Show the hand live in a web page: 3D hand, camera overlay, 3D mouse, link figures.
    ///
    /// Serves one page on this machine (default http://127.0.0.1:7878/; every asset is in
    /// the binary, nothing is fetched from the internet) and feeds it from one source:
    ///   --port TTY        a board on a serial port (as `listen` reads it; --setup sets it up)
    ///   --udp ADDR:PORT   JSON lines of board messages, as `listen --forward udp://` sends
    ///   --replay SEQDIR   a tracked sequence played back at its frame rate, with its frames
    ///                     and the model drawn over them (states from --states, default
    ///                     SEQDIR/states.csv)
    /// The page shows the 3D hand at the newest state (drag to orbit, wheel to zoom), the
    /// camera frame with the back-projected model when the source has frames, the 3D mouse
    /// (thesis Sec. 4.3.4: the pole's base follows the palm on the table, its height finger
    /// 1's fingertip, finger 4 and thumb abduction are two buttons), every state's value,
    /// states/s, drops, CRC and framing errors, and a lost-track / no-signal badge. Runs
    /// until interrupted (Ctrl-C) or --seconds.
    #[command(verbatim_doc_comment)]
    #[command(group = clap::ArgGroup::new("source").required(true).args(["port", "udp", "replay"]))]
    Ui {
        /// The board's serial device (/dev/ttyUSB0, or the /dev/pts/N of `digiteyes sim`).
        #[arg(long, value_name = "TTY")]
        port: Option<String>,
        /// With --port: line speed in bits/s.
        #[arg(long, value_name = "B", default_value_t = DEFAULT_BAUD, requires = "port")]
        baud: u32,
        /// With --port: set the board up first (Configure + Reset) from this sequence.json or
        /// sequence folder.
        #[arg(long, value_name = "PATH", requires = "port")]
        setup: Option<PathBuf>,
        /// Receive board messages as JSON lines on this UDP address (port 0: any free port).
        #[arg(long, value_name = "ADDR:PORT")]
        udp: Option<SocketAddr>,
        /// Play back this tracked sequence folder.
        #[arg(long, value_name = "SEQDIR")]
        replay: Option<PathBuf>,
        /// With --replay: the states to show (default SEQDIR/states.csv).
        #[arg(long, value_name = "CSV", requires = "replay")]
        states: Option<PathBuf>,
        /// With --replay: frames/s, 0.01 to 1000 (default: the sequence's, else 15).
        #[arg(long, value_name = "FPS", requires = "replay", value_parser = cli_values::fps)]
        fps: Option<f64>,
        /// The camera of a multi-camera sequence (0-based; --replay and --setup).
        #[arg(long, value_name = "N")]
        camera_index: Option<usize>,
        /// Where to serve the page (port 0: any free port). Keep it on loopback unless you
        /// mean to show the hand to your network.
        #[arg(long, value_name = "ADDR:PORT", default_value = DEFAULT_BIND)]
        bind: SocketAddr,
        /// Stop after this many seconds (at most a week).
        #[arg(long, value_name = "S", value_parser = cli_values::positive_seconds)]
        seconds: Option<f64>,
    },
    /// Measure the tracker beyond what a test should: `bench robustness`.
    #[command(subcommand)]
    Bench(BenchCommand),
    /// Render the thesis' 3D-mouse trial, stream it to a board, evaluate, report, show.
    ///
    /// The trial is the `mouse-thesis` scenario (see `render --help`).
    ///
    /// The rendered camera's frames go to a simulated Linux board (the firmware loop on a
    /// pseudo-terminal, as `digiteyes sim` runs it) over a real serial link; the states it
    /// sends back are evaluated against the ground truth. Prints the accuracy and the link's
    /// figures, writes the HTML report (DIR/report.html), and ends by saying where to open it
    /// and the UI. In a terminal it then serves the UI (a replay of the run: 3D hand, camera
    /// overlay, 3D mouse, link figures) until Ctrl-C; otherwise it prints the
    /// `digiteyes ui --replay` command that shows it.
    ///
    /// With --stereo: the whole hand (`fullhand-stereo`) from two cameras, each camera's
    /// frames on its own simulated board, the host solving once per iteration with what both
    /// found (as `stream --port A --port B` does).
    Demo {
        /// Number of frames (default 500, the thesis' pace: fewer play the same trial faster;
        /// with --stereo, default 120).
        #[arg(long, value_parser = cli_values::frame_count)]
        frames: Option<usize>,
        /// Track the whole hand from two cameras instead, one simulated board per camera as
        /// the thesis' stereo system ran (`stream --port A --port B`).
        #[arg(long)]
        stereo: bool,
        /// Folder for the run: the sequence, states.csv and report.html (created if
        /// missing; its files are overwritten).
        #[arg(long, visible_alias = "keep", value_name = "DIR", default_value = DEFAULT_DEMO_DIR)]
        out: PathBuf,
        /// Serve the UI for this many seconds after the run (0: not at all; at most a week).
        /// Default: until Ctrl-C when run in a terminal, not at all otherwise.
        #[arg(long, value_name = "S", value_parser = cli_values::seconds_or_zero)]
        ui_seconds: Option<f64>,
    },
}

/// What `digiteyes bench` measures.
#[derive(Subcommand, Debug)]
enum BenchCommand {
    /// Render and track a randomised sweep of rigs and motions and print the distribution.
    ///
    /// Odd seeds are `random-mono`, even ones `random-stereo` (see `render --help`). Per
    /// group (mono, stereo, all): median and 10th-percentile track life, the share of seeds
    /// at >= 95 %, median fingertip px, joint RMS deg, palm deg and mm, the lost flag's
    /// precision and recall against frames truly lost (fingertips > 20 px at 640 px wide or
    /// palm > 30 mm), non-finite states, frames with the palm > 100 mm away and not flagged,
    /// and tracker ms per frame. See docs/robustness.md.
    Robustness(digiteyes_host::bench::robustness::RobustnessArgs),
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
    /// counts); then the frame counts as dropped, "no reply (timeout)". At most a week.
    #[arg(long, value_name = "S", default_value_t = 2.0, value_parser = cli_values::positive_seconds)]
    reply_timeout: f64,
}

/// The boards `stream` talks to: one, or one per camera.
#[derive(Args, Debug)]
struct StreamPorts {
    /// A board's serial device: a UART or USB serial adapter (/dev/ttyUSB0), or a
    /// pseudo-terminal `digiteyes sim` printed (/dev/pts/N). Give it once per camera of a
    /// stereo --seq (in camera order) for one board per camera.
    #[arg(long, value_name = "TTY", required = true, num_args = 1)]
    port: Vec<String>,
    /// Line speed in bits/s (8N1; ignored by pseudo-terminals).
    #[arg(long, value_name = "B", default_value_t = DEFAULT_BAUD)]
    baud: u32,
    /// Seconds to wait for each answer of a board (a frame's State or Dropped, an Ack, the
    /// answer to a Measure). Without a frame's answer by then, a Ping probes for as long
    /// again (a slow answer still counts); then the frame counts as dropped, "no reply
    /// (timeout)". With one board per camera, a board that does not answer a Measure in time
    /// is left out until it answers again. At most a week.
    #[arg(long, value_name = "S", default_value_t = 2.0, value_parser = cli_values::positive_seconds)]
    reply_timeout: f64,
}

fn main() -> ExitCode {
    quiet_on_closed_pipe();
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
            overlay,
        } => {
            let config = tracker_config(iterations, no_predict);
            let summary = track_sequence_with(
                &seqdir,
                &out,
                config,
                progress && !quiet,
                overlay.as_deref(),
            )?;
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
        Command::Report {
            seqdir,
            states,
            out,
            thumb_every,
            thumb_width,
            camera_index,
        } => {
            let mut options = digiteyes_host::report::ReportOptions::default();
            options.thumb_every = thumb_every;
            options.thumb_width = thumb_width;
            options.camera = camera_index;
            let summary = digiteyes_host::report::write_report(&seqdir, &states, &out, &options)?;
            for warning in &summary.warnings {
                eprintln!("digiteyes: warning: {warning}");
            }
            println!("{summary}");
        }
        Command::Sim {
            corrupt,
            corrupt_frames,
            seed,
            restart_after,
            boards,
            deaf_frames,
            max_frame,
            report_every,
            overlay,
            ui,
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
            // The writer runs until the process is interrupted, like the board.
            let _overlays = match &overlay {
                Some(dir) => {
                    let (tap, writer) = digiteyes_host::sim::overlay_tap(dir)?;
                    options = options.frame_tap(tap);
                    println!("overlays of the tracked frames go to {}", dir.display());
                    Some(writer)
                }
                None => None,
            };
            // The UI server and its feeding thread live as long as the board.
            let _ui = match ui {
                Some(bind) => {
                    let model = digiteyes_core::model::Model::hand()
                        .map_err(|e| anyhow::anyhow!("built-in hand model: {e}"))?;
                    let hub = Hub::new(model, Vec::new(), "simulated board");
                    attach_mouse(&hub, None);
                    let (tap, feeder) = ui_tap(std::sync::Arc::clone(&hub))?;
                    options = options.frame_tap(tap);
                    let server = UiServer::start(bind, hub)?;
                    println!("UI: {}", server.url());
                    Some((server, feeder))
                }
                None => None,
            };
            if boards > 1 && (overlay.is_some() || ui.is_some()) {
                bail!("--overlay and --ui watch one board: leave them out with --boards {boards}");
            }
            let mut started = Vec::new();
            for b in 0..boards {
                let mut options = options.clone();
                if let (Some(deaf), true) = (&deaf_frames, b + 1 == boards) {
                    options = options.deaf(deaf.start, deaf.end.saturating_sub(deaf.start));
                }
                let board = digiteyes_host::sim::start(options)?;
                println!("simulated board on {}", board.path().display());
                started.push(board);
            }
            let ports: Vec<String> = started
                .iter()
                .map(|b| format!("--port {}", b.path().display()))
                .collect();
            println!(
                "connect with: digiteyes stream {} --seq DIR   (Ctrl-C stops the board{})",
                ports.join(" "),
                if boards > 1 { "s" } else { "" }
            );
            let every = (report_every > 0.0).then(|| cli_values::duration(report_every));
            digiteyes_host::sim::serve(started, every)?;
        }
        Command::Stream {
            port,
            seq,
            camera,
            setup,
            frames,
            camera_index,
            iterations,
            out,
            quiet,
        } => {
            let tracker = TrackerParams::from_config(&tracker_config(iterations, false));
            if port.port.len() > 1 {
                let Some(seq) = seq else {
                    bail!(
                        "one board per camera (--port given {} times) needs --seq DIR: a                          sequence with that many cameras",
                        port.port.len()
                    );
                };
                if camera_index.is_some() {
                    bail!("--camera-index picks the one camera of a single board; with one --port per camera leave it out");
                }
                let mut options = StereoOptions::new(port.port);
                options.baud = port.baud;
                options.reply_timeout = cli_values::duration(port.reply_timeout);
                options.tracker = tracker;
                options.progress = progress && !quiet;
                let summary = stream_stereo(&seq, &out, &options)?;
                print!("{summary}");
                if summary.frames == summary.lost_frames {
                    bail!("every frame was lost: no board measured the hand");
                }
                return Ok(());
            }
            let port_path = port.port.first().cloned().unwrap_or_default();
            let mut options = StreamOptions::new(&port_path)
                .baud(port.baud)
                .reply_timeout(cli_values::duration(port.reply_timeout))
                .camera_index(camera_index)
                .progress(progress && !quiet);
            options.tracker = tracker;
            let summary = match (seq, camera, setup) {
                (Some(seq), None, _) => stream_sequence(&seq, &out, &options)?,
                (None, Some(camera), Some(setup)) => {
                    stream_camera(&camera, &setup, frames, &out, &options)?
                }
                _ => bail!("give --seq DIR, or --camera /dev/videoN with --setup FILE"),
            };
            println!("{summary}");
            summary.ensure_some_tracked()?;
        }
        Command::Listen {
            port,
            json,
            forward,
            smooth,
            min_cutoff,
            beta,
            beta_rad,
            d_cutoff,
            setup,
            camera_index,
            states,
            seconds,
        } => {
            let mut options = ListenOptions::default();
            options.json = json;
            options.forward = forward
                .iter()
                .map(|url| parse_forward(url))
                .collect::<Result<_>>()?;
            options.smoothing = match smooth {
                true => Some(Smoothing::new(min_cutoff, beta, beta_rad, d_cutoff)?),
                false => None,
            };
            options.setup = setup;
            options.camera_index = camera_index;
            options.states = states;
            options.duration = seconds.map(cli_values::duration);
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
        Command::Ui {
            port,
            baud,
            setup,
            udp,
            replay,
            states,
            fps,
            camera_index,
            bind,
            seconds,
        } => {
            let source = match (port, udp, replay) {
                (Some(port), None, None) => UiSource::Serial {
                    port,
                    baud,
                    setup,
                    camera_index,
                },
                (None, Some(addr), None) => UiSource::Udp(addr),
                (None, None, Some(seqdir)) => UiSource::Replay {
                    states: states.unwrap_or_else(|| seqdir.join("states.csv")),
                    seqdir,
                    camera: camera_index.unwrap_or(0),
                    fps,
                },
                _ => bail!("give one of --port TTY, --udp ADDR:PORT or --replay SEQDIR"),
            };
            let options = UiOptions {
                bind,
                source,
                duration: seconds.map(cli_values::duration),
            };
            run_ui(&options, &mut std::io::stdout())?;
        }
        Command::Bench(BenchCommand::Robustness(args)) => {
            let sweep = digiteyes_host::bench::robustness::run(&args)?;
            print!("{sweep}");
        }
        Command::Demo {
            frames,
            stereo,
            out,
            ui_seconds,
        } => {
            let sequence = if stereo {
                let frames = frames.unwrap_or(STEREO_DEMO_FRAMES);
                let result = run_stereo_demo(frames, &out, TrackerConfig::default(), progress)?;
                print!("{}", result.stream);
                for (i, board) in result.boards.iter().enumerate() {
                    println!("camera {i}'s {board}");
                }
                print!("{}", result.eval);
                result.sequence
            } else {
                let frames = frames.unwrap_or(DEMO_FRAMES);
                let result = run_demo(frames, &out, TrackerConfig::default(), progress)?;
                println!("{}", result.stream);
                println!("{}", result.board);
                print!("{}", result.eval);
                println!("{}", result.mouse);
                result.sequence
            };
            let dir = std::path::absolute(&sequence).unwrap_or(sequence);
            println!("run kept in {}", dir.display());
            println!();
            println!("report: {}", dir.join(REPORT_HTML).display());
            let interactive = std::io::stdin().is_terminal() && std::io::stdout().is_terminal();
            let serve = match ui_seconds {
                Some(s) if s > 0.0 => Some(Some(cli_values::duration(s))),
                Some(_) => None,
                None if interactive => Some(None),
                None => None,
            };
            match serve {
                Some(duration) => {
                    if duration.is_none() {
                        println!("(serving the UI, a replay of this run; Ctrl-C stops it)");
                    }
                    serve_demo_ui(&dir, duration, &mut std::io::stdout())?;
                }
                None => {
                    // The command as this very binary, so it runs from `cargo run` too.
                    let exe = std::env::current_exe()
                        .map_or_else(|_| "digiteyes".into(), |p| p.display().to_string());
                    println!(
                        "UI: {exe} ui --replay {}   then open http://{DEFAULT_BIND}/",
                        dir.display()
                    );
                }
            }
        }
    }
    Ok(())
}

/// `digiteyes eval ... | head` closes the pipe early; Rust ignores SIGPIPE, so the next
/// `println!` panics. Like any Unix tool, end quietly instead (exit status 141, as a process
/// killed by SIGPIPE reports in a shell); every other panic is reported as before.
fn quiet_on_closed_pipe() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let message = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        if message.starts_with("failed printing to stdout") && message.contains("Broken pipe") {
            std::process::exit(141);
        }
        default(info);
    }));
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
