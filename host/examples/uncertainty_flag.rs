//! Does the track's own uncertainty tell a lost frame? The lost flag misses most truly lost
//! frames: a finger placed wrong on a hand whose likelihood stays within the watch's bar
//! (`docs/robustness.md`, "The lost flag's recall"). Most of those are fingers whose last
//! joints the images hardly show ("What the images tell of each joint"). A tracker that kept
//! a covariance would know it: a state the images leave to the motion model grows uncertain
//! frame by frame, and so does the fingertip it places.
//!
//! For each seed `bench robustness --keep DIR` kept, every frame the tracker is put at the
//! *kept* state and runs one iteration of its own search there; the information `JᵀWJ` of
//! that iteration (less the prior) updates a Kalman covariance over the free states whose
//! process noise per frame is the prior's own `1 / weight` times `--q-scale`, and whose
//! measurement rows have a standard deviation of `--sigma-px`:
//! `Σ⁻ = Σ + Q`, `Σ = (Σ⁻⁻¹ + I / σ²)⁻¹`. The fingertips' image positions' standard deviation
//! (px, mean over tips and cameras, from a finite-difference Jacobian) is the signal. A frame
//! flagged lost resets `Σ` to `Q`.
//!
//! Printed per group: the signal's AUC for truly lost among the frames the flag leaves, and
//! the lost flag's precision and recall alone and ORed with `signal > T` for several `T`.
//!
//! ```text
//! cargo run --release -p digiteyes-host --example uncertainty_flag -- /tmp/kv_N [/tmp/kv_M ...]
//! ```

use std::path::PathBuf;

use anyhow::Result;
use clap::Parser;
use digiteyes_core::camera::Camera;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::{Model, Shape};
use digiteyes_core::nalgebra::{SMatrix, Vector3};
use digiteyes_host::eval::stats::percentile;
use digiteyes_host::sequence::Sequence;
use digiteyes_host::sequence_tracker;

/// States (all of them; a state not free keeps a unit variance and no column).
const NS: usize = 28;
/// Jacobian rows: u and v of five tips in up to two cameras.
const NR: usize = 20;
type Cov = SMatrix<f64, NS, NS>;
type Jac = SMatrix<f64, NR, NS>;

#[path = "common/kept.rs"]
mod kept;
#[path = "common/roc.rs"]
mod roc;

#[derive(Parser)]
struct Args {
    /// Folders of kept seeds.
    #[arg(required = true)]
    dirs: Vec<PathBuf>,
    /// Process noise per frame as a multiple of the prior's `1 / weight`; several allowed.
    #[arg(long, value_delimiter = ',', default_values_t = [1.0])]
    q_scale: Vec<f64>,
    /// The measurement rows' standard deviation (px); several allowed.
    #[arg(long, value_delimiter = ',', default_values_t = [1.0, 3.0])]
    sigma_px: Vec<f64>,
    /// The signal is the worst fingertip's standard deviation, not the mean over tips.
    #[arg(long)]
    worst: bool,
    /// Thresholds (px) of the signal to OR with the flag.
    #[arg(long, value_delimiter = ',', default_values_t = [3.0, 5.0, 8.0, 12.0, 20.0])]
    thresholds: Vec<f64>,
}

/// One frame: flagged, truly lost, and the signal under each (q, σ) pair.
struct Frame {
    flagged: bool,
    truly: bool,
    signal: Vec<f64>,
}

fn main() -> Result<()> {
    let args = Args::parse();
    let pairs: Vec<(f64, f64)> = args
        .q_scale
        .iter()
        .flat_map(|&q| args.sigma_px.iter().map(move |&s| (q, s)))
        .collect();
    let mut groups: [Vec<Frame>; 2] = [Vec::new(), Vec::new()];
    for dir in &args.dirs {
        for seed_dir in kept::seed_dirs(dir)? {
            let seed = kept::seed_of(&seed_dir);
            let sequence = Sequence::open(&seed_dir)?;
            let truth = sequence.read_truth()?;
            let judged = kept::Judged::open(&seed_dir, &sequence)?;
            let (config, _) = kept::variant("default")?;
            let mut tracker = sequence_tracker(&sequence, config)?;
            let prior = tracker.config().motion.prior;
            let free: Vec<usize> = (0..sequence.n_states())
                .filter(|&s| tracker.free().contains(s))
                .collect();
            let q_base: Vec<f64> = (0..NS)
                .map(|s| {
                    if s < 4 && free.contains(&s) {
                        // No prior on the palm's turn: a quaternion component's process
                        // noise of 0.01 per frame (about 1° of turn).
                        1e-4
                    } else if free.contains(&s) {
                        1.0 / f64::from(prior.for_state(s).max(1e-6))
                    } else {
                        0.0
                    }
                })
                .collect();
            let fresh = |q: f64| {
                Cov::from_fn(|i, j| match (i == j, q_base[i] > 0.0) {
                    (false, _) => 0.0,
                    (true, true) => q * q_base[i],
                    (true, false) => 1.0,
                })
            };
            let mut sigmas: Vec<Cov> = pairs.iter().map(|&(q, _)| fresh(q)).collect();
            let rows = kept::f32s(&judged.table.rows);
            let model = tracker.model().clone();
            let cameras = tracker.cameras().to_vec();
            let g = &mut groups[usize::from(seed.is_multiple_of(2))];
            for (k, true_state) in truth.rows.iter().enumerate().take(rows.len()) {
                let (flagged, truly) = judged.frame(k, true_state);
                let state = &rows[k];
                tracker.reset(state)?;
                let images = kept::read_instant(&sequence, k)?;
                let info = match tracker.track(&kept::views(&images)?) {
                    Ok(_) => {
                        let normal = tracker.normal_equations();
                        Cov::from_fn(|i, j| {
                            if !free.contains(&i) || !free.contains(&j) {
                                return 0.0;
                            }
                            let v = f64::from(normal.element(i, j));
                            if i == j {
                                (v - f64::from(prior.for_state(i))).max(0.0)
                            } else {
                                v
                            }
                        })
                    }
                    Err(_) => Cov::zeros(),
                };
                // JᵀWJ less the prior, clipped to its non-negative directions.
                let eigen = info.symmetric_eigen();
                let clipped = eigen.eigenvalues.map(|l| l.max(0.0));
                let info = eigen.eigenvectors
                    * Cov::from_diagonal(&clipped)
                    * eigen.eigenvectors.transpose();
                let jac = tip_jacobian(&model, &cameras, state, &free);
                let mut signal = Vec::with_capacity(pairs.len());
                for ((q, s), sigma) in pairs.iter().zip(sigmas.iter_mut()) {
                    if flagged {
                        *sigma = fresh(*q);
                    } else {
                        let mut predicted = *sigma;
                        for i in 0..NS {
                            predicted[(i, i)] += q * q_base[i];
                        }
                        let updated = predicted
                            .cholesky()
                            .map(|c| c.inverse() + info / (s * s))
                            .and_then(|a| a.cholesky())
                            .map(|c| c.inverse());
                        *sigma = match updated {
                            Some(u) => (u + u.transpose()) * 0.5,
                            None => predicted,
                        };
                    }
                    signal.push(tip_std_px(&jac, sigma, args.worst));
                }
                g.push(Frame {
                    flagged,
                    truly,
                    signal,
                });
            }
            eprintln!("seed {seed} done");
        }
    }
    for (name, frames) in ["mono", "stereo"].iter().zip(&groups) {
        let (tp, fp, fn_) = confusion(frames, |f| f.flagged);
        println!(
            "{name}: {} frames; the flag alone: precision {:.2}, recall {:.2}",
            frames.len(),
            ratio(tp, tp + fp),
            ratio(tp, tp + fn_)
        );
        for (p, &(q, s)) in pairs.iter().enumerate() {
            let unflagged: Vec<(f64, bool)> = frames
                .iter()
                .filter(|f| !f.flagged)
                .map(|f| (f.signal[p], f.truly))
                .collect();
            let lost: Vec<f64> = unflagged.iter().filter(|u| u.1).map(|u| u.0).collect();
            let right: Vec<f64> = unflagged.iter().filter(|u| !u.1).map(|u| u.0).collect();
            println!(
                "  q×{q}, σ {s} px: AUC {:.3} on {} unflagged lost / {} right; median signal lost {:.1} px, right {:.1} px",
                roc::auc(&lost, &right),
                lost.len(),
                right.len(),
                percentile(&lost, 0.5),
                percentile(&right, 0.5)
            );
            let deciles = |v: &[f64]| {
                let mut v = v.to_vec();
                v.sort_by(f64::total_cmp);
                (1..10)
                    .map(|d| {
                        format!(
                            "{:.1}",
                            v.get(v.len() * d / 10).copied().unwrap_or(f64::NAN)
                        )
                    })
                    .collect::<Vec<_>>()
                    .join(" ")
            };
            println!("    deciles lost: {}", deciles(&lost));
            println!("    deciles right: {}", deciles(&right));
            for &t in &args.thresholds {
                let (tp, fp, fn_) = confusion(frames, |f| f.flagged || f.signal[p] > t);
                println!(
                    "    OR signal > {t} px: precision {:.2}, recall {:.2}",
                    ratio(tp, tp + fp),
                    ratio(tp, tp + fn_)
                );
            }
        }
    }
    Ok(())
}

/// True positives, false positives and false negatives of `flag` against truly lost.
fn confusion(frames: &[Frame], flag: impl Fn(&Frame) -> bool) -> (usize, usize, usize) {
    let mut c = (0, 0, 0);
    for f in frames {
        match (flag(f), f.truly) {
            (true, true) => c.0 += 1,
            (true, false) => c.1 += 1,
            (false, true) => c.2 += 1,
            (false, false) => {}
        }
    }
    c
}

fn ratio(a: usize, b: usize) -> f64 {
    if b == 0 {
        1.0
    } else {
        a as f64 / b as f64
    }
}

/// The fingertips' image positions' Jacobian by finite differences: two rows (u, v) per tip
/// per camera, one column per free state; rows of tips behind a camera are left zero.
fn tip_jacobian(model: &Model, cameras: &[Camera], state: &[f32], free: &[usize]) -> (Jac, usize) {
    let tips: Vec<usize> = (0..model.links().len())
        .filter(|&i| matches!(model.links()[i].shape, Shape::Tip { .. }))
        .collect();
    let project = |q: &[f32]| -> Vec<Option<[f64; 2]>> {
        let poses = Poses::compute(model, q).ok();
        let mut out = Vec::new();
        for c in cameras {
            for &t in &tips {
                let p: Option<Vector3<f32>> = poses.as_ref().and_then(|p| p.origin(t));
                out.push(
                    p.and_then(|p| c.project(&p))
                        .map(|u| [f64::from(u.x), f64::from(u.y)]),
                );
            }
        }
        out
    };
    let base = project(state);
    let mut jac = Jac::zeros();
    for &s in free {
        let col = s;
        let step = if s < 4 { 1e-3 } else { 1e-2 };
        let (mut up, mut down) = (state.to_vec(), state.to_vec());
        up[s] += step;
        down[s] -= step;
        let (plus, minus) = (project(&up), project(&down));
        for (r, (a, b)) in minus.iter().zip(&plus).enumerate().take(NR / 2) {
            if let (Some(a), Some(b)) = (a, b) {
                jac[(2 * r, col)] = (b[0] - a[0]) / f64::from(2.0 * step);
                jac[(2 * r + 1, col)] = (b[1] - a[1]) / f64::from(2.0 * step);
            }
        }
    }
    (jac, base.len().min(NR / 2))
}

/// The fingertips' mean (or `worst`) image standard deviation (px) under covariance `sigma`.
fn tip_std_px((jac, tips): &(Jac, usize), sigma: &Cov, worst: bool) -> f64 {
    let cov = jac * sigma * jac.transpose();
    let tips = *tips;
    let (mut sum, mut max) = (0.0, 0.0f64);
    for t in 0..tips {
        let std = (cov[(2 * t, 2 * t)] + cov[(2 * t + 1, 2 * t + 1)])
            .max(0.0)
            .sqrt();
        sum += std;
        max = max.max(std);
    }
    if worst {
        max
    } else {
        sum / tips.max(1) as f64
    }
}
