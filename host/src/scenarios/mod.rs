//! Named synthetic sequences, rendered to disk in the format of `sequence-format.md`.
//!
//! A scenario ([`catalogue`]) fixes the cameras, the base pose, which states are free and how
//! far they move. [`generate`] draws a smooth seeded trajectory ([`trajectory`]), scales its
//! speed so the fastest fingertip peaks at the scenario's image speed (in the first camera),
//! checks the hand stays in view (shrinking the amplitudes for the rare seed whose motion would
//! leave it), and [`render_scenario`] writes `sequence.json` (`model: "builtin:hand"`), the
//! frames and `truth.csv` (every state, every frame). [`mouse_thesis`] is scripted instead of
//! random: the thesis' four-phase 3D-mouse trial, played whole in any number of frames.

pub mod cameras;
pub mod catalogue;
pub mod measure;
pub mod mouse_thesis;
pub mod random;
pub mod trajectory;

use std::ops::Range;
use std::path::Path;

use anyhow::{bail, ensure, Context, Result};
use digiteyes_core::camera::Camera;
use digiteyes_core::model::Model;

use crate::render::{Background, Lighting, RenderSettings, Renderer, Surface};
use crate::sequence::{self, CameraFile, SequenceFile, BUILTIN_HAND};
pub use catalogue::{scenario, Scenario, NAMES};
pub use random::RANDOM_NAMES;
use trajectory::Motion;

/// Frames rendered unless asked otherwise.
pub const DEFAULT_FRAMES: usize = 60;
/// Frame rate written to `sequence.json` (frames/s).
pub const FPS: f64 = 30.0;
/// The hand keeps at least this far from the image border (px).
pub const VIEW_MARGIN_PX: f32 = 2.0;
/// When a seed's motion would leave the view, its amplitudes shrink by this factor, again and
/// again down to [`MIN_SHRINK`], until the hand stays in view (deterministic per seed).
pub const SHRINK_STEP: f64 = 0.9;
/// The smallest fraction of a scenario's amplitudes tried before giving up.
pub const MIN_SHRINK: f64 = 0.5;

/// The hand's surface in a rendered sequence (`--surface`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SurfaceChoice {
    /// One matte grey under the light: what the tracker's shading fit assumes.
    #[default]
    Matte,
    /// Each part its own grey, a glossy highlight, and the shadows the hand casts on itself,
    /// drawn from the seed (`Surface::varied`).
    Varied,
    /// `varied`'s parts' greys alone.
    Greys,
    /// `varied`'s highlight alone.
    Gloss,
    /// `varied`'s cast shadows alone.
    Shadows,
}

impl SurfaceChoice {
    /// The surface this choice draws for seed `seed`.
    pub fn surface(self, seed: u64) -> Surface {
        let varied = Surface::varied(seed);
        let matte = Surface::default();
        match self {
            SurfaceChoice::Matte => matte,
            SurfaceChoice::Varied => varied,
            SurfaceChoice::Greys => Surface {
                albedo_spread: varied.albedo_spread,
                seed: varied.seed,
                ..matte
            },
            SurfaceChoice::Gloss => Surface {
                specular: varied.specular,
                shininess: varied.shininess,
                ..matte
            },
            SurfaceChoice::Shadows => Surface {
                cast_shadows: true,
                ..matte
            },
        }
    }
}

/// Options of [`render_scenario`]; `None` fields take the scenario's own setting.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderOptions {
    /// Seed of the trajectory, the noise and the clutter.
    pub seed: u64,
    /// Frames to render; `None` for [`DEFAULT_FRAMES`]. The trajectory does not depend on it
    /// for up to [`DEFAULT_FRAMES`] frames: a shorter sequence is the start of the default one
    /// (except `mouse-thesis`, which plays its whole trial in however many frames).
    pub frames: Option<usize>,
    /// Noise standard deviation (grey levels).
    pub noise: Option<f32>,
    /// Blur standard deviation (px).
    pub blur: Option<f32>,
    /// Cluttered background.
    pub clutter: Option<bool>,
    /// The hand's lighting; `None` for the scenario's own (drawn from the seed for the random
    /// scenarios, [`Lighting::default`] for the others).
    pub lighting: Option<Lighting>,
    /// What the hand's surface does with the light: matte and even (the default), or drawn
    /// from the seed ([`Surface::varied`]).
    pub surface: SurfaceChoice,
    /// Image size (px); the intrinsics scale so the view is the same.
    pub size: Option<(u32, u32)>,
    /// Rays per pixel along each axis.
    pub supersample: u32,
    /// Show a progress bar on stderr (when it is a terminal).
    pub progress: bool,
    /// Leave `initial_state` out of `sequence.json`; every state is then free (`free` left
    /// out), as the format requires, and the tracker must find the hand itself.
    pub no_initial_state: bool,
    /// Frames (first included, last excluded) rendered as the empty background — the same
    /// noise and clutter, no hand — while the hand moves on as before (`truth.csv` keeps its
    /// true state).
    pub blackout: Option<Range<usize>>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            seed: 1,
            frames: None,
            noise: None,
            blur: None,
            clutter: None,
            lighting: None,
            surface: SurfaceChoice::Matte,
            size: None,
            supersample: 3,
            progress: false,
            no_initial_state: false,
            blackout: None,
        }
    }
}

/// A scenario's sequence before rendering.
#[derive(Debug, Clone)]
pub struct Generated {
    /// The scenario.
    pub scenario: Scenario,
    /// `sequence.json`.
    pub file: SequenceFile,
    /// The cameras of `file`, as the core sees them.
    pub cameras: Vec<Camera>,
    /// The true state of every frame (quaternion, mm, rad).
    pub truth: Vec<Vec<f64>>,
    /// How frames are rendered (camera 0; other cameras draw their own clutter and noise).
    pub settings: RenderSettings,
    /// Time scale of the trajectory (τ per frame; for `mouse-thesis`, thesis frames per frame).
    pub time_scale: f64,
    /// Fraction of the scenario's amplitudes used (below 1 when the full motion would have
    /// left the view for this seed).
    pub amplitude_factor: f64,
}

/// Times a random rig whose motion leaves its view is widened (focal length ×
/// [`ZOOM_OUT`] each).
pub const MAX_ZOOM_OUTS: usize = 4;
/// The focal length's factor per widening.
pub const ZOOM_OUT: f64 = 0.9;

/// Draws the trajectory of scenario `name` and everything else needed to render it. The
/// random rigs ([`random`]) are drawn from `opts.seed`; one whose hand would leave the view is
/// widened until it does not.
pub fn generate(name: &str, opts: &RenderOptions) -> Result<Generated> {
    let Some(drawn) = random::by_name(name, opts.seed) else {
        return generate_from(catalogue::scenario(name)?, opts);
    };
    let mut last = None;
    for k in 0..=MAX_ZOOM_OUTS {
        match generate_from(random::zoomed(&drawn, ZOOM_OUT.powi(k as i32)), opts) {
            Ok(generated) => return Ok(generated),
            Err(e) => last = Some(e),
        }
    }
    Err(last.unwrap_or_else(|| anyhow::anyhow!("scenario {name}: no view fits")))
}

/// [`generate`] for a scenario already defined.
pub fn generate_from(scenario: Scenario, opts: &RenderOptions) -> Result<Generated> {
    let frames = opts.frames.unwrap_or(DEFAULT_FRAMES);
    ensure!(frames > 0, "at least one frame is needed");
    let name = scenario.name;
    let model = Model::hand().map_err(|e| anyhow::anyhow!("built-in hand model: {e}"))?;
    let amplitudes = within_limits(&model, &scenario.base, &scenario.amplitudes);
    // Speed is set in the first camera at the default size, so the motion depends neither on
    // the image size nor on further cameras (`fullhand-mono` moves as `fullhand-stereo`).
    let full_size = sequence::check_cameras(&scenario.cameras)?;
    let reference = &full_size[..1];
    let camera_files: Vec<CameraFile> = match opts.size {
        Some((w, h)) => scenario
            .cameras
            .iter()
            .map(|c| cameras::resized(c, w, h))
            .collect(),
        None => scenario.cameras.clone(),
    };
    let cameras = sequence::check_cameras(&camera_files)?;
    let horizon = frames.max(DEFAULT_FRAMES);
    let mut shrink = 1.0;
    let (truth, time_scale, amplitude_factor) = loop {
        if name == mouse_thesis::NAME {
            let truth = mouse_thesis::sample(&model, &full_size, &scenario.base, frames)?;
            break (truth, mouse_thesis::thesis_time(1, frames), 1.0);
        }
        let motion = Motion::random(
            scenario.base.clone(),
            &amplitudes,
            scenario.rotation,
            opts.seed,
        )
        .scaled(shrink);
        let time_scale =
            calibrate_speed(&model, reference, &motion, horizon, scenario.peak_tip_speed)
                .with_context(|| format!("scenario {name}"))?;
        // The view is checked at the default size, so every size shows the same motion.
        let truth = motion.sample(horizon, time_scale);
        match measure::check_in_view(&model, &full_size, &truth, VIEW_MARGIN_PX) {
            Ok(()) => break (motion.sample(frames, time_scale), time_scale, shrink),
            Err(e) if shrink <= MIN_SHRINK => {
                return Err(e.context(format!("scenario {name}, seed {}", opts.seed)))
            }
            Err(_) => shrink *= SHRINK_STEP,
        }
    };
    let file = SequenceFile {
        model: BUILTIN_HAND.to_string(),
        fps: Some(FPS),
        cameras: camera_files,
        initial_state: if opts.no_initial_state {
            Vec::new()
        } else {
            truth[0].clone()
        },
        free: (!opts.no_initial_state).then(|| scenario.free.iter().map(|&s| s as i64).collect()),
    };
    let clutter = opts.clutter.unwrap_or(scenario.clutter);
    let settings = RenderSettings {
        supersample: opts.supersample.max(1),
        noise_sigma: opts.noise.unwrap_or(scenario.noise),
        blur_sigma: opts.blur.unwrap_or(scenario.blur),
        background: if clutter {
            Background::Clutter {
                seed: mix(opts.seed, 0, u64::MAX),
            }
        } else {
            Background::default()
        },
        lighting: opts.lighting.unwrap_or(scenario.lighting),
        surface: opts.surface.surface(opts.seed),
        threads: 0,
    };
    Ok(Generated {
        scenario,
        file,
        cameras,
        truth,
        settings,
        time_scale,
        amplitude_factor,
    })
}

/// Renders scenario `name` into folder `out` (created if needed): `sequence.json`, the frames
/// `camN/NNNNNN.pgm` and `truth.csv`.
pub fn render_scenario(name: &str, out: &Path, opts: &RenderOptions) -> Result<()> {
    let generated = generate(name, opts)?;
    write_generated(&generated, out, opts)
}

/// Writes a generated scenario into `out`.
pub fn write_generated(generated: &Generated, out: &Path, opts: &RenderOptions) -> Result<()> {
    if let Some(b) = &opts.blackout {
        ensure!(
            b.start < b.end && b.end <= generated.truth.len(),
            "blackout {}..{}: give frames A..B with A < B <= {} (the sequence's frames)",
            b.start,
            b.end,
            generated.truth.len()
        );
    }
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    sequence::write_sequence_json(out, &generated.file)?;
    sequence::write_truth(&out.join(sequence::TRUTH_CSV), &generated.truth)?;
    let model = Model::hand().map_err(|e| anyhow::anyhow!("built-in hand model: {e}"))?;
    let renderers: Vec<Renderer> = generated
        .cameras
        .iter()
        .enumerate()
        .map(|(c, camera)| {
            let mut settings = generated.settings;
            if let Background::Clutter { seed } = settings.background {
                settings.background = Background::Clutter {
                    seed: mix(seed, c as u64, 0),
                };
            }
            Renderer::new(&model, camera, settings)
        })
        .collect();
    let bar = crate::progress::bar(
        generated.truth.len(),
        &format!("render {}", generated.scenario.name),
        opts.progress,
    );
    for (k, q) in generated.truth.iter().enumerate() {
        let q: Vec<f32> = q.iter().map(|&v| v as f32).collect();
        let dark = opts.blackout.as_ref().is_some_and(|b| b.contains(&k));
        for (c, renderer) in renderers.iter().enumerate() {
            let seed = mix(opts.seed, c as u64, k as u64);
            let image = if dark {
                renderer.render_empty(seed)
            } else {
                renderer
                    .render(&q, seed)
                    .with_context(|| format!("frame {k}, camera {c}"))?
            };
            sequence::write_frame(out, c, k, &image)?;
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(())
}

/// Cuts each amplitude so `base ± amplitude` stays inside the model's range of that joint.
fn within_limits(model: &Model, base: &[f64], amplitudes: &[(usize, f64)]) -> Vec<(usize, f64)> {
    amplitudes
        .iter()
        .map(|&(s, a)| match model.limit(s) {
            Some(l) => {
                let room = (base[s] - f64::from(l.lo)).min(f64::from(l.hi) - base[s]);
                (s, a.min(room.max(0.0)))
            }
            None => (s, a),
        })
        .collect()
}

/// The time scale (τ per frame) at which the fastest fingertip's image speed peaks at
/// `target` px/frame over `horizon` frames.
fn calibrate_speed(
    model: &Model,
    cameras: &[Camera],
    motion: &Motion,
    horizon: usize,
    target: f64,
) -> Result<f64> {
    let mut scale = 0.01;
    for _ in 0..20 {
        let peak = measure::peak_tip_speed(model, cameras, &motion.sample(horizon, scale))?;
        if peak <= 0.0 {
            bail!("no fingertip moves");
        }
        let ratio = target / peak;
        scale *= ratio;
        if (ratio - 1.0).abs() < 1e-3 {
            break;
        }
    }
    Ok(scale)
}

/// A seed for one camera and frame, from the sequence's seed.
fn mix(seed: u64, camera: u64, frame: u64) -> u64 {
    let mut x = seed
        ^ camera.wrapping_mul(0x9e37_79b9_7f4a_7c15)
        ^ frame.wrapping_mul(0xc2b2_ae3d_27d4_eb4f);
    x ^= x >> 31;
    x = x.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x ^ (x >> 29)
}
