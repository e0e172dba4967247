//! Can the image tell one wrong finger from a right one? On the sequences that
//! `bench robustness --keep DIR` kept, each kept (tracked) frame's fingers are scored one at a
//! time and the scores set against each finger's true fingertip error:
//!
//! - `bright`: the share of points along the finger's visible link axes that are hand-bright
//!   (above the midpoint of the whole silhouette grid's inside and outside means);
//! - `chamfer`: the mean oriented chamfer distance (px) of the finger's visible silhouette
//!   points (the likelihood's edge term, per finger);
//! - `unexplained`: the share of the grid's samples outside the model that are hand-bright
//!   (the image's hand the model does not cover), per camera, the worst.
//!
//! A finger is *wrong* when its tip is over 10 px off in some camera and *right* when under
//! 3 px in all. Printed: each score's distribution for both, and how often the score prefers
//! the finger's true joints (the rest of the hand as kept) over the kept ones when the finger
//! is wrong: what a per-finger re-acquisition scored this way could do.
//!
//! With `--drift`, the same scores as a lost signal: each finger's chamfer and bright share
//! against its own level on the seed's first `--reference` scored frames, the worst finger's
//! change per frame, and the AUC for the frames truly lost (as the benchmark judges them)
//! against the right ones, among the frames the lost flag leaves unflagged.
//!
//! ```text
//! digiteyes bench robustness --seeds 60 --frames 200 --keep /tmp/keep
//! cargo run --release -p digiteyes-host --example finger_check -- /tmp/keep [--drift]
//! ```

use std::path::{Path, PathBuf};

#[path = "common/kept.rs"]
mod kept;
#[path = "common/roc.rs"]
mod roc;

use anyhow::Result;
use clap::Parser;
use digiteyes_core::camera::Camera;
use digiteyes_core::frame::FrameView;
use digiteyes_core::hypotheses::fingers::Fingers;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::likelihood::{EdgeMap, LikelihoodConfig, Samples};
use digiteyes_core::model::{Model, Shape};
use digiteyes_core::nalgebra::Vector2;
use digiteyes_core::projection::ProjectedModel;
use digiteyes_core::silhouette::{covers, hand_bounds};
use digiteyes_core::visibility::{candidates, cover_among, Cover};
use digiteyes_host::eval::{reprojection_error, stats};
use digiteyes_host::sequence::{read_states, Sequence};

#[derive(Parser)]
struct Args {
    /// A folder of kept seeds (`seedNNNN/`), as `bench robustness --keep` writes.
    dir: PathBuf,
    /// Score every this many frames.
    #[arg(long, default_value_t = 4)]
    every: usize,
    /// Only frames where all fingers are right, or one is wrong and the rest within 5 px.
    #[arg(long)]
    single: bool,
    /// Instead: each finger's scores against its own level on the seed's first
    /// `--reference` scored frames (the track starts at the truth), the worst finger's change
    /// per frame as a lost signal, judged as the benchmark judges frames.
    #[arg(long)]
    drift: bool,
    /// With `--drift`: scored frames that set each finger's own level.
    #[arg(long, default_value_t = 5)]
    reference: usize,
}

/// Per finger: bright share and chamfer; and the unexplained share, of one camera's view.
struct Scores {
    bright: Vec<Option<f32>>,
    chamfer: Vec<Option<f32>>,
    unexplained: f32,
}

fn score_view(
    model: &Model,
    fingers: &Fingers,
    view: &ProjectedModel,
    camera: &Camera,
    frame: &FrameView<'_>,
    edges: &EdgeMap<'_>,
    config: &LikelihoodConfig,
) -> Option<Scores> {
    // The silhouette grid's class means set the bright threshold.
    let bounds = hand_bounds(view)?;
    let size = bounds.max - bounds.min;
    let min = bounds.min - size * 0.25;
    let grid = 32;
    let step = size * 1.5 / (grid - 1) as f32;
    let mut inside = Vec::new();
    let mut outside = Vec::new();
    for j in 0..grid {
        for i in 0..grid {
            let p = Vector2::new(min.x + step.x * i as f32, min.y + step.y * j as f32);
            let Some(v) = frame.sample(p.x, p.y) else {
                continue;
            };
            if covers(view, camera, &p) {
                inside.push(v);
            } else {
                outside.push(v);
            }
        }
    }
    if inside.len() < 8 || outside.len() < 8 {
        return None;
    }
    let mean = |v: &[f32]| v.iter().sum::<f32>() / v.len() as f32;
    let threshold = 0.5 * (mean(&inside) + mean(&outside));
    let unexplained =
        outside.iter().filter(|&&v| v > threshold).count() as f32 / outside.len() as f32;
    let n = fingers.count();
    let mut bright_hits = vec![(0u32, 0u32); n];
    for (index, link) in view.links.iter().enumerate() {
        let Some(f) = kept::finger_of_frame(model, fingers, usize::from(link.frame)) else {
            continue;
        };
        let (among, palm) = candidates(view, index, &link.bounds);
        let (_, normal) = link.axis_frame();
        for k in 0..7 {
            let s = (k as f32 + 0.5) / 7.0;
            let axis = link.a + (link.b - link.a) * s;
            for side in [-0.4f32, 0.0, 0.4] {
                let p = axis + normal * (side * link.radius_at(s));
                if cover_among(view, camera, &among, palm, &p, link.depth_at(s)) == Cover::Hidden {
                    continue;
                }
                let Some(v) = frame.sample(p.x, p.y) else {
                    continue;
                };
                bright_hits[f].1 += 1;
                if v > threshold {
                    bright_hits[f].0 += 1;
                }
            }
        }
    }
    let bright = bright_hits
        .iter()
        .map(|&(b, t)| (t >= 6).then(|| b as f32 / t as f32))
        .collect();
    // Per-finger chamfer: the likelihood's samples, grouped by the link they came from.
    let mut chamfer = vec![(0.0f32, 0u32); n];
    for (index, link) in view.links.iter().enumerate() {
        let Some(f) = kept::finger_of_frame(model, fingers, usize::from(link.frame)) else {
            continue;
        };
        let mut one = view.clone();
        one.links.clear();
        let _ = one.links.push(*link);
        one.palm = None;
        let samples = Samples::of(&one, camera, config);
        // Visibility against the whole view: drop points a nearer part hides.
        let (among, palm) = candidates(view, index, &link.bounds);
        for p in &samples.points {
            if cover_among(view, camera, &among, palm, &p.at, link.depth_at(0.5)) == Cover::Hidden {
                continue;
            }
            let d = edges
                .distance_px(usize::from(p.bin), &p.at)
                .unwrap_or(config.chamfer_cap_px)
                .min(config.chamfer_cap_px);
            chamfer[f].0 += d;
            chamfer[f].1 += 1;
        }
    }
    let chamfer = chamfer
        .iter()
        .map(|&(s, c)| (c >= 4).then(|| s / c as f32))
        .collect();
    Some(Scores {
        bright,
        chamfer,
        unexplained,
    })
}

struct Rig<'a> {
    model: &'a Model,
    fingers: &'a Fingers,
    cameras: &'a [Camera],
    frames: &'a [FrameView<'a>],
    edges: &'a [EdgeMap<'a>],
    config: &'a LikelihoodConfig,
}

/// Per finger the worst camera's bright share and chamfer, and the worst unexplained share.
fn score_state(rig: &Rig<'_>, q: &[f32]) -> Option<(Vec<f32>, Vec<f32>, f32)> {
    let poses = Poses::compute(rig.model, q).ok()?;
    let n = rig.fingers.count();
    let mut bright = vec![1.0f32; n];
    let mut chamfer = vec![0.0f32; n];
    let mut unexplained = 0.0f32;
    for ((camera, frame), edges) in rig.cameras.iter().zip(rig.frames).zip(rig.edges) {
        let mut view = ProjectedModel::default();
        view.update(rig.model, &poses, camera, 4.0);
        let Some(s) = score_view(
            rig.model,
            rig.fingers,
            &view,
            camera,
            frame,
            edges,
            rig.config,
        ) else {
            continue;
        };
        for f in 0..n {
            if let Some(b) = s.bright[f] {
                bright[f] = bright[f].min(b);
            }
            if let Some(c) = s.chamfer[f] {
                chamfer[f] = chamfer[f].max(c);
            }
        }
        unexplained = unexplained.max(s.unexplained);
    }
    Some((bright, chamfer, unexplained))
}

/// Per finger, how deep its capsules sink into another finger's (mm, 0 when apart).
fn penetration(rig: &Rig<'_>, q: &[f32]) -> Option<Vec<f32>> {
    let poses = Poses::compute(rig.model, q).ok()?;
    let mut view = ProjectedModel::default();
    view.update(rig.model, &poses, &rig.cameras[0], 0.0);
    let n = rig.fingers.count();
    let mut depth = vec![0.0f32; n];
    let finger = |l: &digiteyes_core::projection::ProjectedLink| {
        kept::finger_of_frame(rig.model, rig.fingers, usize::from(l.frame))
    };
    for a in &view.links {
        let Some(fa) = finger(a) else { continue };
        for b in &view.links {
            let Some(fb) = finger(b) else { continue };
            if fa == fb {
                continue;
            }
            let d = kept::segment_distance_mm(&a.p0, &a.p1, &b.p0, &b.p1);
            depth[fa] = depth[fa].max(a.radius_mm + b.radius_mm - d);
        }
    }
    Some(depth)
}

fn summary(name: &str, v: &[f64]) {
    println!(
        "  {name:<28} n {:>5}  p10 {:>6.3}  p25 {:>6.3}  median {:>6.3}  p75 {:>6.3}  p90 {:>6.3}",
        v.len(),
        stats::percentile(v, 0.1),
        stats::percentile(v, 0.25),
        stats::percentile(v, 0.5),
        stats::percentile(v, 0.75),
        stats::percentile(v, 0.9)
    );
}

/// A kept seed: its sequence, true states and tracked states.
type Kept = (Sequence, Vec<Vec<f32>>, Vec<Vec<f32>>);

fn open(dir: &Path) -> Result<Kept> {
    let sequence = Sequence::open(dir)?;
    let truth = kept::f32s(&sequence.read_truth()?.rows);
    let kept = kept::f32s(&read_states(&dir.join("states.csv"), sequence.n_states())?.rows);
    Ok((sequence, truth, kept))
}

/// `f` of the rig of `seq`'s instant `k`: its frames and their edge maps.
fn with_rig<R>(
    seq: &Sequence,
    k: usize,
    fingers: &Fingers,
    config: &LikelihoodConfig,
    f: impl FnOnce(&Rig<'_>) -> R,
) -> Result<R> {
    let images = kept::read_instant(seq, k)?;
    let frames = kept::views(&images)?;
    let mut buffers = kept::edge_buffers(&frames, config);
    let edges = kept::edge_maps(&mut buffers, &frames, config)?;
    let rig = Rig {
        model: &seq.model,
        fingers,
        cameras: &seq.cameras,
        frames: &frames,
        edges: &edges,
        config,
    };
    Ok(f(&rig))
}

/// `--drift`: per group, the AUC of the worst finger's change in chamfer (px) and in bright
/// share since the seed's first scored frames, and of the worst finger's chamfer itself,
/// for the frames truly lost against the right ones, among the frames the flag leaves.
fn drift(args: &Args) -> Result<()> {
    let config = LikelihoodConfig::default();
    // Per group: (signal chamfer change, bright drop, raw chamfer, truly lost).
    let mut groups: [Vec<(f64, f64, f64, bool)>; 2] = [Vec::new(), Vec::new()];
    for dir in kept::seed_dirs(&args.dir)? {
        let seed = kept::seed_of(&dir);
        let (seq, truth, kept_states) = open(&dir)?;
        let judged = kept::Judged::open(&dir, &seq)?;
        let model = &seq.model;
        let fingers = Fingers::of(model);
        let n = fingers.count();
        let mut history: Vec<Vec<(f32, f32)>> = vec![Vec::new(); n];
        let group = &mut groups[usize::from(seed.is_multiple_of(2))];
        for k in (1..truth.len().min(kept_states.len())).step_by(args.every.max(1)) {
            let scores = with_rig(&seq, k, &fingers, &config, |rig| {
                score_state(rig, &kept_states[k])
            })?;
            let Some((bright, chamfer, _)) = scores else {
                continue;
            };
            let (mut worst_change, mut worst_drop, mut worst_raw) = (0.0f64, 0.0f64, 0.0f64);
            let mut referenced = true;
            for f in 0..n {
                let level = |h: &[(f32, f32)], pick: fn(&(f32, f32)) -> f32| {
                    let v: Vec<f64> = h.iter().map(|x| f64::from(pick(x))).collect();
                    stats::percentile(&v, 0.5)
                };
                if history[f].len() < args.reference {
                    history[f].push((chamfer[f], bright[f]));
                    referenced = false;
                    continue;
                }
                let base = &history[f][..args.reference];
                worst_change = worst_change.max(f64::from(chamfer[f]) - level(base, |x| x.0));
                worst_drop = worst_drop.max(level(base, |x| x.1) - f64::from(bright[f]));
                worst_raw = worst_raw.max(f64::from(chamfer[f]));
            }
            let true_state: Vec<f64> = truth[k].iter().map(|&v| f64::from(v)).collect();
            let (flagged, truly) = judged.frame(k, &true_state);
            if !referenced || flagged {
                continue;
            }
            group.push((worst_change, worst_drop, worst_raw, truly));
        }
        eprintln!("{}", dir.display());
    }
    for (name, frames) in ["mono", "stereo"].iter().zip(&groups) {
        let split = |pick: fn(&(f64, f64, f64, bool)) -> f64| {
            let lost: Vec<f64> = frames.iter().filter(|f| f.3).map(pick).collect();
            let right: Vec<f64> = frames.iter().filter(|f| !f.3).map(pick).collect();
            roc::auc(&lost, &right)
        };
        let lost_count = frames.iter().filter(|f| f.3).count();
        println!(
            "{name}: {} unflagged frames scored, {lost_count} truly lost; AUC: chamfer change {:.3}, \
             bright drop {:.3}, chamfer itself {:.3}",
            frames.len(),
            split(|f| f.0),
            split(|f| f.1),
            split(|f| f.2)
        );
    }
    Ok(())
}

fn main() -> Result<()> {
    let args = Args::parse();
    if args.drift {
        return drift(&args);
    }
    let dirs = kept::seed_dirs(&args.dir)?;
    let config = LikelihoodConfig::default();
    let (mut bright_right, mut bright_wrong) = (Vec::new(), Vec::new());
    let (mut chamfer_right, mut chamfer_wrong) = (Vec::new(), Vec::new());
    let (mut unexpl_right, mut unexpl_wrong) = (Vec::new(), Vec::new());
    let (mut pen_right, mut pen_wrong, mut pen_truth_wrong) = (Vec::new(), Vec::new(), Vec::new());
    let (mut prefers_bright, mut prefers_chamfer, mut prefers_unexpl, mut asked) = (0, 0, 0, 0);
    for dir in dirs {
        let (seq, truth, kept) = open(&dir)?;
        let model = &seq.model;
        let fingers = Fingers::of(model);
        // Each finger's tip link.
        let tips: Vec<(usize, usize)> = (0..model.links().len())
            .filter(|&i| matches!(model.links()[i].shape, Shape::Tip { .. }))
            .filter_map(|i| kept::finger_of_frame(model, &fingers, i).map(|f| (f, i)))
            .collect();
        for k in (1..truth.len().min(kept.len())).step_by(args.every.max(1)) {
            with_rig(&seq, k, &fingers, &config, |rig| -> Result<()> {
                let (pt, pe) = (
                    Poses::compute(model, &truth[k])?,
                    Poses::compute(model, &kept[k])?,
                );
                let Some((bright, chamfer, unexplained)) = score_state(rig, &kept[k]) else {
                    return Ok(());
                };
                let tip_err = |tip: usize| {
                    seq.cameras
                        .iter()
                        .map(|c| reprojection_error(c, &pt, &pe, tip))
                        .fold(0.0f64, f64::max)
                };
                let wrong_count = tips.iter().filter(|&&(_, t)| tip_err(t) > 10.0).count();
                let others_right =
                    tips.iter().filter(|&&(_, t)| tip_err(t) < 5.0).count() + 1 == tips.len();
                if args.single && !(wrong_count == 0 || (wrong_count == 1 && others_right)) {
                    return Ok(());
                }
                let pen = penetration(rig, &kept[k]).unwrap_or_default();
                let pen_truth = penetration(rig, &truth[k]).unwrap_or_default();
                let mut any_wrong = false;
                for &(f, tip) in &tips {
                    let e = tip_err(tip);
                    if let (Some(p), Some(pt)) = (pen.get(f), pen_truth.get(f)) {
                        if e < 3.0 {
                            pen_right.push(f64::from(*p));
                        } else if e > 10.0 {
                            pen_wrong.push(f64::from(*p));
                            pen_truth_wrong.push(f64::from(*pt));
                        }
                    }
                    let err = seq
                        .cameras
                        .iter()
                        .map(|c| reprojection_error(c, &pt, &pe, tip))
                        .fold(0.0f64, f64::max);
                    let (b, c) = (f64::from(bright[f]), f64::from(chamfer[f]));
                    if err < 3.0 {
                        bright_right.push(b);
                        chamfer_right.push(c);
                    } else if err > 10.0 {
                        any_wrong = true;
                        bright_wrong.push(b);
                        chamfer_wrong.push(c);
                        // The same hand with this finger's joints at the truth.
                        let mut q = kept[k].clone();
                        for (s, v) in q.iter_mut().enumerate() {
                            if fingers.contains(f, s) {
                                *v = truth[k][s];
                            }
                        }
                        if let Some((b2, c2, u2)) = score_state(rig, &q) {
                            asked += 1;
                            prefers_bright += usize::from(b2[f] > bright[f]);
                            prefers_chamfer += usize::from(c2[f] < chamfer[f]);
                            prefers_unexpl += usize::from(u2 < unexplained);
                        }
                    }
                }
                if any_wrong {
                    unexpl_wrong.push(f64::from(unexplained));
                } else if tips.iter().all(|&(_, tip)| {
                    seq.cameras
                        .iter()
                        .all(|c| reprojection_error(c, &pt, &pe, tip) < 3.0)
                }) {
                    unexpl_right.push(f64::from(unexplained));
                }
                Ok(())
            })??;
        }
        eprintln!("{}", dir.display());
    }
    println!("fingers right (tip < 3 px) vs wrong (> 10 px), kept states:");
    summary("bright, right", &bright_right);
    summary("bright, wrong", &bright_wrong);
    summary("chamfer px, right", &chamfer_right);
    summary("chamfer px, wrong", &chamfer_wrong);
    summary("penetration mm, right", &pen_right);
    summary("penetration mm, wrong", &pen_wrong);
    summary("... the truth there", &pen_truth_wrong);
    println!("frames all right vs some finger wrong:");
    summary("unexplained, right", &unexpl_right);
    summary("unexplained, wrong", &unexpl_wrong);
    println!(
        "wrong fingers set to the truth ({asked}): bright prefers truth {:.2}, chamfer {:.2}, unexplained {:.2}",
        prefers_bright as f64 / asked.max(1) as f64,
        prefers_chamfer as f64 / asked.max(1) as f64,
        prefers_unexpl as f64 / asked.max(1) as f64
    );
    Ok(())
}
