//! A per-finger re-search chosen by the hand's shading, tried on whole tracks. On the
//! sequences `bench robustness --keep DIR` kept, each seed is tracked twice from its first
//! true state by the plain `Tracker` (no status machine, no watch, no search):
//!
//! - as it is;
//! - and every `--every` frames one finger in turn is re-searched after the frame: its last
//!   three joint states set to 1/6, 1/2 and 5/6 of their ranges (27 starts), each refined by
//!   one tracker frame from rest, and the candidate whose shading fit
//!   (`likelihood::shading::fit`, summed squared residual over the cameras) leaves least —
//!   the tracked state among them, which a candidate must beat by `--margin` — carries on,
//!   with the track's velocity.
//!
//! Printed: each seed's track life both ways (mean fingertip error over 10 px for 5 frames,
//! as `eval`), and the paired change, mono and stereo.
//!
//! ```text
//! digiteyes bench robustness --seeds 60 --keep /tmp/keep
//! cargo run --release -p digiteyes-host --example finger_research -- /tmp/keep
//! ```

use std::path::PathBuf;

#[path = "common/kept.rs"]
mod kept;

use anyhow::Result;
use clap::Parser;
use digiteyes_core::frame::FrameView;
use digiteyes_core::hypotheses::fingers::Fingers;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::likelihood::shading;
use digiteyes_core::projection::ProjectedModel;
use digiteyes_core::tracker::Tracker;
use digiteyes_host::eval::{compare, track_life};
use digiteyes_host::sequence::Sequence;
use digiteyes_host::sequence_tracker;
use digiteyes_host::TrackerConfig;

#[derive(Parser)]
struct Args {
    /// Folders of kept seeds (`seedNNNN/`), as `bench robustness --keep` writes.
    #[arg(required = true)]
    dirs: Vec<PathBuf>,
    /// Re-search one finger every this many frames.
    #[arg(long, default_value_t = 8)]
    every: usize,
    /// The shading fit's lattice side.
    #[arg(long, default_value_t = 64)]
    grid: usize,
    /// A candidate replaces the tracked state only when it leaves less than `1 − margin` of
    /// the tracked state's residual.
    #[arg(long, default_value_t = 0.0)]
    margin: f64,
}

/// The three levels of a joint's range the re-search starts from.
const LEVELS: [f32; 3] = [1.0 / 6.0, 0.5, 5.0 / 6.0];

/// The summed squared residual of the shading fit of `q` over the cameras (infinite where a
/// camera gives no fit).
fn shading_residual(sequence: &Sequence, frames: &[FrameView<'_>], q: &[f32], grid: usize) -> f64 {
    let Ok(poses) = Poses::compute(&sequence.model, q) else {
        return f64::INFINITY;
    };
    let mut view = ProjectedModel::new();
    let mut sum = 0.0;
    for (camera, frame) in sequence.cameras.iter().zip(frames) {
        view.update(&sequence.model, &poses, camera, 0.0);
        sum += shading::fit(&view, camera, frame, grid).map_or(f64::INFINITY, |f| {
            f64::from(f.rms).powi(2) * f64::from(f.points)
        });
    }
    sum
}

/// Re-searches finger `finger` of the tracker's state on `frames` and carries on from the
/// candidate the shading prefers; true when it is not the tracked state.
fn research(
    tracker: &mut Tracker,
    sequence: &Sequence,
    fingers: &Fingers,
    frames: &[FrameView<'_>],
    finger: usize,
    grid: usize,
    margin: f64,
) -> Result<bool> {
    let kept = tracker.memory();
    let state = tracker.state().to_vec();
    let joints: Vec<usize> = (0..state.len())
        .filter(|&s| fingers.contains(finger, s))
        .collect();
    let mut best = (
        shading_residual(sequence, frames, &state, grid) * (1.0 - margin),
        state.clone(),
    );
    let mut switched = false;
    for code in 0..27 {
        let mut start = state.clone();
        for (d, &s) in joints.iter().rev().take(3).enumerate() {
            if let Some(limit) = sequence.model.limit(s) {
                let level = LEVELS[(code / 3usize.pow(d as u32)) % 3];
                start[s] = limit.lo + (limit.hi - limit.lo) * level;
            }
        }
        let mut memory = kept.clone();
        memory.state = heapless::Vec::from_slice(&start).map_err(|_| anyhow::anyhow!("states"))?;
        memory.velocity = None;
        tracker.restore(&memory)?;
        tracker.track(frames)?;
        let q = tracker.state().to_vec();
        let residual = shading_residual(sequence, frames, &q, grid);
        if residual < best.0 {
            best = (residual, q);
            switched = true;
        }
    }
    let mut memory = kept;
    memory.state = heapless::Vec::from_slice(&best.1).map_err(|_| anyhow::anyhow!("states"))?;
    tracker.restore(&memory)?;
    Ok(switched)
}

/// Tracks `sequence` from its first true state, re-searching a finger every `every` frames
/// when `every` > 0; each frame's mean fingertip error (px) and the re-searches that switched.
fn run(
    sequence: &Sequence,
    truth: &[Vec<f32>],
    args: &Args,
    every: usize,
) -> Result<(Vec<f64>, usize)> {
    let fingers = Fingers::of(&sequence.model);
    let mut tracker = sequence_tracker(sequence, TrackerConfig::default())?;
    let mut memory = tracker.memory();
    memory.state = heapless::Vec::from_slice(&truth[0]).map_err(|_| anyhow::anyhow!("states"))?;
    memory.velocity = None;
    tracker.restore(&memory)?;
    let mut states = vec![truth[0].iter().map(|&v| f64::from(v)).collect::<Vec<f64>>()];
    let mut switched = 0;
    for k in 1..truth.len() {
        let images = kept::read_instant(sequence, k)?;
        let frames = kept::views(&images)?;
        tracker.track(&frames)?;
        if every > 0 && k % every == 0 {
            let finger = (k / every) % fingers.count().max(1);
            switched += usize::from(research(
                &mut tracker,
                sequence,
                &fingers,
                &frames,
                finger,
                args.grid,
                args.margin,
            )?);
        }
        states.push(tracker.state().iter().map(|&v| f64::from(v)).collect());
    }
    let names: Vec<String> = (0..sequence.cameras.len())
        .map(|c| sequence.camera_name(c))
        .collect();
    let truth64: Vec<Vec<f64>> = truth
        .iter()
        .map(|q| q.iter().map(|&v| f64::from(v)).collect())
        .collect();
    let report = compare(
        &sequence.model,
        &sequence.cameras,
        &names,
        &sequence.free_states(),
        &truth64,
        &states,
    )?;
    Ok((report.fingertip_mean_by_frame, switched))
}

fn main() -> Result<()> {
    let args = Args::parse();
    // Per rig (mono, stereo): (plain life, with the re-search), per seed.
    let mut lives: [Vec<(f64, f64)>; 2] = [Vec::new(), Vec::new()];
    for root in &args.dirs {
        for dir in kept::seed_dirs(root)? {
            let sequence = Sequence::open(&dir)?;
            let truth = kept::f32s(&sequence.read_truth()?.rows);
            let (plain, _) = run(&sequence, &truth, &args, 0)?;
            let (with, switched) = run(&sequence, &truth, &args, args.every)?;
            let pair = (track_life(&plain), track_life(&with));
            println!(
                "{}: life {:.0} % plain, {:.0} % with the re-search ({switched} switches)",
                dir.display(),
                100.0 * pair.0,
                100.0 * pair.1
            );
            lives[usize::from(sequence.cameras.len() > 1)].push(pair);
        }
    }
    for (rig, pairs) in ["mono", "stereo"].iter().zip(&lives) {
        let n = pairs.len().max(1) as f64;
        let change = pairs.iter().map(|(a, b)| b - a).sum::<f64>() / n * 100.0;
        let gained = pairs.iter().filter(|(a, b)| b - a > 0.05).count();
        let lost = pairs.iter().filter(|(a, b)| a - b > 0.05).count();
        let held = |f: fn(&(f64, f64)) -> f64| pairs.iter().filter(|p| f(p) >= 0.95).count();
        println!(
            "{rig}: {} seeds; mean life change {change:+.1} points, {gained} gained / {lost} lost \
             over 5; at >= 95 %: {} plain, {} with",
            pairs.len(),
            held(|p| p.0),
            held(|p| p.1)
        );
    }
    Ok(())
}
