//! What the tracker claims of a frame: the states of the tracker that finds the hand itself
//! ([`auto_tracker`](crate::auto_tracker)).
//!
//! ```text
//!  Searching ──(a searched state, refined and accepted)──▶ Tracking
//!      ▲                                                     │
//!      └──(too many lost frames in a row)── Lost ◀──(lost)───┘
//! ```

use core::fmt;

/// The tracker's status after a frame. A frame claims a hand only while [`Status::Tracking`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Status {
    /// No hand claimed: the search runs.
    #[default]
    Searching,
    /// The hand is tracked.
    Tracking,
    /// The hand was being tracked and this frame lost it (the last good state is held).
    Lost,
}

impl Status {
    /// Every status, in wire order.
    pub const ALL: [Status; 3] = [Status::Searching, Status::Tracking, Status::Lost];

    /// The word in the states CSV's `status` column.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Searching => "searching",
            Status::Tracking => "tracking",
            Status::Lost => "lost",
        }
    }

    /// The status a word of [`Status::as_str`] names.
    pub fn from_word(word: &str) -> Option<Status> {
        Status::ALL.into_iter().find(|s| s.as_str() == word)
    }

    /// True when the frame claims a hand.
    pub fn claims_hand(self) -> bool {
        self == Status::Tracking
    }
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_round_trip_and_only_tracking_claims() {
        for s in Status::ALL {
            assert_eq!(Status::from_word(s.as_str()), Some(s));
            assert_eq!(s.claims_hand(), s == Status::Tracking);
        }
        assert_eq!(Status::from_word("Tracking"), None);
    }
}
