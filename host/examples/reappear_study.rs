//! When does a tracked finger go wrong: while the cameras see it, while it is hidden, or just
//! after it comes back into view? On the sequences `bench robustness --keep DIR` kept (their
//! truth, cameras and the tracked `states.csv`), each finger's tip error (mean over the
//! cameras, px) is followed frame by frame, and so is whether the truth's distal link of that
//! finger is seen by some camera (`common/seen.rs`: a point of its axis inside the frame and
//! not hidden by a nearer part of the hand).
//!
//! A finger's *onset* is a frame at which its tip error rises over the limit and stays over it
//! for the next frames, while the palm is still within its limit (a finger going wrong, not
//! the hand). Each frame at which the finger is within the limit is *at risk*, and is put in
//! one of three classes by the finger's visibility: hidden now; seen now but hidden in one of
//! the last `window` frames (just back in view); seen throughout. The onsets per at-risk frame
//! of each class say where fingers are lost.
//!
//! Each class is also split by whether the *tracked* state's own distal link is seen: the
//! tracker searches only a link its state shows, so a finger whose last link the image shows
//! and the track hides cannot be pulled back by its slices. `--at-risk-px` counts a finger at
//! risk only while nearer the truth than that (with `--limit-px` as low, the frame a finger
//! first leaves the truth, before its own error can hide its link).
//!
//! ```text
//! digiteyes bench robustness --seeds 60 --frames 200 --keep /tmp/keep
//! cargo run --release -p digiteyes-host --example reappear_study -- /tmp/keep [--window 10] [--oracle]
//! ```

use std::path::PathBuf;

use anyhow::{ensure, Result};
use clap::Parser;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::projection::ProjectedModel;
use digiteyes_host::eval::reprojection_error;
use digiteyes_host::eval::stats::percentile;
use digiteyes_host::sequence::{read_states, Sequence};

#[path = "common/kept.rs"]
mod kept;
#[path = "common/seen.rs"]
mod seen;

#[derive(Parser)]
struct Args {
    /// Folders of kept seeds (`seedNNNN/`), as `bench robustness --keep` writes.
    #[arg(required = true)]
    dirs: Vec<PathBuf>,
    /// Frames back a finger counts as just back in view after being hidden.
    #[arg(long, default_value_t = 10)]
    window: usize,
    /// A finger's tip error over this is wrong (px at the frame's own width).
    #[arg(long, default_value_t = 20.0)]
    limit_px: f64,
    /// A finger is at risk only while its tip error is under this (px; default: the limit):
    /// a lower bar asks whether a class goes wrong from a finger that was near right.
    #[arg(long)]
    at_risk_px: Option<f64>,
    /// Read each seed's tracked states from `DIR/seedN.csv` (as `kept_ab --states-out`
    /// keeps a variant's) instead of the seed's own `states.csv`.
    #[arg(long)]
    states_dir: Option<PathBuf>,
    /// Frames the error must stay over the limit for an onset.
    #[arg(long, default_value_t = 5)]
    hold: usize,
    /// The palm's limit (mm): onsets with the palm farther off are the hand's, not a finger's.
    #[arg(long, default_value_t = 30.0)]
    palm_mm: f64,
    /// Follow the seen-oracle of `seen_bound` (every seen joint true, an unseen one held)
    /// instead of the tracked states: how often a finger goes wrong only by being held.
    #[arg(long)]
    oracle: bool,
    /// Print every onset: seed, finger, frame, class, and the finger's worst shown and hidden
    /// joint errors (degrees).
    #[arg(long)]
    list: bool,
}

/// The three classes of an at-risk frame.
const CLASSES: [&str; 3] = ["hidden now", "back in view", "seen throughout"];

/// Per frame: each finger's tip error (px, mean over cameras), whether its distal link is
/// seen, and the palm's error (mm).
struct Frame {
    tip_px: Vec<f64>,
    seen: Vec<bool>,
    /// Per finger: whether the tracked state's own distal link is seen (the model's view,
    /// which decides whether the tracker searches for it).
    model_seen: Vec<bool>,
    palm_mm: f64,
    /// Per finger: the largest error of a joint the truth's links show, and of one they hide
    /// (rad; `None` when the finger has no such joint).
    joint_rad: Vec<[Option<f64>; 2]>,
    /// Per finger: which of its joints (the place in its chain from the palm) is the most
    /// wrong.
    worst_joint: Vec<usize>,
    /// Per finger: each joint's signed error, tracked less true (rad), from the palm out.
    signed_rad: Vec<Vec<f64>>,
}

fn frames(dir: &std::path::Path, oracle: bool, states: &std::path::Path) -> Result<Vec<Frame>> {
    let sequence = Sequence::open(dir)?;
    let model = &sequence.model;
    let n = sequence.n_states();
    let truth = kept::f32s(&sequence.read_truth()?.rows);
    let tracked = if oracle {
        seen::oracle(&sequence, &truth, 1, seen::Unseen::Hold)?.0
    } else {
        kept::f32s(&read_states(states, n)?.rows)
    };
    let mut view = ProjectedModel::default();
    let mut out = Vec::new();
    for (t, e) in truth.iter().zip(&tracked) {
        let (pt, pe) = (Poses::compute(model, t)?, Poses::compute(model, e)?);
        let joints_seen = seen::joints(&sequence, &pt, 1);
        let joints_model_seen = seen::joints(&sequence, &pe, 1);
        let mut tip_px: Vec<f64> = Vec::new();
        let mut seen = Vec::new();
        let mut model_seen = Vec::new();
        let mut joint_rad = Vec::new();
        let mut worst_joint = Vec::new();
        let mut signed_rad = Vec::new();
        for (c, camera) in sequence.cameras.iter().enumerate() {
            view.update(model, &pt, camera, 0.0);
            for (f, link) in view.links.iter().filter(|l| l.distal).enumerate() {
                let error = reprojection_error(camera, &pt, &pe, usize::from(link.child));
                if c == 0 {
                    tip_px.push(0.0);
                    let chain = model.chain(usize::from(link.frame)).unwrap_or_default();
                    // The distal link's own joint: the last state of its chain.
                    let last = chain.last().copied().map(usize::from);
                    seen.push(last.is_some_and(|s| joints_seen[s]));
                    model_seen.push(last.is_some_and(|s| joints_model_seen[s]));
                    let mut worst = [None::<f64>; 2];
                    let mut most = (0, -1.0);
                    for (place, &s) in chain.iter().enumerate() {
                        let s = usize::from(s);
                        let error = f64::from((t[s] - e[s]).abs());
                        if error > most.1 {
                            most = (place, error);
                        }
                        let w = &mut worst[usize::from(!joints_seen[s])];
                        *w = Some(w.map_or(error, |v: f64| v.max(error)));
                    }
                    joint_rad.push(worst);
                    signed_rad.push(
                        chain
                            .iter()
                            .map(|&s| f64::from(e[usize::from(s)] - t[usize::from(s)]))
                            .collect(),
                    );
                    worst_joint.push(most.0);
                }
                if let Some(v) = tip_px.get_mut(f) {
                    *v += error / sequence.cameras.len() as f64;
                }
            }
        }
        let palm_mm = (4..7)
            .map(|i| f64::from(t[i] - e[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        out.push(Frame {
            tip_px,
            seen,
            model_seen,
            palm_mm,
            joint_rad,
            worst_joint,
            signed_rad,
        });
    }
    Ok(out)
}

fn main() -> Result<()> {
    let args = Args::parse();
    ensure!(args.hold >= 1, "--hold must be at least 1");
    // Per group (stereo 0, mono 1), per class: at-risk frames and onsets.
    let mut at_risk = [[0usize; 3]; 2];
    let mut onsets = [[0usize; 3]; 2];
    // Per group, per class: at each onset, the finger's worst seen and hidden joint errors.
    let mut at_onset: [[[Vec<f64>; 2]; 3]; 2] = Default::default();
    // Per group: at each onset, how often each place in the finger's chain was the worst
    // (the four fingers; the thumb apart, as its joints differ).
    let mut worst_place = [[0usize; 5]; 2];
    let mut thumb_place = [[0usize; 5]; 2];
    // Per group, per class, by whether the tracked state's distal link is seen (0: hidden,
    // 1: seen): at-risk frames and onsets.
    let mut by_model = [[[0usize; 2]; 3]; 2];
    let mut onsets_by_model = [[[0usize; 2]; 3]; 2];
    for base in &args.dirs {
        for dir in kept::seed_dirs(base)? {
            let seed = kept::seed_of(&dir);
            let g = (seed % 2) as usize;
            let states = match &args.states_dir {
                Some(d) => d.join(format!("seed{seed}.csv")),
                None => dir.join("states.csv"),
            };
            let f = frames(&dir, args.oracle, &states)?;
            let fingers = f.first().map_or(0, |f| f.tip_px.len());
            for finger in 0..fingers {
                for k in 1..f.len().saturating_sub(args.hold) {
                    if f[k - 1].tip_px[finger] > args.at_risk_px.unwrap_or(args.limit_px) {
                        continue;
                    }
                    let class = if !f[k].seen[finger] {
                        0
                    } else if (k.saturating_sub(args.window)..k).any(|j| !f[j].seen[finger]) {
                        1
                    } else {
                        2
                    };
                    at_risk[g][class] += 1;
                    let model = usize::from(f[k].model_seen[finger]);
                    by_model[g][class][model] += 1;
                    let onset = (k..k + args.hold).all(|j| f[j].tip_px[finger] > args.limit_px)
                        && f[k].palm_mm <= args.palm_mm;
                    if onset {
                        onsets[g][class] += 1;
                        onsets_by_model[g][class][model] += 1;
                        let place = f[k].worst_joint[finger].min(4);
                        if finger + 1 == fingers {
                            thumb_place[g][place] += 1;
                        } else {
                            worst_place[g][place] += 1;
                        }
                        if args.list {
                            let [shown, hidden] = f[k].joint_rad[finger].map(|e| {
                                e.map_or("-".into(), |r| format!("{:.0}", r.to_degrees()))
                            });
                            let signed: Vec<String> = f[k].signed_rad[finger]
                                .iter()
                                .map(|r| format!("{:+.0}", r.to_degrees()))
                                .collect();
                            println!(
                                "onset seed {seed} finger {finger} frame {k} {}, the track's distal link {}: shown {shown}°, hidden {hidden}°; tracked − true {}°",
                                CLASSES[class],
                                if model == 1 { "seen" } else { "hidden" },
                                signed.join(" ")
                            );
                        }
                        for (v, e) in at_onset[g][class].iter_mut().zip(f[k].joint_rad[finger]) {
                            v.extend(e);
                        }
                    }
                }
            }
        }
    }
    for (g, name) in [(1, "mono"), (0, "stereo")] {
        let total: usize = onsets[g].iter().sum();
        println!(
            "{name}: {total} finger onsets; the most wrong joint, from the palm out: fingers {:?}, thumb {:?}",
            &worst_place[g][..4],
            thumb_place[g]
        );
        for (c, class) in CLASSES.iter().enumerate() {
            let rate = onsets[g][c] as f64 / at_risk[g][c].max(1) as f64;
            let median = |v: &[f64]| {
                if v.is_empty() {
                    "-".to_string()
                } else {
                    format!("{:.0}°", percentile(v, 0.5).to_degrees())
                }
            };
            let [shown, hidden] = &at_onset[g][c];
            println!(
                "  {class:>16}: {:>6} at-risk finger-frames, {:>4} onsets, {:.2} per 100; \
                 at onset, worst joint error median: shown {} ({} fingers), hidden {} ({})",
                at_risk[g][c],
                onsets[g][c],
                100.0 * rate,
                median(shown),
                shown.len(),
                median(hidden),
                hidden.len()
            );
            for (m, view) in ["hidden", "seen"].iter().enumerate() {
                println!(
                    "  {:>16}  the track's own distal link {view:>6}: {:>6} at-risk, {:>4} onsets, {:.2} per 100",
                    "",
                    by_model[g][c][m],
                    onsets_by_model[g][c][m],
                    100.0 * onsets_by_model[g][c][m] as f64 / by_model[g][c][m].max(1) as f64
                );
            }
        }
    }
    Ok(())
}
