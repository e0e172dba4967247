//! `digiteyes stream`: frames to a board over a serial link, its states back, written as the
//! same CSV as `track`.
//!
//! Frames come from a sequence folder or a V4L2 camera on the host; each is uploaded as
//! `FrameChunk`s and answered by the board with a `State` or a `Dropped` (see
//! [`link::Session`](crate::link::Session)). Every frame gets a row, in order: a dropped frame
//! repeats the last state with `lost` = 1, and the extra last column `dropped` says why
//! (empty for tracked frames), and then `status`, what the board claimed of the frame
//! (`searching`, `tracking` or `lost`; `lost` for a dropped frame; `lost` is 1 on every row
//! that is not `tracking`). The board starts tracking from the sequence's initial state, or
//! searching for the hand ([`StreamOptions::start`], `--init auto`). The summary adds the
//! statuses and the board's own measure of its work ([`BoardWork`]: `State::track_ticks` in
//! ticks of its clock, `Hello::clock_hz`).

use std::fmt;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{anyhow, ensure, Context, Result};
use digiteyes_core::protocol::{
    default_search_evaluations, Hypotheses, HypothesesParams, Start, State, TrackerParams,
};
use digiteyes_core::status::Status;
use digiteyes_core::tracker::FrameReport;
use digiteyes_platform_linux::camera::V4l2Camera;

use crate::link::{
    DropCause, FrameOutcome, Link, LinkReport, Session, SessionSetup, DEFAULT_REPLY_TIMEOUT,
};
use crate::sequence::hypotheses::HypothesesWriter;
use crate::sequence::{Sequence, StatesWriter};

/// The column `stream` adds after `track`'s: why a frame was not tracked.
pub const DROPPED_COLUMN: &str = "dropped";

/// The column after it: the board's status for the frame (`Status::as_str`'s words).
pub use crate::sequence::status::STATUS_COLUMN;

/// The last column: the board's own measure of its work on the frame, in ticks of its clock
/// (`State::track_ticks`, `Hello::clock_hz` ticks a second); empty for a dropped frame.
pub const BOARD_TICKS_COLUMN: &str = "board_ticks";

/// The default line speed (bits/s).
pub const DEFAULT_BAUD: u32 = 115_200;

/// How to reach the board and what to tell it.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct StreamOptions {
    /// The serial device of the board.
    pub port: String,
    /// Line speed (bits/s, 8N1).
    pub baud: u32,
    /// How long to wait for each frame's answer.
    pub reply_timeout: Duration,
    /// The camera of a multi-camera sequence to track (a board tracks one).
    pub camera_index: Option<usize>,
    /// The tracker parameters sent in `Configure`.
    pub tracker: TrackerParams,
    /// How the board starts (`Reset`): from the sequence's initial state, or searching for
    /// the free states (`--init auto`); `None`: given when the sequence has an initial state,
    /// searching when it has none.
    pub start: Option<Start>,
    /// The board's search budget per frame, in evaluations (`Configure`).
    pub search_evaluations_per_frame: u16,
    /// The hypotheses the board's tracker carries and what they may cost (`Configure`): more
    /// than one makes it send them after every state; the summary counts them.
    pub hypotheses: HypothesesParams,
    /// Where to write every hypothesis the board sends, frame by frame, as `track
    /// --hypotheses-out` writes the tracker's own ([`crate::sequence::hypotheses`]); `None`:
    /// only counted.
    pub hypotheses_out: Option<PathBuf>,
    /// Show a progress bar (when stderr is a terminal).
    pub progress: bool,
}

impl StreamOptions {
    /// Defaults for the board on `port`: 115200 baud, 2 s reply timeout, the default tracker.
    pub fn new(port: impl Into<String>) -> Self {
        StreamOptions {
            port: port.into(),
            baud: DEFAULT_BAUD,
            reply_timeout: DEFAULT_REPLY_TIMEOUT,
            camera_index: None,
            tracker: TrackerParams::default(),
            start: None,
            search_evaluations_per_frame: default_search_evaluations(),
            hypotheses: HypothesesParams::default(),
            hypotheses_out: None,
            progress: false,
        }
    }

    /// Starting the board this way (`None`: as the sequence allows, see
    /// [`SessionSetup::from_sequence`]).
    pub fn start(mut self, start: Option<Start>) -> Self {
        self.start = start;
        self
    }

    /// With this reply timeout.
    pub fn reply_timeout(mut self, timeout: Duration) -> Self {
        self.reply_timeout = timeout;
        self
    }

    /// Tracking camera `index` of the sequence.
    pub fn camera_index(mut self, index: Option<usize>) -> Self {
        self.camera_index = index;
        self
    }

    /// With this baud rate.
    pub fn baud(mut self, baud: u32) -> Self {
        self.baud = baud;
        self
    }

    /// With a progress bar or not.
    pub fn progress(mut self, progress: bool) -> Self {
        self.progress = progress;
        self
    }
}

/// What a stream did.
#[derive(Debug, Clone)]
pub struct StreamSummary {
    /// Frames uploaded (rows written).
    pub frames: usize,
    /// The fate of every frame, in order.
    pub outcomes: Vec<FrameOutcome>,
    /// Mean RMS residual over the tracked frames (px).
    pub mean_rms_px: f64,
    /// Where the states were written.
    pub out: PathBuf,
    /// The link's figures.
    pub link: LinkReport,
    /// Ticks per second of the board's clock (`Hello::clock_hz`), the unit of `track_ticks`.
    pub board_clock_hz: u32,
    /// Where the board's hypotheses were written, the rows written, and the messages left out
    /// because their frame did not follow the last one written or a hypothesis had another
    /// number of states than the model (none from a working board).
    pub hypotheses_out: Option<(PathBuf, usize, usize)>,
}

impl StreamSummary {
    /// Frames the board tracked.
    pub fn tracked(&self) -> usize {
        self.link.tracked
    }

    /// An error when the board tracked none of the frames: a run that produced no state is a
    /// failure, whatever the reasons its frames were dropped for.
    pub fn ensure_some_tracked(&self) -> Result<()> {
        if self.tracked() == 0 {
            anyhow::bail!(
                "the board tracked none of the {} frame(s) (the drops are listed above); {} \
                 holds no tracked state",
                self.frames,
                self.out.display()
            );
        }
        Ok(())
    }

    /// Frames the board answered with each status, in [`Status::ALL`]'s order (searching,
    /// tracking, lost).
    pub fn statuses(&self) -> [usize; 3] {
        let mut counts = [0; 3];
        for outcome in &self.outcomes {
            if let FrameOutcome::Tracked(state) = outcome {
                let status = Status::from(state.status);
                if let Some(i) = Status::ALL.iter().position(|&s| s == status) {
                    counts[i] += 1;
                }
            }
        }
        counts
    }

    /// The dropped frames and why, in order.
    pub fn dropped(&self) -> Vec<(usize, DropCause)> {
        self.outcomes
            .iter()
            .enumerate()
            .filter_map(|(k, o)| match o {
                FrameOutcome::Dropped(cause) => Some((k, *cause)),
                FrameOutcome::Tracked(_) => None,
            })
            .collect()
    }

    /// The board's work on the tracked frames (`State::track_ticks`, `State::iterations`);
    /// `None` when no frame was tracked.
    pub fn board_work(&self) -> Option<BoardWork> {
        let (mut frames, mut ticks, mut iterations) = (0u64, 0u64, 0u64);
        for outcome in &self.outcomes {
            if let FrameOutcome::Tracked(state) = outcome {
                frames += 1;
                ticks += u64::from(state.track_ticks);
                iterations += u64::from(state.iterations);
            }
        }
        (frames > 0).then_some(BoardWork {
            frames,
            ticks,
            iterations,
            clock_hz: self.board_clock_hz,
        })
    }
}

/// The tracking work a board reported over a stream, in ticks of its clock.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoardWork {
    /// Frames tracked.
    pub frames: u64,
    /// Their `track_ticks`, summed.
    pub ticks: u64,
    /// Their Gauss–Newton iterations, summed.
    pub iterations: u64,
    /// Ticks per second of the board's clock.
    pub clock_hz: u32,
}

impl BoardWork {
    /// Mean ticks per tracked frame.
    pub fn ticks_per_frame(&self) -> f64 {
        self.ticks as f64 / self.frames.max(1) as f64
    }

    /// Ticks per iteration: all ticks over all iterations (0 when none ran).
    pub fn ticks_per_iteration(&self) -> f64 {
        if self.iterations == 0 {
            return 0.0;
        }
        self.ticks as f64 / self.iterations as f64
    }
}

impl fmt::Display for BoardWork {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let ms = |ticks: f64| 1000.0 * ticks / f64::from(self.clock_hz.max(1));
        write!(
            f,
            "board work: mean {:.0} ticks/frame, {:.0} ticks/iteration at {} Hz ({:.3} ms/frame, \
             {:.3} ms/iteration; {:.2} iterations/frame)",
            self.ticks_per_frame(),
            self.ticks_per_iteration(),
            self.clock_hz,
            ms(self.ticks_per_frame()),
            ms(self.ticks_per_iteration()),
            self.iterations as f64 / self.frames.max(1) as f64
        )
    }
}

impl fmt::Display for StreamSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "streamed {} frames: {} tracked ({} lost), {} dropped, mean rms {:.3} px",
            self.frames,
            self.link.tracked,
            self.link.lost,
            self.link.dropped_total(),
            self.mean_rms_px
        )?;
        let [searching, tracking, lost] = self.statuses();
        writeln!(
            f,
            "board status: {tracking} tracking, {lost} lost, {searching} searching"
        )?;
        let dropped = self.dropped();
        if !dropped.is_empty() {
            let list: Vec<String> = dropped
                .iter()
                .take(12)
                .map(|(k, cause)| format!("{k} ({cause})"))
                .collect();
            let more = dropped.len().saturating_sub(12);
            write!(f, "dropped frames: {}", list.join(", "))?;
            if more > 0 {
                write!(f, " and {more} more")?;
            }
            writeln!(f)?;
        }
        writeln!(f, "states written to {}", self.out.display())?;
        if let Some((path, rows, skipped)) = &self.hypotheses_out {
            write!(f, "hypotheses: {rows} row(s) written to {}", path.display())?;
            if *skipped > 0 {
                write!(
                    f,
                    " ({skipped} message(s) out of frame order or of the wrong size left out)"
                )?;
            }
            writeln!(f)?;
        }
        if let Some(work) = self.board_work() {
            writeln!(f, "{work}")?;
        }
        write!(f, "{}", self.link)
    }
}

/// Streams every frame of the sequence in `seq` to the board and writes its states to
/// `out_csv`.
pub fn stream_sequence(
    seq: &Path,
    out_csv: &Path,
    options: &StreamOptions,
) -> Result<StreamSummary> {
    let sequence = Sequence::open(seq)?;
    let camera = pick_camera(&sequence, options.camera_index)?;
    sequence.check_frames()?;
    sequence.check_cameras_see_the_hand(&[camera])?;
    let session = connect(&sequence, options)?;
    let frames = (0..sequence.frames).map(|k| {
        let image = sequence.read_frame(camera, k)?;
        Ok((image.width(), image.height(), image.into_raw()))
    });
    run(
        session,
        &sequence,
        frames,
        sequence.frames,
        out_csv,
        options,
    )
}

/// Streams `frames` frames captured from the V4L2 camera `device` (on this host) to the
/// board, set up from the calibration, model, initial state and free states in `setup` (a
/// `sequence.json`; no frames needed), and writes its states to `out_csv`.
pub fn stream_camera(
    device: &Path,
    setup: &Path,
    frames: usize,
    out_csv: &Path,
    options: &StreamOptions,
) -> Result<StreamSummary> {
    let sequence = Sequence::open_description(setup)?;
    let index = pick_camera(&sequence, options.camera_index)?;
    let calibrated = &sequence.cameras[index];
    let size = (calibrated.width, calibrated.height);
    let mut camera = V4l2Camera::open(device, Some(size))?;
    let session = connect(&sequence, options)?;
    let mut buffer = vec![0u8; size.0 as usize * size.1 as usize];
    let captured = (0..frames).map(move |_| {
        camera
            .capture(&mut buffer, true)
            .with_context(|| format!("camera {}", device.display()))?;
        Ok((size.0, size.1, buffer.clone()))
    });
    run(session, &sequence, captured, frames, out_csv, options)
}

fn pick_camera(sequence: &Sequence, index: Option<usize>) -> Result<usize> {
    // SessionSetup says what is wrong with the choice; the index itself is all we need here.
    SessionSetup::from_sequence(sequence, index)?;
    Ok(index.unwrap_or(0))
}

fn connect(sequence: &Sequence, options: &StreamOptions) -> Result<Session> {
    let mut setup = SessionSetup::from_sequence(sequence, options.camera_index)?;
    setup.tracker = options.tracker;
    if let Some(start) = options.start {
        if start == Start::Given && !sequence.initial_given {
            anyhow::bail!(
                "{}: --init given needs `initial_state` in sequence.json, which has none \
                 (leave --init out, or use --init auto)",
                sequence.dir.display()
            );
        }
        setup.start = start;
    }
    setup.search_evaluations_per_frame = options.search_evaluations_per_frame;
    setup.hypotheses = options.hypotheses;
    setup.reply_timeout = options.reply_timeout;
    let link = Link::open(&options.port, options.baud)?;
    Session::start(link, setup)
}

type Frame = (u32, u32, Vec<u8>);

fn run(
    mut session: Session,
    sequence: &Sequence,
    frames: impl Iterator<Item = Result<Frame>>,
    expected: usize,
    out_csv: &Path,
    options: &StreamOptions,
) -> Result<StreamSummary> {
    let mut writer = StatesWriter::with_columns(
        out_csv,
        sequence.n_states(),
        &[DROPPED_COLUMN, STATUS_COLUMN, BOARD_TICKS_COLUMN],
    )?;
    let mut hypotheses = match &options.hypotheses_out {
        Some(path) => {
            session.keep_hypotheses();
            Some(BoardHypotheses {
                writer: HypothesesWriter::create(path, sequence.n_states())?,
                n_states: sequence.n_states(),
                next_frame: 0,
                skipped: 0,
            })
        }
        None => None,
    };
    let bar = crate::progress::bar(expected, "stream", options.progress);
    let mut last: Vec<f32> = sequence.initial_state.iter().map(|&v| v as f32).collect();
    let mut outcomes = Vec::with_capacity(expected);
    let mut rms_sum = 0.0;
    for (k, frame) in frames.enumerate() {
        let (width, height, pixels) = frame?;
        let number = u32::try_from(k).map_err(|_| anyhow!("frame {k}: too many frames"))?;
        let size = |v: u32| u16::try_from(v).map_err(|_| anyhow!("frame {k} is over 65535 px"));
        let outcome = session.track(number, &pixels, size(width)?, size(height)?)?;
        match &outcome {
            FrameOutcome::Tracked(state) => {
                ensure!(
                    state.q.len() == last.len(),
                    "board on {} sent {} states for frame {k}, the model has {}",
                    options.port,
                    state.q.len(),
                    last.len()
                );
                last.copy_from_slice(&state.q);
                rms_sum += f64::from(state.rms_px);
                let status = Status::from(state.status).as_str();
                let ticks = state.track_ticks.to_string();
                writer.write_with(&last, &report_of(state), &["", status, &ticks])?;
            }
            FrameOutcome::Dropped(cause) => {
                let report = FrameReport {
                    rms_px: f32::NAN,
                    lost: true,
                    ..FrameReport::default()
                };
                let lost = Status::Lost.as_str();
                writer.write_with(&last, &report, &[&cause.to_string(), lost, ""])?;
            }
        }
        outcomes.push(outcome);
        if let Some(out) = hypotheses.as_mut() {
            out.write(session.take_hypotheses())?;
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    let frames = writer.finish()?;
    let link = session.finish()?;
    let hypotheses_out = match (hypotheses, &options.hypotheses_out) {
        (Some(mut out), Some(path)) => {
            // The last frame's message came while `finish` awaited its answer.
            out.write(session.take_hypotheses())?;
            Some((path.clone(), out.writer.finish()?, out.skipped))
        }
        _ => None,
    };
    let board_clock_hz = session.hello().clock_hz;
    Ok(StreamSummary {
        frames,
        mean_rms_px: rms_sum / link.tracked.max(1) as f64,
        outcomes,
        out: out_csv.to_path_buf(),
        link,
        board_clock_hz,
        hypotheses_out,
    })
}

/// The board's hypotheses on their way to the file: each message's rows, frames ascending.
/// A message the file cannot hold is left out and counted, so the stream (and its states
/// file) goes on.
struct BoardHypotheses {
    writer: HypothesesWriter,
    /// The model's states: every hypothesis of a message written must have as many.
    n_states: usize,
    /// The first frame a message may be written for (frames ascend in the file).
    next_frame: u64,
    /// Messages left out: their frame did not follow the last one written, or a hypothesis
    /// had another number of states than the model.
    skipped: usize,
}

impl BoardHypotheses {
    fn write(&mut self, messages: Vec<Hypotheses>) -> Result<()> {
        for message in messages {
            let frame = u64::from(message.frame);
            let whole = message
                .hypotheses
                .iter()
                .all(|h| h.q.len() == self.n_states);
            if frame < self.next_frame || !whole {
                self.skipped += 1;
                continue;
            }
            self.writer.write_message(&message)?;
            self.next_frame = frame + 1;
        }
        Ok(())
    }
}

/// The tracker's report as the board sent it (`lost` whenever the board claims no hand).
pub fn report_of(state: &State) -> FrameReport {
    FrameReport {
        rms_px: state.rms_px,
        features_found: state.features_found,
        features_expected: state.features_expected,
        iterations: state.iterations,
        lost: state.lost || !Status::from(state.status).claims_hand(),
        ..FrameReport::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use digiteyes_core::protocol::{DropReason, WireStatus};

    fn tracked(track_ticks: u32, iterations: u8) -> FrameOutcome {
        with_status(track_ticks, iterations, WireStatus::Tracking)
    }

    fn with_status(track_ticks: u32, iterations: u8, status: WireStatus) -> FrameOutcome {
        FrameOutcome::Tracked(State {
            frame: 0,
            timestamp: 0,
            q: heapless::Vec::new(),
            rms_px: 0.5,
            lost: false,
            features_found: 10,
            features_expected: 10,
            iterations,
            track_ticks,
            status,
            search_evaluations: 0,
        })
    }

    /// Messages are written as they come while their frames ascend; one whose frame does not
    /// follow the last written, or with a hypothesis of another size than the model's, is left
    /// out and counted (not written, and not an error that would end the stream).
    #[test]
    fn the_boards_hypotheses_are_written_in_frame_order_only() {
        use digiteyes_core::protocol::WireHypothesis;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("hyp.csv");
        let message = |frame: u32, count: usize| Hypotheses {
            frame,
            hypotheses: (0..count)
                .map(|i| WireHypothesis {
                    score: 0.5,
                    age: i as u32,
                    q: [1.0, 0.0, 0.0, 0.0, frame as f32].into_iter().collect(),
                })
                .collect(),
        };
        let mut out = BoardHypotheses {
            writer: HypothesesWriter::create(&path, 5).unwrap(),
            n_states: 5,
            next_frame: 0,
            skipped: 0,
        };
        out.write(vec![message(0, 2), message(2, 1)]).unwrap();
        let mut short = message(3, 2);
        short.hypotheses[1].q.pop();
        out.write(vec![
            message(2, 3),
            message(1, 1),
            short,
            message(3, 0),
            message(4, 1),
        ])
        .unwrap();
        assert_eq!(out.skipped, 3);
        assert_eq!(out.writer.finish().unwrap(), 4);
        let table = crate::sequence::hypotheses::read_hypotheses(&path, 5).unwrap();
        let frames: Vec<(usize, usize)> = table.rows.iter().map(|r| (r.frame, r.rank)).collect();
        assert_eq!(frames, [(0, 0), (0, 1), (2, 0), (4, 0)]);
        assert_eq!(table.rows[3].state[4], 4.0);
    }

    #[test]
    fn board_work_sums_the_tracked_frames_only() {
        let summary = StreamSummary {
            frames: 3,
            outcomes: vec![
                tracked(100_000, 8),
                FrameOutcome::Dropped(DropCause::Board(DropReason::Incomplete)),
                tracked(50_000, 4),
            ],
            mean_rms_px: 0.5,
            out: PathBuf::from("states.csv"),
            link: LinkReport::default(),
            board_clock_hz: 25_000_000,
            hypotheses_out: None,
        };
        let work = summary.board_work().unwrap();
        assert_eq!((work.frames, work.ticks, work.iterations), (2, 150_000, 12));
        assert_eq!(work.ticks_per_frame(), 75_000.0);
        assert_eq!(work.ticks_per_iteration(), 12_500.0);
        let text = summary.to_string();
        assert!(
            text.contains(
                "board work: mean 75000 ticks/frame, 12500 ticks/iteration at 25000000 Hz"
            ),
            "{text}"
        );
        let none = StreamSummary {
            outcomes: vec![FrameOutcome::Dropped(DropCause::NoReply)],
            ..summary
        };
        assert!(none.board_work().is_none() && !none.to_string().contains("board work"));
    }

    #[test]
    fn a_run_with_nothing_tracked_is_an_error() {
        let mut summary = StreamSummary {
            frames: 2,
            outcomes: vec![FrameOutcome::Dropped(DropCause::Board(DropReason::Incomplete)); 2],
            mean_rms_px: 0.0,
            out: PathBuf::from("states.csv"),
            link: LinkReport::default(),
            board_clock_hz: 1,
            hypotheses_out: None,
        };
        let e = summary.ensure_some_tracked().unwrap_err().to_string();
        assert!(e.contains("tracked none of the 2 frame(s)"), "{e}");
        summary.link.tracked = 1;
        assert!(summary.ensure_some_tracked().is_ok());
    }

    #[test]
    fn the_summary_counts_the_boards_statuses() {
        let summary = StreamSummary {
            frames: 5,
            outcomes: vec![
                with_status(10, 0, WireStatus::Searching),
                with_status(10, 0, WireStatus::Searching),
                tracked(10, 8),
                with_status(10, 8, WireStatus::Lost),
                FrameOutcome::Dropped(DropCause::NoReply),
            ],
            mean_rms_px: 0.5,
            out: PathBuf::from("states.csv"),
            link: LinkReport::default(),
            board_clock_hz: 1,
            hypotheses_out: None,
        };
        assert_eq!(summary.statuses(), [2, 1, 1]);
        let text = summary.to_string();
        assert!(
            text.contains("board status: 1 tracking, 1 lost, 2 searching"),
            "{text}"
        );
    }
}
