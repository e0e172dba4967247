//! Which of a sweep seed's draws go with a short track? On the sequences `bench robustness
//! --keep DIR` kept, each seed's track life (as `eval` has it) is set beside what the seed
//! drew (`scenarios::random::random_scenario`): the first camera's elevation and azimuth, the
//! hand's span in the image, the stereo baseline, the fingertips' peak speed, noise, blur,
//! the ambient light, the palm's turn; and two things of the true motion: the share of
//! fingertip views the true hand hides, and how far the joints swing. Per group it prints
//! each factor's rank correlation with life (Spearman) and the median life in the factor's
//! lower, middle and upper thirds.
//!
//! ```text
//! digiteyes bench robustness --seeds 60 --frames 200 --first-seed N --keep /tmp/kN
//! cargo run --release -p digiteyes-host --example life_factors -- /tmp/kN [/tmp/kM ...]
//! ```

use std::path::PathBuf;

use anyhow::Result;
use clap::Parser;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::nalgebra::{Matrix3, Vector3};
use digiteyes_core::projection::ProjectedModel;
use digiteyes_core::visibility::{cover, Cover};
use digiteyes_host::eval::stats::percentile;
use digiteyes_host::eval::{reprojection_error, track_life};
use digiteyes_host::scenarios::random::random_scenario;
use digiteyes_host::sequence::{read_states, Sequence};

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
}

/// The factors, in the order they are printed.
const FACTORS: [&str; 12] = [
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
];

struct Seed {
    stereo: bool,
    life: f64,
    factors: [f64; FACTORS.len()],
}

fn main() -> Result<()> {
    let args = Args::parse();
    let mut seeds = Vec::new();
    for dir in &args.dirs {
        for seed_dir in kept::seed_dirs(dir)? {
            let seed = kept::seed_of(&seed_dir);
            let measured = measure(seed, &seed_dir)?;
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
    }
    Ok(())
}

fn measure(seed: u64, dir: &std::path::Path) -> Result<Seed> {
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
        ],
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
