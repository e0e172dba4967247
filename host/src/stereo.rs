//! `digiteyes stream --port A --port B`: one board per camera, one hand, as the thesis' stereo
//! system ran (Sec. 4.3): each board holds its camera's frames; per Gauss–Newton iteration
//! the host sends the state to every board (`Measure`), each searches its own frame at it and
//! answers with what every link and palm outline edge showed (`LinkEdges` …, `PalmEdges` …,
//! `Measured`), and the host fuses all of
//! it in one solve — the same tracker loop as `track`, fed through a
//! [`Measurer`] — then sends the new state back.
//!
//! ```text
//! host                                      board (one per camera)
//!  Configure, Reset, Hold ─────────────────▶  Ack …, Ack(Hold)
//!  FrameChunk × n (frame k) ───────────────▶  (held)
//!  Measure(k, iteration 0, q) ─────────────▶  LinkEdges × links, PalmEdges × edges,
//!                                              Measured(k, 0)
//!  Measure(k, iteration 1, q') ────────────▶  …
//! ```
//!
//! A board that does not answer within the reply timeout is left out — the host carries on
//! with the cameras that answer and says so — and is asked again on every later frame, so it
//! is taken back as soon as it answers.
//!
//! The host's tracker starts from the sequence's initial state only (it does not search):
//! the CSV's `status` column, after `track`'s columns, is `tracking` or `lost` (the tracker's
//! `lost` flag), never `searching`.

use std::fmt;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{anyhow, ensure, Context, Result};
use digiteyes_core::camera::Camera;
use digiteyes_core::config::MAX_STATES;
use digiteyes_core::features::{FeatureConfig, LinkFeatures};
use digiteyes_core::fill::FillConfig;
use digiteyes_core::measurer::Measurer;
use digiteyes_core::palm_outline::{HullEdge, MAX_HULL_EDGES};
use digiteyes_core::projection::ProjectedModel;
use digiteyes_core::protocol::{
    BoardMessage, HostMessage, LinkEdges, Measure, PalmEdges, TrackerParams,
};
use digiteyes_core::status::Status;
use digiteyes_core::tracker::TrackerConfig;

use crate::link::{Link, Session, SessionSetup, DEFAULT_REPLY_TIMEOUT};
use crate::sequence::{Sequence, StatesWriter};
use crate::stream::{DEFAULT_BAUD, STATUS_COLUMN};

/// Most boards (cameras) one host drives.
pub const MAX_BOARDS: usize = digiteyes_core::config::MAX_CAMERAS;

/// How long a board left out is waited for on each later frame before the host goes on
/// without it: short, so a dead board costs little; an answer within it takes it back.
pub const ABSENT_PROBE: Duration = Duration::from_millis(200);

/// How to reach the boards and what to tell them.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct StereoOptions {
    /// The serial devices of the boards: board `i` holds camera `i` of the sequence.
    pub ports: Vec<String>,
    /// Line speed (bits/s, 8N1).
    pub baud: u32,
    /// How long to wait for a board's answer to each `Measure` (and each command).
    pub reply_timeout: Duration,
    /// The tracker: the host solves with it, the boards search with its parameters.
    pub tracker: TrackerParams,
    /// Show a progress bar (when stderr is a terminal).
    pub progress: bool,
}

impl StereoOptions {
    /// Defaults for boards on `ports`: 115200 baud, 2 s reply timeout, the default tracker.
    pub fn new(ports: Vec<String>) -> Self {
        StereoOptions {
            ports,
            baud: DEFAULT_BAUD,
            reply_timeout: DEFAULT_REPLY_TIMEOUT,
            tracker: TrackerParams::default(),
            progress: false,
        }
    }
}

/// What one board did over a run.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct BoardFigures {
    /// Its serial device.
    pub port: String,
    /// `Measure`s it answered.
    pub answered: u64,
    /// `Measure`s it left unanswered (timed out).
    pub unanswered: u64,
    /// Frames tracked without it.
    pub frames_without: usize,
    /// Times it was left out, and taken back.
    pub left_out: u32,
    /// Times it came back after being left out.
    pub taken_back: u32,
    /// Frames it did not hold when asked (an upload lost on the line).
    pub not_held: u64,
    /// Reboots it went through (set up again each time).
    pub restarts: u32,
    /// Bytes host → board, frames included.
    pub bytes_up: u64,
    /// Bytes board → host.
    pub bytes_down: u64,
    /// `Measure` bytes host → board (no frames).
    pub measure_bytes_up: u64,
    /// Answer bytes board → host (`LinkEdges` and `Measured`).
    pub answer_bytes_down: u64,
    /// What went wrong last, if anything.
    pub last_problem: Option<String>,
}

/// The outcome of a two-board run.
#[derive(Debug, Clone)]
pub struct StereoSummary {
    /// Frames tracked (rows written).
    pub frames: usize,
    /// Frames reported lost.
    pub lost_frames: usize,
    /// Gauss–Newton iterations run, in all.
    pub iterations: u64,
    /// Mean residual RMS (px).
    pub mean_rms_px: f64,
    /// Each board's figures, in camera order.
    pub boards: Vec<BoardFigures>,
    /// Where the states went.
    pub out: PathBuf,
    /// Wall time of the run (s).
    pub seconds: f64,
}

impl fmt::Display for StereoSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "tracked {} frames with {} boards ({} iterations, {:.2} per frame): {} lost, mean \
             RMS {:.2} px, {:.1} frames/s -> {}",
            self.frames,
            self.boards.len(),
            self.iterations,
            self.iterations as f64 / self.frames.max(1) as f64,
            self.lost_frames,
            self.mean_rms_px,
            self.frames as f64 / self.seconds.max(1e-9),
            self.out.display()
        )?;
        for (i, b) in self.boards.iter().enumerate() {
            let per = (b.answered + b.unanswered).max(1) as f64;
            write!(
                f,
                "  camera {i} on {}: {} measures answered, {} unanswered; {} frames without it \
                 (left out {}x, taken back {}x); {} restart(s); {:.0} B up and {:.0} B down per \
                 measure",
                b.port,
                b.answered,
                b.unanswered,
                b.frames_without,
                b.left_out,
                b.taken_back,
                b.restarts,
                b.measure_bytes_up as f64 / per,
                b.answer_bytes_down as f64 / b.answered.max(1) as f64,
            )?;
            if let Some(p) = &b.last_problem {
                write!(f, "; last problem: {p}")?;
            }
            writeln!(f)?;
        }
        Ok(())
    }
}

/// One board holding one camera's frames.
struct BoardCamera {
    session: Session,
    present: bool,
    figures: BoardFigures,
    /// This iteration's answer: `LinkEdges` by their index in view.
    links: Vec<Option<LinkEdges>>,
    /// ... and `PalmEdges`, in the order they came (at most one per outline edge).
    palm: Vec<PalmEdges>,
    silhouette: Option<f32>,
    /// A `Measure` went out this iteration and its answer is awaited.
    awaiting: bool,
    /// Answered this frame (for `frames_without`).
    answered_this_frame: bool,
}

impl BoardCamera {
    fn clear_answer(&mut self) {
        self.links.iter_mut().for_each(|l| *l = None);
        self.palm.clear();
        self.silhouette = None;
    }

    fn note_problem(&mut self, problem: impl Into<String>) {
        self.figures.last_problem = Some(problem.into());
    }

    /// Waits until `deadline` for the answer to (frame, iteration); true when it came.
    fn collect(&mut self, frame: u32, iteration: u8, deadline: Instant) -> Result<bool> {
        loop {
            let before = self.session.link().bytes_down();
            let Some(message) = self.session.link_mut().recv_until(deadline)? else {
                return Ok(false);
            };
            let bytes = self.session.link().bytes_down() - before;
            match message {
                BoardMessage::LinkEdges(e) if e.frame == frame && e.iteration == iteration => {
                    self.figures.answer_bytes_down += bytes;
                    let index = usize::from(e.index);
                    if let Some(slot) = self.links.get_mut(index) {
                        *slot = Some(e);
                    }
                }
                BoardMessage::PalmEdges(e) if e.frame == frame && e.iteration == iteration => {
                    self.figures.answer_bytes_down += bytes;
                    if self.palm.len() < MAX_HULL_EDGES {
                        self.palm.push(e);
                    }
                }
                BoardMessage::Measured(m) if m.frame == frame && m.iteration == iteration => {
                    self.figures.answer_bytes_down += bytes;
                    if !m.held {
                        self.figures.not_held += 1;
                        self.note_problem(format!("frame {frame} was not held"));
                    }
                    self.silhouette = m.silhouette;
                    return Ok(true);
                }
                BoardMessage::Hello(hello) => {
                    // Rebooted: its frame and setup are gone; set it up again, measure later.
                    self.figures.restarts += 1;
                    self.session.hold_again(hello)?;
                    self.note_problem("the board restarted");
                    return Ok(false);
                }
                // Late answers to earlier measures, counters, acks: nothing to wait for.
                _ => {}
            }
        }
    }
}

/// The boards as the tracker's [`Measurer`].
struct Boards<'b> {
    boards: &'b mut [BoardCamera],
    frame: u32,
    iteration: u8,
    reply_timeout: Duration,
}

impl Boards<'_> {
    fn ask_all(&mut self, q: &[f32]) {
        let measure = HostMessage::Measure(Measure {
            frame: self.frame,
            iteration: self.iteration,
            q: q.iter().copied().take(MAX_STATES).collect(),
        });
        for board in self.boards.iter_mut() {
            board.clear_answer();
            // A board left out is asked on each frame's first iteration only.
            board.awaiting = board.present || self.iteration == 0;
            if !board.awaiting {
                continue;
            }
            let before = board.session.link().bytes_up();
            if let Err(e) = board.session.link_mut().send(&measure) {
                board.note_problem(format!("{e:#}"));
                board.awaiting = false;
                continue;
            }
            board.figures.measure_bytes_up += board.session.link().bytes_up() - before;
        }
        // Every board got its state before any answer is awaited: they search in parallel.
        let started = Instant::now();
        for board in self.boards.iter_mut().filter(|b| b.awaiting) {
            let wait = if board.present {
                self.reply_timeout
            } else {
                ABSENT_PROBE.min(self.reply_timeout)
            };
            let answered = match board.collect(self.frame, self.iteration, started + wait) {
                Ok(answered) => answered,
                Err(e) => {
                    // A port gone or a board set up wrong after a reboot: leave it out.
                    board.note_problem(format!("{e:#}"));
                    false
                }
            };
            if answered {
                board.figures.answered += 1;
                board.answered_this_frame = true;
                if !board.present {
                    board.present = true;
                    board.figures.taken_back += 1;
                }
            } else {
                board.clear_answer();
                if board.present {
                    board.figures.unanswered += 1;
                    board.figures.left_out += 1;
                    board.present = false;
                    board.note_problem(format!(
                        "no answer to frame {} iteration {} within {:.1} s",
                        self.frame,
                        self.iteration,
                        wait.as_secs_f64()
                    ));
                }
            }
        }
    }
}

impl Measurer for Boards<'_> {
    fn begin_iteration(&mut self, q: &[f32], refine: bool) {
        self.iteration = if refine { self.iteration + 1 } else { 0 };
        self.ask_all(q);
    }

    fn link_features(
        &mut self,
        camera_index: usize,
        _camera: &Camera,
        view: &ProjectedModel,
        index: usize,
        _config: &FeatureConfig,
        _refine: bool,
        out: &mut LinkFeatures,
    ) {
        let answer = self
            .boards
            .get(camera_index)
            .and_then(|b| b.links.get(index))
            .and_then(Option::as_ref);
        match (answer, view.links.get(index)) {
            (Some(edges), Some(link)) if edges.link == link.frame => edges.to_features(out),
            _ => *out = LinkFeatures::default(),
        }
    }

    fn palm_edge_features(
        &mut self,
        camera_index: usize,
        _camera: &Camera,
        _view: &ProjectedModel,
        edge: &HullEdge,
        _config: &FeatureConfig,
        _refine: bool,
        out: &mut LinkFeatures,
    ) {
        let answer = self
            .boards
            .get(camera_index)
            .and_then(|b| b.palm.iter().find(|p| p.corners == edge.corners));
        match answer {
            Some(edges) => edges.to_features(out),
            None => *out = LinkFeatures::default(),
        }
    }

    fn silhouette(
        &mut self,
        camera_index: usize,
        _camera: &Camera,
        _view: &ProjectedModel,
        _grid: usize,
    ) -> Option<f32> {
        self.boards.get(camera_index)?.silhouette
    }
}

/// Tracks the sequence in `seq` with one board per camera on `options.ports` and writes the
/// states to `out_csv` (the same CSV as `track`).
pub fn stream_stereo(seq: &Path, out_csv: &Path, options: &StereoOptions) -> Result<StereoSummary> {
    let started = Instant::now();
    let sequence = Sequence::open(seq)?;
    sequence.check_frames()?;
    let n_cameras = sequence.cameras.len();
    ensure!(
        options.ports.len() == n_cameras,
        "{}: the sequence has {n_cameras} camera(s) and {} --port(s) were given: give one \
         board per camera, in camera order",
        seq.display(),
        options.ports.len()
    );
    ensure!(
        n_cameras <= MAX_BOARDS,
        "at most {MAX_BOARDS} boards, one per camera"
    );
    let config: TrackerConfig = boards_config(&options.tracker)?;
    let mut tracker = crate::track::sequence_tracker(&sequence, config)
        .map_err(|e| anyhow!("{}: cannot start the tracker: {e}", seq.display()))?;
    let mut boards = Vec::with_capacity(n_cameras);
    for (camera, port) in options.ports.iter().enumerate() {
        let link = Link::open(port, options.baud)?;
        let mut setup = SessionSetup::from_sequence(&sequence, Some(camera))?;
        setup.tracker = options.tracker;
        setup.reply_timeout = options.reply_timeout;
        let mut session = Session::start(link, setup)
            .with_context(|| format!("setting up the board of camera {camera} on {port}"))?;
        session
            .hold()
            .with_context(|| format!("the board of camera {camera} on {port}"))?;
        boards.push(BoardCamera {
            session,
            present: true,
            figures: BoardFigures {
                port: port.clone(),
                ..BoardFigures::default()
            },
            links: vec![None; digiteyes_core::config::MAX_LINKS],
            palm: Vec::with_capacity(MAX_HULL_EDGES),
            silhouette: None,
            awaiting: false,
            answered_this_frame: false,
        });
    }
    let mut writer = StatesWriter::with_columns(out_csv, sequence.n_states(), &[STATUS_COLUMN])?;
    let bar = crate::progress::bar(sequence.frames, "stream", options.progress);
    let (mut lost, mut rms_sum, mut iterations) = (0, 0.0, 0u64);
    for k in 0..sequence.frames {
        let frame = k as u32;
        for (c, board) in boards.iter_mut().enumerate() {
            let image = sequence.read_frame(c, k)?;
            board.answered_this_frame = false;
            if let Err(e) = board.session.upload(
                frame,
                image.as_raw(),
                image.width() as u16,
                image.height() as u16,
            ) {
                board.note_problem(format!("{e:#}"));
            }
        }
        let mut measurer = Boards {
            boards: &mut boards,
            frame,
            iteration: 0,
            reply_timeout: options.reply_timeout,
        };
        let report = tracker
            .track_with(&mut measurer)
            .map_err(|e| anyhow!("frame {k}: the tracker failed: {e}"))?;
        for board in boards.iter_mut() {
            board.session.note_state(tracker.state());
            if !board.answered_this_frame {
                board.figures.frames_without += 1;
            }
        }
        // Given-only: the host's tracker never searches, so a frame is tracking or lost.
        let status = match report.lost {
            true => Status::Lost,
            false => Status::Tracking,
        };
        writer
            .write_with(tracker.state(), &report, &[status.as_str()])
            .with_context(|| format!("frame {k}"))?;
        lost += usize::from(report.lost);
        rms_sum += f64::from(report.rms_px);
        iterations += u64::from(report.iterations);
        bar.inc(1);
    }
    bar.finish_and_clear();
    let frames = writer.finish()?;
    let boards = boards
        .into_iter()
        .map(|b| BoardFigures {
            bytes_up: b.session.link().bytes_up(),
            bytes_down: b.session.link().bytes_down(),
            ..b.figures
        })
        .collect();
    Ok(StereoSummary {
        frames,
        lost_frames: lost,
        iterations,
        mean_rms_px: rms_sum / frames.max(1) as f64,
        boards,
        out: out_csv.to_path_buf(),
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// The host's solve over boards: `params` as the boards run them, without region rows. The
/// boards send the features they find, not their frames, and region rows need the pixels
/// ([`digiteyes_core::fill`]), so the host adds none.
pub fn boards_config(params: &TrackerParams) -> Result<TrackerConfig> {
    let mut config = params
        .to_config()
        .map_err(|e| anyhow!("tracker parameters: {e}"))?;
    config.fill = FillConfig::OFF;
    Ok(config)
}

/// A tracker configuration as the boards will run it: `config` through the wire form, so
/// the host's solve and the boards' searches use the same parameters.
pub fn wire_config(config: &TrackerConfig) -> Result<TrackerConfig> {
    TrackerParams::from_config(config)
        .to_config()
        .map_err(|e| anyhow!("tracker parameters: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_tracker_survives_the_wire_form() {
        let mut config = TrackerConfig::default();
        config.iterations = 3;
        assert_eq!(wire_config(&config).unwrap(), config);
    }
}
