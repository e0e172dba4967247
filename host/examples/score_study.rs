//! Does the image likelihood rank a frame's hypotheses better with a second, reverse chamfer
//! term? Today's score asks how far each projected silhouette line lies from a like-oriented
//! image edge (model → image). A finger read onto the palm or a neighbour finds edges under
//! its lines there, and nothing asks about the true finger's edges that no model line
//! explains. The reverse term asks it: the mean distance (px, truncated at `--cap-px`) from
//! each edge cell of the frame's edge map near the hand to the nearest visible model
//! silhouette point (or palm outline point) of like orientation.
//!
//! On the sequences `bench robustness --keep DIR` kept, a variant (default `k=4`) tracks
//! each seed and writes its hypotheses; every `--every`th frame carrying several is scored
//! again, each hypothesis and the truth, under today's score and under today's score less
//! `w × reverse / cap` for each `--weights` w. Printed per group (mono, stereo) and weight:
//! how often the score's choice is the hypothesis nearest the truth (mean fingertip error),
//! the chosen one's error against the nearest's, the share of pairs whose fingertip errors
//! differ by over 3 px (and 10 px) in which the higher score goes with the nearer, and how
//! often the truth itself scores above the chosen hypothesis (over all frames, and over the
//! frames whose choice is over 10 px off).
//!
//! And one finger at a time, for each finger of the output (rank 0) whose tip is over 10 px
//! off, split by whether the finger's last link is seen at the truth (4 of 7 axis points):
//! how often the score prefers the output with that finger put back at its true joints; with
//! the palm's 7 states put back too; and how often it prefers the truth to the truth with
//! that finger at the output's joints. A per-finger repair can only be chosen right when the
//! first is high.
//!
//! ```text
//! digiteyes bench robustness --seeds 60 --first-seed 8681 --keep /tmp/k8681
//! cargo run --release -p digiteyes-host --example score_study -- --dirs /tmp/k8681
//! ```

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Parser;
use digiteyes_core::camera::Camera;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::likelihood::{
    visit, EdgeMap, LikelihoodConfig, Scene, StateScorer, EDGE_BINS, MIN_LINK_PX,
};
use digiteyes_core::model::BASE_STATES;
use digiteyes_core::nalgebra::Vector2;
use digiteyes_core::palm_outline::PalmOutline;
use digiteyes_core::projection::ProjectedModel;
use digiteyes_host::eval::reprojection_error;
use digiteyes_host::parallel;
use digiteyes_host::sequence::hypotheses::read_hypotheses;
use digiteyes_host::sequence::Sequence;
use digiteyes_host::track::{track_sequence_to, TrackOutputs};

#[path = "common/kept.rs"]
mod kept;
#[path = "common/seen.rs"]
mod seen;

#[derive(Parser)]
struct Args {
    /// Folders of kept seeds (`seedNNNN/`), as `bench robustness --keep` writes.
    #[arg(long, required = true, num_args = 1..)]
    dirs: Vec<PathBuf>,
    /// The variant that tracks and carries the hypotheses, as `kept_ab` takes it.
    #[arg(long, default_value = "k=4")]
    variant: String,
    /// Weights of the reverse term (0 is today's score, always printed first).
    #[arg(long, value_delimiter = ',', default_value = "0.1,0.2,0.4,0.8,1.6")]
    weights: Vec<f32>,
    /// Reverse distances are truncated here (px).
    #[arg(long, default_value_t = 12.0)]
    cap_px: f32,
    /// The region of edge cells: the hypotheses' bounds widened by this (px).
    #[arg(long, default_value_t = 8.0)]
    margin_px: f32,
    /// Score every this many frames.
    #[arg(long, default_value_t = 2)]
    every: usize,
    #[arg(long, default_value_t = 2)]
    jobs: usize,
}

/// Points sampled along each silhouette line for the reverse term.
const POINTS_PER_LINE: u8 = 16;

/// One scored candidate of a frame: today's score, the reverse term (px, mean over the
/// cameras) and its mean fingertip error against the truth (px).
#[derive(Clone, Copy)]
struct Scored {
    score: f32,
    reverse_px: f32,
    tip_px: f64,
}

/// A frame's hypotheses and the truth, scored; and, for each finger of the output over
/// [`WRONG_FINGER_PX`] off, the output and the output with that finger at its true joints.
struct FrameScores {
    hypotheses: Vec<Scored>,
    truth: Scored,
    fingers_put_back: Vec<(Scored, Scored, bool)>,
    /// The same, with the palm's 7 states put back too.
    with_palm_put_back: Vec<(Scored, Scored, bool)>,
    /// The same fingers: the truth, and the truth with that finger at the output's joints.
    fingers_in_truth: Vec<(Scored, Scored, bool)>,
}

/// A finger of the output is wrong when its tip is this far off (px, mean over cameras).
const WRONG_FINGER_PX: f64 = 10.0;

/// How well one score ranks, summed over frames.
#[derive(Default, Clone, Copy)]
struct Ranking {
    frames: usize,
    chosen_nearest: usize,
    chosen_px: f64,
    nearest_px: f64,
    pairs: [usize; 2],
    agreeing: [usize; 2],
    truth_above: usize,
    /// Frames whose choice is over 10 px off, and of those, frames the truth scores above it.
    far_frames: usize,
    truth_above_far: usize,
    /// Wrong fingers of the output, and how often the score prefers it put back.
    /// Indexed by whether the finger's last joint is seen at the truth.
    wrong_fingers: [usize; 2],
    put_back_preferred: [usize; 2],
    truth_preferred: [usize; 2],
    with_palm_preferred: [usize; 2],
}

const APART_PX: [f64; 2] = [3.0, 10.0];

impl Ranking {
    fn add(&mut self, f: &FrameScores, value: &dyn Fn(&Scored) -> f32) {
        for (output, put_back, seen) in &f.fingers_put_back {
            self.wrong_fingers[usize::from(*seen)] += 1;
            self.put_back_preferred[usize::from(*seen)] +=
                usize::from(value(put_back) > value(output));
        }
        for (output, put_back, seen) in &f.with_palm_put_back {
            self.with_palm_preferred[usize::from(*seen)] +=
                usize::from(value(put_back) > value(output));
        }
        for (truth, wrong, seen) in &f.fingers_in_truth {
            self.truth_preferred[usize::from(*seen)] += usize::from(value(truth) > value(wrong));
        }
        let h = &f.hypotheses;
        let Some(chosen) = h.iter().max_by(|a, b| value(a).total_cmp(&value(b))) else {
            return;
        };
        let nearest = h.iter().map(|s| s.tip_px).fold(f64::INFINITY, f64::min);
        self.frames += 1;
        self.chosen_nearest += usize::from(chosen.tip_px <= nearest);
        self.chosen_px += chosen.tip_px;
        self.nearest_px += nearest;
        self.truth_above += usize::from(value(&f.truth) > value(chosen));
        if chosen.tip_px > APART_PX[1] {
            self.far_frames += 1;
            self.truth_above_far += usize::from(value(&f.truth) > value(chosen));
        }
        for (i, a) in h.iter().enumerate() {
            for b in &h[i + 1..] {
                for (j, &apart) in APART_PX.iter().enumerate() {
                    if (a.tip_px - b.tip_px).abs() > apart && value(a) != value(b) {
                        self.pairs[j] += 1;
                        self.agreeing[j] +=
                            usize::from((value(a) > value(b)) == (a.tip_px < b.tip_px));
                    }
                }
            }
        }
    }
}

/// The edge cells of `edges` within `region` (min, max px): each cell's centre and the bins
/// (a bit each) in which it holds an edge.
fn edge_cells(
    edges: &EdgeMap<'_>,
    region: (Vector2<f32>, Vector2<f32>),
) -> Vec<(Vector2<f32>, u8)> {
    let s = edges.stride_px() as f32;
    let (cols, rows) = edges.cells();
    let mut out = Vec::new();
    let lo_x = (region.0.x / s).floor().max(0.0) as usize;
    let lo_y = (region.0.y / s).floor().max(0.0) as usize;
    let hi_x = ((region.1.x / s).ceil().max(0.0) as usize).min(cols);
    let hi_y = ((region.1.y / s).ceil().max(0.0) as usize).min(rows);
    for cy in lo_y..hi_y {
        for cx in lo_x..hi_x {
            let c = Vector2::new((cx as f32 + 0.5) * s, (cy as f32 + 0.5) * s);
            let mut mask = 0u8;
            for bin in 0..EDGE_BINS {
                if edges.distance_units(bin, &c) == Some(0) {
                    mask |= 1 << bin;
                }
            }
            if mask != 0 {
                out.push((c, mask));
            }
        }
    }
    out
}

/// The orientation bin of a line whose normal points at `angle` (rad), as the edge map bins.
fn bin_of(angle: f32) -> u8 {
    let pi = std::f32::consts::PI;
    let a = angle.rem_euclid(pi);
    ((a / pi * EDGE_BINS as f32).round() as usize % EDGE_BINS) as u8
}

/// The visible model silhouette points of `view` and its palm outline's points, each with
/// its bin.
fn model_points(view: &ProjectedModel, camera: &Camera) -> Vec<(Vector2<f32>, u8)> {
    let config = LikelihoodConfig {
        samples_per_line: POINTS_PER_LINE,
        ..LikelihoodConfig::default()
    };
    let mut out = Vec::new();
    visit(view, camera, &config, |p| out.push((p.at, p.bin)));
    let mut outline = PalmOutline::new();
    outline.update(view.palm.as_ref(), 1.0);
    for edge in &outline.edges {
        let (a, b) = (edge.segment.a, edge.segment.b);
        let n = edge.segment.normal();
        let bin = bin_of(n.y.atan2(n.x));
        for i in 0..POINTS_PER_LINE {
            let t = (f32::from(i) + 0.5) / f32::from(POINTS_PER_LINE);
            out.push((a + (b - a) * t, bin));
        }
    }
    out
}

/// The reverse chamfer term: the mean over `cells` of the distance (px, at most `cap`) to
/// the nearest point of `points` of a bin the cell holds.
fn reverse_px(cells: &[(Vector2<f32>, u8)], points: &[(Vector2<f32>, u8)], cap: f32) -> f32 {
    if cells.is_empty() {
        return 0.0;
    }
    // Buckets of `cap` px, so a cell's nearest point within the cap is in its 3×3 buckets.
    let mut buckets: std::collections::HashMap<(i32, i32), Vec<usize>> = Default::default();
    let key = |p: &Vector2<f32>| ((p.x / cap).floor() as i32, (p.y / cap).floor() as i32);
    for (i, (p, _)) in points.iter().enumerate() {
        buckets.entry(key(p)).or_default().push(i);
    }
    let mut sum = 0.0;
    for (c, mask) in cells {
        let (kx, ky) = key(c);
        let mut best = cap;
        for dy in -1..=1 {
            for dx in -1..=1 {
                for &i in buckets.get(&(kx + dx, ky + dy)).into_iter().flatten() {
                    let (p, bin) = points[i];
                    if mask & (1 << bin) != 0 {
                        best = best.min((p - c).norm());
                    }
                }
            }
        }
        sum += best;
    }
    sum / cells.len() as f32
}

/// The bounds (px) of every link and palm of `view`.
fn bounds(view: &ProjectedModel) -> Option<(Vector2<f32>, Vector2<f32>)> {
    let mut b: Option<(Vector2<f32>, Vector2<f32>)> = None;
    let all = view
        .links
        .iter()
        .map(|l| l.bounds)
        .chain(view.palm.iter().map(|p| p.bounds));
    for x in all {
        b = Some(match b {
            None => (x.min, x.max),
            Some((lo, hi)) => (lo.inf(&x.min), hi.sup(&x.max)),
        });
    }
    b
}

fn study(dir: &Path, args: &Args) -> Result<Vec<FrameScores>> {
    let (config, options) = kept::variant(&args.variant)?;
    let seed = kept::seed_of(dir);
    let out = std::env::temp_dir().join(format!("score_study_{}_{seed}.csv", std::process::id()));
    let hypotheses_out = out.with_extension("hypotheses.csv");
    let sequence = Sequence::open(dir)?;
    let n = sequence.n_states();
    let outputs = TrackOutputs {
        hypotheses_out: Some(hypotheses_out.as_path()),
        ..TrackOutputs::default()
    };
    let tracked = track_sequence_to(dir, &out, config, false, &outputs, &options)
        .and_then(|_| read_hypotheses(&hypotheses_out, n));
    let _ = std::fs::remove_file(&out);
    let _ = std::fs::remove_file(&hypotheses_out);
    let table = tracked?;
    let carried = table.by_frame(sequence.frames);
    let model = &sequence.model;
    let truth = kept::f32s(&sequence.read_truth()?.rows);
    let names = ["finger1", "finger2", "finger3", "finger4", "thumb"];
    let mut tips = Vec::new();
    let mut fingers = Vec::new();
    for name in names {
        let tip = model
            .find(&format!("{name}.tip"))
            .with_context(|| format!("no {name}"))?;
        tips.push(tip);
        let chain = model
            .chain(tip)
            .with_context(|| format!("no chain for {name}"))?;
        let joints: Vec<usize> = chain
            .iter()
            .map(|&s| usize::from(s))
            .filter(|&s| s >= BASE_STATES)
            .collect();
        fingers.push(joints);
    }
    let likelihood = LikelihoodConfig::default();
    let mut scorer = StateScorer::new();
    let mut view = ProjectedModel::new();
    let mut out = Vec::new();
    for (k, hypotheses) in carried.iter().enumerate() {
        if hypotheses.len() < 2 || k % args.every != 0 {
            continue;
        }
        let images = kept::read_instant(&sequence, k)?;
        let frames = kept::views(&images)?;
        let mut buffers = kept::edge_buffers(&frames, &likelihood);
        let maps = kept::edge_maps(&mut buffers, &frames, &likelihood)?;
        let scene = Scene::new(model, &sequence.cameras, &frames, &maps);
        let truth_poses = Poses::compute(model, &truth[k])?;
        let mut states: Vec<Vec<f32>> = hypotheses
            .iter()
            .map(|h| h.state.iter().map(|&v| v as f32).collect())
            .collect();
        states.push(truth[k].clone());
        // The region: every hypothesis' bounds in each camera (not the truth's), widened.
        let mut cells = Vec::new();
        for (c, camera) in sequence.cameras.iter().enumerate() {
            let mut region: Option<(Vector2<f32>, Vector2<f32>)> = None;
            for q in &states[..hypotheses.len()] {
                let poses = Poses::compute(model, q)?;
                view.update(model, &poses, camera, MIN_LINK_PX);
                if let Some((lo, hi)) = bounds(&view) {
                    region = Some(match region {
                        None => (lo, hi),
                        Some((a, b)) => (a.inf(&lo), b.sup(&hi)),
                    });
                }
            }
            let m = Vector2::new(args.margin_px, args.margin_px);
            cells.push(
                region
                    .map(|(lo, hi)| edge_cells(&maps[c], (lo - m, hi + m)))
                    .unwrap_or_default(),
            );
        }
        let cameras = sequence.cameras.len().max(1);
        let mut score_of = |q: &[f32]| -> Result<(Scored, Vec<f64>)> {
            let poses = Poses::compute(model, q)?;
            let score = scorer.score(&scene, q, &likelihood);
            let mut reverse = 0.0;
            let mut per_tip = vec![0.0; tips.len()];
            for (c, camera) in sequence.cameras.iter().enumerate() {
                view.update(model, &poses, camera, MIN_LINK_PX);
                reverse += reverse_px(&cells[c], &model_points(&view, camera), args.cap_px);
                for (e, &t) in per_tip.iter_mut().zip(&tips) {
                    *e += reprojection_error(camera, &truth_poses, &poses, t) / cameras as f64;
                }
            }
            let tip_px = per_tip.iter().sum::<f64>() / tips.len().max(1) as f64;
            Ok((
                Scored {
                    score,
                    reverse_px: reverse / cameras as f32,
                    tip_px,
                },
                per_tip,
            ))
        };
        let mut scored = Vec::new();
        let mut output_tips = Vec::new();
        for (i, q) in states.iter().enumerate() {
            let (s, per_tip) = score_of(q)?;
            if i == 0 {
                output_tips = per_tip;
            }
            scored.push(s);
        }
        let truth = scored.pop().context("no truth")?;
        let seen = seen::joints(&sequence, &truth_poses, 4);
        let mut fingers_put_back = Vec::new();
        let mut fingers_in_truth = Vec::new();
        let mut with_palm_put_back = Vec::new();
        for (f, joints) in fingers.iter().enumerate() {
            if output_tips.get(f).is_some_and(|&e| e > WRONG_FINGER_PX) {
                let mut q = states[0].clone();
                for &j in joints {
                    q[j] = states[hypotheses.len()][j];
                }
                let last_seen = joints.last().is_some_and(|&j| seen[j]);
                fingers_put_back.push((scored[0], score_of(&q)?.0, last_seen));
                q[..BASE_STATES].copy_from_slice(&states[hypotheses.len()][..BASE_STATES]);
                with_palm_put_back.push((scored[0], score_of(&q)?.0, last_seen));
                let mut q = states[hypotheses.len()].clone();
                for &j in joints {
                    q[j] = states[0][j];
                }
                fingers_in_truth.push((truth, score_of(&q)?.0, last_seen));
            }
        }
        out.push(FrameScores {
            hypotheses: scored,
            truth,
            fingers_put_back,
            fingers_in_truth,
            with_palm_put_back,
        });
    }
    Ok(out)
}

fn main() -> Result<()> {
    let args = Args::parse();
    let mut dirs = Vec::new();
    for d in &args.dirs {
        dirs.extend(kept::seed_dirs(d)?);
    }
    let results = parallel::map(&dirs, args.jobs, |d| (kept::seed_of(d), study(d, &args)));
    let mut weights = vec![0.0f32];
    weights.extend(&args.weights);
    println!(
        "variant {}, cap {} px, {} seeds; per weight: frames, chosen nearest %, chosen px / nearest px, pairs >3 px agree %, >10 px agree %, truth above chosen %",
        args.variant,
        args.cap_px,
        dirs.len()
    );
    for (parity, group) in [(1, "mono"), (0, "stereo")] {
        let frames: Vec<&FrameScores> = results
            .iter()
            .filter(|(seed, _)| seed % 2 == parity)
            .filter_map(|(seed, r)| match r {
                Ok(f) => Some(f),
                Err(e) => {
                    eprintln!("seed {seed}: {e:#}");
                    None
                }
            })
            .flatten()
            .collect();
        for &w in &weights {
            let cap = args.cap_px;
            let value = move |s: &Scored| s.score - w * s.reverse_px / cap;
            let mut r = Ranking::default();
            for f in &frames {
                r.add(f, &value);
            }
            let pct = |a: usize, b: usize| 100.0 * a as f64 / b.max(1) as f64;
            println!(
                "{group:6} w {w:4.2}: {:6} frames, nearest {:5.1} %, {:5.2} / {:5.2} px, >3 px {:5.1} % of {}, >10 px {:5.1} % of {}, truth above {:5.1} % (over 10 px off: {:5.1} % of {}), wrong finger put back preferred: hidden {:5.1} % of {}, seen {:5.1} % of {}; truth preferred to it with the output's finger: hidden {:5.1} %, seen {:5.1} %; put back with the palm preferred: hidden {:5.1} %, seen {:5.1} %",
                r.frames,
                pct(r.chosen_nearest, r.frames),
                r.chosen_px / r.frames.max(1) as f64,
                r.nearest_px / r.frames.max(1) as f64,
                pct(r.agreeing[0], r.pairs[0]),
                r.pairs[0],
                pct(r.agreeing[1], r.pairs[1]),
                r.pairs[1],
                pct(r.truth_above, r.frames),
                pct(r.truth_above_far, r.far_frames),
                r.far_frames,
                pct(r.put_back_preferred[0], r.wrong_fingers[0]),
                r.wrong_fingers[0],
                pct(r.put_back_preferred[1], r.wrong_fingers[1]),
                r.wrong_fingers[1],
                pct(r.truth_preferred[0], r.wrong_fingers[0]),
                pct(r.truth_preferred[1], r.wrong_fingers[1]),
                pct(r.with_palm_preferred[0], r.wrong_fingers[0]),
                pct(r.with_palm_preferred[1], r.wrong_fingers[1]),
            );
        }
    }
    Ok(())
}
