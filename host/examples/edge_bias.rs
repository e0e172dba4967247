//! Is the measurement biased at the truth? On the sequences `bench robustness --keep DIR`
//! kept, every `--every`th frame is posed at its true state and the tracker's own slice search
//! run once (first iteration, full window); each edge point's signed distance from the
//! predicted silhouette line (px, + outward) and each tip's along the axis (px, + beyond the
//! predicted tip) are collected, by the link's place in its finger (0 = next to the palm).
//!
//! ```text
//! digiteyes bench robustness --seeds 60 --frames 200 --keep /tmp/keep
//! cargo run --release -p digiteyes-host --example edge_bias -- /tmp/keep
//! ```

use std::path::PathBuf;

#[path = "common/kept.rs"]
mod kept;

use anyhow::Result;
use clap::Parser;
use digiteyes_core::features::{FeatureConfig, LinkFeatures};
use digiteyes_core::kinematics::Poses;
use digiteyes_core::measurer::{LocalFrames, Measurer};
use digiteyes_core::projection::ProjectedModel;
use digiteyes_host::eval::stats;
use digiteyes_host::sequence::Sequence;

#[derive(Parser)]
struct Args {
    /// A folder of kept seeds (`seedNNNN/`), as `bench robustness --keep` writes.
    dir: PathBuf,
    /// Every this many frames.
    #[arg(long, default_value_t = 10)]
    every: usize,
}

fn main() -> Result<()> {
    let args = Args::parse();
    let dirs = kept::seed_dirs(&args.dir)?;
    let config = FeatureConfig::default();
    // [depth in finger 0..3] -> residuals; 4 = palm-attached/other.
    let mut edge: Vec<Vec<f64>> = vec![Vec::new(); 5];
    let mut width: Vec<Vec<f64>> = vec![Vec::new(); 5];
    let mut tip: Vec<f64> = Vec::new();
    for dir in dirs {
        let seq = Sequence::open(&dir)?;
        let truth = seq.read_truth()?.rows;
        let model = &seq.model;
        for k in (0..truth.len()).step_by(args.every.max(1)) {
            let q: Vec<f32> = truth[k].iter().map(|&v| v as f32).collect();
            let poses = Poses::compute(model, &q)?;
            let images = kept::read_instant(&seq, k)?;
            let frames = kept::views(&images)?;
            let mut measurer = LocalFrames::new(&frames);
            measurer.begin_iteration(&q, false);
            for (ci, camera) in seq.cameras.iter().enumerate() {
                let mut view = ProjectedModel::default();
                view.update(model, &poses, camera, config.min_link_px);
                for index in 0..view.links.len() {
                    let mut out = LinkFeatures::default();
                    measurer.link_features(ci, camera, &view, index, &config, false, &mut out);
                    let link = &view.links[index];
                    let place = model
                        .chain(usize::from(link.frame))
                        .map(|c| c.len().saturating_sub(1).min(4))
                        .unwrap_or(4);
                    let (dir, normal) = link.axis_frame();
                    let mut sides = [Vec::new(), Vec::new()];
                    for e in &out.edges {
                        let on_axis = link.a + (link.b - link.a) * e.s;
                        let r = link.side_radius_at(e.s, e.side);
                        let d = f32::from(e.side) * (e.position - on_axis).dot(&normal) - r;
                        edge[place].push(f64::from(d));
                        sides[usize::from(e.side > 0)].push((e.s, d));
                    }
                    for (s0, d0) in &sides[0] {
                        if let Some((_, d1)) =
                            sides[1].iter().find(|(s1, _)| (s1 - s0).abs() < 1e-4)
                        {
                            width[place].push(f64::from(d0 + d1));
                        }
                    }
                    if let Some(t) = out.tip {
                        let predicted = link.b + dir * link.tip_offset;
                        tip.push(f64::from((t - predicted).dot(&dir)));
                    }
                }
            }
        }
    }
    let show = |name: &str, v: &[f64]| {
        let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
        println!(
            "{name:<22} n {:>6} mean {:>6.2} p10 {:>6.2} p25 {:>6.2} median {:>6.2} p75 {:>6.2} p90 {:>6.2}",
            v.len(),
            mean,
            stats::percentile(v, 0.1),
            stats::percentile(v, 0.25),
            stats::percentile(v, 0.5),
            stats::percentile(v, 0.75),
            stats::percentile(v, 0.9)
        );
    };
    for p in 0..5 {
        show(&format!("edge, link place {p}"), &edge[p]);
        show(&format!("width, link place {p}"), &width[p]);
    }
    show("tip along axis", &tip);
    Ok(())
}
