//! How long could *any* tracker hold the sweep's hands, if it knew exactly what the cameras
//! see and nothing more? On the sequences `bench robustness --keep DIR` kept (only their
//! truth and cameras are read), a *seen-oracle* is built frame by frame: the palm's 7 states
//! are the truth, and so is every joint that moves a link some camera sees at the truth (a
//! point of the link's axis inside the frame and not hidden by a nearer part of the hand, by
//! the core's own depth-order test, `visibility::cover`); a joint that moves no seen link
//! keeps what the oracle had (`hold`), or goes on at the speed it last had while seen
//! (`velocity`, clamped to the joint's range). Its track life is then computed as `eval` and
//! the benchmark compute it, over every fingertip in every camera.
//!
//! This is a generous ceiling for an image-based tracker: it is perfect wherever the geometry
//! leaves anything in view, and the palm is always right. A target above it is out of reach
//! of a tracker that follows what it sees, unless it guesses the hidden joints better than
//! by holding them.
//!
//! ```text
//! digiteyes bench robustness --seeds 60 --frames 200 --keep /tmp/keep
//! cargo run --release -p digiteyes-host --example seen_bound -- /tmp/keep [--points 1]
//! ```

use std::path::PathBuf;

use anyhow::Result;
use clap::Parser;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::projection::ProjectedModel;
use digiteyes_host::eval::stats::percentile;
use digiteyes_host::eval::{reprojection_error, track_life};
use digiteyes_host::sequence::Sequence;

#[path = "common/kept.rs"]
mod kept;
#[path = "common/seen.rs"]
mod seen;

use seen::{oracle, Unseen};

#[derive(Parser)]
struct Args {
    /// Folders of kept seeds (`seedNNNN/`), as `bench robustness --keep` writes.
    #[arg(required = true)]
    dirs: Vec<PathBuf>,
    /// Points along a link's axis that must be seen for the link to count as seen.
    #[arg(long, default_value_t = 1)]
    points: usize,
}

/// Mean fingertip error over every tip and camera, per frame (px).
fn tip_errors(sequence: &Sequence, truth: &[Vec<f32>], states: &[Vec<f32>]) -> Result<Vec<f64>> {
    let model = &sequence.model;
    let mut out = Vec::with_capacity(truth.len());
    let mut view = ProjectedModel::default();
    for (t, e) in truth.iter().zip(states) {
        let (pt, pe) = (Poses::compute(model, t)?, Poses::compute(model, e)?);
        let mut errors = Vec::new();
        for camera in &sequence.cameras {
            view.update(model, &pt, camera, 0.0);
            for link in view.links.iter().filter(|l| l.distal) {
                errors.push(reprojection_error(
                    camera,
                    &pt,
                    &pe,
                    usize::from(link.child),
                ));
            }
        }
        out.push(errors.iter().sum::<f64>() / errors.len().max(1) as f64);
    }
    Ok(out)
}

fn main() -> Result<()> {
    let args = Args::parse();
    let ways = [("hold", Unseen::Hold), ("velocity", Unseen::Velocity)];
    // Per way and group (stereo 0, mono 1): lives; per group: unseen shares.
    let mut life = vec![[Vec::new(), Vec::new()]; ways.len()];
    let mut unseen = [Vec::new(), Vec::new()];
    for base in &args.dirs {
        for dir in kept::seed_dirs(base)? {
            let seed = kept::seed_of(&dir);
            let g = (seed % 2) as usize;
            let sequence = Sequence::open(&dir)?;
            let truth = kept::f32s(&sequence.read_truth()?.rows);
            let mut line = format!("seed {seed}:");
            for (w, (name, how)) in ways.iter().enumerate() {
                let (states, share) = oracle(&sequence, &truth, args.points, *how)?;
                let l = track_life(&tip_errors(&sequence, &truth, &states)?);
                life[w][g].push(l);
                if w == 0 {
                    unseen[g].push(share);
                    line += &format!(" joints unseen {:.0} %;", 100.0 * share);
                }
                line += &format!(" life ({name}) {:.0} %", 100.0 * l);
            }
            println!("{line}");
        }
    }
    for (g, group) in [(1, "mono"), (0, "stereo")] {
        let n = unseen[g].len();
        let mean_unseen = unseen[g].iter().sum::<f64>() / n.max(1) as f64;
        println!(
            "{group}: {n} seeds; joint-frames unseen {:.0} %",
            100.0 * mean_unseen
        );
        for (w, (name, _)) in ways.iter().enumerate() {
            let l = &life[w][g];
            println!(
                "  seen-oracle, unseen joints {name}: life median {:.0} %, p10 {:.0} %, >= 95 % on {} of {n}",
                100.0 * percentile(l, 0.5),
                100.0 * percentile(l, 0.1),
                l.iter().filter(|&&v| v >= 0.95).count()
            );
        }
    }
    Ok(())
}
