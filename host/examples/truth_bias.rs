//! Where a track goes wrong, measured against the truth on the sequences that
//! `bench robustness --keep DIR` kept (each `seedNNNN/` with the tracker's `states.csv`).
//!
//! Modes (`--start`):
//! - `truth`: every sampled frame is tracked alone from its own true state (the bias of the
//!   measurement: how far the image's features pull the truth);
//! - `prev`: ... from the previous frame's true state, no motion (one frame's true motion);
//! - `prev-velocity`: ... from the previous frame's true state moving as the truth moved;
//! - `contract`: ... from the truth carrying the kept run's error of the frame before: does
//!   one frame of tracking shrink an error the track has (errors before and after, per tip);
//! - `sequential`: the whole sequence, from frame 1's truth, with `--oracle` states set to the
//!   truth before every frame (e.g. the palm's `0,1,2,3,4,5,6`: is the palm what is lost?),
//!   and with `--oracle-unseen N` every joint no camera sees (is what it cannot see lost?);
//! - `settle`: the truth with one finger's joints pushed `--push-rad` off (0: the truth
//!   itself), the same frame tracked `--passes` times, each from where the last left it:
//!   where a static frame's iteration settles, and whether it pulls a finger back;
//! - `census`: no tracking; per seed, the frame where the kept run's track life ends and each
//!   fingertip's error there (which fingers are lost).
//!
//! Errors are mean fingertip reprojection errors (px) over the tips and cameras, as `eval`
//! has them. Each seed's line also gives the palm's error along camera 0's optical axis (mm,
//! positive away from the camera): with one camera the depth its image shows only through
//! the hand's size (`docs/robustness.md`, "The sweep on the varied surface").
//!
//! ```text
//! digiteyes bench robustness --seeds 60 --frames 200 --keep /tmp/keep
//! cargo run --release -p digiteyes-host --example truth_bias -- /tmp/keep --start truth
//! ```

use std::path::{Path, PathBuf};

#[path = "common/kept.rs"]
mod kept;
#[path = "common/seen.rs"]
mod seen;

use anyhow::{Context, Result};
use clap::Parser;
use digiteyes_core::config::MAX_STATES;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::{Shape, BASE_STATES};
use digiteyes_core::motion::PriorWeights;
use digiteyes_core::state::TRANSLATION;
use digiteyes_core::tracker::Tracker;
use digiteyes_host::eval::{compare, reprojection_error, stats, track_life, LOST_ERROR_PX};
use digiteyes_host::sequence::{read_states, Sequence};
use digiteyes_host::sequence_tracker;

#[derive(Parser)]
struct Args {
    /// A folder of kept seeds (`seedNNNN/`), as `bench robustness --keep` writes.
    dir: PathBuf,
    /// Where each tracked frame starts (see the module's documentation).
    #[arg(long, default_value = "truth")]
    start: String,
    /// Track every this many frames (not with `sequential`).
    #[arg(long, default_value_t = 10)]
    every: usize,
    /// Only seeds whose number has this parity (1: mono, 0: stereo).
    #[arg(long)]
    parity: Option<u64>,
    /// With `sequential`: these states are set to the truth before every frame.
    #[arg(long, value_delimiter = ',')]
    oracle: Vec<usize>,
    /// With `sequential`: also every joint that moves no link a camera sees at the frame's
    /// truth (`seen_bound`'s test, at least this many axis points) is set to that truth
    /// before the frame: the tracker is left only what the images can tell it.
    #[arg(long)]
    oracle_unseen: Option<usize>,
    /// With `settle`: how far each of one finger's joints is pushed off the truth (rad).
    #[arg(long, default_value_t = 0.15)]
    push_rad: f32,
    /// With `settle`: how many times the frame is tracked.
    #[arg(long, default_value_t = 10)]
    passes: usize,
    /// No prior toward the prediction: the images alone.
    #[arg(long)]
    no_prior: bool,
    /// The tracker's parameters: `default`, or overrides as `kept_ab` takes them
    /// (`window=12+tipw=0`).
    #[arg(long, default_value = "default")]
    set: String,
}

/// One seed's sequence, truth and kept run.
struct Seed {
    number: u64,
    sequence: Sequence,
    truth: Vec<Vec<f32>>,
    kept: Vec<Vec<f32>>,
}

fn open(dir: &Path) -> Result<Option<Seed>> {
    let Some(number) = dir
        .file_name()
        .and_then(|n| n.to_str())
        .and_then(|n| n.strip_prefix("seed"))
        .and_then(|n| n.parse().ok())
    else {
        return Ok(None);
    };
    let sequence = Sequence::open(dir)?;
    let truth = kept::f32s(&sequence.read_truth()?.rows);
    let kept = kept::f32s(&read_states(&dir.join("states.csv"), sequence.n_states())?.rows);
    Ok(Some(Seed {
        number,
        sequence,
        truth,
        kept,
    }))
}

/// Each fingertip's reprojection error (px) in each camera, tips in model order, as `eval`
/// measures it.
fn tip_errors(seed: &Seed, truth: &[f32], estimate: &[f32]) -> Result<Vec<f32>> {
    let model = &seed.sequence.model;
    let pt = Poses::compute(model, truth)?;
    let pe = Poses::compute(model, estimate)?;
    let tips: Vec<usize> = (0..model.links().len())
        .filter(|&i| matches!(model.links()[i].shape, Shape::Tip { .. }))
        .collect();
    Ok(seed
        .sequence
        .cameras
        .iter()
        .flat_map(|camera| {
            tips.iter()
                .map(|&i| reprojection_error(camera, &pt, &pe, i) as f32)
        })
        .collect())
}

/// The mean fingertip error (px) of `estimate` at frame `k`, as `eval` computes it.
fn tip_error(seed: &Seed, k: usize, estimate: &[f32]) -> Result<f64> {
    let seq = &seed.sequence;
    let names: Vec<String> = (0..seq.cameras.len()).map(|c| seq.camera_name(c)).collect();
    let to64 = |q: &[f32]| q.iter().map(|&v| f64::from(v)).collect::<Vec<f64>>();
    let report = compare(
        &seq.model,
        &seq.cameras,
        &names,
        &seq.free_states(),
        &[to64(&seed.truth[k])],
        &[to64(estimate)],
    )?;
    Ok(report.fingertip_mean_by_frame[0])
}

fn track_frame(tracker: &mut Tracker, seed: &Seed, k: usize) -> Result<()> {
    let seq = &seed.sequence;
    let images = kept::read_instant(seq, k)?;
    let frames = kept::views(&images).with_context(|| format!("frame {k}"))?;
    tracker.track(&frames).context("track")?;
    Ok(())
}

fn start_at(
    tracker: &mut Tracker,
    state: &[f32],
    velocity: Option<[f32; MAX_STATES]>,
) -> Result<()> {
    let mut memory = tracker.memory();
    memory.state = heapless::Vec::from_slice(state).map_err(|_| anyhow::anyhow!("states"))?;
    memory.velocity = velocity;
    tracker.restore(&memory)?;
    Ok(())
}

/// How far `estimate`'s palm lies beyond `truth`'s along camera 0's optical axis (mm): the
/// depth one camera sees only through the hand's size in its image.
fn palm_along_ray_mm(seed: &Seed, truth: &[f32], estimate: &[f32]) -> f64 {
    let axis = seed.sequence.cameras[0].r.row(2);
    TRANSLATION
        .enumerate()
        .map(|(i, s)| f64::from(axis[i]) * f64::from(estimate[s] - truth[s]))
        .sum()
}

/// The angle between the palm rotations of two states (deg): quaternion states 0..4.
fn palm_turn_deg(a: &[f32], b: &[f32]) -> f64 {
    let dot: f64 = (0..4).map(|i| f64::from(a[i]) * f64::from(b[i])).sum();
    let norm = |q: &[f32]| (0..4).map(|i| f64::from(q[i]).powi(2)).sum::<f64>().sqrt();
    let c = (dot / (norm(a) * norm(b)).max(1e-12)).abs().min(1.0);
    2.0 * c.acos().to_degrees()
}

/// Prints `label` with the median, 10th and 90th percentiles of `values` and `tail`; nothing
/// when there are no values.
fn print_spread(label: &str, values: &[f64], tail: &str) {
    if values.is_empty() {
        return;
    }
    println!(
        "{label} median {:.2}, p10 {:.2}, p90 {:.2}{tail}",
        stats::percentile(values, 0.5),
        stats::percentile(values, 0.1),
        stats::percentile(values, 0.9),
    );
}

fn fmt_tips(tips: &[f32]) -> String {
    tips.iter()
        .map(|e| format!("{e:.1}"))
        .collect::<Vec<_>>()
        .join(" ")
}

fn main() -> Result<()> {
    let args = Args::parse();
    let dirs = kept::seed_dirs(&args.dir)?;
    let mut all = Vec::new();
    let mut shrink = Vec::new();
    let mut all_passes = Vec::new();
    // Settle runs whose error grew over 3×: how far the palm turned (deg).
    let mut grown_turns = Vec::new();
    // Every tracked frame's palm error along camera 0's optical axis (mm, + away from it).
    let mut all_along_ray = Vec::new();
    for dir in dirs {
        let Some(seed) = open(&dir)? else { continue };
        if args.parity.is_some_and(|p| seed.number % 2 != p) {
            continue;
        }
        let cams = seed.sequence.cameras.len();
        if args.start == "census" {
            let errors: Vec<f64> = (0..seed.truth.len())
                .map(|k| tip_error(&seed, k, &seed.kept[k]))
                .collect::<Result<_>>()?;
            let life = track_life(&errors);
            let end = (life * errors.len() as f64).round() as usize;
            if end < errors.len() {
                let tips = tip_errors(&seed, &seed.truth[end], &seed.kept[end])?;
                let wrong = tips.iter().filter(|&&e| e > LOST_ERROR_PX as f32).count();
                println!(
                    "seed {} cams {cams} life {life:.2} ends at frame {end}: tips over {LOST_ERROR_PX} px {wrong} of {}: {}",
                    seed.number,
                    tips.len(),
                    fmt_tips(&tips)
                );
                all.push(wrong as f64);
            }
            continue;
        }
        let (mut config, _) = kept::variant(&args.set)?;
        if args.no_prior {
            config.motion.prior = PriorWeights::OFF;
        }
        let mut tracker = sequence_tracker(&seed.sequence, config)?;
        let sequential = args.start == "sequential";
        let step = if sequential { 1 } else { args.every.max(1) };
        if sequential {
            start_at(&mut tracker, &seed.truth[1], None)?;
        }
        let mut errors = Vec::new();
        let mut along_ray = Vec::new();
        for k in (2..seed.truth.len()).step_by(step) {
            let (t0, t1) = (&seed.truth[k - 1], &seed.truth[k]);
            match args.start.as_str() {
                "sequential" => {
                    let mut q = tracker.state().to_vec();
                    for &i in &args.oracle {
                        if let (Some(v), Some(t)) = (q.get_mut(i), t0.get(i)) {
                            *v = *t;
                        }
                    }
                    if let Some(points) = args.oracle_unseen {
                        let poses = Poses::compute(&seed.sequence.model, t1)?;
                        let seen = seen::joints(&seed.sequence, &poses, points);
                        for (i, v) in q.iter_mut().enumerate() {
                            if i >= BASE_STATES && !seen[i] {
                                *v = t1[i];
                            }
                        }
                    }
                    let memory = tracker.memory();
                    start_at(&mut tracker, &q, memory.velocity)?;
                }
                "truth" => start_at(&mut tracker, t1, None)?,
                "prev" => start_at(&mut tracker, t0, None)?,
                "prev-velocity" => {
                    let mut velocity = [0.0f32; MAX_STATES];
                    for (v, (a, b)) in velocity.iter_mut().zip(seed.truth[k - 2].iter().zip(t0)) {
                        *v = b - a;
                    }
                    start_at(&mut tracker, t0, Some(velocity))?;
                }
                "settle" => {
                    // The truth with one finger's joints pushed off, the same frame tracked
                    // again and again from where the last pass left it.
                    let fingers =
                        digiteyes_core::hypotheses::fingers::Fingers::of(&seed.sequence.model);
                    let f = (k / step) % fingers.count();
                    let mut start = t1.to_vec();
                    for (s, v) in start.iter_mut().enumerate() {
                        if fingers.contains(f, s) {
                            let sign = if (s + k) % 2 == 0 { 1.0 } else { -1.0 };
                            *v = digiteyes_core::state::clamp_to_limit(
                                &seed.sequence.model,
                                s,
                                *v + sign * args.push_rad,
                            );
                        }
                    }
                    let before = tip_error(&seed, k, &start)?;
                    let mut trace = vec![before];
                    let mut q = start;
                    for _ in 0..args.passes {
                        start_at(&mut tracker, &q, None)?;
                        track_frame(&mut tracker, &seed, k)?;
                        q = tracker.state().to_vec();
                        trace.push(tip_error(&seed, k, &q)?);
                    }
                    let turned = palm_turn_deg(&q, t1);
                    if before > 1.0 && trace[trace.len() - 1] > 3.0 * before {
                        grown_turns.push(turned);
                    }
                    println!(
                        "  seed {} frame {k} finger {f}, palm turned {turned:.1} deg: {}",
                        seed.number,
                        trace
                            .iter()
                            .map(|e| format!("{e:.1}"))
                            .collect::<Vec<_>>()
                            .join(" ")
                    );
                    if before > 1.0 {
                        shrink.push(trace[1] / before);
                        all_passes.push(trace[trace.len() - 1] / before);
                    }
                    errors.push(trace[trace.len() - 1]);
                    continue;
                }
                "contract" => {
                    let start: Vec<f32> = (0..t1.len())
                        .map(|i| t1[i] + seed.kept[k - 1][i] - t0[i])
                        .collect();
                    let before = tip_error(&seed, k, &start)?;
                    start_at(&mut tracker, &start, None)?;
                    track_frame(&mut tracker, &seed, k)?;
                    let after = tip_error(&seed, k, tracker.state())?;
                    errors.push(after);
                    if before > 2.0 && before < 30.0 {
                        shrink.push(after / before);
                        println!(
                            "  seed {} frame {k}: before {before:.1} after {after:.1}; tips after {}",
                            seed.number,
                            fmt_tips(&tip_errors(&seed, t1, tracker.state())?)
                        );
                    }
                    continue;
                }
                other => anyhow::bail!("unknown --start {other}"),
            }
            track_frame(&mut tracker, &seed, k)?;
            errors.push(tip_error(&seed, k, tracker.state())?);
            along_ray.push(palm_along_ray_mm(&seed, t1, tracker.state()));
        }
        let over = errors.iter().filter(|&&e| e > LOST_ERROR_PX).count() as f64;
        println!(
            "seed {} cams {cams} median {:.1} p90 {:.1} max {:.1} over {LOST_ERROR_PX} px {:.2} life {:.2}; palm along camera 0's ray median {:+.1} mm, p10 {:+.1}, p90 {:+.1}",
            seed.number,
            stats::percentile(&errors, 0.5),
            stats::percentile(&errors, 0.9),
            stats::percentile(&errors, 1.0),
            over / errors.len().max(1) as f64,
            track_life(&errors),
            stats::percentile(&along_ray, 0.5),
            stats::percentile(&along_ray, 0.1),
            stats::percentile(&along_ray, 0.9),
        );
        all_along_ray.extend(along_ray);
        all.extend(errors);
    }
    if args.start == "census" {
        println!(
            "seeds whose life ended: {}; tips over {LOST_ERROR_PX} px there: median {:.0}",
            all.len(),
            stats::percentile(&all, 0.5)
        );
        return Ok(());
    }
    let over = all.iter().filter(|&&e| e > LOST_ERROR_PX).count() as f64;
    println!(
        "all: {} frames, median {:.2} px, p75 {:.2}, p90 {:.2}, over {LOST_ERROR_PX} px {:.3}",
        all.len(),
        stats::percentile(&all, 0.5),
        stats::percentile(&all, 0.75),
        stats::percentile(&all, 0.9),
        over / all.len().max(1) as f64
    );
    print_spread("after all passes / before:", &all_passes, "");
    print_spread(
        "palm along camera 0's ray (mm, + away from it):",
        &all_along_ray,
        "",
    );
    print_spread(
        &format!(
            "runs grown over 3x: {}; palm turned (deg)",
            grown_turns.len()
        ),
        &grown_turns,
        "",
    );
    print_spread(
        "contraction (after / before, errors of 2-30 px):",
        &shrink,
        &format!(" over {} frames", shrink.len()),
    );
    Ok(())
}
