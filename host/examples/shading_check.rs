//! Does the hand's shading tell one wrong finger from a right one, where its outline and
//! edges do not (`finger_check`)? On the sequences `bench robustness --keep DIR` kept, at
//! every frame where one finger's tip is over 10 px off in some camera and the others within
//! 5 px, and that finger's tip comes within 3 px of the truth's in every camera when its
//! joints are set to the truth's, the kept state and that corrected state are each
//! rendered (noise-free, one ray a pixel) and compared with the frame by the sum of squared
//! grey-level differences over every camera:
//!
//! - `shaded`: rendered with the seed's own lighting and blur: an upper bound on what a
//!   shading term could tell, since it is given the light the sweep drew;
//! - `flat`: the same with uniform albedo (no shading): the outline alone, as a control;
//! - `fitted`: what a tracker could do without being told the light: each state's normals
//!   and coverage are rendered (blurred as the frame), and the background, the hand's mean
//!   grey and a linear shading `c·n` fitted to the frame by least squares, per state; the
//!   fit's squared residual is the score;
//! - `core`: the core's own fit (`likelihood::shading::fit`) on a `--grid` lattice over the
//!   projected hand, normals by ray casting in f32, no blur: the summed squared residual;
//! - `likelihood`: the tracker's own image likelihood (`StateScorer::score`), as the
//!   hypotheses weigh it (with the reverse chamfer term).
//!
//! Printed: how often each prefers the finger at its true joints, mono and stereo, split by
//! whether some camera sees that finger's tip at the truth (`visibility::cover`).
//!
//! ```text
//! digiteyes bench robustness --seeds 60 --keep /tmp/keep
//! cargo run --release -p digiteyes-host --example shading_check -- /tmp/keep
//! ```

use std::path::PathBuf;

#[path = "common/kept.rs"]
mod kept;

use anyhow::Result;
use clap::Parser;
use digiteyes_core::hypotheses::fingers::Fingers;
use digiteyes_core::hypotheses::HypothesesConfig;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::likelihood::{shading, Scene, StateScorer};
use digiteyes_core::model::{Model, Shape};
use digiteyes_core::projection::ProjectedModel;
use digiteyes_core::tracker::Tracker;
use digiteyes_core::visibility::{cover, Cover};
use digiteyes_host::eval::reprojection_error;
use digiteyes_host::render::{Background, Lighting, RenderSettings, Renderer};
use digiteyes_host::scenarios::{generate, RenderOptions};
use digiteyes_host::sequence::{read_states, Sequence};
use digiteyes_host::sequence_tracker;
use digiteyes_host::TrackerConfig;
use image::GrayImage;
use nalgebra::{SMatrix, SVector};

#[derive(Parser)]
struct Args {
    /// Folders of kept seeds (`seedNNNN/`), as `bench robustness --keep` writes.
    #[arg(required = true)]
    dirs: Vec<PathBuf>,
    /// Look at every this many frames.
    #[arg(long, default_value_t = 4)]
    every: usize,
    /// The fitted shading reads only every this many pixels along each axis (a lattice, as a
    /// tracker's grid would), 1: every pixel.
    #[arg(long, default_value_t = 1)]
    lattice: usize,
    /// The side of the core fit's lattice over the projected hand.
    #[arg(long, default_value_t = 32)]
    grid: usize,
    /// Also re-search the wrong finger as a per-finger library would: its last three joint
    /// states set to 1/6, 1/2 and 5/6 of their ranges (27 starts), each refined by one
    /// tracker frame, and the best chosen by the fitted shading and by the likelihood; and the
    /// same for one finger in turn of every other frame looked at where every tip is within
    /// 3 px (does the re-search keep a right finger right?).
    #[arg(long)]
    library: bool,
}

/// One library case: the finger's tip error (px, worst camera) as kept, as chosen by
/// the fitted shading, by the likelihood, and the best of the candidates.
#[derive(Clone, Copy)]
struct Chosen {
    stereo: bool,
    /// A finger of a hand that was right (every tip within 3 px), re-searched in turn.
    right: bool,
    kept: f64,
    shading: f64,
    likelihood: f64,
    best: f64,
}

/// The three levels of a joint's range the library starts from.
const LEVELS: [f32; 3] = [1.0 / 6.0, 0.5, 5.0 / 6.0];

/// Sum of squared grey-level differences between two frames of one size.
fn ssd(a: &GrayImage, b: &GrayImage) -> f64 {
    a.as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(&x, &y)| (f64::from(x) - f64::from(y)).powi(2))
        .sum()
}

/// Per rig (mono, stereo): cases, and how often each score prefers the truth.
#[derive(Default, Clone, Copy)]
struct Tally {
    cases: usize,
    shaded: usize,
    flat: usize,
    flat_ties: usize,
    fitted: usize,
    core: usize,
    likelihood: usize,
}

/// Renders of one camera's coverage and normals, each blurred as the frame: the basis of the
/// fitted shading (`ALBEDO` grey levels for coverage 1 or a unit normal component).
struct Bases {
    coverage: Renderer,
    /// Lights along +x, −x, +y, −y, +z, −z (camera axes), no ambient.
    axes: [Renderer; 6],
}

const ALBEDO: f64 = 200.0;

impl Bases {
    fn new(model: &Model, camera: &digiteyes_core::camera::Camera, blur_sigma: f32) -> Self {
        let settings = |toward_light: [f64; 3], ambient: f64| RenderSettings {
            supersample: 1,
            noise_sigma: 0.0,
            blur_sigma,
            background: Background::Plain(0.0),
            lighting: Lighting {
                albedo: ALBEDO,
                ambient,
                toward_light,
            },
            surface: Default::default(),
            threads: 0,
        };
        let axis = |k: usize, sign: f64| {
            let mut l = [0.0; 3];
            l[k] = sign;
            Renderer::new(model, camera, settings(l, 0.0))
        };
        Bases {
            coverage: Renderer::new(model, camera, settings([0.0, 0.0, -1.0], 1.0)),
            axes: [
                axis(0, 1.0),
                axis(0, -1.0),
                axis(1, 1.0),
                axis(1, -1.0),
                axis(2, 1.0),
                axis(2, -1.0),
            ],
        }
    }

    /// The least-squares residual (sum of squares) of `image` against background + mean
    /// grey + linear shading of the hand at states `q`.
    fn residual(&self, q: &[f32], image: &GrayImage, lattice: usize) -> Result<f64> {
        let width = image.width() as usize;
        let lattice = lattice.max(1);
        let m = self.coverage.render(q, 0)?;
        let r: Vec<GrayImage> = self
            .axes
            .iter()
            .map(|a| a.render(q, 0))
            .collect::<Result<_>>()?;
        let mut ata = SMatrix::<f64, 5, 5>::zeros();
        let mut atb = SVector::<f64, 5>::zeros();
        let mut rows = Vec::with_capacity(image.as_raw().len());
        for (i, &v) in image.as_raw().iter().enumerate() {
            if !(i % width).is_multiple_of(lattice) || !(i / width).is_multiple_of(lattice) {
                continue;
            }
            let cover = f64::from(m.as_raw()[i]) / ALBEDO;
            let n = |k: usize| {
                (f64::from(r[2 * k].as_raw()[i]) - f64::from(r[2 * k + 1].as_raw()[i])) / ALBEDO
            };
            let row = SVector::<f64, 5>::new(1.0 - cover, cover, n(0), n(1), n(2));
            ata += row * row.transpose();
            atb += row * f64::from(v);
            rows.push((row, f64::from(v)));
        }
        let Some(c) = (ata + SMatrix::<f64, 5, 5>::identity() * 1e-6).try_inverse() else {
            return Ok(f64::INFINITY);
        };
        let c = c * atb;
        Ok(rows.iter().map(|(row, v)| (row.dot(&c) - v).powi(2)).sum())
    }
}

fn main() -> Result<()> {
    let args = Args::parse();
    // By rig (mono, stereo) and by whether some camera sees the wrong finger's tip at the truth.
    let mut tally = [[Tally::default(); 2]; 2];
    let mut view = ProjectedModel::default();
    let likelihood = HypothesesConfig::default().likelihood;
    let mut scorer = StateScorer::new();
    let mut chosen: Vec<Chosen> = Vec::new();
    for root in &args.dirs {
        for dir in kept::seed_dirs(root)? {
            let seed = kept::seed_of(&dir);
            let sequence = Sequence::open(&dir)?;
            let stereo = sequence.cameras.len() > 1;
            let name = if stereo {
                "random-stereo"
            } else {
                "random-mono"
            };
            let generated = generate(
                name,
                &RenderOptions {
                    seed,
                    frames: Some(1),
                    ..RenderOptions::default()
                },
            )?;
            let shaded = RenderSettings {
                supersample: 1,
                noise_sigma: 0.0,
                ..generated.settings
            };
            let flat = RenderSettings {
                lighting: Lighting {
                    ambient: 1.0,
                    ..shaded.lighting
                },
                ..shaded
            };
            let model = &sequence.model;
            let renderers: Vec<(Renderer, Renderer)> = sequence
                .cameras
                .iter()
                .map(|c| {
                    (
                        Renderer::new(model, c, shaded),
                        Renderer::new(model, c, flat),
                    )
                })
                .collect();
            let bases: Vec<Bases> = sequence
                .cameras
                .iter()
                .map(|c| Bases::new(model, c, shaded.blur_sigma))
                .collect();
            let truth = kept::f32s(&sequence.read_truth()?.rows);
            let states =
                kept::f32s(&read_states(&dir.join("states.csv"), sequence.n_states())?.rows);
            let fingers = Fingers::of(model);
            let mut tracker = sequence_tracker(&sequence, TrackerConfig::default())?;
            let library = Library {
                model,
                sequence: &sequence,
                fingers: &fingers,
                bases: &bases,
                lattice: args.lattice,
            };
            let tips: Vec<(usize, usize)> = (0..model.links().len())
                .filter(|&i| matches!(model.links()[i].shape, Shape::Tip { .. }))
                .filter_map(|i| kept::finger_of_frame(model, &fingers, i).map(|f| (f, i)))
                .collect();
            for k in (1..truth.len().min(states.len())).step_by(args.every.max(1)) {
                let (pt, pe) = (
                    Poses::compute(model, &truth[k])?,
                    Poses::compute(model, &states[k])?,
                );
                let tip_err = |tip: usize| {
                    sequence
                        .cameras
                        .iter()
                        .map(|c| reprojection_error(c, &pt, &pe, tip))
                        .fold(0.0f64, f64::max)
                };
                let wrong: Vec<usize> = tips
                    .iter()
                    .filter(|&&(_, tip)| tip_err(tip) > 10.0)
                    .map(|&(f, _)| f)
                    .collect();
                let right = tips.iter().filter(|&&(_, tip)| tip_err(tip) < 5.0).count();
                let all_right = tips.iter().all(|&(_, tip)| tip_err(tip) < 3.0);
                let turn = k / args.every.max(1);
                if args.library && all_right && turn % 2 == 0 {
                    // A right hand: does re-searching one of its fingers (in turn) keep it?
                    let (f, tip) = tips[(turn / 2) % tips.len()];
                    let case = Case {
                        truth: &pt,
                        state: &states[k],
                        k,
                        finger: f,
                        tip,
                        right: true,
                    };
                    chosen.push(library.choose(&mut tracker, &mut scorer, &case)?);
                }
                if wrong.len() != 1 || right + 1 != tips.len() {
                    continue;
                }
                let mut fixed = states[k].clone();
                for (s, v) in fixed.iter_mut().enumerate() {
                    if fingers.contains(wrong[0], s) {
                        *v = truth[k][s];
                    }
                }
                // Only where the finger at its true joints, on the kept palm, is right in
                // every image (its tip within 3 px): else the true joints, on a palm a little
                // off, are not the finger the image shows.
                let pf = Poses::compute(model, &fixed)?;
                let tip = tips.iter().find(|&&(f, _)| f == wrong[0]).map(|&(_, t)| t);
                let fixed_right = tip.is_some_and(|tip| {
                    sequence
                        .cameras
                        .iter()
                        .all(|c| reprojection_error(c, &pt, &pf, tip) < 3.0)
                });
                if !fixed_right {
                    continue;
                }
                let tip_seen = tip.is_some_and(|tip| {
                    sequence.cameras.iter().any(|camera| {
                        view.update(model, &pt, camera, 0.0);
                        view.links.iter().enumerate().any(|(i, link)| {
                            usize::from(link.child) == tip
                                && cover(&view, camera, i, &link.b, link.z1 - link.radius_mm)
                                    != Cover::Hidden
                        })
                    })
                });
                let t = &mut tally[usize::from(stereo)][usize::from(tip_seen)];
                let images = kept::read_instant(&sequence, k)?;
                let (mut sh, mut fl, mut fit) = ([0.0f64; 2], [0.0f64; 2], [0.0f64; 2]);
                for (((shade, plain), basis), image) in renderers.iter().zip(&bases).zip(&images) {
                    for (i, q) in [&states[k], &fixed].into_iter().enumerate() {
                        sh[i] += ssd(&shade.render(q, 0)?, image);
                        fl[i] += ssd(&plain.render(q, 0)?, image);
                        fit[i] += basis.residual(q, image, args.lattice)?;
                    }
                }
                t.fitted += usize::from(fit[1] < fit[0]);
                let frames = kept::views(&images)?;
                let mut core = [0.0f64; 2];
                for (i, q) in [&states[k], &fixed].into_iter().enumerate() {
                    let poses = Poses::compute(model, q)?;
                    for (camera, frame) in sequence.cameras.iter().zip(&frames) {
                        view.update(model, &poses, camera, 0.0);
                        core[i] += shading::fit(&view, camera, frame, args.grid)
                            .map_or(f64::INFINITY, |f| {
                                f64::from(f.rms).powi(2) * f64::from(f.points)
                            });
                    }
                }
                t.core += usize::from(core[1] < core[0]);
                let mut buffers = kept::edge_buffers(&frames, &likelihood);
                let maps = kept::edge_maps(&mut buffers, &frames, &likelihood)?;
                let scene = Scene::new(model, &sequence.cameras, &frames, &maps);
                let (kept_score, fixed_score) = (
                    scorer.score(&scene, &states[k], &likelihood),
                    scorer.score(&scene, &fixed, &likelihood),
                );
                t.likelihood += usize::from(fixed_score > kept_score);
                if args.library {
                    let case = Case {
                        truth: &pt,
                        state: &states[k],
                        k,
                        finger: wrong[0],
                        tip: tip.unwrap_or(usize::MAX),
                        right: false,
                    };
                    chosen.push(library.choose(&mut tracker, &mut scorer, &case)?);
                }
                t.cases += 1;
                t.shaded += usize::from(sh[1] < sh[0]);
                t.flat += usize::from(fl[1] < fl[0]);
                t.flat_ties += usize::from(fl[1] == fl[0]);
            }
            eprintln!("{}", dir.display());
        }
    }
    for ((rig, seen), t) in ["mono", "stereo"]
        .iter()
        .flat_map(|r| [(r, "tip hidden"), (r, "tip seen")])
        .zip(tally.iter().flatten())
    {
        let share = |n: usize| n as f64 / t.cases.max(1) as f64;
        println!(
            "{rig}, {seen}: {} frames with one finger wrong; the finger at its true joints preferred by \
             shaded {:.2}, flat {:.2} (ties {}), fitted {:.2}, core {:.2}, likelihood {:.2}",
            t.cases,
            share(t.shaded),
            share(t.flat),
            t.flat_ties,
            share(t.fitted),
            share(t.core),
            share(t.likelihood)
        );
    }
    if args.library {
        for (stereo, right) in [(false, false), (true, false), (false, true), (true, true)] {
            let cases: Vec<&Chosen> = chosen
                .iter()
                .filter(|c| c.stereo == stereo && c.right == right)
                .collect();
            let n = cases.len().max(1) as f64;
            let within =
                |f: fn(&Chosen) -> f64| cases.iter().filter(|c| f(c) <= 10.0).count() as f64 / n;
            let better = |f: fn(&Chosen) -> f64| {
                cases.iter().filter(|c| f(c) < c.kept - 2.0).count() as f64 / n
            };
            let worse = |f: fn(&Chosen) -> f64| {
                cases.iter().filter(|c| f(c) > c.kept + 2.0).count() as f64 / n
            };
            println!(
                "library, {}, {}: {} cases; the finger's tip within 10 px: kept {:.2}, chosen by \
                 shading {:.2} (better / worse by 2 px {:.2} / {:.2}), by the likelihood {:.2} \
                 ({:.2} / {:.2}), the best candidate {:.2}",
                if stereo { "stereo" } else { "mono" },
                if right {
                    "a right finger"
                } else {
                    "the wrong finger"
                },
                cases.len(),
                within(|c| c.kept),
                within(|c| c.shading),
                better(|c| c.shading),
                worse(|c| c.shading),
                within(|c| c.likelihood),
                better(|c| c.likelihood),
                worse(|c| c.likelihood),
                within(|c| c.best),
            );
        }
    }
    Ok(())
}

/// One seed, for a per-finger library's re-search.
struct Library<'a> {
    model: &'a Model,
    sequence: &'a Sequence,
    fingers: &'a Fingers,
    bases: &'a [Bases],
    lattice: usize,
}

/// One finger of one frame to re-search.
struct Case<'a> {
    /// The frame's true poses.
    truth: &'a Poses,
    /// The kept state.
    state: &'a [f32],
    /// The frame.
    k: usize,
    finger: usize,
    /// The finger's tip frame.
    tip: usize,
    /// Whether the hand was right (every tip within 3 px).
    right: bool,
}

impl Library<'_> {
    /// Re-searches the case's finger: its last three joint states at every
    /// combination of [`LEVELS`], each refined by one tracker frame, and the kept state; the
    /// candidates chosen by the fitted shading and by the likelihood, and the best.
    fn choose(
        &self,
        tracker: &mut Tracker,
        scorer: &mut StateScorer,
        at: &Case<'_>,
    ) -> Result<Chosen> {
        let likelihood = HypothesesConfig::default().likelihood;
        let (finger, tip) = (at.finger, at.tip);
        let images = kept::read_instant(self.sequence, at.k)?;
        let frames = kept::views(&images)?;
        let mut buffers = kept::edge_buffers(&frames, &likelihood);
        let maps = kept::edge_maps(&mut buffers, &frames, &likelihood)?;
        let scene = Scene::new(self.model, &self.sequence.cameras, &frames, &maps);
        let finger_err = |q: &[f32]| -> Result<f64> {
            let p = Poses::compute(self.model, q)?;
            Ok(self
                .sequence
                .cameras
                .iter()
                .map(|c| reprojection_error(c, at.truth, &p, tip))
                .fold(0.0f64, f64::max))
        };
        let joints: Vec<usize> = (0..at.state.len())
            .filter(|&s| self.fingers.contains(finger, s))
            .collect();
        let mut candidates = vec![at.state.to_vec()];
        for code in 0..27 {
            let mut q = at.state.to_vec();
            for (d, &s) in joints.iter().rev().take(3).enumerate() {
                if let Some(limit) = self.model.limit(s) {
                    let level = LEVELS[(code / 3usize.pow(d as u32)) % 3];
                    q[s] = limit.lo + (limit.hi - limit.lo) * level;
                }
            }
            candidates.push(refined(tracker, &frames, &q)?);
        }
        let (mut by_shading, mut by_likelihood) = ((f64::INFINITY, 0), (f32::MIN, 0));
        let mut best = f64::INFINITY;
        for (i, q) in candidates.iter().enumerate() {
            let mut residual = 0.0;
            for (basis, image) in self.bases.iter().zip(&images) {
                residual += basis.residual(q, image, self.lattice)?;
            }
            if residual < by_shading.0 {
                by_shading = (residual, i);
            }
            let score = scorer.score(&scene, q, &likelihood);
            if score > by_likelihood.0 {
                by_likelihood = (score, i);
            }
            best = best.min(finger_err(q)?);
        }
        Ok(Chosen {
            stereo: self.sequence.cameras.len() > 1,
            right: at.right,
            kept: finger_err(&candidates[0])?,
            shading: finger_err(&candidates[by_shading.1])?,
            likelihood: finger_err(&candidates[by_likelihood.1])?,
            best,
        })
    }
}

/// `start` refined by one tracker frame on `frames`, from rest (no velocity).
fn refined(
    tracker: &mut Tracker,
    frames: &[digiteyes_core::frame::FrameView<'_>],
    start: &[f32],
) -> Result<Vec<f32>> {
    let mut memory = tracker.memory();
    memory.state = heapless::Vec::from_slice(start).map_err(|_| anyhow::anyhow!("states"))?;
    memory.velocity = None;
    tracker.restore(&memory)?;
    tracker.track(frames)?;
    Ok(tracker.state().to_vec())
}
