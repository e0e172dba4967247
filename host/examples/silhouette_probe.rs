//! How well the silhouette agreement separates right states from wrong ones: renders seeds of
//! a scenario, scores the truth and random perturbations of it at every frame, and prints the
//! agreement's distribution by the perturbation's fingertip error.
//!
//! ```text
//! cargo run --release -p digiteyes-host --example silhouette_probe -- fullhand-mono --seeds 4
//! ```

use std::path::Path;

use anyhow::Result;
use clap::Parser;
use digiteyes_core::frame::FrameView;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::Shape;
use digiteyes_core::projection::ProjectedModel;
use digiteyes_core::silhouette;
use digiteyes_host::scenarios::{render_scenario, RenderOptions};
use digiteyes_host::sequence::Sequence;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};

#[derive(Parser)]
struct Args {
    scenario: String,
    #[arg(long, default_value_t = 4)]
    seeds: u64,
    #[arg(long, default_value_t = 20)]
    frames: usize,
    #[arg(long, default_value_t = 24)]
    grid: usize,
    #[arg(long, default_value_t = 6)]
    perturbations: usize,
}

fn percentiles(name: &str, v: &mut [f32]) {
    if v.is_empty() {
        println!("{name:>14}: none");
        return;
    }
    v.sort_by(|a, b| a.total_cmp(b));
    let at = |p: f32| v[((v.len() - 1) as f32 * p) as usize];
    println!(
        "{name:>14}: n={:5} p5={:.3} p10={:.3} p50={:.3} p90={:.3}",
        v.len(),
        at(0.05),
        at(0.10),
        at(0.5),
        at(0.9)
    );
}

fn main() -> Result<()> {
    let args = Args::parse();
    let dir = tempfile::tempdir()?;
    let mut truth_scores = Vec::new();
    let mut near = Vec::new();
    let mut mid = Vec::new();
    let mut far = Vec::new();
    for seed in 1..=args.seeds {
        let seq_dir = dir.path().join(format!("s{seed}"));
        let opts = RenderOptions {
            seed,
            frames: Some(args.frames),
            size: Some((320, 240)),
            supersample: 1,
            ..RenderOptions::default()
        };
        render_scenario(&args.scenario, &seq_dir, &opts)?;
        probe(
            &seq_dir,
            &args,
            seed,
            &mut truth_scores,
            &mut near,
            &mut mid,
            &mut far,
        )?;
    }
    percentiles("truth", &mut truth_scores);
    percentiles("wrong <5px", &mut near);
    percentiles("wrong 5-15px", &mut mid);
    percentiles("wrong >15px", &mut far);
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn probe(
    seq_dir: &Path,
    args: &Args,
    seed: u64,
    truth_scores: &mut Vec<f32>,
    near: &mut Vec<f32>,
    mid: &mut Vec<f32>,
    far: &mut Vec<f32>,
) -> Result<()> {
    let seq = Sequence::open(seq_dir)?;
    let truth = seq.read_truth()?;
    let free = seq.free_states();
    let model = &seq.model;
    let tips: Vec<usize> = (0..model.links().len())
        .filter(|&i| matches!(model.links()[i].shape, Shape::Tip { .. }))
        .collect();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed * 7919);
    let joint = Normal::new(0.0f32, 0.35).unwrap();
    let mm = Normal::new(0.0f32, 12.0).unwrap();
    let quat = Normal::new(0.0f32, 0.12).unwrap();
    let mut view = ProjectedModel::new();
    for k in 0..seq.frames {
        let images: Vec<_> = (0..seq.cameras.len())
            .map(|c| seq.read_frame(c, k))
            .collect::<Result<_>>()?;
        let qt: Vec<f32> = truth.rows[k].iter().map(|&v| v as f32).collect();
        let pt = Poses::compute(model, &qt)?;
        let score = |q: &[f32], view: &mut ProjectedModel| -> Option<f32> {
            let poses = Poses::compute(model, q).ok()?;
            let mut least = 1.0f32;
            for (c, cam) in seq.cameras.iter().enumerate() {
                let img = &images[c];
                let frame =
                    FrameView::packed(img.as_raw(), img.width() as usize, img.height() as usize)
                        .ok()?;
                view.update(model, &poses, cam, 4.0);
                let s = silhouette::score(view, cam, &frame, args.grid)?;
                least = least.min(s.agreement);
            }
            Some(least)
        };
        if let Some(s) = score(&qt, &mut view) {
            truth_scores.push(s);
        }
        for _ in 0..args.perturbations {
            let mut q = qt.clone();
            for &s in &free {
                q[s] += match s {
                    0..=3 => quat.sample(&mut rng),
                    4..=6 => mm.sample(&mut rng),
                    _ => joint.sample(&mut rng) * if rng.random_bool(0.5) { 1.0 } else { 0.3 },
                };
                if let Some(l) = model.limit(s) {
                    q[s] = q[s].clamp(l.lo, l.hi);
                }
            }
            let Ok(pe) = Poses::compute(model, &q) else {
                continue;
            };
            let mut err = 0.0f32;
            let mut n = 0.0f32;
            for cam in &seq.cameras {
                for &i in &tips {
                    if let (Some(a), Some(b)) = (pt.origin(i), pe.origin(i)) {
                        if let (Some(u), Some(v)) = (cam.project(&a), cam.project(&b)) {
                            err += (u - v).norm();
                            n += 1.0;
                        }
                    }
                }
            }
            let err = err / n.max(1.0);
            if let Some(s) = score(&q, &mut view) {
                match err {
                    e if e < 5.0 => near.push(s),
                    e if e < 15.0 => mid.push(s),
                    _ => far.push(s),
                }
            }
        }
    }
    Ok(())
}
