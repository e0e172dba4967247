//! `digiteyes listen`: decode what a board sends, print it, and forward it to the machines
//! that show the hand (as DigitEyes sent its states on over TCP).
//!
//! Each message is one line: human-readable by default, or its JSON form (serde's
//! externally tagged form of `BoardMessage`, e.g. `{"State":{"frame":12,"q":[…],…}}`).
//! Forwarding ([`crate::forward`]) sends every JSON line (with its newline) as one UDP
//! datagram, or Open Sound Control packets; only forwarded states are smoothed.

use std::io::Write;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::Result;
use digiteyes_core::protocol::{BoardMessage, LinkCounters, Start, WireStatus};
use digiteyes_core::status::Status;

use crate::forward::one_euro::Smoothing;
use crate::forward::{Forward, ForwardOptions, Forwarder};
use crate::link::{set_up_board_starting, DropCause, Link};

/// What to listen for and where it goes.
#[derive(Debug, Clone, Default)]
#[non_exhaustive]
pub struct ListenOptions {
    /// Print JSON lines instead of text.
    pub json: bool,
    /// Forward to each of these (JSON lines or OSC over UDP).
    pub forward: Vec<Forward>,
    /// Smooth forwarded states with the one-euro filter (`None`: forward them raw).
    pub smoothing: Option<Smoothing>,
    /// Stop after this many `State`s.
    pub states: Option<usize>,
    /// Stop after this long.
    pub duration: Option<Duration>,
    /// Set the board up first (Configure + Reset) from this `sequence.json` or sequence
    /// folder: for a board with its own camera.
    pub setup: Option<PathBuf>,
    /// The camera of a multi-camera setup.
    pub camera_index: Option<usize>,
    /// With `setup`: how the board starts, from the initial state or searching.
    pub start: Option<Start>,
}

/// What a listen session saw.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ListenSummary {
    /// Messages decoded.
    pub messages: usize,
    /// `State`s among them.
    pub states: usize,
    /// Those states by the board's status: searching, tracking, lost ([`Status::ALL`]'s
    /// order).
    pub statuses: [usize; 3],
    /// `Hypotheses` messages among them (a board tracking several hypotheses).
    pub hypotheses_messages: usize,
    /// The hypotheses they carried, summed.
    pub hypotheses_carried: usize,
    /// Datagrams forwarded (to all targets).
    pub forwarded: usize,
    /// The host receiver's counters.
    pub link: LinkCounters,
}

/// Listens on `link`, writing a line per message to `out`, until the options' limits (or
/// forever).
pub fn listen(link: Link, options: &ListenOptions, out: &mut dyn Write) -> Result<ListenSummary> {
    let mut forwarder = match options.forward.is_empty() {
        true => None,
        false => {
            let forward = ForwardOptions {
                smoothing: options.smoothing,
                ..ForwardOptions::default()
            };
            Some(Forwarder::new(&options.forward, forward)?)
        }
    };
    let mut link = match &options.setup {
        Some(path) => {
            let start = options.start.unwrap_or(Start::Given);
            let board = set_up_board_starting(link, path, options.camera_index, start, out)?;
            let (link, hello) = (board.link, board.hello);
            let initial_state: Vec<f32> = board
                .sequence
                .initial_state
                .iter()
                .map(|&v| v as f32)
                .collect();
            if let Some(forwarder) = &mut forwarder {
                forwarder.set_up(&hello, &initial_state);
            }
            link
        }
        None => link,
    };
    let until = options.duration.map(|d| Instant::now() + d);
    let mut summary = ListenSummary::default();
    loop {
        if options.states.is_some_and(|n| summary.states >= n)
            || until.is_some_and(|t| Instant::now() >= t)
        {
            break;
        }
        let wait = match until {
            Some(t) => t.saturating_duration_since(Instant::now()),
            None => Duration::from_millis(200),
        };
        let Some(message) = link.recv(wait.min(Duration::from_millis(200)))? else {
            continue;
        };
        let received = Instant::now();
        summary.messages += 1;
        if let BoardMessage::State(state) = &message {
            summary.states += 1;
            let status = Status::from(state.status);
            if let Some(i) = Status::ALL.iter().position(|&s| s == status) {
                summary.statuses[i] += 1;
            }
        }
        if let BoardMessage::Hypotheses(h) = &message {
            summary.hypotheses_messages += 1;
            summary.hypotheses_carried += h.hypotheses.len();
        }
        if options.json {
            writeln!(out, "{}", serde_json::to_string(&message)?)?;
        } else {
            // A board's strings (its name) are the board's to choose: never raw to a terminal.
            writeln!(out, "{}", crate::text::escape_control(&describe(&message)))?;
        }
        out.flush()?;
        if let Some(forwarder) = &mut forwarder {
            summary.forwarded += forwarder.send(&message, received)?;
        }
    }
    summary.link = link.counters();
    Ok(summary)
}

/// One line of text for a message.
pub fn describe(message: &BoardMessage) -> String {
    match message {
        BoardMessage::Hello(h) => format!(
            "hello: board {} (protocol {}, model digest {:#010x}, clock {} Hz, {} states, \
             frames up to {} bytes)",
            h.board,
            h.version,
            h.model_digest,
            h.clock_hz,
            h.capacities.states,
            h.capacities.max_frame_bytes
        ),
        BoardMessage::State(s) => {
            let q: Vec<String> = s.q.iter().map(|v| format!("{v:.4}")).collect();
            let search = match s.status {
                WireStatus::Searching => format!(" ({} evaluations)", s.search_evaluations),
                WireStatus::Tracking | WireStatus::Lost => String::new(),
            };
            format!(
                "state {} {}{search}: rms {:.3} px, {}/{} features, {} iterations, {} ticks{} \
                 q=[{}]",
                s.frame,
                Status::from(s.status),
                s.rms_px,
                s.features_found,
                s.features_expected,
                s.iterations,
                s.track_ticks,
                if s.lost { ", LOST," } else { "," },
                q.join(" ")
            )
        }
        BoardMessage::Features(f) => format!(
            "features {}: camera {}, {} links measured",
            f.frame,
            f.camera,
            f.links.len()
        ),
        BoardMessage::Stats(s) => format!(
            "stats: {} frames, {} iterations, {} lost, {} bad frames; receiver {} messages, {} \
             CRC errors, {} framing errors",
            s.frames,
            s.iterations,
            s.lost,
            s.bad_frames,
            s.link.messages,
            s.link.crc_errors,
            s.link.framing_errors
        ),
        BoardMessage::Dropped(d) => format!("dropped {}: {}", d.frame, DropCause::Board(d.reason)),
        BoardMessage::Ack(c) => format!("ack {c:?}"),
        BoardMessage::Nak(c, r) => format!("nak {c:?}: {r:?}"),
        BoardMessage::Pong(t) => format!("pong {t}"),
        BoardMessage::LinkEdges(e) => format!(
            "link edges {} (iteration {}): link {}, {} edges{}",
            e.frame,
            e.iteration,
            e.link,
            e.edges.len(),
            if e.tip.is_some() { ", tip" } else { "" }
        ),
        BoardMessage::PalmEdges(e) => format!(
            "palm edges {} (iteration {}): outline edge from corner {} to {}, {} edges",
            e.frame,
            e.iteration,
            e.corners[0],
            e.corners[1],
            e.edges.len()
        ),
        BoardMessage::Hypotheses(h) => {
            let each: Vec<String> = h
                .hypotheses
                .iter()
                .map(|x| format!("{:.4} (age {})", x.score, x.age))
                .collect();
            format!(
                "hypotheses {}: {} carried{}{}",
                h.frame,
                h.hypotheses.len(),
                if each.is_empty() {
                    ""
                } else {
                    ", best first: "
                },
                each.join(", ")
            )
        }
        BoardMessage::Measured(m) => format!(
            "measured {} (iteration {}): {} links{}",
            m.frame,
            m.iteration,
            m.links,
            if m.held { "" } else { ", frame not held" }
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use digiteyes_core::protocol::{encode, State, MAX_MESSAGE};
    use serialport::{SerialPort, TTYPort};
    use std::net::UdpSocket;

    /// A board on a PTY sends two states; listen prints them raw and forwards them smoothed,
    /// as JSON lines and as OSC, at once.
    #[test]
    fn prints_raw_and_forwards_smoothed_json_and_osc() {
        let (mut board, slave) = TTYPort::pair().unwrap();
        let link = Link::open(&slave.name().unwrap(), 115_200).unwrap();
        let receiver = || {
            let socket = UdpSocket::bind("127.0.0.1:0").unwrap();
            socket
                .set_read_timeout(Some(Duration::from_secs(10)))
                .unwrap();
            socket
        };
        let (json_rx, osc_rx) = (receiver(), receiver());
        let rest: Vec<f32> = crate::scenarios::scenario("mouse")
            .unwrap()
            .base
            .iter()
            .map(|&v| v as f32)
            .collect();
        let mut bytes = Vec::new();
        for (frame, x) in [(7, 1.5), (9, 101.5)] {
            let mut q = rest.clone();
            q[4] = x;
            let message = BoardMessage::State(State {
                frame,
                timestamp: 1000 * u64::from(frame),
                q: q.into_iter().collect(),
                rms_px: 0.5,
                lost: false,
                features_found: 20,
                features_expected: 24,
                iterations: 5,
                track_ticks: 1234,
                status: WireStatus::Tracking,
                search_evaluations: 0,
            });
            let mut buf = [0u8; MAX_MESSAGE];
            bytes.extend_from_slice(encode(&message, &mut buf).unwrap());
        }
        board.write_all(&bytes).unwrap();

        let options = ListenOptions {
            json: true,
            states: Some(2),
            forward: vec![
                Forward::Json(json_rx.local_addr().unwrap()),
                Forward::Osc(osc_rx.local_addr().unwrap()),
            ],
            smoothing: Some(Smoothing::default()),
            ..ListenOptions::default()
        };
        let mut out = Vec::new();
        let summary = listen(link, &options, &mut out).unwrap();
        assert_eq!((summary.states, summary.forwarded), (2, 4));

        let printed: Vec<serde_json::Value> = std::str::from_utf8(&out)
            .unwrap()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        assert_eq!(printed[1]["State"]["q"][4], 101.5, "printed raw");
        let mut buf = [0u8; 65_536];
        let mut forwarded_x = Vec::new();
        for _ in 0..2 {
            let n = json_rx.recv(&mut buf).unwrap();
            let line: serde_json::Value = serde_json::from_slice(&buf[..n]).unwrap();
            forwarded_x.push(line["State"]["q"][4].as_f64().unwrap());
        }
        assert_eq!(forwarded_x[0], 1.5, "the first state passes through");
        assert!(
            forwarded_x[1] > 1.5 && forwarded_x[1] < 100.0,
            "forwarded smoothed: {forwarded_x:?}"
        );
        for frame in [7, 9] {
            let n = osc_rx.recv(&mut buf).unwrap();
            let (_, packet) = rosc::decoder::decode_udp(&buf[..n]).unwrap();
            let rosc::OscPacket::Bundle(bundle) = packet else {
                panic!("a State is a bundle");
            };
            let addrs: Vec<String> = bundle
                .content
                .iter()
                .filter_map(|p| match p {
                    rosc::OscPacket::Message(m) => Some(m.addr.clone()),
                    _ => None,
                })
                .collect();
            assert_eq!(addrs[0], "/digiteyes/state", "frame {frame}");
            assert_eq!(addrs.last().unwrap(), "/digiteyes/mouse", "frame {frame}");
        }
    }

    /// A board's name is the board's to choose: an escape sequence in it (here one that
    /// clears the screen) reaches the terminal as visible text, never as control bytes.
    #[test]
    fn a_boards_control_characters_are_escaped_in_text_output() {
        use digiteyes_core::protocol::{Capacities, Hello};
        let (mut board, slave) = TTYPort::pair().unwrap();
        let link = Link::open(&slave.name().unwrap(), 115_200).unwrap();
        let hello = BoardMessage::Hello(Hello {
            version: 1,
            board: "evil\u{1b}[2J\u{7}".try_into().unwrap(),
            model_digest: 0,
            clock_hz: 1000,
            capacities: Capacities {
                states: 28,
                max_states: 28,
                max_links: 37,
                max_frame_bytes: 64,
                max_chunk: 1024,
                max_message: 2048,
            },
        });
        let mut buf = [0u8; MAX_MESSAGE];
        board.write_all(encode(&hello, &mut buf).unwrap()).unwrap();
        let options = ListenOptions {
            duration: Some(Duration::from_millis(500)),
            ..ListenOptions::default()
        };
        let mut out = Vec::new();
        let summary = listen(link, &options, &mut out).unwrap();
        assert_eq!(summary.messages, 1);
        let text = String::from_utf8(out).unwrap();
        assert!(!text.bytes().any(|b| b == 0x1b || b == 0x07), "{text:?}");
        assert!(text.contains("evil\\u{1b}[2J\\u{7}"), "{text:?}");
    }
}
