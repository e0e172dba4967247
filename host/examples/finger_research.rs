//! A per-finger re-search on whole tracks: how often a finger must be put right, and whether
//! anything but the truth can choose how. On the sequences `bench robustness --keep DIR` kept,
//! each seed is tracked twice from its first true state by the plain `Tracker` (no status
//! machine, no watch, no search):
//!
//! - as it is;
//! - and every `--every` frames one finger in turn (`--all-fingers`: each finger) is
//!   re-searched after the frame: its last three joint states set to 1/6, 1/2 and 5/6 of their
//!   ranges (27 starts), each refined by one tracker frame from rest, and the candidate that
//!   `--choose` prefers — the tracked state among them, which a candidate must beat by
//!   `--margin` — carries on, with the track's velocity (`--still`: without it).
//!
//! Choosers: `shading` (the least residual of `likelihood::shading::fit`, summed over the
//! cameras), `oracle` (the least mean fingertip distance from the true state), `joints` (the
//! least joint-angle RMS from it). Three modes make no search: `truth` sets the finger's
//! joints to the truth, `nudge` moves them `--nudge-rad` (the sweep's own noise), `polish`
//! runs a pattern search on the shading residual from the tracked state, `core` the core's
//! `Tracker::refine_shading`. `--trigger-px` re-searches a finger only where its true joints
//! would move its tip that far (an oracle trigger, to tell a chooser's errors from a
//! trigger's).
//!
//! Printed: each seed's track life both ways (mean fingertip error over 10 px for 5 frames,
//! as `eval`), and the paired change, mono and stereo.
//!
//! ```text
//! digiteyes bench robustness --seeds 60 --keep /tmp/keep
//! cargo run --release -p digiteyes-host --example finger_research -- /tmp/keep \
//!     [--choose shading|oracle|joints|truth|nudge|polish|core] [--every 1] [--trigger-px 5]
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
use digiteyes_core::model::Shape;
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
    /// How a candidate is chosen: `shading` (the fit's residual) or `oracle` (the least mean
    /// fingertip distance from the true state: the ceiling of any chooser of these starts).
    #[arg(long, default_value = "shading")]
    choose: Choose,
    /// A switch also drops the track's velocity (the next frame predicts no motion).
    #[arg(long)]
    still: bool,
    /// A candidate replaces the tracked state only when its fingertips lie more than this
    /// many pixels (mean over tips and cameras) from the tracked state's.
    #[arg(long, default_value_t = 0.0)]
    min_move_px: f32,
    /// An oracle trigger: a finger is re-searched only when its joints, set to the truth, would
    /// move its fingertip more than this many pixels (mean over cameras; 0: always).
    #[arg(long, default_value_t = 0.0)]
    trigger_px: f32,
    /// Re-search every finger at each re-search frame instead of one in turn.
    #[arg(long)]
    all_fingers: bool,
    /// The pixel step of `--choose core`'s residual.
    #[arg(long, default_value_t = 2.0)]
    local_step_px: f32,
    /// The change `--choose nudge` makes to each of the finger's joints (rad).
    #[arg(long, default_value_t = 1e-3)]
    nudge_rad: f32,
}

/// How the re-search picks among its candidates.
#[derive(Clone, Copy, clap::ValueEnum)]
enum Choose {
    Shading,
    Oracle,
    /// The least RMS joint-angle error from the true state.
    Joints,
    /// No search: the finger's joints are set to the truth (how often must a finger be put
    /// right for the track to hold?).
    Truth,
    /// No search: the finger's joints are moved `--nudge-rad` (alternating signs), a change
    /// no image could tell: how far does a negligible difference move a seed's life?
    Nudge,
    /// No library: the finger's joints polished by a pattern search on the shading fit's
    /// residual (each joint ±0.08, ±0.04, ±0.02 rad in turn, a move kept when it leaves less):
    /// does the shading pull a finger back where the edges do not?
    Polish,
    /// `polish` as the core runs it: `Tracker::refine_shading` after every `--every` frames
    /// (`TrackerConfig::shading_refine`, margin `--margin`): each move judged only where the
    /// finger is, the start's fit kept, over every `--local-step-px`-th pixel of the finger's
    /// links' image bounds widened by 20 px.
    Core,
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

/// The RMS difference (rad) of the joint angles (the states after the palm's seven) of `a`
/// and `b`.
fn joint_rms_rad(a: &[f32], b: &[f32]) -> f64 {
    let squares: Vec<f64> = a
        .iter()
        .zip(b)
        .skip(7)
        .map(|(x, y)| f64::from(x - y).powi(2))
        .collect();
    (squares.iter().sum::<f64>() / squares.len().max(1) as f64).sqrt()
}

/// Re-searches finger `finger` of the tracker's state on `frames` and carries on from the
/// candidate the shading prefers; true when it is not the tracked state.
#[allow(clippy::too_many_arguments)]
fn research(
    tracker: &mut Tracker,
    sequence: &Sequence,
    fingers: &Fingers,
    frames: &[FrameView<'_>],
    truth: &[f32],
    finger: usize,
    args: &Args,
) -> Result<bool> {
    let kept = tracker.memory();
    let state = tracker.state().to_vec();
    let joints: Vec<usize> = (0..state.len())
        .filter(|&s| fingers.contains(finger, s))
        .collect();
    let set_directly = match args.choose {
        Choose::Truth => Some(joints.iter().map(|&s| (s, truth[s])).collect::<Vec<_>>()),
        Choose::Nudge => Some(
            joints
                .iter()
                .enumerate()
                .map(|(i, &s)| {
                    (
                        s,
                        state[s] + args.nudge_rad * if i % 2 == 0 { 1.0 } else { -1.0 },
                    )
                })
                .collect(),
        ),
        _ => None,
    };
    if matches!(args.choose, Choose::Polish) {
        let residual_of = |q: &[f32]| shading_residual(sequence, frames, q, args.grid);
        let mut q = state.clone();
        let mut best = residual_of(&q);
        for step in [0.08f32, 0.04, 0.02] {
            for &s in &joints {
                let Some(limit) = sequence.model.limit(s) else {
                    continue;
                };
                for sign in [1.0f32, -1.0] {
                    let mut trial = q.clone();
                    trial[s] = (q[s] + sign * step).clamp(limit.lo, limit.hi);
                    let residual = residual_of(&trial);
                    if residual < best * (1.0 - args.margin) {
                        (best, q) = (residual, trial);
                        break;
                    }
                }
            }
        }
        let moved = q != state;
        let mut memory = kept;
        memory.state = heapless::Vec::from_slice(&q).map_err(|_| anyhow::anyhow!("states"))?;
        tracker.restore(&memory)?;
        return Ok(moved);
    }
    if let Some(values) = set_directly {
        let mut memory = kept;
        for (s, v) in values {
            memory.state[s] = v;
        }
        tracker.restore(&memory)?;
        return Ok(true);
    }
    if args.trigger_px > 0.0 {
        let mut put_right = state.clone();
        for &s in &joints {
            put_right[s] = truth[s];
        }
        let tips = sequence
            .model
            .links()
            .iter()
            .filter(|l| matches!(l.shape, Shape::Tip { .. }))
            .count() as f32;
        let finger_px =
            kept::tip_error_px(&sequence.model, &sequence.cameras, &state, &put_right) * tips;
        if finger_px <= args.trigger_px {
            return Ok(false);
        }
    }
    let score = |q: &[f32]| match args.choose {
        Choose::Shading => shading_residual(sequence, frames, q, args.grid),
        Choose::Oracle => f64::from(kept::tip_error_px(
            &sequence.model,
            &sequence.cameras,
            q,
            truth,
        )),
        Choose::Joints => joint_rms_rad(q, truth),
        Choose::Truth | Choose::Nudge | Choose::Polish | Choose::Core => 0.0,
    };
    let mut best = (score(&state) * (1.0 - args.margin), state.clone());
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
        let moved_px = kept::tip_error_px(&sequence.model, &sequence.cameras, &q, &state);
        if moved_px <= args.min_move_px {
            continue;
        }
        let residual = score(&q);
        if residual < best.0 {
            best = (residual, q);
            switched = true;
        }
    }
    let mut memory = kept;
    memory.state = heapless::Vec::from_slice(&best.1).map_err(|_| anyhow::anyhow!("states"))?;
    if switched && args.still {
        memory.velocity = None;
    }
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
    let mut config = TrackerConfig::default();
    if matches!(args.choose, Choose::Core) && every > 0 {
        config.shading_refine.every_frames = every as u8;
        config.shading_refine.margin = args.margin as f32;
        config.shading_refine.region_step_px = args.local_step_px;
        config.shading_refine.grid = args.grid as u8;
    }
    let mut tracker = sequence_tracker(sequence, config)?;
    let mut memory = tracker.memory();
    memory.state = heapless::Vec::from_slice(&truth[0]).map_err(|_| anyhow::anyhow!("states"))?;
    memory.velocity = None;
    tracker.restore(&memory)?;
    let mut states = vec![truth[0].iter().map(|&v| f64::from(v)).collect::<Vec<f64>>()];
    let mut switched = 0;
    for (k, truth_k) in truth.iter().enumerate().skip(1) {
        let images = kept::read_instant(sequence, k)?;
        let frames = kept::views(&images)?;
        tracker.track(&frames)?;
        if matches!(args.choose, Choose::Core) {
            switched += usize::from(tracker.refine_shading(&frames)?.moves > 0);
        } else if every > 0 && k % every == 0 {
            let turn = (k / every) % fingers.count().max(1);
            let chosen = if args.all_fingers {
                0..fingers.count()
            } else {
                turn..turn + 1
            };
            for finger in chosen {
                switched += usize::from(research(
                    &mut tracker,
                    sequence,
                    &fingers,
                    &frames,
                    truth_k,
                    finger,
                    args,
                )?);
            }
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
            let mean = |e: &[f64]| e.iter().sum::<f64>() / e.len().max(1) as f64;
            println!(
                "{}: life {:.0} % plain, {:.0} % with the re-search ({switched} switches); \
                 fingertips {:.2} px plain, {:.2} px with",
                dir.display(),
                100.0 * pair.0,
                100.0 * pair.1,
                mean(&plain),
                mean(&with)
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
