//! Forwarding a board's messages to the machines that show the hand (`listen --forward`;
//! `docs/forwarding.md`), as DigitEyes sent its states on over TCP.
//!
//! - `udp://HOST:PORT`: every message as its JSON line (serde's externally tagged form of
//!   `BoardMessage`, with the newline), one per UDP datagram;
//! - `osc://HOST:PORT`: States, drops and counters as Open Sound Control packets ([`osc`]),
//!   with the 3D mouse ([`crate::mouse_pole`]) when the board tracks the built-in hand.
//!
//! Forwarded states may be smoothed by the one-euro filter ([`one_euro`]); what `listen`
//! prints, and the tracker's own states, stay raw.

pub mod one_euro;
pub mod osc;

use std::fmt;
use std::net::{Ipv6Addr, SocketAddr, ToSocketAddrs, UdpSocket};
use std::time::Instant;

use anyhow::{anyhow, bail, Context, Result};
use digiteyes_core::model::Model;
use digiteyes_core::protocol::{model_digest, BoardMessage, Hello, State};

use crate::mouse_pole::{MouseConfig, MouseMapper, MousePole};
use one_euro::{Smoothing, StateSmoother};

/// Where and how to forward.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Forward {
    /// `udp://HOST:PORT`: JSON lines, one per datagram.
    Json(SocketAddr),
    /// `osc://HOST:PORT`: Open Sound Control over UDP.
    Osc(SocketAddr),
}

impl Forward {
    /// The destination.
    pub fn addr(&self) -> SocketAddr {
        match self {
            Forward::Json(a) | Forward::Osc(a) => *a,
        }
    }
}

impl fmt::Display for Forward {
    /// The URL form, e.g. `osc://127.0.0.1:9000`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Forward::Json(a) => write!(f, "udp://{a}"),
            Forward::Osc(a) => write!(f, "osc://{a}"),
        }
    }
}

/// What `--forward` accepts, for messages.
const ACCEPTED: &str = "udp://HOST:PORT (JSON lines) or osc://HOST:PORT (Open Sound Control)";

/// Parses `udp://HOST:PORT` or `osc://HOST:PORT` (HOST a name or an address; IPv6 in
/// brackets).
pub fn parse_forward(url: &str) -> Result<Forward> {
    let (make, rest): (fn(SocketAddr) -> Forward, &str) =
        if let Some(rest) = url.strip_prefix("udp://") {
            (Forward::Json, rest)
        } else if let Some(rest) = url.strip_prefix("osc://") {
            (Forward::Osc, rest)
        } else {
            bail!("--forward `{url}`: expected {ACCEPTED}");
        };
    let addr = rest
        .to_socket_addrs()
        .with_context(|| {
            format!("--forward `{url}`: cannot resolve `{rest}`: expected {ACCEPTED}")
        })?
        .next()
        .ok_or_else(|| anyhow!("--forward `{url}`: {rest} resolves to no address"))?;
    Ok(make(addr))
}

/// How forwarded states are treated.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[non_exhaustive]
pub struct ForwardOptions {
    /// Smooth forwarded states with the one-euro filter (`None`: send them as they are).
    pub smoothing: Option<Smoothing>,
    /// The 3D mouse's buttons.
    pub mouse: MouseConfig,
}

/// Sends a board's messages to every `--forward` target.
///
/// Time for the filter: the State's `timestamp` in seconds of the board's clock
/// (`Hello::clock_hz`) once a Hello has been seen (at `--setup`, or when the board boots);
/// before that, the host's receive time. A Hello (the board restarted, its clock too) starts
/// the filter afresh.
#[derive(Debug)]
pub struct Forwarder {
    targets: Vec<(Forward, UdpSocket)>,
    smoother: Option<StateSmoother>,
    mouse: Option<MouseSource>,
    clock_hz: Option<u32>,
    start: Instant,
}

impl Forwarder {
    /// Opens a UDP socket for each target.
    pub fn new(targets: &[Forward], options: ForwardOptions) -> Result<Forwarder> {
        let targets = targets
            .iter()
            .map(|&to| {
                let local: SocketAddr = if to.addr().is_ipv4() {
                    ([0, 0, 0, 0], 0).into()
                } else {
                    (Ipv6Addr::UNSPECIFIED, 0).into()
                };
                let socket = UdpSocket::bind(local)
                    .with_context(|| format!("cannot open a UDP socket to forward to {to}"))?;
                Ok((to, socket))
            })
            .collect::<Result<Vec<_>>>()?;
        let wants_mouse = targets.iter().any(|(t, _)| matches!(t, Forward::Osc(_)));
        let mouse = match wants_mouse {
            true => Some(MouseSource::new(options.mouse)?),
            false => None,
        };
        Ok(Forwarder {
            targets,
            smoother: options.smoothing.map(StateSmoother::new),
            mouse,
            clock_hz: None,
            start: Instant::now(),
        })
    }

    /// What `--setup` learnt: the board's Hello and the sequence's initial state (the 3D
    /// mouse's rest state; without it, the first state received is).
    pub fn set_up(&mut self, hello: &Hello, initial_state: &[f32]) {
        self.hello(hello);
        if let Some(mouse) = &mut self.mouse {
            mouse.rest = Some(initial_state.to_vec());
        }
    }

    /// Sends `message` (received at `received`) to every target; returns the datagrams sent.
    /// OSC targets get States, Dropped and Stats only.
    pub fn send(&mut self, message: &BoardMessage, received: Instant) -> Result<usize> {
        if let BoardMessage::Hello(h) = message {
            self.hello(h);
        }
        let state = match message {
            BoardMessage::State(s) => Some(self.prepare(s, received)),
            _ => None,
        };
        let mut json: Option<Vec<u8>> = None;
        let mut osc: Option<Option<Vec<u8>>> = None;
        let mut sent = 0;
        for (to, socket) in &self.targets {
            let bytes = match to {
                Forward::Json(_) => match &mut json {
                    Some(bytes) => bytes,
                    None => json.insert(json_line(message, state.as_ref())?),
                },
                Forward::Osc(_) => {
                    let packet = match &mut osc {
                        Some(packet) => packet,
                        None => osc.insert(osc_packet(message, state.as_ref())?),
                    };
                    match packet {
                        Some(bytes) => bytes,
                        None => continue,
                    }
                }
            };
            socket
                .send_to(bytes, to.addr())
                .with_context(|| format!("cannot forward to {to}"))?;
            sent += 1;
        }
        Ok(sent)
    }

    fn hello(&mut self, hello: &Hello) {
        self.clock_hz = Some(hello.clock_hz).filter(|&hz| hz > 0);
        if let Some(smoother) = &mut self.smoother {
            smoother.reset();
        }
        if let Some(mouse) = &mut self.mouse {
            mouse.hello(hello);
        }
    }

    /// The state to forward: smoothed or not, and the mouse.
    fn prepare(&mut self, state: &State, received: Instant) -> Forwarded {
        let q = match &mut self.smoother {
            Some(smoother) => {
                let t = match self.clock_hz {
                    Some(hz) => state.timestamp as f64 / f64::from(hz),
                    None => received.saturating_duration_since(self.start).as_secs_f64(),
                };
                smoother.filter(t, &state.q)
            }
            None => state.q.to_vec(),
        };
        let mouse = self.mouse.as_mut().and_then(|m| m.pole(state, &q));
        Forwarded {
            smoothed: self.smoother.is_some(),
            q,
            mouse,
        }
    }
}

/// A State as it is forwarded.
struct Forwarded {
    smoothed: bool,
    q: Vec<f32>,
    mouse: Option<MousePole>,
}

/// The JSON line (with its newline) of `message`; a smoothed State carries the smoothed q.
fn json_line(message: &BoardMessage, state: Option<&Forwarded>) -> Result<Vec<u8>> {
    let mut line = match (message, state) {
        (BoardMessage::State(s), Some(f)) if f.smoothed => {
            let mut s = s.clone();
            s.q.iter_mut().zip(&f.q).for_each(|(d, v)| *d = *v);
            serde_json::to_string(&BoardMessage::State(s))?
        }
        _ => serde_json::to_string(message)?,
    };
    line.push('\n');
    Ok(line.into_bytes())
}

/// The OSC packet of `message`, if it has one.
fn osc_packet(message: &BoardMessage, state: Option<&Forwarded>) -> Result<Option<Vec<u8>>> {
    let packet = match (message, state) {
        (BoardMessage::State(s), Some(f)) => osc::state_bundle(s, &f.q, f.mouse.as_ref()),
        (BoardMessage::Dropped(d), _) => osc::dropped_message(d),
        (BoardMessage::Stats(s), _) => osc::stats_message(s),
        _ => return Ok(None),
    };
    osc::encode(&packet).map(Some)
}

/// The 3D mouse of the forwarded states, when the board tracks the built-in hand.
#[derive(Debug)]
struct MouseSource {
    hand: Model,
    hand_digest: u32,
    config: MouseConfig,
    /// Whether the board's model is the built-in hand, from its Hello; unknown before one
    /// (then a state with the hand's state count is taken as the hand's).
    board_is_hand: Option<bool>,
    /// The buttons' rest state: `--setup`'s initial state, else the first state tracked.
    rest: Option<Vec<f32>>,
    mapper: Option<MouseMapper>,
}

impl MouseSource {
    fn new(config: MouseConfig) -> Result<MouseSource> {
        let hand = Model::hand().map_err(|e| anyhow!("the built-in hand model: {e}"))?;
        Ok(MouseSource {
            hand_digest: model_digest(&hand),
            hand,
            config,
            board_is_hand: None,
            rest: None,
            mapper: None,
        })
    }

    fn hello(&mut self, hello: &Hello) {
        self.board_is_hand = Some(hello.model_digest == self.hand_digest);
        // Buttons up again; the rest state stays.
        self.mapper = None;
    }

    /// The pole for forwarded states `q` of `state`; none for a lost state (its buttons stay
    /// as they were), another model, or states the mouse cannot place (not finite).
    fn pole(&mut self, state: &State, q: &[f32]) -> Option<MousePole> {
        let n = self.hand.n_states();
        if !self.board_is_hand.unwrap_or(q.len() == n) || state.lost || q.len() != n {
            return None;
        }
        if self.mapper.is_none() {
            let rest = match &self.rest {
                Some(rest) if rest.len() == n => rest.clone(),
                _ => state.q.to_vec(),
            };
            let mapper = MouseMapper::new(&self.hand, &rest, self.config).ok()?;
            self.rest = Some(rest);
            self.mapper = Some(mapper);
        }
        self.mapper.as_mut()?.update(q).ok()
    }
}

#[cfg(test)]
mod tests;
