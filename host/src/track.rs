//! Tracking a recorded sequence with the core tracker, inside the status machine of
//! [`crate::acquire::AutoTracker`] (Searching → Tracking → Lost → Searching).
//!
//! With [`Init::Given`] the tracker starts tracking from `initial_state`; with [`Init::Auto`]
//! it starts searching for the hand (the free states' given values unused). It estimates the
//! `free` states and sees every frame of every camera: one step per instant with one frame per
//! camera. Each instant's state, report and status go to the output CSV (written beside it and
//! put in place when every frame is tracked, so a failed run leaves an earlier file untouched;
//! header `frame,q0..q{n-1},rms_px,iterations,features_found,features_expected,lost,status`).
//! `lost` is 1 on every frame that claims no hand (searching or lost); while searching, the
//! states are the last tracked ones (the search's base state before the first acquisition).
//! Optionally each frame of each camera is also drawn with the model, the slices searched and
//! the features found at the state tracked for it ([`crate::overlay`]), as PNGs.
//!
//! With [`TrackOptions::hypotheses`] asking for K > 1, the tracker carries up to K hypotheses
//! ([`digiteyes_core::hypotheses`]); the best is the output. [`TrackOutputs::hypotheses_out`]
//! writes every one carried, frame by frame ([`crate::sequence::hypotheses`]).

use std::fmt;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Context, Result};
use digiteyes_core::acquire::{AcquireConfig, FinderConfig};
use digiteyes_core::config::MAX_HYPOTHESES;
use digiteyes_core::frame::FrameView;
use digiteyes_core::hypotheses::HypothesesConfig;
use digiteyes_core::tracker::{Tracker, TrackerConfig};
use digiteyes_core::watch::WatchConfig;

use crate::acquire::{AutoTracker, Recovery, Status};
use crate::overlay::{draw_overlay, overlay_path, PngStats, PngWriter};
use crate::sequence::hypotheses::HypothesesWriter;
pub use crate::sequence::status::{StatusCounts, STATUS_COLUMN};
use crate::sequence::{Sequence, StatesWriter};

/// How `track` starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Init {
    /// Track from the sequence's `initial_state` from frame 0.
    Given,
    /// Search for the hand: the free states' given values are not used (fixed ones are).
    Auto,
}

impl Init {
    /// The default for `sequence`: [`Init::Given`] when it has an initial state, else
    /// [`Init::Auto`].
    pub fn default_for(sequence: &Sequence) -> Init {
        if sequence.initial_given {
            Init::Given
        } else {
            Init::Auto
        }
    }
}

/// How a sequence is tracked besides the tracker's own parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackOptions {
    /// How to start; `None`: [`Init::default_for`] the sequence.
    pub init: Option<Init>,
    /// What to do once the hand is lost for
    /// [`LOST_FRAMES_BEFORE_SEARCH`](crate::acquire::LOST_FRAMES_BEFORE_SEARCH) frames.
    pub recovery: Recovery,
    /// The search's parameters.
    pub acquire: AcquireConfig,
    /// The hypotheses carried (`count` 1, the default: the single tracker, bit for bit).
    /// Their likelihood's edge-map stride is taken from [`TrackOptions::acquire`], whose
    /// buffers they share.
    pub hypotheses: HypothesesConfig,
    /// How the image checks the track ([`digiteyes_core::watch`]; not with
    /// [`Recovery::Never`]).
    pub watch: WatchConfig,
    /// How the search's leaves and the local re-acquisition's starts are refined and judged.
    pub finder: FinderConfig,
}

impl Default for TrackOptions {
    fn default() -> Self {
        TrackOptions {
            init: None,
            recovery: Recovery::Search,
            acquire: AcquireConfig::default(),
            hypotheses: HypothesesConfig::default(),
            watch: WatchConfig::default(),
            finder: FinderConfig::default(),
        }
    }
}

/// The files a tracking run writes besides the states CSV.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TrackOutputs<'a> {
    /// Each frame of each camera drawn at its tracked state into `DIR/camN/NNNNNN.png`.
    pub overlay_dir: Option<&'a Path>,
    /// Every hypothesis carried, one row per hypothesis per frame
    /// ([`crate::sequence::hypotheses`]).
    pub hypotheses_out: Option<&'a Path>,
}

/// What the hypotheses did over a run.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct HypothesesSummary {
    /// Hypotheses asked for (K).
    pub asked: usize,
    /// Hypotheses carried after each frame (0 on a searching frame).
    pub carried: Vec<u8>,
    /// Frames on which the best was not the previous frame's best.
    pub switches: usize,
    /// Where the hypotheses were written, and the rows written.
    pub out: Option<(PathBuf, usize)>,
}

impl HypothesesSummary {
    /// Frames with hypotheses (not searching).
    pub fn frames_with(&self) -> usize {
        self.carried.iter().filter(|&&c| c > 0).count()
    }

    /// The mean count carried over the frames with hypotheses (0 when none had any).
    pub fn mean_carried(&self) -> f64 {
        let sum: usize = self.carried.iter().map(|&c| usize::from(c)).sum();
        sum as f64 / self.frames_with().max(1) as f64
    }
}

/// What a tracking run did.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackSummary {
    /// Instants tracked (frames per camera).
    pub frames: usize,
    /// Cameras.
    pub cameras: usize,
    /// Frames written `lost` (no hand claimed: searching or lost).
    pub lost_frames: usize,
    /// Mean over the frames not searching of the tracker's RMS image residual (px).
    pub mean_rms_px: f64,
    /// How the run started.
    pub init: Init,
    /// Frames per status and the frames where it changed.
    pub status: StatusCounts,
    /// Time spent in the tracker itself (s), without reading frames.
    pub tracking_seconds: f64,
    /// Wall time of the whole run, reading and writing included (s).
    pub total_seconds: f64,
    /// Where the states were written.
    pub out: PathBuf,
    /// The sequence's frame rate (frames/s), when `sequence.json` gives one.
    pub fps: Option<f64>,
    /// The overlay PNGs written, when asked for: where, and the writer's figures.
    pub overlays: Option<(PathBuf, PngStats)>,
    /// The hypotheses carried and how often the best changed.
    pub hypotheses: HypothesesSummary,
}

impl TrackSummary {
    /// Instants tracked per second of tracker time (frames/s).
    pub fn frames_per_second(&self) -> f64 {
        self.frames as f64 / self.tracking_seconds.max(1e-9)
    }
}

impl fmt::Display for TrackSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "tracked {} frames x {} camera(s): {} lost, mean rms {:.3} px",
            self.frames, self.cameras, self.lost_frames, self.mean_rms_px
        )?;
        let init = match self.init {
            Init::Given => "from the given initial state",
            Init::Auto => "searching from frame 0",
        };
        writeln!(f, "{} ({init})", self.status)?;
        write!(
            f,
            "tracker time {:.3} s ({:.1} frames/s), total {:.3} s",
            self.tracking_seconds,
            self.frames_per_second(),
            self.total_seconds
        )?;
        match self.fps {
            Some(fps) if fps > 0.0 => writeln!(
                f,
                "; {:.2}x real time at the sequence's {fps} frames/s",
                self.frames_per_second() / fps
            )?,
            _ => writeln!(f)?,
        }
        let h = &self.hypotheses;
        if h.asked > 1 {
            writeln!(
                f,
                "hypotheses: up to {}, {:.2} carried on average over {} frame(s) not searching; \
                 the best switched on {} frame(s) ({:.1} %)",
                h.asked,
                h.mean_carried(),
                h.frames_with(),
                h.switches,
                100.0 * h.switches as f64 / h.frames_with().max(1) as f64
            )?;
        }
        write!(f, "states written to {}", self.out.display())?;
        if let Some((path, rows)) = &h.out {
            write!(
                f,
                "\nhypotheses: {rows} row(s) written to {}",
                path.display()
            )?;
        }
        if let Some((dir, png)) = &self.overlays {
            write!(
                f,
                "\noverlays: {} PNG(s) written to {} ({:.1} ms each to encode and write)",
                png.files,
                dir.display(),
                1e3 * png.seconds / png.files.max(1) as f64
            )?;
        }
        Ok(())
    }
}

/// A tracker for `sequence`: its model, cameras, initial state and free states — how `track`
/// starts, and the in-process reference the board tests compare against.
pub fn sequence_tracker(
    sequence: &Sequence,
    config: TrackerConfig,
) -> Result<Tracker, digiteyes_core::tracker::TrackerError> {
    let initial: Vec<f32> = sequence.initial_state.iter().map(|&v| v as f32).collect();
    Tracker::new(
        sequence.model.clone(),
        &sequence.cameras,
        &initial,
        sequence.free_mask(),
        config,
    )
}

/// Tracks every frame of the sequence in folder `seq` and writes the states to `out_csv`.
/// A progress bar goes to stderr when `progress` is set and stderr is a terminal. Fails,
/// naming the file, on unreadable input; fails naming the frame and its files if the tracker
/// rejects a frame; then `out_csv` is left as it was (an earlier file stays whole).
pub fn track_sequence(
    seq: &Path,
    out_csv: &Path,
    config: TrackerConfig,
    progress: bool,
) -> Result<TrackSummary> {
    track_sequence_with(seq, out_csv, config, progress, None)
}

/// [`track_sequence`], and when `overlay_dir` is given, each frame of each camera drawn at
/// the state tracked for it ([`draw_overlay`]) into `overlay_dir/camN/NNNNNN.png` (a writer
/// thread encodes them while the next frame is tracked; tracker time excludes both).
pub fn track_sequence_with(
    seq: &Path,
    out_csv: &Path,
    config: TrackerConfig,
    progress: bool,
    overlay_dir: Option<&Path>,
) -> Result<TrackSummary> {
    track_sequence_opts(
        seq,
        out_csv,
        config,
        progress,
        overlay_dir,
        &TrackOptions::default(),
    )
}

/// The status machine for `sequence` as `options` ask: tracking from the initial state
/// ([`Init::Given`]) or searching from the search's base ([`Init::Auto`]). Fails, naming the
/// sequence, when [`Init::Given`] is asked of a sequence without `initial_state`.
pub fn sequence_auto_tracker(
    sequence: &Sequence,
    config: TrackerConfig,
    options: &TrackOptions,
) -> Result<AutoTracker> {
    let init = options.init.unwrap_or(Init::default_for(sequence));
    let to_f32 = |q: &[f64]| q.iter().map(|&v| v as f32).collect::<Vec<f32>>();
    let name = sequence.dir.display();
    let mut auto = match init {
        Init::Given if !sequence.initial_given => bail!(
            "{name}: --init given needs `initial_state` in sequence.json, which has none \
             (use --init auto to let the tracker find the hand)"
        ),
        Init::Given => AutoTracker::tracking(
            sequence.model.clone(),
            &sequence.cameras,
            &to_f32(&sequence.initial_state),
            sequence.free_mask(),
            config,
            options.acquire,
        ),
        Init::Auto => AutoTracker::new(
            sequence.model.clone(),
            &sequence.cameras,
            &to_f32(&sequence.search_base()),
            sequence.free_mask(),
            config,
            options.acquire,
        ),
    }
    .with_context(|| format!("{name}"))?;
    auto.set_recovery(options.recovery);
    auto.set_finder(options.finder);
    auto.set_watch(options.watch);
    auto.set_hypotheses(hypotheses_config(options)?);
    Ok(auto)
}

/// The hypotheses' parameters `options` ask for, their edge-map stride the search's (the
/// buffers are shared). Fails, naming `--hypotheses`, on a count outside 1..=[`MAX_HYPOTHESES`].
pub fn hypotheses_config(options: &TrackOptions) -> Result<HypothesesConfig> {
    let mut config = options.hypotheses;
    check_hypotheses_count(usize::from(config.count))?;
    config.likelihood.stride_px = options.acquire.likelihood.stride_px;
    Ok(config)
}

/// Checks a count of hypotheses: 1..=[`MAX_HYPOTHESES`], else an error naming
/// `--hypotheses` and the range.
pub fn check_hypotheses_count(count: usize) -> Result<()> {
    if !(1..=MAX_HYPOTHESES).contains(&count) {
        bail!(
            "--hypotheses {count}: the count must be 1 to {MAX_HYPOTHESES} (1: the single tracker)"
        );
    }
    Ok(())
}

/// [`track_sequence_with`] as `options` ask: how to start and whether to search again after
/// a loss.
pub fn track_sequence_opts(
    seq: &Path,
    out_csv: &Path,
    config: TrackerConfig,
    progress: bool,
    overlay_dir: Option<&Path>,
    options: &TrackOptions,
) -> Result<TrackSummary> {
    let outputs = TrackOutputs {
        overlay_dir,
        ..TrackOutputs::default()
    };
    track_sequence_to(seq, out_csv, config, progress, &outputs, options)
}

/// [`track_sequence_opts`] writing every file `outputs` asks for; each output appears whole
/// or not at all.
pub fn track_sequence_to(
    seq: &Path,
    out_csv: &Path,
    config: TrackerConfig,
    progress: bool,
    outputs: &TrackOutputs<'_>,
    options: &TrackOptions,
) -> Result<TrackSummary> {
    let overlay_dir = outputs.overlay_dir;
    let start = Instant::now();
    let sequence = Sequence::open(seq)?;
    sequence.check_frames()?;
    sequence.check_cameras_see_the_hand(&(0..sequence.cameras.len()).collect::<Vec<_>>())?;
    let init = options.init.unwrap_or(Init::default_for(&sequence));
    let mut tracker = sequence_auto_tracker(&sequence, config, options)?;
    let mut writer = StatesWriter::with_columns(out_csv, sequence.n_states(), &[STATUS_COLUMN])?;
    let mut overlays = overlay_dir.map(|_| PngWriter::start(8)).transpose()?;
    let mut hypotheses_out = outputs
        .hypotheses_out
        .map(|path| HypothesesWriter::create(path, sequence.n_states()))
        .transpose()?;
    let mut hypotheses = HypothesesSummary {
        asked: usize::from(options.hypotheses.count),
        ..HypothesesSummary::default()
    };
    let bar = crate::progress::bar(sequence.frames, "track", progress);
    let mut tracking = Duration::ZERO;
    let (mut lost, mut rms_sum, mut rms_frames) = (0, 0.0, 0);
    let mut statuses = Vec::with_capacity(sequence.frames);
    for k in 0..sequence.frames {
        let images = (0..sequence.cameras.len())
            .map(|c| sequence.read_frame(c, k))
            .collect::<Result<Vec<_>>>()?;
        let views = images
            .iter()
            .enumerate()
            .map(|(c, img)| {
                FrameView::packed(img.as_raw(), img.width() as usize, img.height() as usize)
                    .map_err(|e| anyhow!("{}: {e}", sequence.frame_path(c, k).display()))
            })
            .collect::<Result<Vec<_>>>()?;
        let t0 = Instant::now();
        let report = tracker.step(&views);
        tracking += t0.elapsed();
        let auto = report.map_err(|e| {
            let files: Vec<String> = (0..sequence.cameras.len())
                .map(|c| sequence.frame_path(c, k).display().to_string())
                .collect();
            anyhow!(
                "frame {k} ({}): the tracker failed: {e:#}",
                files.join(", ")
            )
        })?;
        let report = auto.report;
        writer
            .write_with(tracker.state(), &report, &[auto.status.as_str()])
            .with_context(|| format!("frame {k}"))?;
        let carried = match auto.status {
            Status::Searching => &[][..],
            Status::Tracking | Status::Lost => tracker.inner().hypotheses(),
        };
        if let Some(out) = hypotheses_out.as_mut() {
            out.write_frame(k, carried)?;
        }
        hypotheses.carried.push(match auto.status {
            Status::Searching => 0,
            Status::Tracking | Status::Lost => auto.hypotheses,
        });
        hypotheses.switches += usize::from(auto.switched);
        if let (Some(dir), Some(writer)) = (overlay_dir, overlays.as_mut()) {
            for (c, image) in images.iter().enumerate() {
                let drawn = draw_overlay(
                    tracker.tracker().model(),
                    &sequence.cameras[c],
                    tracker.state(),
                    image,
                    &config.features,
                )
                .with_context(|| format!("{}", sequence.frame_path(c, k).display()))?;
                writer.write((overlay_path(dir, c, k), drawn))?;
            }
        }
        lost += usize::from(report.lost);
        if auto.status != Status::Searching {
            rms_sum += f64::from(report.rms_px);
            rms_frames += 1;
        }
        statuses.push(auto.status);
        bar.inc(1);
    }
    bar.finish_and_clear();
    let frames = writer.finish()?;
    if let (Some(path), Some(out)) = (outputs.hypotheses_out, hypotheses_out) {
        hypotheses.out = Some((path.to_path_buf(), out.finish()?));
    }
    let overlays = match (overlay_dir, overlays) {
        (Some(dir), Some(writer)) => Some((dir.to_path_buf(), writer.finish()?)),
        _ => None,
    };
    Ok(TrackSummary {
        frames,
        cameras: sequence.cameras.len(),
        lost_frames: lost,
        mean_rms_px: rms_sum / f64::from(rms_frames.max(1)),
        init,
        status: StatusCounts::of(&statuses),
        tracking_seconds: tracking.as_secs_f64(),
        total_seconds: start.elapsed().as_secs_f64(),
        out: out_csv.to_path_buf(),
        fps: sequence.fps(),
        overlays,
        hypotheses,
    })
}
