//! `digiteyes`: render, track and evaluate hand sequences. A thin layer over the library.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;
use clap::{Parser, Subcommand};
use digiteyes_host::demo::run_demo;
use digiteyes_host::scenarios::{render_scenario, RenderOptions, DEFAULT_FRAMES, NAMES};
use digiteyes_host::{evaluate, track_sequence, TrackerConfig};

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
        #[arg(long, value_name = "WxH", value_parser = parse_size)]
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
    /// Render the `mouse` scenario, track it and evaluate it.
    Demo {
        /// Number of frames.
        #[arg(long, default_value_t = DEFAULT_FRAMES)]
        frames: usize,
        /// Keep the sequence (and states.csv) in this folder instead of a temporary one.
        #[arg(long, value_name = "DIR")]
        keep: Option<PathBuf>,
    },
}

fn parse_size(text: &str) -> Result<(u32, u32), String> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("`{text}` is not WxH, e.g. 320x240"))?;
    let parse = |s: &str| {
        s.trim()
            .parse::<u32>()
            .ok()
            .filter(|&v| v > 0)
            .ok_or_else(|| format!("`{s}` is not a positive number of pixels"))
    };
    Ok((parse(w)?, parse(h)?))
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
        Command::Demo { frames, keep } => {
            let result = run_demo(frames, keep.as_deref(), TrackerConfig::default(), progress)?;
            println!("{}", result.track);
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
