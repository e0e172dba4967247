//! Tracking that finds the hand itself: the tracker's status machine around the anytime
//! search of `digiteyes_core::acquire` (issue 10).
//!
//! ```text
//!  Searching ──(search's best leaf, refined by Gauss–Newton, scores ≥ accept)──▶ Tracking
//!      ▲                                                                           │
//!      └──(LOST_FRAMES_BEFORE_SEARCH lost frames in a row)── Lost ◀──(frame lost)──┘
//! ```
//!
//! A frame claims a hand only while `Tracking`; `Searching` and `Lost` frames are written with
//! `lost` = 1.

use std::fmt;

use anyhow::{anyhow, Result};
use digiteyes_core::acquire::{AcquireConfig, Acquirer, Progress, WorkingVolume};
use digiteyes_core::camera::Camera;
use digiteyes_core::config::MAX_STATES;
use digiteyes_core::estimator::FreeMask;
use digiteyes_core::frame::FrameView;
use digiteyes_core::likelihood::EdgeMap;
use digiteyes_core::model::Model;
use digiteyes_core::tracker::{FrameReport, Tracker, TrackerConfig};

/// Lost frames in a row after which the tracker gives the hand up and searches again.
pub const LOST_FRAMES_BEFORE_SEARCH: u32 = 10;

/// The likelihood score (0..=1) a refined leaf needs to be taken for the hand: the true state
/// scored 0.94–0.99 on six untuned random rigs at 320×240, wrong refined leaves up to 0.96
/// (docs/recovery.md), so this refuses most wrong leaves and few right ones.
pub const DEFAULT_ACCEPT_SCORE: f32 = 0.93;

/// Depth (mm) along a camera's axis of the default working volume when no camera sees the
/// world origin.
pub const FALLBACK_DEPTH_MM: f32 = 600.0;

/// What the tracker claims of a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// No hand claimed: the search runs.
    Searching,
    /// The hand is tracked.
    Tracking,
    /// The hand was being tracked and this frame lost it (the last state is held).
    Lost,
}

impl Status {
    /// The word in the states CSV's `status` column.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Searching => "searching",
            Status::Tracking => "tracking",
            Status::Lost => "lost",
        }
    }
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One frame's outcome.
#[derive(Debug, Clone, Copy)]
pub struct AutoReport {
    /// The status after this frame.
    pub status: Status,
    /// The tracker's report (default while searching).
    pub report: FrameReport,
    /// Hypotheses the search scored on this frame.
    pub evaluated: u16,
    /// The likelihood score of a leaf refined on this frame, accepted or not.
    pub leaf_score: Option<f32>,
}

/// A tracker that finds the hand, tracks it, and finds it again.
pub struct AutoTracker {
    tracker: Tracker,
    acquirer: Acquirer,
    status: Status,
    lost_run: u32,
    accept_score: f32,
    edge_buffers: Vec<Vec<u8>>,
    /// The search's leaves still to refine (one per frame), and the best refined so far.
    leaves: Vec<[f32; MAX_STATES]>,
    best_refined: Option<(f32, Vec<f32>)>,
}

impl AutoTracker {
    /// A tracker for `model` seen by `cameras`, starting by searching: the states in `free`
    /// are searched for, the others kept at `base`.
    pub fn new(
        model: Model,
        cameras: &[Camera],
        base: &[f32],
        free: FreeMask,
        config: TrackerConfig,
        acquire: AcquireConfig,
    ) -> Result<Self> {
        let tracker = Tracker::new(model, cameras, base, free, config)
            .map_err(|e| anyhow!("cannot start the tracker: {e}"))?;
        let volume = WorkingVolume::from_cameras(cameras, FALLBACK_DEPTH_MM);
        let acquirer = Acquirer::new(tracker.model(), base, tracker.free(), volume, acquire);
        let edge_buffers = cameras
            .iter()
            .map(|c| {
                vec![
                    0u8;
                    EdgeMap::bytes_needed(
                        c.width as usize,
                        c.height as usize,
                        acquire.likelihood.stride_px
                    )
                ]
            })
            .collect();
        Ok(AutoTracker {
            tracker,
            acquirer,
            status: Status::Searching,
            lost_run: 0,
            accept_score: DEFAULT_ACCEPT_SCORE,
            edge_buffers,
            leaves: Vec::new(),
            best_refined: None,
        })
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

    /// One instant: `frames[i]` is camera `i`'s.
    pub fn step(&mut self, frames: &[FrameView<'_>]) -> Result<AutoReport> {
        match self.status {
            Status::Searching => self.search(frames),
            Status::Tracking | Status::Lost => {
                let report = self
                    .tracker
                    .track(frames)
                    .map_err(|e| anyhow!("the tracker failed: {e}"))?;
                if report.lost {
                    self.lost_run += 1;
                    self.status = if self.lost_run >= LOST_FRAMES_BEFORE_SEARCH {
                        self.acquirer.restart();
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
        }
    }

    fn search(&mut self, frames: &[FrameView<'_>]) -> Result<AutoReport> {
        let config = *self.acquirer.config();
        let mut maps = Vec::with_capacity(frames.len());
        for (buffer, frame) in self.edge_buffers.iter_mut().zip(frames) {
            maps.push(
                EdgeMap::build(buffer, frame, &config.likelihood)
                    .map_err(|e| anyhow!("edge map: {e}"))?,
            );
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
                    self.leaves = self.acquirer.best().iter().rev().map(|c| c.q).collect();
                    self.best_refined = None;
                }
            }
            return Ok(out);
        }
        let Some(leaf) = self.leaves.pop() else {
            return Ok(out);
        };
        let n = self.tracker.model().n_states().min(MAX_STATES);
        self.tracker
            .restart_fresh(&leaf[..n])
            .map_err(|e| anyhow!("the search's leaf: {e}"))?;
        let report = self
            .tracker
            .track(frames)
            .map_err(|e| anyhow!("the tracker failed: {e}"))?;
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
        if self.best_refined.as_ref().is_none_or(|(s, _)| score > *s) {
            self.best_refined = Some((score, self.tracker.state().to_vec()));
        }
        if !self.leaves.is_empty() {
            return Ok(out);
        }
        // Every leaf refined: take the best, if it explains the frame well enough.
        match self.best_refined.take() {
            Some((score, state)) if score >= self.accept_score => {
                self.tracker
                    .restart_fresh(&state)
                    .map_err(|e| anyhow!("the refined leaf: {e}"))?;
                self.status = Status::Tracking;
                self.lost_run = 0;
                out.status = Status::Tracking;
                out.report = FrameReport {
                    lost: false,
                    ..report
                };
            }
            _ => self.acquirer.restart(),
        }
        Ok(out)
    }
}
