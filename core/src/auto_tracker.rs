//! The tracker that finds the hand itself: the [`Status`] machine around the anytime
//! [search](crate::acquire) and the Gauss–Newton [tracker](crate::tracker) (issue 10).
//!
//! - **Searching**: each frame moves the search on within its budget. When it is over, its
//!   leaves are refined by the tracker's Gauss–Newton on the frames that follow, one leaf per
//!   frame, and the best refined leaf is taken for the hand if its likelihood reaches the
//!   acceptance score; otherwise the search starts over.
//! - **Tracking**: the tracker runs; a lost frame makes the status [`Status::Lost`].
//! - **Lost**: the tracker still runs (holding its last good state); a frame not lost makes it
//!   `Tracking` again, [`LOST_FRAMES_BEFORE_SEARCH`] lost frames in a row make it `Searching`
//!   (unless [`Recovery::Never`]: then it stays `Lost`, as the plain tracker does).
//! - **Searching after a loss** first tries a *local re-acquisition* for
//!   [`LOCAL_SEARCH_FRAMES`] frames (the hand does not go far while it is hidden for a second
//!   or two): each frame, the last good state is slid over each camera's edge map within
//!   [`LOCAL_WINDOW`] of the frame's width of where it projects ([`Acquirer::place`]), each
//!   placed state refined by the tracker's Gauss–Newton ([`LOCAL_REFINE_PASSES`] passes on the
//!   frame), and the best taken for the hand if its likelihood reaches the acceptance score —
//!   the same test as the search's leaves. The work per frame is bounded: one slide and
//!   [`LOCAL_REFINE_PASSES`] tracker passes per camera. Only then does the global search run.
//! - While searching, [`AutoTracker::state`] holds the last state that claimed the hand (the
//!   base state before the first acquisition), never a refused hypothesis.
//!
//! The edge maps the search needs live in the caller's buffers, one per camera, of
//! [`AutoTracker::edge_bytes_needed`] bytes; only searching frames build them.

use core::fmt;

use heapless::Vec;

use crate::acquire::{AcquireConfig, Acquirer, Progress, WorkingVolume, MAX_KEEP};
use crate::camera::Camera;
use crate::config::{MAX_CAMERAS, MAX_STATES};
use crate::estimator::FreeMask;
use crate::frame::FrameView;
use crate::likelihood::{EdgeMap, LikelihoodError};
use crate::model::Model;
pub use crate::status::Status;
use crate::tracker::{FrameReport, Tracker, TrackerConfig, TrackerError};

/// Lost frames in a row after which the tracker gives the hand up and searches again.
pub const LOST_FRAMES_BEFORE_SEARCH: u32 = 10;

/// The likelihood score (0..=1) a refined leaf needs to be taken for the hand: the true state
/// scored 0.94–0.99 on six untuned random rigs at 320×240, wrong refined leaves up to 0.96
/// (docs/recovery.md), so this refuses most wrong leaves and few right ones.
pub const DEFAULT_ACCEPT_SCORE: f32 = 0.93;

/// Searching frames after a loss spent on the local re-acquisition before the global search:
/// two seconds at 30 frames/s, after the [`LOST_FRAMES_BEFORE_SEARCH`] lost frames.
pub const LOCAL_SEARCH_FRAMES: u32 = 60;

/// Half the side of the window the local re-acquisition slides the last good state over, as a
/// share of the frame's width (0.25: ±80 px at 320×240).
pub const LOCAL_WINDOW: f32 = 0.25;

/// Gauss–Newton passes (each a whole tracker frame, restarted fresh) over a placed state in
/// the local re-acquisition.
pub const LOCAL_REFINE_PASSES: u32 = 2;

/// A refined local hypothesis scoring at least this (but under the acceptance score) is
/// followed to the next frame, where it is refined again: a hand half back in view, or moved
/// far from the last good state, is then closed in on over a few frames.
pub const LOCAL_FOLLOW_SCORE: f32 = 0.8;

/// What the tracker does once the hand has been lost for [`LOST_FRAMES_BEFORE_SEARCH`] frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Recovery {
    /// Search again: first locally around the last good state, then globally.
    #[default]
    Search,
    /// Never search: stay [`Status::Lost`] and keep tracking, as the plain tracker does.
    Never,
}

/// Depth (mm) along a camera's axis of the default working volume when no camera sees the
/// world origin.
pub const FALLBACK_DEPTH_MM: f32 = 600.0;

/// Why a frame could not be used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum AutoError {
    /// The tracker refused the frames or a state.
    Tracker(TrackerError),
    /// An edge map could not be built (e.g. a buffer too small).
    EdgeMap(LikelihoodError),
    /// Fewer edge-map buffers than cameras.
    BufferCount,
}

impl fmt::Display for AutoError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Tracker(e) => write!(f, "tracker: {e}"),
            Self::EdgeMap(e) => write!(f, "edge map: {e}"),
            Self::BufferCount => f.write_str("one edge-map buffer per camera is needed"),
        }
    }
}

impl core::error::Error for AutoError {}

impl From<TrackerError> for AutoError {
    fn from(e: TrackerError) -> Self {
        AutoError::Tracker(e)
    }
}

/// One frame's outcome.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AutoReport {
    /// The status after this frame.
    pub status: Status,
    /// The tracker's report (`lost` set whenever no hand is claimed).
    pub report: FrameReport,
    /// Hypotheses the search scored on this frame.
    pub evaluated: u16,
    /// The likelihood score of a leaf refined on this frame, accepted or not.
    pub leaf_score: Option<f32>,
    /// The frame was spent on the local re-acquisition around the last good state.
    pub local: bool,
}

/// A tracker that finds the hand, tracks it, and finds it again.
#[derive(Debug, Clone)]
pub struct AutoTracker {
    tracker: Tracker,
    acquirer: Acquirer,
    status: Status,
    lost_run: u32,
    accept_score: f32,
    /// The search's leaves still to refine (one per frame), best last.
    leaves: Vec<[f32; MAX_STATES], MAX_KEEP>,
    /// The best leaf refined so far in this round, and its score.
    best_refined: Option<(f32, [f32; MAX_STATES])>,
    /// The state of the last frame that claimed the hand (the base before any).
    held: [f32; MAX_STATES],
    /// Whether `held` is a tracked state (else the base).
    ever_tracked: bool,
    /// Searching frames of local re-acquisition left before the global search.
    local_left: u32,
    /// The best refined local hypothesis of the last frame, when it scored at least
    /// [`LOCAL_FOLLOW_SCORE`]: refined again on the next.
    following: Option<[f32; MAX_STATES]>,
    recovery: Recovery,
}

impl AutoTracker {
    /// A tracker for `model` seen by `cameras`, starting by searching: the states in `free`
    /// are searched for, the others kept at `base` (one value per model state).
    pub fn new(
        model: Model,
        cameras: &[Camera],
        base: &[f32],
        free: FreeMask,
        config: TrackerConfig,
        acquire: AcquireConfig,
    ) -> Result<Self, AutoError> {
        let tracker = Tracker::new(model, cameras, base, free, config)?;
        let volume = WorkingVolume::from_cameras(cameras, FALLBACK_DEPTH_MM);
        let acquirer = Acquirer::new(tracker.model(), base, tracker.free(), volume, acquire);
        let mut held = [0.0f32; MAX_STATES];
        for (h, s) in held.iter_mut().zip(tracker.state()) {
            *h = *s;
        }
        Ok(AutoTracker {
            tracker,
            acquirer,
            status: Status::Searching,
            lost_run: 0,
            accept_score: DEFAULT_ACCEPT_SCORE,
            leaves: Vec::new(),
            best_refined: None,
            held,
            ever_tracked: false,
            local_left: 0,
            following: None,
            recovery: Recovery::Search,
        })
    }

    /// A tracker for `model` seen by `cameras` that starts by tracking from `initial` (a known
    /// state of the first frame), and searches only once the hand is lost.
    pub fn tracking(
        model: Model,
        cameras: &[Camera],
        initial: &[f32],
        free: FreeMask,
        config: TrackerConfig,
        acquire: AcquireConfig,
    ) -> Result<Self, AutoError> {
        let mut auto = AutoTracker::new(model, cameras, initial, free, config, acquire)?;
        auto.status = Status::Tracking;
        auto.ever_tracked = true;
        Ok(auto)
    }

    /// Bytes of edge-map buffer camera `camera` needs.
    pub fn edge_bytes_needed(camera: &Camera, acquire: &AcquireConfig) -> usize {
        EdgeMap::bytes_needed(
            camera.width as usize,
            camera.height as usize,
            acquire.likelihood.stride_px,
        )
    }

    /// Sets the score a refined leaf needs to be accepted.
    pub fn set_accept_score(&mut self, score: f32) {
        self.accept_score = score;
    }

    /// Sets what happens once the hand is lost for [`LOST_FRAMES_BEFORE_SEARCH`] frames.
    pub fn set_recovery(&mut self, recovery: Recovery) {
        self.recovery = recovery;
    }

    /// The state to report for the last frame: the tracker's while tracking or lost; while
    /// searching, the last state that claimed the hand (the base before the first
    /// acquisition), never a hypothesis under test.
    pub fn state(&self) -> &[f32] {
        match self.status {
            Status::Searching => &self.held[..self.tracker.state().len().min(MAX_STATES)],
            Status::Tracking | Status::Lost => self.tracker.state(),
        }
    }

    /// The status after the last frame.
    pub fn status(&self) -> Status {
        self.status
    }

    /// The tracker (its model, cameras, free states).
    pub fn tracker(&self) -> &Tracker {
        &self.tracker
    }

    /// The search.
    pub fn acquirer(&self) -> &Acquirer {
        &self.acquirer
    }

    /// One instant: `frames[i]` is camera `i`'s, `edge_buffers[i]` its edge map's buffer.
    pub fn step(
        &mut self,
        frames: &[FrameView<'_>],
        edge_buffers: &mut [&mut [u8]],
    ) -> Result<AutoReport, AutoError> {
        match self.status {
            Status::Searching => self.search(frames, edge_buffers),
            Status::Tracking | Status::Lost => self.follow(frames),
        }
    }

    /// A tracking or lost frame: the tracker runs, the status follows its `lost` flag.
    fn follow(&mut self, frames: &[FrameView<'_>]) -> Result<AutoReport, AutoError> {
        let report = self.tracker.track(frames)?;
        if report.lost {
            self.lost_run = self.lost_run.saturating_add(1);
            self.status = if self.lost_run >= LOST_FRAMES_BEFORE_SEARCH
                && self.recovery == Recovery::Search
            {
                self.restart_search();
                self.following = None;
                self.local_left = if self.ever_tracked {
                    LOCAL_SEARCH_FRAMES
                } else {
                    0
                };
                Status::Searching
            } else {
                Status::Lost
            };
        } else {
            self.lost_run = 0;
            self.status = Status::Tracking;
            self.hold_tracked();
        }
        Ok(AutoReport {
            status: self.status,
            report,
            evaluated: 0,
            leaf_score: None,
            local: false,
        })
    }

    /// Keeps the tracker's state as the last that claimed the hand.
    fn hold_tracked(&mut self) {
        for (h, s) in self.held.iter_mut().zip(self.tracker.state()) {
            *h = *s;
        }
        self.ever_tracked = true;
    }

    fn restart_search(&mut self) {
        self.acquirer.restart();
        self.leaves.clear();
        self.best_refined = None;
    }

    /// Takes `state` (refined on this frame) for the hand: the status becomes `Tracking`.
    fn accept(&mut self, state: &[f32; MAX_STATES], n: usize) -> Result<(), AutoError> {
        self.tracker.restart_fresh(&state[..n])?;
        self.status = Status::Tracking;
        self.lost_run = 0;
        self.local_left = 0;
        self.hold_tracked();
        Ok(())
    }

    /// One frame of local re-acquisition: the last good state slid over each camera's edge
    /// map near where it projects, and the hypothesis followed from the last frame (if any),
    /// each refined by Gauss–Newton and scored over every camera; the best is accepted if its
    /// score reaches the acceptance score, else followed to the next frame if it reaches
    /// [`LOCAL_FOLLOW_SCORE`].
    fn local_search(
        &mut self,
        frames: &[FrameView<'_>],
        maps: &[EdgeMap<'_>],
        out: &mut AutoReport,
    ) -> Result<(), AutoError> {
        self.local_left = self.local_left.saturating_sub(1);
        out.local = true;
        let n = self.tracker.model().n_states().min(MAX_STATES);
        let seed = self.held;
        let mut best: Option<(f32, [f32; MAX_STATES], FrameReport)> = None;
        let followed = self.following.take();
        for c in 0..=maps.len() {
            let start = match (maps.get(c), self.tracker.cameras().get(c).copied()) {
                (Some(map), Some(camera)) => {
                    let near_px = camera.width as f32 * LOCAL_WINDOW;
                    self.acquirer
                        .place(self.tracker.model(), &camera, map, seed, Some(near_px))
                        .map(|placed| placed.q)
                }
                _ => followed,
            };
            let Some(start) = start else { continue };
            let (score, q, report) = self.refine(frames, maps, start, n)?;
            out.evaluated = out.evaluated.saturating_add(1);
            if best.as_ref().is_none_or(|(s, _, _)| score > *s) {
                best = Some((score, q, report));
            }
        }
        let Some((score, q, report)) = best else {
            return Ok(());
        };
        out.leaf_score = Some(score);
        if score >= self.accept_score {
            self.accept(&q, n)?;
            out.status = Status::Tracking;
            out.report = FrameReport {
                lost: false,
                ..report
            };
        } else if score >= LOCAL_FOLLOW_SCORE {
            self.following = Some(q);
        }
        Ok(())
    }

    /// `start` refined by [`LOCAL_REFINE_PASSES`] fresh tracker passes on this frame, and its
    /// likelihood score (0 when the tracker calls it lost).
    fn refine(
        &mut self,
        frames: &[FrameView<'_>],
        maps: &[EdgeMap<'_>],
        start: [f32; MAX_STATES],
        n: usize,
    ) -> Result<(f32, [f32; MAX_STATES], FrameReport), AutoError> {
        let mut q = start;
        let mut report = FrameReport::default();
        for _ in 0..LOCAL_REFINE_PASSES {
            self.tracker.restart_fresh(&q[..n])?;
            report = self.tracker.track(frames)?;
            q[..n].copy_from_slice(&self.tracker.state()[..n]);
            if report.lost {
                return Ok((0.0, q, report));
            }
        }
        let score = self.acquirer.score(
            self.tracker.model(),
            self.tracker.cameras(),
            frames,
            maps,
            &q,
        );
        Ok((score, q, report))
    }

    /// A searching frame: the search moves on, or one of its leaves is refined and judged.
    fn search(
        &mut self,
        frames: &[FrameView<'_>],
        edge_buffers: &mut [&mut [u8]],
    ) -> Result<AutoReport, AutoError> {
        if frames.len() != self.tracker.cameras().len() {
            return Err(AutoError::Tracker(TrackerError::FrameCount));
        }
        if edge_buffers.len() < frames.len() {
            return Err(AutoError::BufferCount);
        }
        let config = *self.acquirer.config();
        let mut maps: Vec<EdgeMap<'_>, MAX_CAMERAS> = Vec::new();
        for (buffer, frame) in edge_buffers.iter_mut().zip(frames) {
            let map =
                EdgeMap::build(buffer, frame, &config.likelihood).map_err(AutoError::EdgeMap)?;
            if maps.push(map).is_err() {
                return Err(AutoError::Tracker(TrackerError::CameraCount));
            }
        }
        let mut out = AutoReport {
            status: Status::Searching,
            report: FrameReport {
                lost: true,
                ..FrameReport::default()
            },
            evaluated: 0,
            leaf_score: None,
            local: false,
        };
        if self.local_left > 0 {
            self.local_search(frames, &maps, &mut out)?;
            return Ok(out);
        }
        if self.leaves.is_empty() {
            match self
                .acquirer
                .step(self.tracker.model(), self.tracker.cameras(), frames, &maps)
            {
                Progress::Searching { evaluated } => out.evaluated = evaluated,
                Progress::Found(_) => {
                    // Refine the leaves one per frame, best last (popped first).
                    self.leaves.clear();
                    for c in self.acquirer.best().iter().rev() {
                        let _ = self.leaves.push(c.q);
                    }
                    self.best_refined = None;
                }
            }
            return Ok(out);
        }
        let Some(leaf) = self.leaves.pop() else {
            return Ok(out);
        };
        let n = self.tracker.model().n_states().min(MAX_STATES);
        self.tracker.restart_fresh(&leaf[..n])?;
        let report = self.tracker.track(frames)?;
        let mut refined = [0.0f32; MAX_STATES];
        refined[..n].copy_from_slice(&self.tracker.state()[..n]);
        let score = if report.lost {
            0.0
        } else {
            self.acquirer.score(
                self.tracker.model(),
                self.tracker.cameras(),
                frames,
                &maps,
                &refined,
            )
        };
        out.leaf_score = Some(score);
        if self.best_refined.is_none_or(|(s, _)| score > s) {
            self.best_refined = Some((score, refined));
        }
        if !self.leaves.is_empty() {
            return Ok(out);
        }
        // Every leaf refined: take the best, if it explains the frame well enough.
        match self.best_refined.take() {
            Some((score, state)) if score >= self.accept_score => {
                self.accept(&state, n)?;
                out.status = Status::Tracking;
                out.report = FrameReport {
                    lost: false,
                    ..report
                };
            }
            _ => self.restart_search(),
        }
        Ok(out)
    }
}
