//! Are the lost fingertips ones a camera could see? On the sequences `bench robustness --keep
//! DIR` kept, every frame's fingertips are split by whether the *true* hand hides them in
//! each camera (the front of the tip's sphere inside a nearer link or the palm, by the core's
//! own depth-order test, `visibility::cover`), and the track life is computed twice: over
//! every fingertip (as `eval` and the benchmark do) and over the visible ones only.
//!
//! ```text
//! digiteyes bench robustness --seeds 60 --frames 200 --keep /tmp/keep
//! cargo run --release -p digiteyes-host --example hidden_tips -- /tmp/keep [--states states.csv]
//! ```

use std::path::PathBuf;

use anyhow::Result;
use clap::Parser;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::projection::ProjectedModel;
use digiteyes_core::visibility::{cover, Cover};
use digiteyes_host::eval::stats::percentile;
use digiteyes_host::eval::{reprojection_error, track_life, LOST_ERROR_PX};
use digiteyes_host::sequence::{read_states, Sequence};

#[path = "common/kept.rs"]
mod kept;

#[derive(Parser)]
struct Args {
    /// A folder of kept seeds (`seedNNNN/`), as `bench robustness --keep` writes.
    dir: PathBuf,
    /// The tracked states in each seed's folder.
    #[arg(long, default_value = "states.csv")]
    states: String,
}

/// One frame: the mean fingertip error over every tip and camera, over the visible ones
/// (`None` when none is), and the share of tips hidden.
struct Frame {
    all_px: f64,
    visible_px: Option<f64>,
    hidden_share: f64,
}

fn frames(dir: &std::path::Path, states: &str) -> Result<Vec<Frame>> {
    let sequence = Sequence::open(dir)?;
    let model = &sequence.model;
    let n = sequence.n_states();
    let truth = kept::f32s(&sequence.read_truth()?.rows);
    let tracked = kept::f32s(&read_states(&dir.join(states), n)?.rows);
    let mut out = Vec::new();
    let mut view = ProjectedModel::default();
    for (t, e) in truth.iter().zip(&tracked) {
        let (pt, pe) = (Poses::compute(model, t)?, Poses::compute(model, e)?);
        let (mut all, mut visible, mut hidden) = (Vec::new(), Vec::new(), 0usize);
        for camera in &sequence.cameras {
            view.update(model, &pt, camera, 0.0);
            for (i, link) in view.links.iter().enumerate().filter(|(_, l)| l.distal) {
                let error = reprojection_error(camera, &pt, &pe, usize::from(link.child));
                let front = link.z1 - link.radius_mm;
                let seen = cover(&view, camera, i, &link.b, front) != Cover::Hidden;
                all.push(error);
                if seen {
                    visible.push(error);
                } else {
                    hidden += 1;
                }
            }
        }
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
        out.push(Frame {
            all_px: mean(&all),
            visible_px: (!visible.is_empty()).then(|| mean(&visible)),
            hidden_share: hidden as f64 / all.len().max(1) as f64,
        });
    }
    Ok(out)
}

fn main() -> Result<()> {
    let args = Args::parse();
    // Per group (stereo 0, mono 1): lives over every tip, over the visible ones; lost frames
    // (every tip) whose visible tips are within the limit; lost frames; hidden share.
    let mut life = [(Vec::new(), Vec::new()), (Vec::new(), Vec::new())];
    let mut lost = [(0usize, 0usize); 2];
    let mut hidden = [Vec::new(), Vec::new()];
    for dir in kept::seed_dirs(&args.dir)? {
        let seed = kept::seed_of(&dir);
        let g = (seed % 2) as usize;
        let f = frames(&dir, &args.states)?;
        let all: Vec<f64> = f.iter().map(|f| f.all_px).collect();
        // A frame with no visible tip carries no visible error: it does not count as lost.
        let visible: Vec<f64> = f.iter().map(|f| f.visible_px.unwrap_or(0.0)).collect();
        let (la, lv) = (track_life(&all), track_life(&visible));
        println!(
            "seed {seed}: life {:.0} % (visible tips {:.0} %), hidden tips {:.0} %",
            100.0 * la,
            100.0 * lv,
            100.0 * f.iter().map(|f| f.hidden_share).sum::<f64>() / f.len().max(1) as f64
        );
        life[g].0.push(la);
        life[g].1.push(lv);
        for f in &f {
            hidden[g].push(f.hidden_share);
            if f.all_px > LOST_ERROR_PX {
                lost[g].1 += 1;
                if f.visible_px.is_none_or(|v| v <= LOST_ERROR_PX) {
                    lost[g].0 += 1;
                }
            }
        }
    }
    for (g, name) in [(1, "mono"), (0, "stereo")] {
        let (a, v) = &life[g];
        let ge95 = |v: &[f64]| v.iter().filter(|&&l| l >= 0.95).count();
        let n = a.len();
        println!(
            "{name}: {n} seeds; life median / p10 / >= 95 %: every tip {:.0} / {:.0} / {} of {n}; \
             visible tips {:.0} / {:.0} / {} of {n}; lost frames whose visible tips are within \
             {LOST_ERROR_PX} px: {} of {}; tips hidden at the truth: mean {:.0} %",
            100.0 * percentile(a, 0.5),
            100.0 * percentile(a, 0.1),
            ge95(a),
            100.0 * percentile(v, 0.5),
            100.0 * percentile(v, 0.1),
            ge95(v),
            lost[g].0,
            lost[g].1,
            100.0 * hidden[g].iter().sum::<f64>() / hidden[g].len().max(1) as f64,
        );
    }
    Ok(())
}
