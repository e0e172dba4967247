//! Which of a sweep seed's draws go with a short track? On the sequences `bench robustness
//! --keep DIR` kept, each seed's track life (as `eval` has it) is set beside what the seed
//! drew (`scenarios::random::random_scenario`): the first camera's elevation and azimuth, the
//! hand's span in the image, the stereo baseline, the fingertips' peak speed, noise, blur,
//! the ambient light, the palm's turn; and two things of the true motion: the share of
//! fingertip views the true hand hides, and how far the joints swing. Per group it prints
//! each factor's rank correlation with life (Spearman) and the median life in the factor's
//! lower, middle and upper thirds.
//!
//! With `--information`, one more factor, of what the images can tell at all: every
//! `--every`th frame the tracker is put at the truth and runs one iteration of its own
//! search; a joint whose information there (the diagonal of `JᵀWJ` without the prior, px² per
//! rad²) is under the prior's weight is *left to the prior*: the image would move it less
//! than half the way to what it shows (the diagonal overstates what the images tell a joint
//! apart from its neighbours and the palm, so the shares are lower bounds). The factor is the
//! share of joint-frames left to the prior; a table gives that share by kind of joint
//! (abduction, MCP, PIP, DIP, the thumb's five) per group and per third of the first camera's
//! elevation, and the median information per kind.
//!
//! ```text
//! digiteyes bench robustness --seeds 60 --frames 200 --first-seed N --keep /tmp/kN
//! cargo run --release -p digiteyes-host --example life_factors -- /tmp/kN [/tmp/kM ...] \
//!     [--list] [--information]
//! ```

use std::path::PathBuf;

use anyhow::Result;
use clap::Parser;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::BASE_STATES;
use digiteyes_core::nalgebra::{Matrix3, Vector3};
use digiteyes_core::projection::ProjectedModel;
use digiteyes_core::visibility::{cover, Cover};
use digiteyes_host::eval::stats::percentile;
use digiteyes_host::eval::{reprojection_error, track_life};
use digiteyes_host::scenarios::random::random_scenario;
use digiteyes_host::sequence::{read_states, Sequence};
use digiteyes_host::{sequence_tracker, TrackerConfig};

/// The thumb's first joint (`q23`): the four fingers' joints come before it, four each.
const THUMB_FIRST: usize = 23;

#[path = "common/kept.rs"]
mod kept;

#[derive(Parser)]
struct Args {
    /// Folders of kept seeds (`seedNNNN/`), as `bench robustness --keep` writes.
    #[arg(required = true)]
    dirs: Vec<PathBuf>,
    /// Also print every seed's life and factors (in the order of the table).
    #[arg(long)]
    list: bool,
    /// Also measure the joints the images leave to the prior, at the truth (slower: one
    /// tracker iteration per sampled frame).
    #[arg(long)]
    information: bool,
    /// With `--information`: sample every this many frames.
    #[arg(long, default_value_t = 5)]
    every: usize,
}

/// The factors, in the order they are printed.
const FACTORS: [&str; 13] = [
    "elevation deg",
    "azimuth from fingertips deg",
    "hand span px",
    "baseline mm",
    "tip speed px/frame",
    "noise sigma",
    "blur sigma px",
    "ambient share",
    "palm turn deg",
    "tips hidden share",
    "joint swing rad",
    "palm travel mm",
    "joints left to the prior",
];

/// What the images tell of each kind of joint ([`KINDS`]) at the truth: the information of
/// each sampled joint-frame (px² per rad²).
type Information = [Vec<f64>; KINDS.len()];

/// The prior's weight on a joint (px² per rad²): information under it leaves the joint to it.
fn joint_prior() -> f64 {
    f64::from(TrackerConfig::default().motion.prior.joint)
}

/// The share of `values` left to the prior.
fn left_share(values: &[f64]) -> f64 {
    let prior = joint_prior();
    values.iter().filter(|&&v| v < prior).count() as f64 / values.len().max(1) as f64
}

/// The kinds of joint `--information` splits by: a finger's four, then the thumb's five.
const KINDS: [&str; 5] = ["abduction", "MCP", "PIP", "DIP", "thumb"];

struct Seed {
    stereo: bool,
    life: f64,
    factors: [f64; FACTORS.len()],
    /// Per kind of joint, with `--information`.
    information: Information,
}

fn main() -> Result<()> {
    let args = Args::parse();
    let mut seeds = Vec::new();
    for dir in &args.dirs {
        for seed_dir in kept::seed_dirs(dir)? {
            let seed = kept::seed_of(&seed_dir);
            let measured = measure(seed, &seed_dir, args.information.then_some(args.every))?;
            if args.list {
                let factors: Vec<String> =
                    measured.factors.iter().map(|f| format!("{f:.2}")).collect();
                println!(
                    "seed {seed} life {:.0} % factors {}",
                    100.0 * measured.life,
                    factors.join(" ")
                );
            }
            seeds.push(measured);
        }
    }
    for (stereo, name) in [(false, "mono"), (true, "stereo")] {
        let group: Vec<&Seed> = seeds.iter().filter(|s| s.stereo == stereo).collect();
        let lives: Vec<f64> = group.iter().map(|s| s.life).collect();
        println!(
            "{name}: {} seeds, life median {:.0} %",
            group.len(),
            100.0 * percentile(&lives, 0.5)
        );
        println!("  factor                        rho   life median by third (low / mid / high)");
        for (f, factor) in FACTORS.iter().enumerate() {
            let values: Vec<f64> = group.iter().map(|s| s.factors[f]).collect();
            if values.iter().all(|v| *v == values[0]) {
                continue;
            }
            let rho = spearman(&values, &lives);
            let thirds = thirds(&values, &lives);
            println!(
                "  {factor:<28} {rho:+.2}   {:.0} / {:.0} / {:.0} %",
                100.0 * thirds[0],
                100.0 * thirds[1],
                100.0 * thirds[2]
            );
        }
        if args.information {
            left_table(&group);
        }
    }
    Ok(())
}

/// The share of joint-frames left to the prior, by kind of joint, over `group` and over each
/// third of it by the first camera's elevation.
fn left_table(group: &[&Seed]) {
    let pooled = |seeds: &[&Seed], k: usize| -> Vec<f64> {
        seeds
            .iter()
            .flat_map(|s| s.information[k].iter().copied())
            .collect()
    };
    let share = |seeds: &[&Seed]| -> Vec<String> {
        (0..KINDS.len())
            .map(|k| format!("{:>9.0} %", 100.0 * left_share(&pooled(seeds, k))))
            .collect()
    };
    println!(
        "  joints left to the prior    {}",
        KINDS.map(|k| format!("{k:>11}")).join("")
    );
    println!("  all                      {}", share(group).join(" "));
    let medians: Vec<String> = (0..KINDS.len())
        .map(|k| format!("{:>11.0}", percentile(&pooled(group, k), 0.5)))
        .collect();
    println!("  median information px²/rad²{}", medians.join(""));
    let mut order: Vec<&Seed> = group.to_vec();
    order.sort_by(|a, b| a.factors[0].total_cmp(&b.factors[0]));
    let n = order.len();
    for (t, name) in ["low", "mid", "high"].iter().enumerate() {
        let part = &order[t * n / 3..(t + 1) * n / 3];
        println!("  elevation {name:<5} third     {}", share(part).join(" "));
    }
}

/// The information of every free joint, per kind ([`KINDS`]): every `every`th frame of
/// `sequence`, the tracker put at the truth runs one iteration, and each joint's is the
/// diagonal of that iteration's `JᵀWJ` less the prior's weight.
fn information_at_truth(
    sequence: &Sequence,
    truth: &[Vec<f32>],
    every: usize,
) -> Result<Information> {
    let mut config = TrackerConfig::default();
    config.iterations = 1;
    let prior = config.motion.prior.joint;
    let mut tracker = sequence_tracker(sequence, config)?;
    let free = tracker.free();
    let mut information = Information::default();
    for (k, state) in truth.iter().enumerate().step_by(every.max(1)) {
        tracker.reset(state)?;
        let images = kept::read_instant(sequence, k)?;
        tracker.track(&kept::views(&images)?)?;
        let normal = tracker.normal_equations();
        for j in BASE_STATES..sequence.n_states() {
            if !free.contains(j) {
                continue;
            }
            let kind = if j >= THUMB_FIRST {
                4
            } else {
                (j - BASE_STATES) % 4
            };
            information[kind].push(f64::from(normal.element(j, j) - prior));
        }
    }
    Ok(information)
}

fn measure(seed: u64, dir: &std::path::Path, information: Option<usize>) -> Result<Seed> {
    let stereo = seed.is_multiple_of(2);
    let scenario = random_scenario(seed, stereo);
    let sequence = Sequence::open(dir)?;
    let model = &sequence.model;
    let truth = kept::f32s(&sequence.read_truth()?.rows);
    let tracked = kept::f32s(&read_states(&dir.join("states.csv"), sequence.n_states())?.rows);
    let mut errors = Vec::new();
    let (mut hidden, mut tips) = (0usize, 0usize);
    let mut view = ProjectedModel::default();
    for (t, e) in truth.iter().zip(&tracked) {
        let (pt, pe) = (Poses::compute(model, t)?, Poses::compute(model, e)?);
        let mut sum = 0.0;
        let mut count = 0usize;
        for camera in &sequence.cameras {
            view.update(model, &pt, camera, 0.0);
            for (i, link) in view.links.iter().enumerate().filter(|(_, l)| l.distal) {
                sum += reprojection_error(camera, &pt, &pe, usize::from(link.child));
                count += 1;
                let front = link.z1 - link.radius_mm;
                tips += 1;
                if cover(&view, camera, i, &link.b, front) == Cover::Hidden {
                    hidden += 1;
                }
            }
        }
        errors.push(sum / count.max(1) as f64);
    }
    let eyes: Vec<Vector3<f64>> = scenario
        .cameras
        .iter()
        .map(|c| {
            let r = Matrix3::from_fn(|i, j| c.r[i][j]);
            -(r.transpose() * Vector3::from(c.t))
        })
        .collect();
    let first = &scenario.cameras[0];
    let poses = Poses::compute(model, &truth[0])?;
    let points: Vec<Vector3<f32>> = (0..model.links().len())
        .filter_map(|i| poses.origin(i))
        .collect();
    let centre = points.iter().fold(Vector3::zeros(), |a, p| a + p) / points.len().max(1) as f32;
    let centre = centre.cast::<f64>();
    let offset = eyes[0] - centre;
    let distance = offset.norm();
    let elevation = (offset.z / distance).asin().to_degrees();
    // The fingers point along +y: azimuth 0 looks from beyond the fingertips, 180 from
    // behind the wrist, 90 from either side.
    let azimuth = offset.x.atan2(offset.y).to_degrees().abs();
    let span_px = first.fx * 190.0 / distance;
    let baseline = eyes.get(1).map_or(0.0, |e| (e - eyes[0]).norm());
    let swing = |states: std::ops::Range<usize>| -> f64 {
        let mut spread = Vec::new();
        for s in states {
            let values: Vec<f64> = truth.iter().map(|q| f64::from(q[s])).collect();
            let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            spread.push(hi - lo);
        }
        spread.iter().sum::<f64>() / spread.len().max(1) as f64
    };
    let turn = scenario.rotation.map_or(0.0, |r| r[0].to_degrees());
    let information = match information {
        Some(every) => information_at_truth(&sequence, &truth, every)?,
        None => Information::default(),
    };
    let all_joints: Vec<f64> = information.iter().flatten().copied().collect();
    Ok(Seed {
        stereo,
        life: track_life(&errors),
        factors: [
            elevation,
            azimuth,
            span_px,
            baseline,
            scenario.peak_tip_speed,
            f64::from(scenario.noise),
            f64::from(scenario.blur),
            scenario.lighting.ambient,
            turn,
            hidden as f64 / tips.max(1) as f64,
            swing(7..sequence.n_states()),
            swing(4..7),
            left_share(&all_joints),
        ],
        information,
    })
}

/// Ranks, ties sharing their mean rank.
fn ranks(values: &[f64]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    let mut ranks = vec![0.0; values.len()];
    let mut i = 0;
    while i < order.len() {
        let mut j = i;
        while j + 1 < order.len() && values[order[j + 1]] == values[order[i]] {
            j += 1;
        }
        for &k in &order[i..=j] {
            ranks[k] = (i + j) as f64 / 2.0;
        }
        i = j + 1;
    }
    ranks
}

fn spearman(a: &[f64], b: &[f64]) -> f64 {
    let (ra, rb) = (ranks(a), ranks(b));
    let n = ra.len() as f64;
    let (ma, mb) = (ra.iter().sum::<f64>() / n, rb.iter().sum::<f64>() / n);
    let cov: f64 = ra.iter().zip(&rb).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = ra.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = rb.iter().map(|y| (y - mb).powi(2)).sum();
    cov / (va * vb).sqrt().max(f64::MIN_POSITIVE)
}

/// The median life of the seeds in each third of `values`.
fn thirds(values: &[f64], lives: &[f64]) -> [f64; 3] {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    let n = order.len();
    [0, 1, 2].map(|t| {
        let part: Vec<f64> = order[t * n / 3..(t + 1) * n / 3]
            .iter()
            .map(|&i| lives[i])
            .collect();
        percentile(&part, 0.5)
    })
}
