//! A/B of tracker settings on the sequences `bench robustness --keep DIR` kept: tracks every
//! seed with each variant and prints the track-life distribution per group. A variant is
//! `default` or `key=value` overrides joined by `+` (keys: `pj`, `pt`, `pq` the prior's
//! weights, `sj`, `st`, `sq` the conditioning; `iters` (the tracker's Gauss–Newton iterations),
//! `liters` (a search leaf's or local start's), `predict`, `window`, `margin` (the narrowed
//! windows' margin, px), `contrast` (the smallest edge), `slices`, `palm`,
//! `palmw`, `residual` (0 edge points, 1 axis lines, 2 axis points), `widthw`, `widthw1`
//! and `widthws` (the width rows' weight with two cameras, with one, and for a link only one
//! of two sees), `tipw`, `fvf`, `outer`, `knuckle`
//! (0: no knuckle tips), `bounds` (0: the plain step); `angle` the edge-direction limit in degrees (90: off); `huber`, `tukey` the robust
//! kernel's px; `k`, `s`, `spawn`, `step`, `smem`, `switch` the hypotheses (their count, scoring
//! period, samples, their step in spread units, score memory, switch margin), `si`, `oi` (a
//! sample's and another hypothesis' iterations), `keepf` (0 / 1: fingers undone weighed),
//! `lo` (0 / 1: the others tracked light between scored frames); `csmem`, `cswitch` the confirm phase's score
//! memory and switch margin; `settle` the frames without the palm's position prior after an
//! acquisition; `cdepth1` one camera's confirm-phase depth share; `rival` the share of its offset that makes two hypotheses rival depths, `rivalm` the margin within which a rival leaves a confirm frame unclaimed (negative: all claimed); `cframes` its frames; `watch`
//! its period, `drop` its bar; `depth1` one camera's local depth share; `turn` the local
//! re-acquisition's palm turn (rad); `probation` the acceptance's probation drop, negative:
//! off; `budget` the search's evaluations a frame and camera; `pursue1` the searching frames
//! one camera pursues a refused leaf, 0: never); `shade` the shading refinement's period,
//! `shadegrid` its fit's lattice, `shadestep` its region's pixel step, `shademargin` its
//! margin, `shadefingers` its fingers a call, `shadecurl` and `shadesingle` its moves (0 / 1),
//! `shaderad` its first step (rad; then half and a quarter), `shadelevels` how many steps,
//! `shadecap` its residual's cap per pixel, grey levels; 0: none, `shadeclamp` the light's
//! term clamped at 0, 0 / 1); the region rows' `fill` (weight), `fillgrid`, `fillreach`,
//! `fillgather`, `fillmargin`, `core`, `corem`, `fillend` and `fillhidden` (the share at which
//! a hidden link's gap counts; `inf`: hidden links never take a bright sample).
//! Each group's row also gives its frames far from the hand and not flagged (`far`)
//! and the lost flag's precision and recall (`lostP`, `lostR`), as the benchmark counts them,
//! and the median share of frames held (`held50`, as `eval`'s frames held).
//! Every variant after the first is also compared with the first seed by seed (paired):
//! the mean change of track life, how many seeds gained or lost more than 5 points, the
//! two-sided sign test's p over those, and the mean change of the share of frames held (the
//! median of 30 seeds moves by 10–20 points between sweeps by chance alone; pairing the same
//! seeds sees far smaller effects).
//! With `--draws N` every variant is tracked N times under last-bit changes and each seed is
//! judged by its mean, so the first variant's luck on one run is not every comparison's.
//! For trying a change quickly; the benchmark itself is the judge.
//!
//! ```text
//! cargo run --release -p digiteyes-host --example kept_ab -- /tmp/keep default pj=500
//! cargo run --release -p digiteyes-host --example kept_ab -- /tmp/keep --draws 3 default k=2
//! ```

use anyhow::Result;
use clap::Parser;
use digiteyes_host::bench::robustness::{count_run, FrameCounts};
use digiteyes_host::eval::{evaluate, stats};
use digiteyes_host::parallel;
use digiteyes_host::track::{track_sequence_opts, TrackOptions};
use digiteyes_host::TrackerConfig;
use std::path::PathBuf;

#[path = "common/kept.rs"]
mod kept;
use kept::variant;

#[derive(Parser)]
struct Args {
    dir: PathBuf,
    /// More folders of kept seeds (seed numbers must not repeat).
    #[arg(long)]
    more: Vec<PathBuf>,
    /// Variants: `default`, or overrides such as `pj=500+mask=1+iters=12`.
    variants: Vec<String>,
    /// Only seeds whose number has this parity (1 mono, 0 stereo).
    #[arg(long)]
    parity: Option<u64>,
    #[arg(long, default_value_t = 2)]
    jobs: usize,
    /// Keep each run's states here, as `VARIANT/seedN.csv` (`track`'s output), to look at
    /// frame by frame.
    #[arg(long)]
    states_out: Option<PathBuf>,
    /// Track each variant this many times, draw `d` with the palm position prior's weight
    /// moved by `d` units in its last place, and judge each seed by its mean over the draws.
    /// A change in the last bit sends a track standing at a fork down the other branch, so one
    /// draw of the first variant is a reference with its own luck, shared by every comparison
    /// made against it (`docs/robustness.md`, "The sweep's null"); the per-draw means of each
    /// group are printed, to show that spread.
    #[arg(long, default_value_t = 1)]
    draws: u32,
}

fn main() -> Result<()> {
    let args = Args::parse();
    let mut paths = Vec::new();
    for dir in std::iter::once(&args.dir).chain(&args.more) {
        paths.extend(std::fs::read_dir(dir)?.filter_map(|e| e.ok().map(|e| e.path())));
    }
    let mut seeds: Vec<(u64, PathBuf)> = paths
        .into_iter()
        .filter(|p| p.join("sequence.json").exists())
        .filter_map(|p| {
            let n = p
                .file_name()?
                .to_str()?
                .trim_start_matches("seed")
                .parse()
                .ok()?;
            Some((n, p))
        })
        .filter(|(n, _)| args.parity.is_none_or(|p| n % 2 == p))
        .collect();
    seeds.sort();
    println!("variant group seeds life50 life10 ge95 held50 joint50 tip50 far lostP lostR lives");
    let mut first: Option<Vec<Run>> = None;
    for name in &args.variants {
        let (config, options) = variant(name)?;
        let mut draws: Vec<Vec<Row>> = Vec::new();
        for draw in 0..args.draws.max(1) {
            let mut config = config;
            let prior = &mut config.motion.prior.translation;
            *prior *= 1.0 + draw as f32 * f32::EPSILON;
            // The states of the first draw are the ones kept.
            let keep = if draw == 0 {
                args.states_out.as_ref()
            } else {
                None
            };
            draws.push(track_all(&seeds, args.jobs, name, config, &options, keep));
        }
        if draws.len() > 1 {
            print_draws(name, &draws);
        }
        let results = mean_of_draws(&draws);
        let lives: Vec<Run> = results.iter().map(|r| (r.0, r.1, r.5)).collect();
        match &first {
            None => first = Some(lives),
            Some(base) => paired(name, base, &lives),
        }
        for (group, parity) in [("mono", 1), ("stereo", 0)] {
            let g: Vec<_> = results.iter().filter(|r| r.0 % 2 == parity).collect();
            if g.is_empty() {
                continue;
            }
            let life: Vec<f64> = g.iter().map(|r| r.1).collect();
            let joint: Vec<f64> = g.iter().map(|r| r.2).collect();
            let tip: Vec<f64> = g.iter().map(|r| r.3).collect();
            let held: Vec<f64> = g.iter().map(|r| r.5).collect();
            let ge95 = life.iter().filter(|&&l| l >= 0.95).count() as f64 / life.len() as f64;
            let far: usize = g.iter().map(|r| r.4.far_unflagged).sum();
            let both: usize = g.iter().map(|r| r.4.flagged_and_lost).sum();
            let flagged: usize = both + g.iter().map(|r| r.4.flagged_only).sum::<usize>();
            let truly: usize = both + g.iter().map(|r| r.4.lost_only).sum::<usize>();
            let ratio = |a: usize, b: usize| if b == 0 { 1.0 } else { a as f64 / b as f64 };
            let (precision, recall) = (ratio(both, flagged), ratio(both, truly));
            let lives: Vec<String> = g
                .iter()
                .map(|r| format!("{}:{:.0}", r.0, 100.0 * r.1))
                .collect();
            println!(
                "{name} {group} {} {:.0}% {:.0}% {:.0}% {:.0}% {:.2} {:.2} {far} {precision:.2} {recall:.2} {}",
                g.len(),
                100.0 * stats::percentile(&life, 0.5),
                100.0 * stats::percentile(&life, 0.1),
                100.0 * ge95,
                100.0 * stats::percentile(&held, 0.5),
                stats::percentile(&joint, 0.5),
                stats::percentile(&tip, 0.5),
                lives.join(" ")
            );
        }
    }
    Ok(())
}

/// One seed tracked once: the seed, its track life, joint RMS (deg), mean fingertip error
/// (px), the benchmark's counts, and its share of frames held.
type Row = (u64, f64, f64, f64, FrameCounts, f64);

/// Every seed tracked under `config` and `options`; its states kept under `keep/name` if asked.
fn track_all(
    seeds: &[(u64, PathBuf)],
    jobs: usize,
    name: &str,
    config: TrackerConfig,
    options: &TrackOptions,
    keep: Option<&PathBuf>,
) -> Vec<Row> {
    let runs = parallel::map(seeds, jobs, |(seed, dir)| {
        let out = std::env::temp_dir().join(format!("kept_ab_{}_{seed}.csv", std::process::id()));
        let r = track_sequence_opts(dir, &out, config, false, None, options).and_then(|_| {
            let report = evaluate(dir, &out)?;
            let judged = count_run(dir, &out, &report)?;
            Ok((report, judged))
        });
        if let (Ok(_), Some(keep)) = (&r, keep) {
            let dir = keep.join(name);
            let kept = std::fs::create_dir_all(&dir)
                .and_then(|_| std::fs::copy(&out, dir.join(format!("seed{seed}.csv"))));
            if let Err(e) = kept {
                eprintln!("seed {seed}: its states not kept: {e}");
            }
        }
        let _ = std::fs::remove_file(&out);
        match r {
            Ok((r, judged)) => {
                let tip = r.cameras.iter().map(|c| c.fingertip_mean_px).sum::<f64>()
                    / r.cameras.len() as f64;
                Some((
                    *seed,
                    r.track_life,
                    r.joint_rms_deg,
                    tip,
                    judged,
                    r.held_share,
                ))
            }
            Err(e) => {
                eprintln!("seed {seed}: {e:#}");
                None
            }
        }
    });
    runs.into_iter().flatten().collect()
}

/// Each group's mean track life per draw, and the spread of those means.
fn print_draws(name: &str, draws: &[Vec<Row>]) {
    for (group, parity) in [("mono", 1), ("stereo", 0)] {
        let means: Vec<f64> = draws
            .iter()
            .map(|rows| {
                let lives: Vec<f64> = rows
                    .iter()
                    .filter(|r| r.0 % 2 == parity)
                    .map(|r| r.1)
                    .collect();
                100.0 * lives.iter().sum::<f64>() / lives.len().max(1) as f64
            })
            .collect();
        let (lo, hi) = means
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &m| {
                (lo.min(m), hi.max(m))
            });
        let text: Vec<String> = means.iter().map(|m| format!("{m:.1}")).collect();
        println!(
            "  draws {name} {group}: mean life per draw {} (range {:.1} points)",
            text.join(" "),
            hi - lo
        );
    }
}

/// Each seed tracked in every draw, its life and share held averaged over them; the other
/// figures are the first draw's.
fn mean_of_draws(draws: &[Vec<Row>]) -> Vec<Row> {
    let Some((first, rest)) = draws.split_first() else {
        return Vec::new();
    };
    first
        .iter()
        .filter_map(|row| {
            let same: Vec<&Row> = rest
                .iter()
                .map(|rows| rows.iter().find(|r| r.0 == row.0))
                .collect::<Option<_>>()?;
            let n = (same.len() + 1) as f64;
            let mut mean = *row;
            mean.1 = (row.1 + same.iter().map(|r| r.1).sum::<f64>()) / n;
            mean.5 = (row.5 + same.iter().map(|r| r.5).sum::<f64>()) / n;
            Some(mean)
        })
        .collect()
}

/// One seed's run under a variant: the seed, its track life and its share of frames held.
type Run = (u64, f64, f64);

/// The seed-by-seed comparison of `lives` with `base`, per group.
fn paired(name: &str, base: &[Run], lives: &[Run]) {
    for (group, parity) in [("mono", 1), ("stereo", 0), ("all", 2)] {
        // (life before, life after) of each seed of the group.
        let matched: Vec<(&Run, &Run)> = lives
            .iter()
            .filter(|(s, _, _)| parity == 2 || s % 2 == parity)
            .filter_map(|l| base.iter().find(|b| b.0 == l.0).map(|b| (b, l)))
            .collect();
        let pairs: Vec<(f64, f64)> = matched.iter().map(|(b, l)| (b.1, l.1)).collect();
        let held_change =
            matched.iter().map(|(b, l)| l.2 - b.2).sum::<f64>() / matched.len().max(1) as f64;
        if pairs.is_empty() {
            continue;
        }
        let better = pairs.iter().filter(|(b, l)| l - b > 0.05).count();
        let worse = pairs.iter().filter(|(b, l)| l - b < -0.05).count();
        let rose = pairs
            .iter()
            .filter(|(b, l)| *b < 0.95 && *l >= 0.95)
            .count();
        let fell = pairs
            .iter()
            .filter(|(b, l)| *b >= 0.95 && *l < 0.95)
            .count();
        println!(
            "  paired {name} {group}: mean life change {:+.1} points, {better} seeds gained > 5, {worse} lost > 5, sign test p {:.3}; {rose} rose to >= 95 %, {fell} fell below; frames held {:+.1} points",
            100.0 * pairs.iter().map(|(b, l)| l - b).sum::<f64>() / pairs.len() as f64,
            sign_test(better, worse),
            100.0 * held_change
        );
    }
}

/// Two-sided sign test: the chance of a split at least this uneven when either way is
/// equally likely.
fn sign_test(a: usize, b: usize) -> f64 {
    let n = a + b;
    if n == 0 {
        return 1.0;
    }
    let k = a.min(b);
    let mut tail = 0.0;
    let mut choose = 1.0f64;
    for i in 0..=k {
        if i > 0 {
            choose *= (n - i + 1) as f64 / i as f64;
        }
        tail += choose;
    }
    (2.0 * tail / 2f64.powi(n as i32)).min(1.0)
}
