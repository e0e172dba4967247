//! The robustness benchmark: render a sweep of random rigs and motions (`random-mono` for odd
//! seeds, `random-stereo` for even ones), track each with one tracker configuration, and
//! report the distribution — never the best case — split mono/stereo (`docs/robustness.md`).

use std::fmt;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use digiteyes_core::motion::MotionConfig;
use digiteyes_core::state::TRANSLATION;
use serde::Serialize;

use crate::eval::{evaluate, stats, EvalReport};
use crate::render::Lighting;
use crate::scenarios::{render_scenario, RenderOptions, SurfaceChoice};
use crate::sequence::states::read_states_with_gaps;
use crate::sequence::Sequence;
use crate::track::track_sequence_with;
use crate::TrackerConfig;

/// A frame is *truly lost* when its mean fingertip error exceeds this many px at 640 px of
/// image width (scaled with the width rendered) ...
pub const TRULY_LOST_TIP_PX_AT_640: f64 = 20.0;
/// ... or the palm is further than this from the truth (mm).
pub const TRULY_LOST_PALM_MM: f64 = 30.0;
/// A palm this far from the truth (mm) on a frame not flagged lost is the worst failure: a
/// confident answer that is nowhere near the hand.
pub const FAR_PALM_MM: f64 = 100.0;

/// The hand's surface the sweep draws unless asked otherwise: each part its own grey, glossy,
/// casting shadows on itself (stop 67). A matte hand of one grey is what the tracker's shading
/// fit assumes, so a sweep of matte hands flatters it (`docs/robustness.md`, "A surface the
/// shading fit does not model").
pub const SWEEP_SURFACE: SurfaceChoice = SurfaceChoice::Varied;

/// The tracker configurations the benchmark compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum, Serialize)]
pub enum Motion {
    /// The tracker's defaults (the motion model on).
    Default,
    /// The loop as the thesis ran it: no prior, the full velocity, a lost frame's estimate
    /// kept, no silhouette check.
    Plain,
    /// The tracker's defaults without the palm's outline edges (`FeatureConfig::palm_edges`
    /// off; issue 9).
    NoPalmEdges,
}

impl Motion {
    /// The tracker configuration.
    pub fn config(self) -> TrackerConfig {
        let mut config = TrackerConfig::default();
        if self == Motion::Plain {
            config.motion = MotionConfig::PLAIN;
            config.silhouette_grid = 0;
            config.lost_silhouette_drop = 0.0;
        }
        if self == Motion::NoPalmEdges {
            config.features.palm_edges = false;
        }
        config
    }
}

/// `digiteyes bench robustness`.
#[derive(Debug, Clone, Args)]
pub struct RobustnessArgs {
    /// Seeds in the sweep (odd seeds one camera, even seeds two).
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u64).range(1..=10_000))]
    pub seeds: u64,
    /// The first seed.
    #[arg(long, default_value_t = 1)]
    pub first_seed: u64,
    /// Frames per seed.
    #[arg(long, default_value_t = 200, value_parser = crate::cli_values::frame_count)]
    pub frames: usize,
    /// Image size rendered, WxH.
    #[arg(long, value_name = "WxH", default_value = "640x480",
          value_parser = digiteyes_platform_linux::parse_frame_size)]
    pub size: (u32, u32),
    /// Seeds rendered and tracked at once.
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u64).range(1..=64))]
    pub jobs: u64,
    /// The tracker configuration.
    #[arg(long, value_enum, default_value_t = Motion::Default)]
    pub motion: Motion,
    /// Write every seed's figures as JSON here.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Keep the rendered sequences and states here (default: a temporary folder).
    #[arg(long, value_name = "DIR")]
    pub keep: Option<PathBuf>,
    /// Write a gallery of the failures here: for every seed that is truly lost, each
    /// camera's frame where that first happens, with the tracked model drawn over it
    /// (DIR/seedNNNN-frameNNNN-camN.png, the colours of docs/overlay.md).
    #[arg(long, value_name = "DIR")]
    pub gallery: Option<PathBuf>,
    /// Light every seed with the one fixed light the sweep used before its lighting was
    /// varied (albedo 200, ambient 0.35), to reproduce the figures docs/robustness.md
    /// measured under it.
    #[arg(long)]
    pub fixed_light: bool,
    /// The hand's surface in every seed: `varied` (the default since stop 67: each part its
    /// own grey, a glossy highlight, shadows the hand casts on itself; drawn from each seed,
    /// which keeps its rig, motion and light) or `matte` (one even grey, as the tracker's
    /// shading fit assumes; the surface of docs/robustness.md's figures up to stop 66).
    #[arg(long, value_enum, default_value_t = SWEEP_SURFACE)]
    pub surface: SurfaceChoice,
    /// After every N-th frame tracked, move one finger in turn where the hand's shading says
    /// it lies, as `track --shading-refine N` (0: never, the default).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub shading_refine: u8,
}

impl RobustnessArgs {
    /// The tracker configuration each seed is tracked with.
    pub fn config(&self) -> TrackerConfig {
        let mut config = self.motion.config();
        config.shading_refine.every_frames = self.shading_refine;
        config
    }
}

/// One seed's figures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SeedResult {
    /// The seed.
    pub seed: u64,
    /// Two cameras.
    pub stereo: bool,
    /// Track life (0–1), as `eval` defines it.
    pub track_life: f64,
    /// Share of all frames held (0–1; `eval`'s frames held): the mean fingertip error within
    /// `eval`'s threshold, also after the track life ends.
    pub held_share: f64,
    /// Mean fingertip reprojection error over frames and cameras (px at the size rendered).
    pub fingertip_px: f64,
    /// RMS joint error (deg).
    pub joint_rms_deg: f64,
    /// Mean palm rotation error (deg).
    pub palm_deg: f64,
    /// Mean palm position error (mm).
    pub palm_mm: f64,
    /// Frames.
    pub frames: usize,
    /// Frames the tracker flagged lost and that were truly lost.
    pub lost_flagged_and_true: usize,
    /// Frames flagged lost that were not truly lost.
    pub lost_flagged_only: usize,
    /// Frames truly lost that were not flagged.
    pub lost_true_only: usize,
    /// States that were not finite numbers.
    pub nan_frames: usize,
    /// Frames not flagged lost whose palm was over [`FAR_PALM_MM`] from the truth.
    pub far_unflagged: usize,
    /// The first truly lost frame, if any.
    pub first_truly_lost: Option<usize>,
    /// Tracker wall time per frame (ms; noisy, a guide only).
    pub ms_per_frame: f64,
    /// Mean Gauss–Newton iterations per frame.
    pub iterations_per_frame: f64,
}

/// Frame `k`'s palm position error (mm) and whether it is truly lost: its mean fingertip
/// error (from `report`) over `tip_limit_px`, or its palm over [`TRULY_LOST_PALM_MM`] from
/// the truth (a missing or non-finite error counts as lost).
pub fn judge_frame(
    estimate: &[f64],
    truth: &[f64],
    report: &EvalReport,
    k: usize,
    tip_limit_px: f64,
) -> (f64, bool) {
    let palm_mm = TRANSLATION
        .map(|i| (estimate[i] - truth[i]).powi(2))
        .sum::<f64>()
        .sqrt();
    let tip = report
        .fingertip_mean_by_frame
        .get(k)
        .copied()
        .unwrap_or(f64::NAN);
    let within = tip <= tip_limit_px && palm_mm <= TRULY_LOST_PALM_MM;
    (palm_mm, !within)
}

/// The frames of a tracked run, judged against the truth by [`judge_frame`]: the lost flag
/// against the frames truly lost, and the frames far from the hand and not flagged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FrameCounts {
    /// Flagged lost and truly lost.
    pub flagged_and_lost: usize,
    /// Flagged lost, not truly lost.
    pub flagged_only: usize,
    /// Truly lost, not flagged.
    pub lost_only: usize,
    /// Not flagged, the palm over [`FAR_PALM_MM`] from the truth (or not a number).
    pub far_unflagged: usize,
    /// The first truly lost frame, if any.
    pub first_truly_lost: Option<usize>,
}

/// [`FrameCounts`] of the estimated states `rows` against `truth`, with the `lost` column
/// (nonzero: flagged; a missing value: not flagged), the fingertip errors of `report` and
/// the truly-lost limit `tip_limit_px`.
pub fn count_frames(
    rows: &[Vec<f64>],
    truth: &[Vec<f64>],
    lost: &[f64],
    report: &EvalReport,
    tip_limit_px: f64,
) -> FrameCounts {
    let mut counts = FrameCounts::default();
    for (k, (estimate, true_state)) in rows.iter().zip(truth).enumerate() {
        let (palm_mm, truly) = judge_frame(estimate, true_state, report, k, tip_limit_px);
        let flagged = lost.get(k).is_some_and(|&v| v != 0.0);
        match (flagged, truly) {
            (true, true) => counts.flagged_and_lost += 1,
            (true, false) => counts.flagged_only += 1,
            (false, true) => counts.lost_only += 1,
            (false, false) => {}
        }
        if truly && counts.first_truly_lost.is_none() {
            counts.first_truly_lost = Some(k);
        }
        if !flagged && (palm_mm.is_nan() || palm_mm > FAR_PALM_MM) {
            counts.far_unflagged += 1;
        }
    }
    counts
}

/// [`count_frames`] of the states CSV `states` written for the sequence at `seq`, evaluated
/// as `report` (by [`evaluate`]), at the sequence's first camera's width.
pub fn count_run(seq: &Path, states: &Path, report: &EvalReport) -> Result<FrameCounts> {
    let sequence = Sequence::open(seq)?;
    let truth = sequence.read_truth()?;
    let table = crate::sequence::read_states(states, sequence.n_states())?;
    let lost = table.extra("lost").unwrap_or_default();
    let width = sequence.cameras.first().map_or(640, |c| c.width);
    let tip_limit = TRULY_LOST_TIP_PX_AT_640 * f64::from(width) / 640.0;
    Ok(count_frames(
        &table.rows,
        &truth.rows,
        &lost,
        report,
        tip_limit,
    ))
}

/// Renders, tracks and judges seed `seed` in `dir`.
pub fn run_seed(seed: u64, args: &RobustnessArgs, dir: &Path) -> Result<SeedResult> {
    let stereo = seed.is_multiple_of(2);
    let name = if stereo {
        "random-stereo"
    } else {
        "random-mono"
    };
    let seq = dir.join(format!("seed{seed:04}"));
    let options = RenderOptions {
        seed,
        frames: Some(args.frames),
        size: Some(args.size),
        supersample: 2,
        lighting: args.fixed_light.then(Lighting::default),
        surface: args.surface,
        ..RenderOptions::default()
    };
    render_scenario(name, &seq, &options).with_context(|| format!("seed {seed}"))?;
    let states = seq.join("states.csv");
    let summary = track_sequence_with(&seq, &states, args.config(), false, None)
        .with_context(|| format!("seed {seed}"))?;
    let report = evaluate(&seq, &states).with_context(|| format!("seed {seed}"))?;
    let sequence = Sequence::open(&seq)?;
    let truth = sequence.read_truth()?;
    let table = read_states_with_gaps(&states, sequence.n_states())?;
    let lost = table.table.extra("lost").unwrap_or_default();
    let iterations = table.table.extra("iterations").unwrap_or_default();
    let tip_limit = TRULY_LOST_TIP_PX_AT_640 * f64::from(args.size.0) / 640.0;
    let mut result = SeedResult {
        seed,
        stereo,
        track_life: report.track_life,
        held_share: report.held_share,
        fingertip_px: stats::mean(
            &report
                .cameras
                .iter()
                .map(|c| c.fingertip_mean_px)
                .collect::<Vec<_>>(),
        ),
        joint_rms_deg: report.joint_rms_deg,
        palm_deg: report.palm_rotation_deg,
        palm_mm: report.palm_translation_mm,
        frames: report.frames,
        lost_flagged_and_true: 0,
        lost_flagged_only: 0,
        lost_true_only: 0,
        nan_frames: table.gap_frames().len(),
        far_unflagged: 0,
        first_truly_lost: None,
        ms_per_frame: 1e3 * summary.tracking_seconds / summary.frames.max(1) as f64,
        iterations_per_frame: stats::mean(&iterations),
    };
    let counts = count_frames(&table.table.rows, &truth.rows, &lost, &report, tip_limit);
    result.lost_flagged_and_true = counts.flagged_and_lost;
    result.lost_flagged_only = counts.flagged_only;
    result.lost_true_only = counts.lost_only;
    result.far_unflagged = counts.far_unflagged;
    result.first_truly_lost = counts.first_truly_lost;
    if let (Some(gallery), Some(k)) = (&args.gallery, result.first_truly_lost) {
        let state: Vec<f32> = table.table.rows[k].iter().map(|&v| v as f32).collect();
        for (c, camera) in sequence.cameras.iter().enumerate() {
            let frame = sequence.read_frame(c, k)?;
            let drawn = crate::overlay::draw_overlay(
                &sequence.model,
                camera,
                &state,
                &frame,
                &args.config().features,
            )?;
            let path = gallery.join(format!("seed{seed:04}-frame{k:04}-cam{c}.png"));
            drawn
                .save(&path)
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
    }
    Ok(result)
}

/// Runs the sweep on `args.jobs` threads; seeds that could not be rendered are listed apart.
pub fn run(args: &RobustnessArgs) -> Result<Sweep> {
    if let Some(gallery) = &args.gallery {
        std::fs::create_dir_all(gallery)
            .with_context(|| format!("cannot create {}", gallery.display()))?;
    }
    let temp;
    let dir = match &args.keep {
        Some(dir) => {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create {}", dir.display()))?;
            dir.clone()
        }
        None => {
            temp = tempfile::tempdir().context("cannot make a temporary folder")?;
            temp.path().to_path_buf()
        }
    };
    let seeds: Vec<u64> = (args.first_seed..args.first_seed + args.seeds).collect();
    let jobs = usize::try_from(args.jobs).unwrap_or(usize::MAX);
    let runs = crate::parallel::map(&seeds, jobs, |&seed| {
        let run = run_seed(seed, args, &dir).map_err(|e| (seed, format!("{e:#}")));
        if args.keep.is_none() {
            let _ = std::fs::remove_dir_all(dir.join(format!("seed{seed:04}")));
        }
        run
    });
    let (mut seeds, mut failed) = (Vec::new(), Vec::new());
    for run in runs {
        match run {
            Ok(r) => seeds.push(r),
            Err(e) => failed.push(e),
        }
    }
    let sweep = Sweep {
        motion: args.motion,
        shading_refine: args.shading_refine,
        frames: args.frames,
        size: args.size,
        fixed_light: args.fixed_light,
        surface: args.surface,
        seeds,
        failed,
    };
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&sweep)?;
        crate::atomic_file::write_atomic(path, text.as_bytes())?;
    }
    Ok(sweep)
}

/// A whole sweep's results.
#[derive(Debug, Clone, Serialize)]
pub struct Sweep {
    /// The configuration tracked with.
    pub motion: Motion,
    /// A finger refined by its shading every this many frames (0: never).
    pub shading_refine: u8,
    /// Frames per seed.
    pub frames: usize,
    /// Image size (px).
    pub size: (u32, u32),
    /// Every seed lit by the fixed light (`--fixed-light`), not its own.
    pub fixed_light: bool,
    /// The hand's surface in every seed (`--surface`).
    pub surface: SurfaceChoice,
    /// Every seed tracked.
    pub seeds: Vec<SeedResult>,
    /// Seeds that could not be rendered or tracked, and why.
    pub failed: Vec<(u64, String)>,
}

/// The distribution over a group of seeds.
#[derive(Debug, Clone, PartialEq)]
pub struct Distribution {
    /// Seeds.
    pub seeds: usize,
    /// Median track life.
    pub life_median: f64,
    /// 10th percentile of track life.
    pub life_p10: f64,
    /// Share of seeds with track life ≥ 0.95.
    pub life_at_least_95: f64,
    /// Median share of frames held ([`SeedResult::held_share`]).
    pub held_median: f64,
    /// 10th percentile of the share of frames held.
    pub held_p10: f64,
    /// Median fingertip error (px).
    pub tip_px_median: f64,
    /// Median joint RMS (deg).
    pub joint_deg_median: f64,
    /// Median palm rotation error (deg).
    pub palm_deg_median: f64,
    /// Median palm position error (mm).
    pub palm_mm_median: f64,
    /// Lost-flag confusion: flagged & truly lost, flagged only, truly lost only, neither.
    pub confusion: [usize; 4],
    /// Non-finite states.
    pub nan_frames: usize,
    /// Frames unflagged with the palm over 100 mm away.
    pub far_unflagged: usize,
    /// Median tracker time per frame (ms).
    pub ms_per_frame_median: f64,
}

impl Distribution {
    /// Over `seeds`.
    pub fn of(seeds: &[&SeedResult]) -> Distribution {
        let pick = |f: fn(&SeedResult) -> f64| seeds.iter().map(|s| f(s)).collect::<Vec<_>>();
        let life = pick(|s| s.track_life);
        let held = pick(|s| s.held_share);
        let confusion = seeds.iter().fold([0; 4], |mut c, s| {
            c[0] += s.lost_flagged_and_true;
            c[1] += s.lost_flagged_only;
            c[2] += s.lost_true_only;
            c[3] += s.frames - s.lost_flagged_and_true - s.lost_flagged_only - s.lost_true_only;
            c
        });
        Distribution {
            seeds: seeds.len(),
            life_median: stats::percentile(&life, 0.5),
            life_p10: stats::percentile(&life, 0.1),
            life_at_least_95: life.iter().filter(|&&l| l >= 0.95).count() as f64
                / life.len().max(1) as f64,
            held_median: stats::percentile(&held, 0.5),
            held_p10: stats::percentile(&held, 0.1),
            tip_px_median: stats::percentile(&pick(|s| s.fingertip_px), 0.5),
            joint_deg_median: stats::percentile(&pick(|s| s.joint_rms_deg), 0.5),
            palm_deg_median: stats::percentile(&pick(|s| s.palm_deg), 0.5),
            palm_mm_median: stats::percentile(&pick(|s| s.palm_mm), 0.5),
            confusion,
            nan_frames: seeds.iter().map(|s| s.nan_frames).sum(),
            far_unflagged: seeds.iter().map(|s| s.far_unflagged).sum(),
            ms_per_frame_median: stats::percentile(&pick(|s| s.ms_per_frame), 0.5),
        }
    }

    /// Precision of the lost flag (flagged frames that were truly lost); 1 with none flagged.
    pub fn lost_precision(&self) -> f64 {
        let flagged = self.confusion[0] + self.confusion[1];
        if flagged == 0 {
            1.0
        } else {
            self.confusion[0] as f64 / flagged as f64
        }
    }

    /// Recall of the lost flag (truly lost frames that were flagged); 1 with none lost.
    pub fn lost_recall(&self) -> f64 {
        let truly = self.confusion[0] + self.confusion[2];
        if truly == 0 {
            1.0
        } else {
            self.confusion[0] as f64 / truly as f64
        }
    }
}

impl fmt::Display for Sweep {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "robustness sweep: {} seeds x {} frames at {}x{}{}{}, tracker: {:?}{}",
            self.seeds.len(),
            self.frames,
            self.size.0,
            self.size.1,
            if self.fixed_light {
                ", the fixed light"
            } else {
                ""
            },
            match self.surface {
                SurfaceChoice::Matte => ", a matte surface",
                SurfaceChoice::Varied => ", a varied surface",
                SurfaceChoice::Greys => ", parts of their own greys",
                SurfaceChoice::Gloss => ", a glossy surface",
                SurfaceChoice::Shadows => ", cast shadows",
            },
            self.motion,
            match self.shading_refine {
                0 => String::new(),
                1 => ", a finger refined by its shading after every frame".to_string(),
                n => format!(", a finger refined by its shading every {n} frames"),
            }
        )?;
        writeln!(
            f,
            "{:<7} {:>5} {:>6} {:>6} {:>6} {:>6} {:>6} {:>7} {:>7} {:>7} {:>7} {:>6} {:>6} {:>5} {:>5} {:>7}",
            "",
            "seeds",
            "life50",
            "life10",
            ">=95%",
            "held50",
            "held10",
            "tip px",
            "joint°",
            "palm°",
            "palm mm",
            "lostP",
            "lostR",
            "NaN",
            "far",
            "ms/frm"
        )?;
        for (label, stereo) in [("mono", false), ("stereo", true), ("all", true)] {
            let group: Vec<&SeedResult> = self
                .seeds
                .iter()
                .filter(|s| label == "all" || s.stereo == stereo)
                .collect();
            let d = Distribution::of(&group);
            writeln!(
                f,
                "{:<7} {:>5} {:>5.0}% {:>5.0}% {:>5.0}% {:>5.0}% {:>5.0}% {:>7.2} {:>7.2} {:>7.2} {:>7.2} {:>6.2} {:>6.2} {:>5} {:>5} {:>7.2}",
                label,
                d.seeds,
                100.0 * d.life_median,
                100.0 * d.life_p10,
                100.0 * d.life_at_least_95,
                100.0 * d.held_median,
                100.0 * d.held_p10,
                d.tip_px_median,
                d.joint_deg_median,
                d.palm_deg_median,
                d.palm_mm_median,
                d.lost_precision(),
                d.lost_recall(),
                d.nan_frames,
                d.far_unflagged,
                d.ms_per_frame_median
            )?;
        }
        let all: Vec<&SeedResult> = self.seeds.iter().collect();
        let c = Distribution::of(&all).confusion;
        writeln!(
            f,
            "lost flag vs truly lost (fingertips > {} px at 640 px wide, or palm > {} mm): \
             flagged & lost {}, flagged only {}, lost only {}, neither {}",
            TRULY_LOST_TIP_PX_AT_640, TRULY_LOST_PALM_MM, c[0], c[1], c[2], c[3]
        )?;
        let mut worst: Vec<&SeedResult> = self.seeds.iter().collect();
        worst.sort_by(|a, b| a.track_life.total_cmp(&b.track_life));
        write!(f, "worst seeds (life):")?;
        for s in worst.iter().take(5) {
            write!(f, " {} ({:.0}%)", s.seed, 100.0 * s.track_life)?;
        }
        writeln!(f)?;
        for (seed, why) in &self.failed {
            writeln!(f, "seed {seed} not run: {why}")?;
        }
        Ok(())
    }
}
