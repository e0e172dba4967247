//! How many region samples pull at the truth, and how many once the hand is pushed off it?
//! On the sequences `bench robustness --keep DIR` kept, every `--every`th frame: the region
//! samples (`fill::gather`) gathered at the true state, and at the truth with every finger
//! joint pushed `--push-rad` (alternating signs), per camera, bright and dark apart.
//!
//! ```text
//! cargo run --release -p digiteyes-host --example fill_truth -- /tmp/keep [--set fillmargin=0]
//! ```

use std::path::PathBuf;

use anyhow::Result;
use clap::Parser;
use digiteyes_core::fill::{gather, FillPoints};
use digiteyes_core::kinematics::Poses;
use digiteyes_core::projection::ProjectedModel;
use digiteyes_host::sequence::Sequence;

#[path = "common/kept.rs"]
mod kept;

#[derive(Parser)]
struct Args {
    /// A folder of kept seeds (`seedNNNN/`), as `bench robustness --keep` writes.
    dir: PathBuf,
    /// Every this many frames.
    #[arg(long, default_value_t = 10)]
    every: usize,
    /// How far each finger joint is pushed for the second count (rad).
    #[arg(long, default_value_t = 0.15)]
    push_rad: f32,
    /// `kept_ab`'s overrides for the tracker's configuration (its region rows).
    #[arg(long, default_value = "default")]
    set: String,
}

fn main() -> Result<()> {
    let args = Args::parse();
    let (config, _) = kept::variant(&args.set)?;
    let (mut truth_counts, mut pushed_counts) = ([0usize; 2], [0usize; 2]);
    let mut views_counted = 0usize;
    let mut out = FillPoints::default();
    let mut view = ProjectedModel::default();
    for dir in kept::seed_dirs(&args.dir)? {
        let sequence = Sequence::open(&dir)?;
        let model = &sequence.model;
        let truth = kept::f32s(&sequence.read_truth()?.rows);
        for (k, t) in truth.iter().enumerate().step_by(args.every.max(1)) {
            let images = kept::read_instant(&sequence, k)?;
            let frames = kept::views(&images)?;
            let mut pushed = t.clone();
            for (n, q) in pushed.iter_mut().enumerate().skip(7) {
                *q += if n % 2 == 0 {
                    args.push_rad
                } else {
                    -args.push_rad
                };
            }
            for (camera, frame) in sequence.cameras.iter().zip(&frames) {
                for (q, counts) in [(t, &mut truth_counts), (&pushed, &mut pushed_counts)] {
                    let poses = Poses::compute(model, q)?;
                    view.update(model, &poses, camera, config.features.min_link_px);
                    gather(&view, camera, frame, &config.fill, &mut out);
                    for p in &out.points {
                        counts[usize::from(!p.bright)] += 1;
                    }
                }
                views_counted += 1;
            }
        }
    }
    let per = |c: usize| c as f64 / views_counted.max(1) as f64;
    println!(
        "{} views; samples a view at the truth: bright {:.1} dark {:.1}; pushed {} rad: bright {:.1} dark {:.1}",
        views_counted,
        per(truth_counts[0]),
        per(truth_counts[1]),
        args.push_rad,
        per(pushed_counts[0]),
        per(pushed_counts[1]),
    );
    Ok(())
}
