//! Does tracking backward tell a wrong track from a right one? (After Kalal, Mikolajczyk and
//! Matas' forward–backward error, 2010.) For each seed `bench robustness --keep DIR` kept,
//! every `--every` frames whose last `--window` frames the kept run claimed (not flagged
//! lost), the tracker starts from the kept state of frame k with no velocity and tracks frames
//! k−1, k−2, …, k−W backward; the *forward–backward error* is the mean fingertip distance (px,
//! over tips and cameras) between where that lands and the kept state of frame k−W. A track
//! that went wrong within the window cannot take its error back (the slices do not pull an
//! error back), so it lands off the state it left; a right one lands on it.
//!
//! Printed per group (mono, stereo): the error's distribution on checks whose frame k is
//! truly lost (the benchmark's definition) and on right ones, the area under the curve, and
//! at each bar the share of each flagged; and per onset of a truly-lost run of claimed frames
//! (not flagged), whether a check within its first `--window` frames is over each bar.
//!
//! ```text
//! cargo run --release -p digiteyes-host --example fb_check -- /tmp/kv_15761 --window 8 --every 8
//! ```

use anyhow::{Context, Result};
use clap::Parser;
use digiteyes_core::tracker::Tracker;
use digiteyes_host::bench::robustness::{judge_frame, TRULY_LOST_TIP_PX_AT_640};
use digiteyes_host::eval::{compare, evaluate, stats};
use digiteyes_host::parallel;
use digiteyes_host::sequence::{read_states, Sequence};
use digiteyes_host::sequence_tracker;
use std::path::PathBuf;

#[path = "common/kept.rs"]
mod kept;
#[path = "common/roc.rs"]
mod roc;

#[derive(Parser)]
struct Args {
    /// Folders of kept seeds.
    dirs: Vec<PathBuf>,
    /// Frames tracked backward.
    #[arg(long, default_value_t = 8)]
    window: usize,
    /// A check every this many frames.
    #[arg(long, default_value_t = 8)]
    every: usize,
    /// The backward tracker's parameters, as `kept_ab` takes them (prediction always off).
    #[arg(long, default_value = "default")]
    set: String,
    #[arg(long, default_value_t = 2)]
    jobs: usize,
}

/// Bars on the forward–backward error (px at 640 px wide).
const BARS_PX: [f64; 6] = [2.0, 3.0, 5.0, 8.0, 12.0, 20.0];

/// One check: its forward–backward error (px) and whether frame k is truly lost.
struct Check {
    frame: usize,
    fb_px: f64,
    truly: bool,
}

/// One seed's checks, and the first frames of its truly-lost runs of claimed frames.
struct SeedChecks {
    stereo: bool,
    checks: Vec<Check>,
    onsets: Vec<usize>,
}

fn main() -> Result<()> {
    let args = Args::parse();
    let mut seeds = Vec::new();
    for dir in &args.dirs {
        seeds.extend(kept::seed_dirs(dir)?);
    }
    let results = parallel::map(&seeds, args.jobs, |dir| {
        check_seed(dir, &args).with_context(|| format!("{}", dir.display()))
    });
    let mut groups: [Vec<SeedChecks>; 2] = [Vec::new(), Vec::new()];
    for r in results {
        let r = r?;
        groups[usize::from(r.stereo)].push(r);
    }
    for (name, g) in ["mono", "stereo"].iter().zip(&groups) {
        summarise(name, g, args.window);
    }
    Ok(())
}

fn check_seed(dir: &std::path::Path, args: &Args) -> Result<SeedChecks> {
    let seed = kept::seed_of(dir);
    let sequence = Sequence::open(dir)?;
    let truth = sequence.read_truth()?;
    let states_path = dir.join("states.csv");
    let table = read_states(&states_path, sequence.n_states())?;
    let report = evaluate(dir, &states_path)?;
    let lost = table.extra("lost").unwrap_or_default();
    let claimed: Vec<bool> = (0..table.rows.len())
        .map(|k| lost.get(k).is_some_and(|&v| v == 0.0))
        .collect();
    let width = sequence.cameras.first().map_or(640, |c| c.width);
    let scale = f64::from(width) / 640.0;
    let limit = TRULY_LOST_TIP_PX_AT_640 * scale;
    let truly: Vec<bool> = (0..table.rows.len().min(truth.rows.len()))
        .map(|k| judge_frame(&table.rows[k], &truth.rows[k], &report, k, limit).1)
        .collect();
    let onsets = (0..truly.len())
        .filter(|&k| truly[k] && claimed[k] && (k == 0 || !(truly[k - 1] && claimed[k - 1])))
        .collect();
    let kept_states = kept::f32s(&table.rows);
    let (mut config, _) = kept::variant(&args.set)?;
    config.predict = false;
    let mut tracker = sequence_tracker(&sequence, config)?;
    let names: Vec<String> = (0..sequence.cameras.len())
        .map(|c| sequence.camera_name(c))
        .collect();
    let free = sequence.free_states();
    let w = args.window.max(1);
    let mut checks = Vec::new();
    for k in (w..truly.len()).step_by(args.every.max(1)) {
        if !claimed[k - w..=k].iter().all(|&c| c) {
            continue;
        }
        start_at(&mut tracker, &kept_states[k])?;
        for j in (k - w..k).rev() {
            let images = kept::read_instant(&sequence, j)?;
            let frames = kept::views(&images)?;
            tracker.track(&frames).context("track")?;
        }
        let back: Vec<f64> = tracker.state().iter().map(|&v| f64::from(v)).collect();
        let fb = compare(
            &sequence.model,
            &sequence.cameras,
            &names,
            &free,
            &[table.rows[k - w].clone()],
            &[back],
        )?;
        checks.push(Check {
            frame: k,
            fb_px: fb.fingertip_mean_by_frame[0] / scale,
            truly: truly[k],
        });
    }
    Ok(SeedChecks {
        stereo: seed.is_multiple_of(2),
        checks,
        onsets,
    })
}

fn start_at(tracker: &mut Tracker, state: &[f32]) -> Result<()> {
    let mut memory = tracker.memory();
    memory.state = heapless::Vec::from_slice(state).map_err(|_| anyhow::anyhow!("states"))?;
    memory.velocity = None;
    tracker.restore(&memory)?;
    Ok(())
}

fn summarise(name: &str, seeds: &[SeedChecks], window: usize) {
    let wrong: Vec<f64> = seeds
        .iter()
        .flat_map(|s| s.checks.iter().filter(|c| c.truly).map(|c| c.fb_px))
        .collect();
    let right: Vec<f64> = seeds
        .iter()
        .flat_map(|s| s.checks.iter().filter(|c| !c.truly).map(|c| c.fb_px))
        .collect();
    if wrong.is_empty() || right.is_empty() {
        println!(
            "{name}: too few checks ({} wrong, {} right)",
            wrong.len(),
            right.len()
        );
        return;
    }
    let spread = |v: &[f64]| {
        format!(
            "median {:.1}, p10 {:.1}, p90 {:.1}",
            stats::percentile(v, 0.5),
            stats::percentile(v, 0.1),
            stats::percentile(v, 0.9)
        )
    };
    // The area under the curve: the chance a wrong check's error exceeds a right one's.
    let auc = roc::auc(&wrong, &right);
    println!(
        "{name}: {} seeds; checks truly lost {} (fb px {}), right {} (fb px {}); AUC {auc:.3}",
        seeds.len(),
        wrong.len(),
        spread(&wrong),
        right.len(),
        spread(&right)
    );
    let onsets: usize = seeds.iter().map(|s| s.onsets.len()).sum();
    for bar in BARS_PX {
        let share = |v: &[f64]| v.iter().filter(|&&x| x > bar).count() as f64 / v.len() as f64;
        // An onset is caught when a check within its first `window` frames is over the bar.
        let caught: usize = seeds
            .iter()
            .map(|s| {
                s.onsets
                    .iter()
                    .filter(|&&o| {
                        s.checks
                            .iter()
                            .any(|c| c.frame >= o && c.frame < o + window && c.fb_px > bar)
                    })
                    .count()
            })
            .sum();
        let seeds_false = seeds
            .iter()
            .filter(|s| s.checks.iter().any(|c| !c.truly && c.fb_px > bar))
            .count();
        println!(
            "  bar {bar:4.1} px: wrong checks over it {:5.1} %, right {:5.1} % (seeds with a false one {seeds_false}); onsets caught within {window} frames {caught} of {onsets}",
            100.0 * share(&wrong),
            100.0 * share(&right),
        );
    }
}
