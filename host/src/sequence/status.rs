//! The states CSV's `status` column: one [`Status`] word per frame (`searching`, `tracking`,
//! `lost`), and what a run's statuses say — frames per status, and the frames where the hand
//! was acquired, given up and re-acquired.

use std::fmt;

use serde::Serialize;

pub use digiteyes_core::status::Status;

/// The column the states CSV adds after the report columns: the frame's [`Status`].
pub const STATUS_COLUMN: &str = "status";

/// Frames per status and the frames where the status changed, over a run.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize)]
pub struct StatusCounts {
    /// Frames searching.
    pub searching: usize,
    /// Frames tracking (claiming the hand).
    pub tracking: usize,
    /// Frames lost (the track held, not claimed).
    pub lost: usize,
    /// The frame the hand was first acquired by a search (`None`: tracked from a given
    /// initial state, or never found).
    pub acquired: Option<usize>,
    /// First frames of the lost runs that ended in a search (the hand given up).
    pub lost_at: Vec<usize>,
    /// Frames the hand was found again by a search after being given up.
    pub reacquired: Vec<usize>,
}

impl StatusCounts {
    /// Counts a run's statuses, frame by frame in order.
    pub fn of(statuses: &[Status]) -> StatusCounts {
        let mut counts = StatusCounts::default();
        let mut run_start = None;
        let mut ever_tracked = false;
        let mut previous = None;
        for (k, &s) in statuses.iter().enumerate() {
            match s {
                Status::Searching => counts.searching += 1,
                Status::Tracking => counts.tracking += 1,
                Status::Lost => counts.lost += 1,
            }
            match (previous, s) {
                (Some(Status::Searching) | None, Status::Tracking) if previous.is_some() => {
                    if ever_tracked {
                        counts.reacquired.push(k);
                    } else {
                        counts.acquired = Some(k);
                    }
                }
                (Some(Status::Tracking) | None, Status::Lost) => run_start = Some(k),
                (Some(Status::Tracking | Status::Lost), Status::Searching) => {
                    counts.lost_at.push(run_start.take().unwrap_or(k));
                }
                _ => {}
            }
            ever_tracked |= s == Status::Tracking;
            previous = Some(s);
        }
        counts
    }
}

impl fmt::Display for StatusCounts {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let list = |frames: &[usize]| {
            frames
                .iter()
                .map(|k| k.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        };
        write!(
            f,
            "status: {} tracking, {} lost, {} searching",
            self.tracking, self.lost, self.searching
        )?;
        match self.acquired {
            Some(k) => write!(f, "; acquired at frame {k}")?,
            None if self.tracking + self.lost > 0 && self.searching == 0 => {}
            None if self.tracking == 0 => write!(f, "; never acquired")?,
            None => {}
        }
        if !self.lost_at.is_empty() {
            write!(f, "; lost at frame(s) {}", list(&self.lost_at))?;
        }
        if !self.reacquired.is_empty() {
            write!(f, "; re-acquired at frame(s) {}", list(&self.reacquired))?;
        }
        Ok(())
    }
}
