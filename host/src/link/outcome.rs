//! What became of one uploaded frame.

use std::fmt;

use digiteyes_core::protocol::{DropReason, State};

/// Every uploaded frame ends as exactly one of these.
#[derive(Debug, Clone, PartialEq)]
pub enum FrameOutcome {
    /// The board tracked it and sent this state.
    Tracked(State),
    /// It was not tracked.
    Dropped(DropCause),
}

/// Why a frame was not tracked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DropCause {
    /// The board said why (`Dropped`).
    Board(DropReason),
    /// Neither a `State` nor a `Dropped` came within the reply timeout (both lost on a noisy
    /// line, or the frame's last chunk lost so the board is still waiting for it).
    NoReply,
    /// The board rebooted (an unsolicited `Hello`) while the frame was in flight.
    BoardRestarted,
}

impl fmt::Display for DropCause {
    /// Short text without commas (it is a CSV field).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DropCause::Board(reason) => match reason {
                DropReason::Incomplete => f.write_str("incomplete"),
                DropReason::WrongSize(w, h) => write!(f, "wrong size {w}x{h}"),
                DropReason::TooLarge => f.write_str("too large"),
                DropReason::NotReady => f.write_str("not ready"),
                DropReason::Superseded => f.write_str("superseded"),
                DropReason::TrackerError => f.write_str("tracker error"),
            },
            DropCause::NoReply => f.write_str("no reply (timeout)"),
            DropCause::BoardRestarted => f.write_str("board restarted"),
        }
    }
}

/// The key under which [`DropCause`]s are counted: the board's reasons without their sizes.
pub(crate) fn cause_key(cause: &DropCause) -> String {
    match cause {
        DropCause::Board(DropReason::WrongSize(..)) => "wrong size".to_string(),
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn causes_read_as_csv_fields() {
        let all = [
            DropCause::Board(DropReason::Incomplete),
            DropCause::Board(DropReason::WrongSize(160, 120)),
            DropCause::Board(DropReason::TooLarge),
            DropCause::Board(DropReason::NotReady),
            DropCause::Board(DropReason::Superseded),
            DropCause::Board(DropReason::TrackerError),
            DropCause::NoReply,
            DropCause::BoardRestarted,
        ];
        for cause in all {
            let text = cause.to_string();
            assert!(!text.is_empty() && !text.contains(','), "{text}");
        }
        assert_eq!(all[1].to_string(), "wrong size 160x120");
        assert_eq!(cause_key(&all[1]), "wrong size");
    }
}
