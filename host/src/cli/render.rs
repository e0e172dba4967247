//! `digiteyes render`: a synthetic scenario to a sequence folder.

use std::ops::Range;
use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use digiteyes_platform_linux::parse_frame_size;

use crate::cli_values;
use crate::render::Lighting;
use crate::scenarios::{
    render_scenario, RenderOptions, SurfaceChoice, DEFAULT_FRAMES, NAMES, RANDOM_NAMES,
};

/// Render a synthetic scenario to a sequence folder.
///
/// Writes OUTDIR/sequence.json (model `builtin:hand`, cameras, initial state = truth at
/// frame 0, free states), the frames OUTDIR/camN/NNNNNN.pgm and OUTDIR/truth.csv (every
/// state at every frame). The motion is smooth and seeded; the hand stays in view.
/// --no-initial-state leaves the initial state out (and every state free): the tracker
/// must find the hand itself. --blackout A..B renders frames A to B-1 of every camera as
/// the empty background (same noise and clutter) while the hand moves on.
///
/// Scenarios:
///   mouse            3D-mouse sub-model (free q4 q5 q8 q9 q10 q19 q24): palm slides on the
///                    table, finger 1 flexes, finger 4 and thumb abduct; one camera at 45°;
///                    fingertips <= 4 px/frame
///   mouse-thesis     the thesis' 3D-mouse trial (free q0..q5 q8 q9 q10 q19 q24), scripted in
///                    four phases: finger 1 raised and lowered twice; held up while the thumb
///                    clicks; palm slides and yaws; all at once. --frames 500 is the thesis'
///                    pace (fewer frames: the same trial, faster)
///   rigid            palm pose only (q0..q6): ±20° rotation, ±30 mm translation
///   twofinger        fingers 1 and 2 (3 joints each) + palm translation (q4 q5 q6)
///   fullhand-stereo  all 28 states, two cameras 35° apart facing the palm
///   fullhand-mono    the same motion, first camera only
///   fast             the mouse motion at 20 px/frame fingertip speed (peak)
///   clutter          the mouse motion over a cluttered background, noise σ 8
///   random-mono      a random rig from --seed: one camera anywhere on the upper
///                    hemisphere (elevation 20-90°, any azimuth, 350-1500 mm, hand
///                    120-350 px wide), a random whole-hand motion through fists,
///                    crossing fingers and end-on fingers, and random lighting (a light
///                    5-60° off the camera's axis, ambient 0.25-0.5; docs/robustness.md)
///   random-stereo    the same with a second camera 150-600 mm beside the first
///   thesis-stereo    the thesis' stereo rig: two cameras behind the wrist, 60° up
#[derive(Args, Debug)]
#[command(verbatim_doc_comment)]
pub struct RenderArgs {
    /// Scenario name (see above).
    #[arg(value_parser = clap::builder::PossibleValuesParser::new(
        NAMES.iter().chain(RANDOM_NAMES.iter()).copied()
    ))]
    pub scenario: String,
    /// Output sequence folder (created if missing; existing files are overwritten).
    pub outdir: PathBuf,
    /// Seed of the motion, noise and clutter (and of the random scenarios' rig and lighting).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Number of frames (1 to 100000).
    #[arg(long, default_value_t = DEFAULT_FRAMES, value_parser = cli_values::frame_count)]
    pub frames: usize,
    /// Gaussian noise standard deviation in grey levels, 0 to 128 (default: the
    /// scenario's, 2; 8 for `clutter`).
    #[arg(long, value_name = "SIGMA", value_parser = cli_values::noise_sigma)]
    pub noise: Option<f32>,
    /// Gaussian blur standard deviation in px, 0 to 20 (default: the scenario's, 0.5).
    #[arg(long, value_name = "SIGMA", value_parser = cli_values::blur_sigma)]
    pub blur: Option<f32>,
    /// Cluttered, textured background (default: only for `clutter`).
    #[arg(long)]
    pub clutter: bool,
    /// Light the hand with the built-in scenarios' fixed light (albedo 200, ambient 0.35,
    /// 31° up-left of the camera's axis) instead of a random scenario's own.
    #[arg(long)]
    pub fixed_light: bool,
    /// The hand's surface: `matte` (one grey, as the tracker's shading fit assumes) or
    /// `varied` (each part its own grey, a glossy highlight, shadows the hand casts on
    /// itself; drawn from the seed, the rig, motion and light left as they are). `bench
    /// robustness` draws `varied`: give it here to render one of its seeds as it tracked it.
    #[arg(long, value_enum, default_value_t = SurfaceChoice::Matte)]
    pub surface: SurfaceChoice,
    /// Image size in px, e.g. 320x240 (default 640x480); the view stays the same.
    #[arg(long, value_name = "WxH", value_parser = parse_frame_size)]
    pub size: Option<(u32, u32)>,
    /// Rays per pixel along each axis (3 = 9 rays per pixel).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=8))]
    pub supersample: u32,
    /// Leave initial_state out of sequence.json (every state then free, `free` left out).
    #[arg(long)]
    pub no_initial_state: bool,
    /// Frames A..B (A included, B excluded, B <= --frames) rendered without the hand.
    #[arg(long, value_name = "A..B", value_parser = frame_range)]
    pub blackout: Option<Range<usize>>,
}

/// `A..B`: a non-empty range of frames (A included, B excluded).
fn frame_range(text: &str) -> Result<Range<usize>, String> {
    let bad = || {
        format!(
            "{} is not a range of frames: give A..B with A < B, e.g. 80..110",
            crate::text::quote_value(text)
        )
    };
    let (a, b) = text.trim().split_once("..").ok_or_else(bad)?;
    let a: usize = a.trim().parse().map_err(|_| bad())?;
    let b: usize = b.trim().parse().map_err(|_| bad())?;
    if a >= b {
        return Err(bad());
    }
    Ok(a..b)
}

/// Renders the scenario; `progress`: a progress bar on stderr.
pub fn run(args: RenderArgs, progress: bool) -> Result<()> {
    let opts = RenderOptions {
        seed: args.seed,
        frames: Some(args.frames),
        noise: args.noise,
        blur: args.blur,
        clutter: args.clutter.then_some(true),
        lighting: args.fixed_light.then(Lighting::default),
        surface: args.surface,
        size: args.size,
        supersample: args.supersample,
        progress,
        no_initial_state: args.no_initial_state,
        blackout: args.blackout,
    };
    render_scenario(&args.scenario, &args.outdir, &opts)?;
    println!(
        "rendered {}: {} frames to {}",
        args.scenario,
        args.frames,
        args.outdir.display()
    );
    Ok(())
}
