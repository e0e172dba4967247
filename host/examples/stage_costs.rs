//! Runs the tracker over a fixed number of frames and iterations, for instruction counting
//! under callgrind (`scripts/bench-instructions` drives it).
//!
//! ```text
//! cargo run --release -p digiteyes-host --example stage_costs -- fullhand-mono /tmp/seq
//! valgrind --tool=callgrind --toggle-collect='digiteyes_core::tracker::Tracker::track' \
//!     target/release/examples/stage_costs fullhand-mono /tmp/seq
//! ```
//!
//! The tracker starts at the truth of frame 0 and tracks frames 1..=FRAMES. By default
//! every frame runs exactly ITERATIONS iterations (convergence test off), so the cost of
//! `Tracker::track` divided by the iterations printed is the cost of one iteration; with
//! `--converge` the default stopping rule applies and the cost per frame is the figure.
//! If SEQ_DIR holds no sequence (or too few frames), SCENARIO is rendered into it first
//! (seed 1); nothing before or after the `track` calls is counted with `--toggle-collect`.
//!
//! `--slices`, `--window` and `--residual` cost other tracker configurations; the worst
//! joint-angle and translation errors against `truth.csv` show what a configuration costs in
//! accuracy. Prints one line of `key=value` pairs for the script to read.

#[path = "common/overrides.rs"]
mod overrides;
#[path = "../benches/support/mod.rs"]
mod support;

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{ensure, Result};
use clap::Parser;
use digiteyes_core::estimator::ResidualKind;
use digiteyes_host::TrackerConfig;

use support::{render_if_missing, Case, Stages};

#[derive(Parser)]
#[command(about = "Track a fixed number of frames x iterations, for callgrind")]
struct Args {
    /// Scenario rendered into SEQ_DIR if it holds no sequence yet (mouse, fullhand-mono, ...).
    scenario: String,
    /// Sequence folder.
    seq_dir: PathBuf,
    /// Frames tracked (1..=FRAMES; frame 0 is the start).
    #[arg(long, default_value_t = 4)]
    frames: usize,
    /// Iterations per frame.
    #[arg(long, default_value_t = TrackerConfig::default().iterations)]
    iterations: u8,
    /// Stop iterating at convergence (the tracker's default rule) instead of running all.
    #[arg(long)]
    converge: bool,
    /// Slices per link (default: the tracker's), to cost a configuration.
    #[arg(long)]
    slices: Option<u8>,
    /// Search window along each slice (px; default: the tracker's).
    #[arg(long)]
    window: Option<u8>,
    /// Residual form (default: the tracker's).
    #[arg(long, value_enum)]
    residual: Option<Residual>,
    /// The slice search's edge-direction limit (degrees; 90: every edge kept; default: the
    /// tracker's), to cost the test.
    #[arg(long)]
    edge_angle_deg: Option<f32>,
    #[command(flatten)]
    tracker: overrides::TrackerOverrides,
    /// The thesis' plain loop: no motion model, no silhouette check (the cost before them).
    #[arg(long)]
    plain: bool,
}

/// The estimator's residual forms, as `--residual` spells them.
#[derive(Clone, Copy, clap::ValueEnum)]
enum Residual {
    /// One row per edge point.
    EdgePoints,
    /// One row per slice (the midpoint of paired edges).
    AxisPoints,
    /// Two rows per link: the model axis' ends against the fitted axis line (Eq. 2.17).
    AxisLines,
}

fn main() -> Result<()> {
    let args = Args::parse();
    ensure!(args.frames >= 1, "track at least one frame");
    render_if_missing(&args.scenario, &args.seq_dir, args.frames + 1)?;
    let case = Case::load(&args.seq_dir, Some(args.frames + 1))?;

    let mut config = TrackerConfig::default();
    config.iterations = args.iterations;
    if args.plain {
        config.motion = digiteyes_core::motion::MotionConfig::PLAIN;
        config.silhouette_grid = 0;
        config.lost_silhouette_drop = 0.0;
    }
    if !args.converge {
        config.converged_rad = 0.0;
        config.converged_mm = 0.0;
    }
    if let Some(slices) = args.slices {
        config.features.slices_per_link = slices;
    }
    if let Some(degrees) = args.edge_angle_deg {
        config.features.max_edge_angle_rad = degrees.to_radians();
    }
    args.tracker.apply(&mut config);
    if let Some(window) = args.window {
        config.features.window_px = window;
    }
    if let Some(residual) = args.residual {
        config.estimator.residual = match residual {
            Residual::EdgePoints => ResidualKind::EdgePoints,
            Residual::AxisPoints => ResidualKind::AxisPoints,
            Residual::AxisLines => ResidualKind::AxisLines,
        };
    }
    let truth = case.sequence.read_truth().ok();
    let mut tracker = case.tracker(config)?;

    let (mut iterations, mut lost, mut found, mut rows) = (0u64, 0u32, 0u64, 0u64);
    let mut rms = 0.0f64;
    // Worst error against truth.csv over the tracked frames: joint angles (deg), translation (mm).
    let (mut worst_deg, mut worst_mm) = (0.0f64, 0.0f64);
    let mut wall = Duration::ZERO;
    for k in 1..=args.frames {
        let frames = case.views(k);
        let t0 = Instant::now();
        let report = tracker.track(&frames)?;
        wall += t0.elapsed();
        iterations += u64::from(report.iterations);
        lost += u32::from(report.lost);
        found += u64::from(report.features_found);
        rms += f64::from(report.rms_px);
        // Rows of one iteration at the frame's result, stage by stage (outside `track`, so
        // not counted): the residual rows the estimator stacks per iteration.
        let state = tracker.state().to_vec();
        if let Some(truth) = truth.as_ref().and_then(|t| t.rows.get(k)) {
            for &i in &case.sequence.free_states() {
                let e = (f64::from(state[i]) - truth[i]).abs();
                match i {
                    4..=6 => worst_mm = worst_mm.max(e),
                    7.. => worst_deg = worst_deg.max(e.to_degrees()),
                    _ => {}
                }
            }
        }
        let mut stages = Stages::new(&tracker, &state);
        rows += u64::from(stages.iterate(&state, &frames).0);
    }
    let n = args.frames as f64;
    println!(
        "stage_costs scenario={} cameras={} frames={} iterations={} rows_per_iteration={:.1} \
         features_found={:.1} lost={} mean_rms_px={:.3} worst_joint_deg={:.3} worst_mm={:.3} \
         wall_us_per_iteration={:.1}",
        args.scenario,
        case.cameras().len(),
        args.frames,
        iterations,
        rows as f64 / n,
        found as f64 / n,
        lost,
        rms / n,
        worst_deg,
        worst_mm,
        wall.as_secs_f64() * 1e6 / iterations.max(1) as f64,
    );
    Ok(())
}
