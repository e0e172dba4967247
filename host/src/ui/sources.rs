//! Where the UI's states come from: a board on a serial port, JSON lines over UDP (what
//! `digiteyes listen --forward udp://` sends), or a replay of a tracked sequence with its
//! frames. Each runs on its own thread and writes into the [`Hub`].

use std::net::{SocketAddr, UdpSocket};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use digiteyes_core::camera::Camera;
use digiteyes_core::protocol::BoardMessage;
use digiteyes_core::status::Status;

use super::hub::{CameraFrame, Hub, ShownHypothesis, ShownState};
use crate::link::Link;
use crate::sequence::hypotheses::read_hypotheses;
use crate::sequence::states::read_states_with_gaps;
use crate::sequence::Sequence;
use crate::stream::STATUS_COLUMN;

/// Longest UDP datagram read (a `Features` message as JSON is a few KB).
const MAX_DATAGRAM: usize = 65_536;

/// Reads a board's messages from `link` into `hub` until `stop` is set or the port fails.
pub fn serial(mut link: Link, hub: &Hub, stop: &AtomicBool) -> Result<()> {
    while !stop.load(Ordering::Relaxed) {
        if let Some(message) = link.recv(Duration::from_millis(100))? {
            hub.push_message(&message);
        }
        hub.set_receiver(link.counters());
    }
    Ok(())
}

/// Binds the UDP socket a [`udp`] source reads (port 0 picks a free one).
pub fn bind_udp(addr: SocketAddr) -> Result<UdpSocket> {
    let socket = UdpSocket::bind(addr).with_context(|| format!("cannot listen on udp://{addr}"))?;
    socket
        .set_read_timeout(Some(Duration::from_millis(100)))
        .context("cannot set the UDP socket's timeout")?;
    Ok(socket)
}

/// Reads JSON lines of board messages (one or more per datagram) from `socket` into `hub`
/// until `stop` is set. Lines that are not a board message are counted, not fatal.
pub fn udp(socket: &UdpSocket, hub: &Hub, stop: &AtomicBool) -> Result<()> {
    let mut buf = vec![0u8; MAX_DATAGRAM];
    while !stop.load(Ordering::Relaxed) {
        let n = match socket.recv_from(&mut buf) {
            Ok((n, _)) => n,
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) =>
            {
                continue
            }
            Err(e) => return Err(e).context("UDP receive failed"),
        };
        let Ok(text) = std::str::from_utf8(&buf[..n]) else {
            hub.push_unreadable();
            continue;
        };
        for line in text.lines().filter(|l| !l.trim().is_empty()) {
            match serde_json::from_str::<BoardMessage>(line) {
                Ok(message) => hub.push_message(&message),
                Err(_) => hub.push_unreadable(),
            }
        }
    }
    Ok(())
}

/// A tracked sequence played back: its frames with the states a tracker wrote for them.
#[derive(Debug)]
pub struct Replay {
    sequence: Sequence,
    states: Vec<(ShownState, Option<String>)>,
    /// Each frame's hypotheses, best first, when a hypotheses CSV was given.
    hypotheses: Option<Vec<Vec<ShownHypothesis>>>,
    camera: Camera,
    camera_index: usize,
    period: Duration,
}

impl Replay {
    /// Opens `seqdir` and `states_csv` (the output of `track` or `stream`), to be shown as
    /// camera `camera_index` saw it, at the sequence's frame rate (`fps` overrides; 15 when
    /// neither gives one). With `hypotheses_csv` (`track --hypotheses-out`), each frame's
    /// other hypotheses are shown ghosted behind the hand.
    pub fn open(
        seqdir: &Path,
        states_csv: &Path,
        hypotheses_csv: Option<&Path>,
        camera_index: usize,
        fps: Option<f64>,
    ) -> Result<Replay> {
        let sequence = Sequence::open(seqdir)?;
        let Some(camera) = sequence.cameras.get(camera_index).copied() else {
            bail!(
                "{}: no camera {camera_index} (the sequence has {})",
                seqdir.display(),
                sequence.cameras.len()
            );
        };
        let table = read_states_with_gaps(states_csv, sequence.n_states())?;
        let column = |name: &str| table.table.extra(name);
        let rows = table.table.rows.len();
        sequence.check_state_rows(states_csv, rows)?;
        let lost = column("lost").unwrap_or_else(|| vec![0.0; rows]);
        let rms = column("rms_px").unwrap_or_else(|| vec![f64::NAN; rows]);
        let found = column("features_found").unwrap_or_else(|| vec![0.0; rows]);
        let expected = column("features_expected").unwrap_or_else(|| vec![0.0; rows]);
        let iterations = column("iterations").unwrap_or_else(|| vec![0.0; rows]);
        let dropped = table.extra_text("dropped");
        let statuses = replay_statuses(table.extra_text(STATUS_COLUMN).as_deref(), &lost)
            .with_context(|| format!("{}", states_csv.display()))?;
        let states = (0..rows)
            .map(|i| {
                let shown = ShownState {
                    frame: i as u32,
                    q: table.table.rows[i].iter().map(|&v| v as f32).collect(),
                    lost: lost[i] != 0.0 || !statuses[i].claims_hand(),
                    status: statuses[i],
                    rms_px: rms[i] as f32,
                    features_found: found[i] as u16,
                    features_expected: expected[i] as u16,
                    iterations: iterations[i] as u8,
                };
                let drop = dropped
                    .as_ref()
                    .map(|d| d[i].to_string())
                    .filter(|d| !d.is_empty());
                (shown, drop)
            })
            .collect();
        let hypotheses = match hypotheses_csv {
            Some(path) => {
                let table = read_hypotheses(path, sequence.n_states())?;
                if let Some(last) = table.last_frame().filter(|&f| f >= rows) {
                    bail!(
                        "{}: frame {last} is past the last frame of {} ({rows} frames): the \
                         hypotheses of another run?",
                        path.display(),
                        states_csv.display()
                    );
                }
                let frames = table.by_frame(rows);
                Some(
                    frames
                        .iter()
                        .map(|rows| {
                            rows.iter()
                                .map(|r| ShownHypothesis {
                                    rank: r.rank.min(usize::from(u8::MAX)) as u8,
                                    score: r.score as f32,
                                    age: r.age.min(u64::from(u32::MAX)) as u32,
                                    q: r.state.iter().map(|&v| v as f32).collect(),
                                })
                                .collect()
                        })
                        .collect(),
                )
            }
            None => None,
        };
        let fps = match (fps, sequence.fps()) {
            (Some(fps), _) => {
                crate::cli_values::check_fps(fps).map_err(|e| anyhow::anyhow!("--fps: {e}"))?;
                fps
            }
            (None, Some(fps)) => {
                crate::cli_values::check_fps(fps).map_err(|e| {
                    anyhow::anyhow!(
                        "{}: \"fps\": {e} (or give --fps)",
                        sequence.dir.join("sequence.json").display()
                    )
                })?;
                fps
            }
            (None, None) => 15.0,
        };
        Ok(Replay {
            sequence,
            states,
            hypotheses,
            camera,
            camera_index,
            period: crate::cli_values::frame_period(fps),
        })
    }

    /// The sequence's folder.
    pub fn dir(&self) -> PathBuf {
        self.sequence.dir.clone()
    }

    /// The free states of the sequence.
    pub fn free(&self) -> Vec<usize> {
        self.sequence.free_states()
    }

    /// The sequence's initial state.
    pub fn initial_state(&self) -> Vec<f32> {
        self.sequence
            .initial_state
            .iter()
            .map(|&v| v as f32)
            .collect()
    }

    /// Frames in the replay.
    pub fn len(&self) -> usize {
        self.states.len()
    }

    /// True when the states file has no frames.
    pub fn is_empty(&self) -> bool {
        self.states.is_empty()
    }

    /// Plays the frames into `hub`, from the first again after the last, until `stop`.
    pub fn play(&self, hub: &Hub, stop: &AtomicBool) -> Result<()> {
        if self.states.is_empty() {
            return Ok(());
        }
        let mut next = Instant::now();
        let mut last_complaint: Option<Instant> = None;
        for (i, (state, drop)) in self.states.iter().enumerate().cycle() {
            if stop.load(Ordering::Relaxed) {
                break;
            }
            // A frame that cannot be read now (the process out of descriptors, the file
            // being replaced) costs that frame's picture only: the states play on.
            match self.sequence.read_frame(self.camera_index, i) {
                Ok(image) => hub.push_frame(CameraFrame {
                    frame: state.frame,
                    camera: self.camera,
                    image,
                    q: state.q.clone(),
                }),
                Err(e) => {
                    if last_complaint.is_none_or(|t| t.elapsed() > Duration::from_secs(10)) {
                        eprintln!("digiteyes: replay: frame {i} not shown: {e:#}");
                        last_complaint = Some(Instant::now());
                    }
                }
            }
            if let Some(frames) = &self.hypotheses {
                hub.push_hypotheses(state.frame, &frames[i]);
            }
            match drop {
                Some(reason) => hub.push_host_drop(reason),
                None => hub.push_state(state.clone()),
            }
            next += self.period;
            let now = Instant::now();
            if next > now {
                // Pacing the replay at the sequence's frame rate, not waiting for an event.
                std::thread::sleep(next - now);
            } else {
                next = now;
            }
        }
        Ok(())
    }
}

/// Each frame's status: from the `status` column's words when the CSV has one, else from the
/// `lost` column (a CSV written before the status existed: `lost` 1 → lost, else tracking).
/// An empty field (e.g. a row a tool left blank) also falls back on `lost`.
fn replay_statuses(words: Option<&[&str]>, lost: &[f64]) -> Result<Vec<Status>> {
    let from_lost = |i: usize| {
        if lost.get(i).is_some_and(|&l| l != 0.0) {
            Status::Lost
        } else {
            Status::Tracking
        }
    };
    let Some(words) = words else {
        return Ok((0..lost.len()).map(from_lost).collect());
    };
    words
        .iter()
        .enumerate()
        .map(|(i, word)| match *word {
            "" => Ok(from_lost(i)),
            word => Status::from_word(word).ok_or_else(|| {
                anyhow::anyhow!(
                    "frame {i}: status {} is not one of searching, tracking, lost",
                    crate::text::quote_value(word)
                )
            }),
        })
        .collect()
}

/// A source's thread: runs `body` and, if it fails, keeps the error for the caller.
pub fn spawn(
    name: &str,
    stop: Arc<AtomicBool>,
    body: impl FnOnce(&AtomicBool) -> Result<()> + Send + 'static,
) -> Result<std::thread::JoinHandle<Result<()>>> {
    std::thread::Builder::new()
        .name(name.into())
        .spawn(move || body(&stop))
        .with_context(|| format!("cannot start the {name} thread"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statuses_come_from_the_status_column_or_else_from_lost() {
        let lost = [0.0, 1.0, 1.0, 0.0];
        assert_eq!(
            replay_statuses(None, &lost).unwrap(),
            [
                Status::Tracking,
                Status::Lost,
                Status::Lost,
                Status::Tracking
            ]
        );
        let words = ["tracking", "lost", "searching", ""];
        assert_eq!(
            replay_statuses(Some(&words), &lost).unwrap(),
            [
                Status::Tracking,
                Status::Lost,
                Status::Searching,
                Status::Tracking
            ]
        );
        let e = replay_statuses(Some(&["tracking", "Found"]), &lost)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("frame 1") && e.contains("Found") && e.contains("searching, tracking, lost"),
            "{e}"
        );
    }
}
