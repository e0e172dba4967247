//! When is the lost flag wrong? For each seed `bench robustness --keep DIR` kept, reads the
//! states the benchmark wrote (or `--states NAME`) and judges every frame as the benchmark
//! does, then splits the frames flagged but not truly lost (false alarms) and those truly lost
//! but not flagged (misses) by the frame's status, by how many frames the track had been
//! claimed in a row before (a false alarm early in a claim is the watch's reference at work),
//! and by the frame's mean fingertip error against the truly-lost limit.
//!
//! ```text
//! cargo run --release -p digiteyes-host --example flag_timing -- /tmp/kv_15761 /tmp/kv_15821
//! ```

use anyhow::Result;
use clap::Parser;
use digiteyes_host::bench::robustness::{judge_frame, TRULY_LOST_TIP_PX_AT_640};
use digiteyes_host::eval::evaluate;
use digiteyes_host::sequence::status::Status;
use digiteyes_host::sequence::{read_states, Sequence};
use std::path::PathBuf;

#[path = "common/kept.rs"]
mod kept;

#[derive(Parser)]
struct Args {
    /// Folders of kept seeds.
    dirs: Vec<PathBuf>,
    /// The states file in each seed's folder.
    #[arg(long, default_value = "states.csv")]
    states: String,
}

/// Counts of one group (mono or stereo).
#[derive(Default)]
struct Group {
    frames: usize,
    true_flags: usize,
    /// False alarms by status: searching, lost, tracking (a confirm frame not yet claimed).
    false_by_status: [usize; 3],
    /// False alarms (status lost) by the claimed run before them: < 8, 8–31, ≥ 32 frames.
    false_by_run: [usize; 3],
    /// False alarms by tip error as a share of the limit: < 0.5, 0.5–0.75, ≥ 0.75.
    false_by_tip: [usize; 3],
    /// Misses by tip error as a multiple of the limit: < 1.5, 1.5–3, ≥ 3 (or the palm alone).
    miss_by_tip: [usize; 3],
    /// Seeds with a false alarm within their first claimed run.
    seeds_false_in_first_run: usize,
    seeds: usize,
}

fn main() -> Result<()> {
    let args = Args::parse();
    let mut groups = [Group::default(), Group::default()];
    for dir in &args.dirs {
        for seed_dir in kept::seed_dirs(dir)? {
            let seed = kept::seed_of(&seed_dir);
            let sequence = Sequence::open(&seed_dir)?;
            let truth = sequence.read_truth()?;
            let states_path = seed_dir.join(&args.states);
            let table = read_states(&states_path, sequence.n_states())?;
            let report = evaluate(&seed_dir, &states_path)?;
            let lost = table.extra("lost").unwrap_or_default();
            let statuses = table.status.clone().unwrap_or_default();
            let width = sequence.cameras.first().map_or(640, |c| c.width);
            let limit = TRULY_LOST_TIP_PX_AT_640 * f64::from(width) / 640.0;
            let g = &mut groups[usize::from(seed.is_multiple_of(2))];
            g.seeds += 1;
            let mut run = 0usize;
            let mut run_before_streak = 0usize;
            let mut starts = Vec::new();
            let mut claims_before = 0usize;
            let mut false_in_first = false;
            for (k, (estimate, true_state)) in table.rows.iter().zip(&truth.rows).enumerate() {
                let (_, truly) = judge_frame(estimate, true_state, &report, k, limit);
                let flagged = lost.get(k).is_some_and(|&v| v != 0.0);
                let status = statuses.get(k).copied().flatten();
                let tip = report
                    .fingertip_mean_by_frame
                    .get(k)
                    .copied()
                    .unwrap_or(f64::NAN);
                g.frames += 1;
                match (flagged, truly) {
                    (true, true) => g.true_flags += 1,
                    (true, false) => {
                        if status == Some(Status::Searching) {
                            g.false_by_status[0] += 1;
                        } else if status == Some(Status::Tracking) {
                            g.false_by_status[2] += 1;
                        } else {
                            g.false_by_status[1] += 1;
                            if run > 0 {
                                run_before_streak = run;
                                starts.push(k);
                            }
                            g.false_by_run[bin(run_before_streak as f64, [8.0, 32.0])] += 1;
                            if claims_before == 0 {
                                false_in_first = true;
                            }
                        }
                        g.false_by_tip[bin(tip / limit, [0.5, 0.75])] += 1;
                    }
                    (false, true) => {
                        let ratio = if tip.is_finite() { tip / limit } else { 9.0 };
                        g.miss_by_tip[bin(ratio, [1.5, 3.0])] += 1;
                    }
                    (false, false) => {}
                }
                if status == Some(Status::Tracking) {
                    run += 1;
                } else if run > 0 {
                    claims_before += 1;
                    run = 0;
                }
            }
            g.seeds_false_in_first_run += usize::from(false_in_first);
            if !starts.is_empty() {
                println!("seed {seed}: false alarms start at frames {starts:?}");
            }
        }
    }
    for (name, g) in ["mono", "stereo"].iter().zip(&groups) {
        let false_alarms: usize = g.false_by_status.iter().sum();
        let misses: usize = g.miss_by_tip.iter().sum();
        println!(
            "{name}: {} seeds, {} frames; flagged and lost {}, false alarms {false_alarms} \
             (searching {}, lost {}, undecided {}), misses {misses}",
            g.seeds,
            g.frames,
            g.true_flags,
            g.false_by_status[0],
            g.false_by_status[1],
            g.false_by_status[2]
        );
        println!(
            "  false alarms (status lost) after a claimed run (before their streak) of <8 / 8-31 / >=32 frames: {:?}; \
             seeds with one in their first claimed run: {}",
            g.false_by_run, g.seeds_false_in_first_run
        );
        println!(
            "  false alarms by tip error / limit <0.5 / 0.5-0.75 / >=0.75: {:?}",
            g.false_by_tip
        );
        println!(
            "  misses by tip error / limit <1.5 / 1.5-3 / >=3: {:?}",
            g.miss_by_tip
        );
    }
    Ok(())
}

/// 0, 1 or 2: `x` under the first edge, under the second, or at or over it.
fn bin(x: f64, edges: [f64; 2]) -> usize {
    if x < edges[0] {
        0
    } else if x < edges[1] {
        1
    } else {
        2
    }
}
