//! Do wrong fingers sink into the hand? A real finger cannot pass through the palm or another
//! finger; the tracker's model can. For each finger of each frame of the kept tracks, how
//! deep its capsules reach into the palm box (its middle and distal links: the proximal link
//! starts at the knuckle, inside the box's edge) and into another finger's capsules (the
//! proximal links of neighbours excluded: knuckles touch), at the truth and at the tracked
//! state, split by that finger's tip error (right: under 5 px; wrong: over 20 px).
//!
//! ```text
//! cargo run --release -p digiteyes-host --example penetration -- /tmp/kv_15761
//! ```

use anyhow::Result;
use clap::Parser;
use digiteyes_core::hypotheses::fingers::Fingers;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::Shape;
use digiteyes_core::projection::{ProjectedLink, ProjectedModel};
use digiteyes_host::eval::stats::percentile;
use digiteyes_host::sequence::{read_states, Sequence};
use nalgebra::Vector3;
use std::path::PathBuf;

#[path = "common/kept.rs"]
mod kept;

#[derive(Parser)]
struct Args {
    /// Folders of kept seeds.
    dirs: Vec<PathBuf>,
    /// Every this many frames.
    #[arg(long, default_value_t = 2)]
    every: usize,
}

/// Points along a capsule's axis tested against the palm box.
const AXIS_POINTS: usize = 7;

/// The palm box as centre, unit axes and half sizes (mm), from its eight world corners.
struct PalmBox {
    centre: Vector3<f32>,
    axes: [Vector3<f32>; 3],
    half: [f32; 3],
}

impl PalmBox {
    fn of(corners: &[Vector3<f32>; 8]) -> PalmBox {
        let centre = corners.iter().fold(Vector3::zeros(), |s, c| s + c) / 8.0;
        // The three corners nearest corner 0 lie along the box's three edges from it.
        let mut others: Vec<Vector3<f32>> = corners[1..].iter().map(|c| c - corners[0]).collect();
        others.sort_by(|a, b| a.norm().total_cmp(&b.norm()));
        let edges = [others[0], others[1], others[2]];
        PalmBox {
            centre,
            axes: edges.map(|e| e / e.norm().max(1e-6)),
            half: edges.map(|e| 0.5 * e.norm()),
        }
    }

    /// Signed distance (mm) from `p` to the box: negative inside.
    fn distance(&self, p: &Vector3<f32>) -> f32 {
        let d = p - self.centre;
        let q: [f32; 3] = core::array::from_fn(|i| d.dot(&self.axes[i]).abs() - self.half[i]);
        let outside = Vector3::new(q[0].max(0.0), q[1].max(0.0), q[2].max(0.0)).norm();
        outside + q[0].max(q[1]).max(q[2]).min(0.0)
    }
}

/// Per finger: (into the palm, into other fingers) penetration depth (mm, 0 when none).
fn penetration(
    view: &ProjectedModel,
    finger_of: &[Option<usize>],
    proximal: &[bool],
    fingers: usize,
) -> Vec<[f32; 2]> {
    let mut out = vec![[0.0f32; 2]; fingers];
    let palm = view.palm.as_ref().map(|p| PalmBox::of(&p.corners_mm));
    let links: &[ProjectedLink] = &view.links;
    for (i, link) in links.iter().enumerate() {
        let Some(f) = finger_of[i] else { continue };
        if let (Some(palm), false) = (&palm, proximal[i]) {
            for k in 0..AXIS_POINTS {
                let p = link.p0 + (link.p1 - link.p0) * (k as f32 / (AXIS_POINTS - 1) as f32);
                let depth = link.radius_mm - palm.distance(&p);
                out[f][0] = out[f][0].max(depth);
            }
        }
        for (j, other) in links.iter().enumerate() {
            let Some(g) = finger_of[j] else { continue };
            if g == f || (proximal[i] && proximal[j]) {
                continue;
            }
            let depth = link.radius_mm + other.radius_mm
                - kept::segment_distance_mm(&link.p0, &link.p1, &other.p0, &other.p1);
            out[f][1] = out[f][1].max(depth);
        }
    }
    out
}

fn main() -> Result<()> {
    let args = Args::parse();
    // [truth, tracked] × [right, wrong] × [palm, fingers]
    let mut depths: [[[Vec<f64>; 2]; 2]; 2] = Default::default();
    for dir in &args.dirs {
        for seed_dir in kept::seed_dirs(dir)? {
            let sequence = Sequence::open(&seed_dir)?;
            let model = &sequence.model;
            let fingers = Fingers::of(model);
            let truth = kept::f32s(&sequence.read_truth()?.rows);
            let tracked =
                kept::f32s(&read_states(&seed_dir.join("states.csv"), sequence.n_states())?.rows);
            let camera = &sequence.cameras[0];
            let mut view = ProjectedModel::default();
            let tips: Vec<usize> = (0..model.links().len())
                .filter(|&i| matches!(model.links()[i].shape, Shape::Tip { .. }))
                .collect();
            for k in (0..truth.len().min(tracked.len())).step_by(args.every.max(1)) {
                let (pt, pe) = (
                    Poses::compute(model, &truth[k])?,
                    Poses::compute(model, &tracked[k])?,
                );
                // Each finger's tip error (px, mean over cameras).
                let mut tip_px = vec![0.0f32; fingers.count()];
                for &t in &tips {
                    let Some(f) = kept::finger_of_frame(model, &fingers, t) else {
                        continue;
                    };
                    for c in &sequence.cameras {
                        if let (Some(u), Some(v)) = (
                            pt.origin(t).and_then(|x| c.project(&x)),
                            pe.origin(t).and_then(|x| c.project(&x)),
                        ) {
                            tip_px[f] += (u - v).norm() / sequence.cameras.len() as f32;
                        }
                    }
                }
                for (which, poses) in [(0usize, &pt), (1, &pe)] {
                    view.update(model, poses, camera, 0.0);
                    let finger_of: Vec<Option<usize>> = view
                        .links
                        .iter()
                        .map(|l| kept::finger_of_frame(model, &fingers, usize::from(l.frame)))
                        .collect();
                    let proximal: Vec<bool> = view
                        .links
                        .iter()
                        .map(|l| {
                            model
                                .chain(usize::from(l.frame))
                                .is_some_and(|c| c.len() <= 2)
                        })
                        .collect();
                    for (f, pen) in penetration(&view, &finger_of, &proximal, fingers.count())
                        .iter()
                        .enumerate()
                    {
                        let class = if tip_px[f] < 5.0 {
                            0
                        } else if tip_px[f] > 20.0 {
                            1
                        } else {
                            continue;
                        };
                        for (part, &d) in pen.iter().enumerate() {
                            depths[which][class][part].push(f64::from(d.max(0.0)));
                        }
                    }
                }
            }
        }
    }
    for (which, name) in ["truth", "tracked"].iter().enumerate() {
        for (class, label) in ["right (< 5 px)", "wrong (> 20 px)"].iter().enumerate() {
            for (part, into) in ["the palm", "other fingers"].iter().enumerate() {
                let v = &depths[which][class][part];
                if v.is_empty() {
                    continue;
                }
                let over =
                    |mm: f64| 100.0 * v.iter().filter(|&&d| d > mm).count() as f64 / v.len() as f64;
                println!(
                    "{name:>7}, fingers {label:>15}, into {into:>13}: {} finger-frames; median {:.1} mm, p90 {:.1}, p99 {:.1}; over 5 mm {:.1} %, over 10 mm {:.1} %",
                    v.len(),
                    percentile(v, 0.5),
                    percentile(v, 0.9),
                    percentile(v, 0.99),
                    over(5.0),
                    over(10.0)
                );
            }
        }
    }
    Ok(())
}
