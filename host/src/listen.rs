//! `digiteyes listen`: decode what a board sends, print it, and forward it as JSON lines over
//! UDP to the machine that shows the hand (as DigitEyes sent its states on over TCP).
//!
//! Each message is one line: human-readable by default, or its JSON form (serde's
//! externally tagged form of `BoardMessage`, e.g. `{"State":{"frame":12,"q":[…],…}}`).
//! Forwarding sends every JSON line (with its newline) as one UDP datagram.

use std::io::Write;
use std::net::{SocketAddr, ToSocketAddrs, UdpSocket};
use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Context, Result};
use digiteyes_core::protocol::{BoardMessage, LinkCounters};

use crate::link::{DropCause, Link, Session, SessionSetup};
use crate::sequence::{Sequence, SEQUENCE_JSON};

/// What to listen for and where it goes.
#[derive(Debug, Clone, Default)]
#[non_exhaustive]
pub struct ListenOptions {
    /// Print JSON lines instead of text.
    pub json: bool,
    /// Forward JSON lines to this UDP address.
    pub forward: Option<SocketAddr>,
    /// Stop after this many `State`s.
    pub states: Option<usize>,
    /// Stop after this long.
    pub duration: Option<Duration>,
    /// Set the board up first (Configure + Reset) from this `sequence.json` or sequence
    /// folder: for a board with its own camera.
    pub setup: Option<PathBuf>,
    /// The camera of a multi-camera setup.
    pub camera_index: Option<usize>,
}

/// What a listen session saw.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ListenSummary {
    /// Messages decoded.
    pub messages: usize,
    /// `State`s among them.
    pub states: usize,
    /// Datagrams forwarded.
    pub forwarded: usize,
    /// The host receiver's counters.
    pub link: LinkCounters,
}

/// Parses `udp://HOST:PORT`.
pub fn parse_forward(url: &str) -> Result<SocketAddr> {
    let Some(rest) = url.strip_prefix("udp://") else {
        bail!("--forward `{url}`: expected udp://HOST:PORT");
    };
    rest.to_socket_addrs()
        .with_context(|| format!("--forward `{url}`: cannot resolve {rest}"))?
        .next()
        .ok_or_else(|| anyhow!("--forward `{url}`: {rest} resolves to no address"))
}

/// Listens on `link`, writing a line per message to `out`, until the options' limits (or
/// forever).
pub fn listen(link: Link, options: &ListenOptions, out: &mut dyn Write) -> Result<ListenSummary> {
    let mut link = match &options.setup {
        Some(path) => set_up(link, path, options.camera_index, out)?,
        None => link,
    };
    let socket = match options.forward {
        Some(to) => {
            let local: SocketAddr = if to.is_ipv4() {
                ([0, 0, 0, 0], 0).into()
            } else {
                (std::net::Ipv6Addr::UNSPECIFIED, 0).into()
            };
            let socket =
                UdpSocket::bind(local).context("cannot open a UDP socket for --forward")?;
            Some((socket, to))
        }
        None => None,
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
        summary.messages += 1;
        summary.states += usize::from(matches!(message, BoardMessage::State(_)));
        let json = serde_json::to_string(&message)?;
        if options.json {
            writeln!(out, "{json}")?;
        } else {
            writeln!(out, "{}", describe(&message))?;
        }
        out.flush()?;
        if let Some((socket, to)) = &socket {
            let line = format!("{json}\n");
            socket
                .send_to(line.as_bytes(), to)
                .with_context(|| format!("cannot forward to udp://{to}"))?;
            summary.forwarded += 1;
        }
    }
    summary.link = link.counters();
    Ok(summary)
}

/// Configures and resets the board from a sequence description, then hands the link back.
fn set_up(
    link: Link,
    path: &std::path::Path,
    camera: Option<usize>,
    out: &mut dyn Write,
) -> Result<Link> {
    let json = if path.is_dir() {
        path.join(SEQUENCE_JSON)
    } else {
        path.to_path_buf()
    };
    let sequence = Sequence::open_description(&json)?;
    let setup = SessionSetup::from_sequence(&sequence, camera)?;
    let session = Session::start(link, setup)?;
    writeln!(
        out,
        "board {} set up from {}",
        session.hello().board,
        json.display()
    )?;
    Ok(session.into_link())
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
            format!(
                "state {}: rms {:.3} px, {}/{} features, {} iterations, {} ticks{} q=[{}]",
                s.frame,
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
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forward_urls() {
        assert_eq!(
            parse_forward("udp://127.0.0.1:9000").unwrap(),
            "127.0.0.1:9000".parse().unwrap()
        );
        let err = format!("{:#}", parse_forward("tcp://127.0.0.1:9000").unwrap_err());
        assert!(err.contains("udp://HOST:PORT"), "{err}");
        assert!(parse_forward("udp://127.0.0.1").is_err());
    }
}
