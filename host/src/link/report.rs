//! The figures of a link session: frames, throughput, bytes, errors on both sides.

use std::collections::BTreeMap;
use std::fmt;

use digiteyes_core::protocol::{Hypotheses, LinkCounters, Stats};

use super::outcome::{cause_key, FrameOutcome};

/// What a session did, as seen from both ends.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LinkReport {
    /// The board's name (`Hello`).
    pub board_name: String,
    /// Frames uploaded.
    pub frames: usize,
    /// Frames the board tracked (a `State` came back).
    pub tracked: usize,
    /// Tracked frames the board flagged `lost`.
    pub lost: usize,
    /// Frames not tracked, by cause (see [`DropCause`](super::DropCause)).
    pub dropped: BTreeMap<String, usize>,
    /// Answers that came after their frame was given up on, or for frames not sent.
    pub late_answers: usize,
    /// `Features` messages received.
    pub features: usize,
    /// `Hypotheses` messages received (one per frame from a board with several hypotheses).
    pub hypotheses_messages: usize,
    /// The hypotheses they carried, summed (their mean is [`LinkReport::mean_hypotheses`]).
    pub hypotheses_carried: usize,
    /// The best hypothesis' score, summed over the messages that carried any.
    pub best_score_sum: f64,
    /// Messages that carried any hypothesis (none while the board searches).
    pub hypotheses_nonempty: usize,
    /// Board reboots seen (unsolicited `Hello`s).
    pub restarts: usize,
    /// Seconds from the end of the set-up to the end of the session.
    pub seconds: f64,
    /// Bytes sent to the board.
    pub bytes_up: u64,
    /// Bytes received from the board.
    pub bytes_down: u64,
    /// The host's decoder: messages, CRC and framing errors.
    pub host_link: LinkCounters,
    /// The tail of a frame the board was sending when the host opened the port, dropped (0
    /// or 1; not an error of the link).
    pub host_joined_mid_frame: u32,
    /// The board's counters, from its last `Stats` (since its last boot).
    pub board: Option<Stats>,
    /// The final `Ping` was answered, so [`LinkReport::board`] is current.
    pub pong: bool,
}

impl LinkReport {
    /// Frames not tracked, all causes.
    pub fn dropped_total(&self) -> usize {
        self.dropped.values().sum()
    }

    /// Tracked frames per second of session time.
    pub fn states_per_second(&self) -> f64 {
        self.tracked as f64 / self.seconds.max(1e-9)
    }

    /// Mean hypotheses carried per `Hypotheses` message; `None` without any.
    pub fn mean_hypotheses(&self) -> Option<f64> {
        (self.hypotheses_messages > 0)
            .then(|| self.hypotheses_carried as f64 / self.hypotheses_messages as f64)
    }

    /// Counts one `Hypotheses` message.
    pub(crate) fn count_hypotheses(&mut self, message: &Hypotheses) {
        self.hypotheses_messages += 1;
        self.hypotheses_carried += message.hypotheses.len();
        if let Some(best) = message.hypotheses.first() {
            self.hypotheses_nonempty += 1;
            self.best_score_sum += f64::from(best.score);
        }
    }

    pub(crate) fn count(&mut self, outcome: &FrameOutcome) {
        self.frames += 1;
        match outcome {
            FrameOutcome::Tracked(state) => {
                self.tracked += 1;
                self.lost += usize::from(state.lost);
            }
            FrameOutcome::Dropped(cause) => {
                *self.dropped.entry(cause_key(cause)).or_default() += 1;
            }
        }
    }
}

impl fmt::Display for LinkReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let seconds = self.seconds.max(1e-9);
        writeln!(
            f,
            "link to board {}: {} frames uploaded, {} tracked ({} lost), {} dropped",
            self.board_name,
            self.frames,
            self.tracked,
            self.lost,
            self.dropped_total()
        )?;
        if !self.dropped.is_empty() {
            let causes: Vec<String> = self
                .dropped
                .iter()
                .map(|(cause, n)| format!("{cause} {n}"))
                .collect();
            writeln!(f, "  dropped by cause: {}", causes.join(", "))?;
        }
        writeln!(
            f,
            "  {:.1} states/s over {:.2} s; {} bytes up ({:.0} kB/s), {} bytes down",
            self.states_per_second(),
            self.seconds,
            self.bytes_up,
            self.bytes_up as f64 / seconds / 1000.0,
            self.bytes_down
        )?;
        if let Some(mean) = self.mean_hypotheses() {
            writeln!(
                f,
                "  hypotheses: {} messages, {mean:.2} carried on average (best's mean score \
                 {:.3})",
                self.hypotheses_messages,
                self.best_score_sum / self.hypotheses_nonempty.max(1) as f64
            )?;
        }
        let joined = if self.host_joined_mid_frame > 0 {
            format!(
                " ({} frame tail from before the port was opened, dropped)",
                self.host_joined_mid_frame
            )
        } else {
            String::new()
        };
        writeln!(
            f,
            "  host receiver: {}{joined}; {} late answers, {} board restart(s)",
            counters(&self.host_link),
            self.late_answers,
            self.restarts
        )?;
        match (&self.board, self.pong) {
            (Some(stats), pong) => {
                let d = &stats.dropped;
                writeln!(
                    f,
                    "  board{}: {} frames tracked, {} iterations, {} lost; dropped: {} \
                     incomplete, {} wrong size, {} too large, {} not ready, {} superseded, {} \
                     tracker error; {} bad frames, {} capacity overflows, {} stale chunks",
                    if pong {
                        ""
                    } else {
                        " (last report; the final ping went unanswered)"
                    },
                    stats.frames,
                    stats.iterations,
                    stats.lost,
                    d.incomplete,
                    d.wrong_size,
                    d.too_large,
                    d.not_ready,
                    d.superseded,
                    d.tracker_error,
                    stats.bad_frames,
                    stats.capacity_overflows,
                    stats.stale_chunks
                )?;
                write!(f, "  board receiver: {}", counters(&stats.link))
            }
            (None, _) => write!(
                f,
                "  board counters: none received (the ping went unanswered)"
            ),
        }
    }
}

fn counters(c: &LinkCounters) -> String {
    format!(
        "{} messages, {} CRC errors, {} framing errors, {} undecodable, {} overflows",
        c.messages, c.crc_errors, c.framing_errors, c.decode_errors, c.overflows
    )
}
