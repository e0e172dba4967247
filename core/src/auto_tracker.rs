//! The tracker that finds the hand itself: the [`Status`] machine around the anytime
//! [search](crate::acquire) and the Gauss–Newton [tracker](crate::tracker) (issue 10).
//!
//! - **Searching**: each frame moves the search on within its budget. When it is over, its
//!   leaves are refined by the tracker's Gauss–Newton on the frames that follow, one leaf per
//!   frame, and the best refined leaf is taken for the hand if its likelihood reaches the
//!   acceptance score; otherwise the search starts over.
//! - **Tracking**: the tracker runs; a lost frame makes the status [`Status::Lost`].
//! - **Lost**: the tracker still runs (holding its last good state); a frame not lost makes it
//!   `Tracking` again, [`LOST_FRAMES_BEFORE_SEARCH`] lost frames in a row make it `Searching`.
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
        Ok(AutoTracker {
            tracker,
            acquirer,
            status: Status::Searching,
            lost_run: 0,
            accept_score: DEFAULT_ACCEPT_SCORE,
            leaves: Vec::new(),
            best_refined: None,
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

    /// The current state (the last tracked one, or the base while searching).
    pub fn state(&self) -> &[f32] {
        self.tracker.state()
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
            self.lost_run += 1;
            self.status = if self.lost_run >= LOST_FRAMES_BEFORE_SEARCH {
                self.restart_search();
                Status::Searching
            } else {
                Status::Lost
            };
        } else {
            self.lost_run = 0;
            self.status = Status::Tracking;
        }
        Ok(AutoReport {
            status: self.status,
            report,
            evaluated: 0,
            leaf_score: None,
        })
    }

    fn restart_search(&mut self) {
        self.acquirer.restart();
        self.leaves.clear();
        self.best_refined = None;
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
        };
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
                self.tracker.restart_fresh(&state[..n])?;
                self.status = Status::Tracking;
                self.lost_run = 0;
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
