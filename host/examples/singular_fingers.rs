//! Joint error on fingers in singular configurations (issue 11's third target). On the
//! sequences `bench robustness --keep DIR` kept, each variant tracks every seed, and each
//! frame's fingers are classed at the *truth*: a finger is **singular** when the plane it bends
//! in passes within an angle (`--angles-deg`, each printed) of every camera's centre (the
//! thesis' singular subspace, Sec. 2.5.4: the finger projects onto one image line, and its
//! line features no longer say how its bend is split among its joints). The plane is the one the finger's two distal links
//! turn in: through the first distal link's frame, normal to its joint axis.
//!
//! Printed per variant and group (mono, stereo): the finger-frames of each class, their joint
//! RMS (degrees, over the finger's joint states) pooled over every frame, and pooled over the
//! frames where the first variant *and* this one hold the hand (mean fingertip error within
//! `eval`'s 10 px), so that a lost track's gross error does not stand in for the ambiguity;
//! and, with several hypotheses, the RMS of each finger's best reading among the hypotheses
//! carried (an oracle: was the right reading carried, for the score to choose?), and how well
//! the score ranks the hypotheses of a frame: how often the output is the one nearest the
//! truth (mean fingertip error), and of the pairs whose fingertip errors differ by over 3 px
//! (and by over 10 px), how often the higher score goes with the nearer.
//!
//! ```text
//! digiteyes bench robustness --seeds 60 --first-seed 8321 --keep /tmp/k8321
//! cargo run --release -p digiteyes-host --example singular_fingers -- --dirs /tmp/k8321 -- \
//!     default k=4
//! ```

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Parser;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::{Model, BASE_STATES};
use digiteyes_host::eval::{evaluate, reprojection_error, LOST_ERROR_PX};
use digiteyes_host::parallel;
use digiteyes_host::sequence::hypotheses::read_hypotheses;
use digiteyes_host::sequence::{read_states, Sequence};
use digiteyes_host::track::{track_sequence_to, TrackOutputs};

#[path = "common/kept.rs"]
mod kept;

#[derive(Parser)]
struct Args {
    /// Folders of kept seeds (`seedNNNN/`), as `bench robustness --keep` writes.
    #[arg(long, required = true, num_args = 1..)]
    dirs: Vec<PathBuf>,
    /// Variants, as `kept_ab` takes them (`default`, `k=4`, ...); the first is the baseline.
    #[arg(required = true)]
    variants: Vec<String>,
    /// A finger is singular when its bending plane passes within this angle of every
    /// camera's centre (degrees); each angle is printed.
    #[arg(long, value_delimiter = ',', default_value = "5,10,20")]
    angles_deg: Vec<f64>,
    #[arg(long, default_value_t = 2)]
    jobs: usize,
}

/// The fingers by the frame of their first distal link (whose joint axis is normal to the
/// plane the finger's distal links bend in).
const FINGERS: [&str; 5] = [
    "finger1.link1",
    "finger2.link1",
    "finger3.link1",
    "finger4.link1",
    "thumb.link1",
];

/// One finger-frame: how far its bending plane passes from the cameras at the truth, and its
/// squared joint errors summed (rad²) with their count.
struct FingerFrame {
    /// The largest over the cameras of the angle between the plane and the ray from the
    /// camera's centre to the plane's origin (degrees).
    plane_deg: f64,
    squared_rad2: f64,
    /// The least [`FingerFrame::squared_rad2`] of this finger over every hypothesis carried
    /// out of the frame (with several hypotheses): whether the right reading was carried.
    carried_squared_rad2: Option<f64>,
    joints: usize,
}

/// One seed under one variant: every frame's finger-frames and whether the frame is held.
struct SeedRun {
    seed: u64,
    frames: Vec<(bool, Vec<FingerFrame>)>,
    ranking: Ranking,
}

/// How well the hypotheses' scores rank them against the truth (mean fingertip error, px),
/// over the frames that carry several.
#[derive(Default, Clone, Copy)]
struct Ranking {
    /// Frames with several hypotheses.
    frames: usize,
    /// Of those, frames whose output (rank 0) is the hypothesis nearest the truth.
    output_nearest: usize,
    /// The output's fingertip error and the nearest hypothesis', summed over those frames.
    output_px: f64,
    nearest_px: f64,
    /// Pairs of hypotheses of one frame whose fingertip errors differ by over each of
    /// [`RANKED_PAIR_PX`], and of those, the pairs whose higher score is the nearer one.
    pairs: [usize; RANKED_PAIR_PX.len()],
    pairs_agreeing: [usize; RANKED_PAIR_PX.len()],
}

impl Ranking {
    fn add(&mut self, other: &Ranking) {
        self.frames += other.frames;
        self.output_nearest += other.output_nearest;
        self.output_px += other.output_px;
        self.nearest_px += other.nearest_px;
        for i in 0..RANKED_PAIR_PX.len() {
            self.pairs[i] += other.pairs[i];
            self.pairs_agreeing[i] += other.pairs_agreeing[i];
        }
    }
}

/// Two hypotheses of a frame are a ranked pair when their fingertip errors differ by more
/// than this (px).
const RANKED_PAIR_PX: [f64; 2] = [3.0, 10.0];

/// Each finger's frame index and its joint states.
fn fingers(model: &Model) -> Result<Vec<(usize, Vec<usize>)>> {
    FINGERS
        .iter()
        .map(|name| {
            let frame = model.find(name).with_context(|| format!("no {name}"))?;
            // Every joint state that moves the finger's tip: the chain of its last frame.
            let tip = name.replace(".link1", ".tip");
            let tip = model.find(&tip).with_context(|| format!("no {tip}"))?;
            let states = model
                .chain(tip)
                .with_context(|| format!("no chain for {name}"))?
                .iter()
                .map(|&s| usize::from(s))
                .filter(|&s| s >= BASE_STATES)
                .collect();
            Ok((frame, states))
        })
        .collect()
}

/// The largest over the cameras of the angle (degrees) between the plane through `frame`'s
/// origin, normal to its z axis, and the ray from the camera's centre to that origin: under
/// an angle, the plane passes that close to every camera.
fn plane_deg(sequence: &Sequence, poses: &Poses, frame: usize) -> f64 {
    let Some(pose) = poses.frame(frame) else {
        return 90.0;
    };
    let normal = pose.r.column(2).into_owned();
    sequence
        .cameras
        .iter()
        .map(|camera| {
            let ray = pose.t - camera.centre();
            let sin = (normal.dot(&ray) / ray.norm()).abs();
            if sin.is_finite() {
                f64::from(sin.min(1.0).asin().to_degrees())
            } else {
                90.0
            }
        })
        .fold(0.0, f64::max)
}

fn run(dir: &Path, variant: &str) -> Result<SeedRun> {
    let (config, options) = kept::variant(variant)?;
    let seed = kept::seed_of(dir);
    let out = std::env::temp_dir().join(format!(
        "singular_fingers_{}_{seed}_{}.csv",
        std::process::id(),
        variant.replace(['=', '+', '.'], "_")
    ));
    let hypotheses_out = out.with_extension("hypotheses.csv");
    let sequence = Sequence::open(dir)?;
    let n = sequence.n_states();
    let outputs = TrackOutputs {
        hypotheses_out: (options.hypotheses.count > 1).then_some(hypotheses_out.as_path()),
        ..TrackOutputs::default()
    };
    let tracked = track_sequence_to(dir, &out, config, false, &outputs, &options).and_then(|_| {
        let hypotheses = match outputs.hypotheses_out {
            Some(path) => Some(read_hypotheses(path, n)?),
            None => None,
        };
        Ok((evaluate(dir, &out)?, read_states(&out, n)?, hypotheses))
    });
    let _ = std::fs::remove_file(&out);
    let _ = std::fs::remove_file(&hypotheses_out);
    let (report, states, hypotheses) = tracked?;
    let carried = hypotheses.as_ref().map(|h| h.by_frame(states.rows.len()));
    let model = &sequence.model;
    let truth = kept::f32s(&sequence.read_truth()?.rows);
    let estimate = kept::f32s(&states.rows);
    let fingers = fingers(model)?;
    let tips: Vec<usize> = FINGERS
        .iter()
        .filter_map(|name| model.find(&name.replace(".link1", ".tip")))
        .collect();
    let mut ranking = Ranking::default();
    let mut frames = Vec::new();
    for (k, (t, e)) in truth.iter().zip(&estimate).enumerate() {
        let poses = Poses::compute(model, t)?;
        let held = report
            .fingertip_mean_by_frame
            .get(k)
            .is_some_and(|&px| px <= LOST_ERROR_PX);
        let squared = |e: &dyn Fn(usize) -> f64, states: &[usize]| -> f64 {
            states
                .iter()
                .map(|&s| (e(s) - f64::from(t[s])).powi(2))
                .sum()
        };
        let per_finger = fingers
            .iter()
            .map(|(frame, states)| FingerFrame {
                plane_deg: plane_deg(&sequence, &poses, *frame),
                squared_rad2: squared(&|s| f64::from(e[s]), states),
                carried_squared_rad2: carried.as_ref().and_then(|c| {
                    c.get(k)?
                        .iter()
                        .map(|h| squared(&|s| h.state[s], states))
                        .reduce(f64::min)
                }),
                joints: states.len(),
            })
            .collect();
        frames.push((held, per_finger));
        if let Some(hypotheses) = carried.as_ref().and_then(|c| c.get(k)) {
            let mut scored = Vec::new();
            for h in hypotheses {
                let state: Vec<f32> = h.state.iter().map(|&v| v as f32).collect();
                let estimate = Poses::compute(model, &state)?;
                let mut px = Vec::new();
                for camera in &sequence.cameras {
                    px.extend(
                        tips.iter()
                            .map(|&tip| reprojection_error(camera, &poses, &estimate, tip)),
                    );
                }
                let mean = px.iter().sum::<f64>() / px.len().max(1) as f64;
                scored.push((h.rank, h.score, mean));
            }
            ranking.add(&rank(&scored));
        }
    }
    Ok(SeedRun {
        seed,
        frames,
        ranking,
    })
}

/// The [`Ranking`] of one frame's hypotheses, each as (rank, score, fingertip error px).
fn rank(scored: &[(usize, f64, f64)]) -> Ranking {
    let mut r = Ranking::default();
    if scored.len() < 2 {
        return r;
    }
    let nearest = scored.iter().map(|h| h.2).fold(f64::INFINITY, f64::min);
    let Some(output) = scored.iter().find(|h| h.0 == 0) else {
        return r;
    };
    r.frames = 1;
    r.output_nearest = usize::from(output.2 <= nearest);
    r.output_px = output.2;
    r.nearest_px = nearest;
    for (i, a) in scored.iter().enumerate() {
        for b in &scored[i + 1..] {
            for (i, &apart_px) in RANKED_PAIR_PX.iter().enumerate() {
                if (a.2 - b.2).abs() > apart_px && a.1 != b.1 {
                    r.pairs[i] += 1;
                    r.pairs_agreeing[i] += usize::from((a.1 > b.1) == (a.2 < b.2));
                }
            }
        }
    }
    r
}

/// Frames after a finger leaves a singular configuration that count as just left it.
const AFTER_FRAMES: usize = 10;

/// A finger-frame's class at one angle.
#[derive(Clone, Copy, PartialEq)]
enum Class {
    /// The bending plane passes within the angle of every camera.
    Singular,
    /// Not singular, but singular within the last [`AFTER_FRAMES`] frames: the bend has just
    /// come into view (the constructed ambiguity of issue 11's tests).
    JustLeft,
    /// Neither.
    Other,
}

impl Class {
    const ALL: [Class; 3] = [Class::Singular, Class::JustLeft, Class::Other];

    fn name(self) -> &'static str {
        match self {
            Class::Singular => "singular",
            Class::JustLeft => "just left",
            Class::Other => "other",
        }
    }

    /// Finger `finger`'s class at frame `k` of `run`, at `angle_deg`.
    fn of(run: &SeedRun, k: usize, finger: usize, angle_deg: f64) -> Class {
        let singular = |k: usize| {
            run.frames
                .get(k)
                .and_then(|f| f.1.get(finger))
                .is_some_and(|f| f.plane_deg < angle_deg)
        };
        if singular(k) {
            Class::Singular
        } else if (k.saturating_sub(AFTER_FRAMES)..k).any(singular) {
            Class::JustLeft
        } else {
            Class::Other
        }
    }
}

/// Joint RMS (degrees) over the finger-frames of class `class` at `angle_deg` of the seeds of
/// `runs` whose number has `parity`, counting frame `k` of a seed only when `keep(seed, k)`;
/// and how many finger-frames that is.
fn rms_deg(
    runs: &[SeedRun],
    parity: u64,
    (angle_deg, class): (f64, Class),
    keep: &dyn Fn(u64, usize) -> bool,
    error: &dyn Fn(&FingerFrame) -> f64,
) -> (f64, usize) {
    let (mut sum, mut n, mut fingers) = (0.0, 0usize, 0usize);
    for run in runs.iter().filter(|r| r.seed % 2 == parity) {
        for (k, (_, per_finger)) in run.frames.iter().enumerate() {
            if !keep(run.seed, k) {
                continue;
            }
            for (i, f) in per_finger.iter().enumerate() {
                if Class::of(run, k, i, angle_deg) == class {
                    sum += error(f);
                    n += f.joints;
                    fingers += 1;
                }
            }
        }
    }
    ((sum / n.max(1) as f64).sqrt().to_degrees(), fingers)
}

fn main() -> Result<()> {
    let args = Args::parse();
    let mut dirs = Vec::new();
    for dir in &args.dirs {
        dirs.extend(kept::seed_dirs(dir)?);
    }
    let mut baseline: Option<Vec<SeedRun>> = None;
    println!(
        "variant group angle | per class: finger-frames, joint RMS over all of them, over those \
         held by both variants (their count)"
    );
    for variant in &args.variants {
        let runs: Vec<SeedRun> = parallel::map(&dirs, args.jobs, |dir| {
            run(dir, variant)
                .map_err(|e| eprintln!("{}: {e:#}", dir.display()))
                .ok()
        })
        .into_iter()
        .flatten()
        .collect();
        let base = baseline.as_deref().unwrap_or(&runs);
        let held = |runs: &[SeedRun], seed: u64, k: usize| {
            runs.iter()
                .find(|r| r.seed == seed)
                .and_then(|r| r.frames.get(k))
                .is_some_and(|f| f.0)
        };
        for (group, parity) in [("mono", 1), ("stereo", 0)] {
            if !runs.iter().any(|r| r.seed % 2 == parity) {
                continue;
            }
            let both = |seed: u64, k: usize| held(base, seed, k) && held(&runs, seed, k);
            let every = |_: u64, _: usize| true;
            for &angle in &args.angles_deg {
                let cells: Vec<String> = Class::ALL
                    .iter()
                    .map(|&class| {
                        let at = (angle, class);
                        let output = |f: &FingerFrame| f.squared_rad2;
                        let (all, n) = rms_deg(&runs, parity, at, &every, &output);
                        let (held, held_n) = rms_deg(&runs, parity, at, &both, &output);
                        let carried =
                            |f: &FingerFrame| f.carried_squared_rad2.unwrap_or(f.squared_rad2);
                        let (best, _) = rms_deg(&runs, parity, at, &every, &carried);
                        format!(
                            "{} {n}, {all:.2}°, {held:.2}° ({held_n}), best carried {best:.2}°",
                            class.name()
                        )
                    })
                    .collect();
                println!("{variant} {group} {angle}° | {}", cells.join(" | "));
            }
            let mut r = Ranking::default();
            for run in runs.iter().filter(|r| r.seed % 2 == parity) {
                r.add(&run.ranking);
            }
            if r.frames > 0 {
                let share = |a: usize, b: usize| 100.0 * a as f64 / b.max(1) as f64;
                let pairs: Vec<String> = RANKED_PAIR_PX
                    .iter()
                    .enumerate()
                    .map(|(i, px)| {
                        format!(
                            "{} pairs over {px} px apart: the higher score the nearer in {:.0} %",
                            r.pairs[i],
                            share(r.pairs_agreeing[i], r.pairs[i])
                        )
                    })
                    .collect();
                println!(
                    "{variant} {group} ranking | {} frames with several hypotheses: the output \
                     nearest the truth on {:.0} %, its fingertips {:.2} px against the nearest's \
                     {:.2} px | {}",
                    r.frames,
                    share(r.output_nearest, r.frames),
                    r.output_px / r.frames as f64,
                    r.nearest_px / r.frames as f64,
                    pairs.join(" | "),
                );
            }
        }
        if baseline.is_none() {
            baseline = Some(runs);
        }
    }
    Ok(())
}
