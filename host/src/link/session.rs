//! A tracking session with a board: set it up, upload frames one at a time and collect each
//! one's fate, follow the board through reboots, and read its counters at the end.
//!
//! ```text
//! host                                   board
//!  Configure ───────────────────────────▶  Ack(Configure)
//!  Reset(q, free, start) ───────────────▶  Hello, Ack(Reset)      (Hello checked: version, model)
//!  FrameChunk × ⌈w·h / MAX_CHUNK⌉ ───────▶  State | Dropped        (one answer per frame)
//!  …                                      Hello (unsolicited: it rebooted → Configure, Reset
//!                                                from the last state, or searching again if
//!                                                it was searching; go on)
//!  Ping(t) ─────────────────────────────▶  Stats, Pong(t)
//! ```

use std::io::Write;
use std::path::Path;
use std::time::Instant;

use anyhow::{bail, Result};
use digiteyes_core::config::MAX_STATES;
use digiteyes_core::protocol::{
    BoardMessage, Command, Configure, FrameChunk, Hello, HostMessage, Hypotheses, Refusal, Reset,
    Start, WireStatus, MAX_CHUNK, PROTOCOL_VERSION,
};
use heapless::Vec as HVec;

use super::outcome::{DropCause, FrameOutcome};
use super::port::Link;
use super::report::LinkReport;
use super::setup::SessionSetup;
use crate::sequence::{Sequence, SEQUENCE_JSON};

/// Attempts at a command (`Configure`, `Reset`, `Ping`) before giving up: on a noisy line a
/// command or its answer may be lost.
const ATTEMPTS: u32 = 3;

/// Frames in a row without a byte from the board (answer and probe timed out) after which the
/// board counts as gone.
const SILENT_FRAMES: u32 = 3;

/// A set-up board, ready for frames.
#[derive(Debug)]
pub struct Session {
    link: Link,
    setup: SessionSetup,
    hello: Hello,
    /// The state to restart from after a reboot: the last one the board sent.
    last_state: Vec<f32>,
    /// How to restart after a reboot: searching again if the board was searching, else from
    /// `last_state`.
    last_start: Start,
    started: Instant,
    report: LinkReport,
    /// Pings sent to probe for lost answers (their tokens count up from 1; the final ping's
    /// tokens are above them).
    probes: u32,
    /// Frames in a row with no byte at all from the board.
    silent: u32,
    /// The `Hypotheses` messages received and not yet taken, when kept
    /// ([`Session::keep_hypotheses`]); `None`: only counted.
    hypotheses: Option<Vec<Hypotheses>>,
}

impl Session {
    /// Sets the board on `link` up for `setup`: `Configure`, then `Reset` (whose `Hello` is
    /// checked: protocol version and model digest). Fails with what the board said.
    pub fn start(link: Link, setup: SessionSetup) -> Result<Session> {
        let mut session = Session {
            link,
            last_state: setup.initial_state.clone(),
            last_start: setup.start,
            setup,
            hello: placeholder_hello(),
            started: Instant::now(),
            report: LinkReport::default(),
            probes: 0,
            silent: 0,
            hypotheses: None,
        };
        let q = session.last_state.clone();
        session.hello = session.handshake(&q, session.last_start, None)?;
        session.started = Instant::now();
        Ok(session)
    }

    /// From now on, keeps every `Hypotheses` message the board sends until
    /// [`take_hypotheses`](Self::take_hypotheses) (they are always counted in the report).
    pub fn keep_hypotheses(&mut self) {
        self.hypotheses.get_or_insert_with(Vec::new);
    }

    /// The `Hypotheses` messages kept since the last call, in the order received (none unless
    /// [`keep_hypotheses`](Self::keep_hypotheses) was called). A frame's message follows its
    /// `State`, so it arrives while the next frame's answer, or [`finish`](Self::finish)'s, is
    /// awaited.
    pub fn take_hypotheses(&mut self) -> Vec<Hypotheses> {
        self.hypotheses
            .as_mut()
            .map(std::mem::take)
            .unwrap_or_default()
    }

    /// The board's `Hello` (the latest).
    pub fn hello(&self) -> &Hello {
        &self.hello
    }

    /// The link.
    pub fn link(&self) -> &Link {
        &self.link
    }

    /// The link, to send and receive what this session does not (a stereo host's
    /// `Measure`s).
    pub fn link_mut(&mut self) -> &mut Link {
        &mut self.link
    }

    /// Sends `Hold` until acknowledged: from now on the board holds each uploaded frame for
    /// `Measure` instead of tracking it (one board per camera).
    pub fn hold(&mut self) -> Result<()> {
        self.command(&HostMessage::Hold, Command::Hold).map(|_| ())
    }

    /// Sets the board up again after it rebooted (its `Hello` came unasked, already checked
    /// by the caller): `Configure`, `Reset` from the last state, then `Hold`.
    pub fn hold_again(&mut self, hello: Hello) -> Result<()> {
        self.check_hello(&hello)?;
        self.report.restarts += 1;
        let q = self.last_state.clone();
        self.hello = self.handshake(&q, Start::Given, Some(hello))?;
        self.hold()
    }

    /// Uploads frame `frame` as `FrameChunk`s without waiting for an answer (a holding board
    /// sends none).
    pub fn upload(&mut self, frame: u32, pixels: &[u8], width: u16, height: u16) -> Result<()> {
        let mut offset = 0usize;
        for data in pixels.chunks(MAX_CHUNK) {
            self.link.send(&HostMessage::FrameChunk(FrameChunk {
                frame,
                width,
                height,
                offset: offset as u32,
                data,
            }))?;
            offset += data.len();
        }
        Ok(())
    }

    /// Notes the state the host estimated, to restart the board from after a reboot.
    pub fn note_state(&mut self, q: &[f32]) {
        self.last_state = q.to_vec();
    }

    /// Uploads frame `frame` (`width × height` bytes of packed 8-bit grey) and waits for its
    /// answer. Any size is sent: the board refuses sizes other than its camera's
    /// (`Dropped{WrongSize}`).
    pub fn track(
        &mut self,
        frame: u32,
        pixels: &[u8],
        width: u16,
        height: u16,
    ) -> Result<FrameOutcome> {
        self.upload(frame, pixels, width, height)?;
        let outcome = self.await_answer(frame)?;
        self.report.count(&outcome);
        if let FrameOutcome::Tracked(state) = &outcome {
            self.last_state = state.q.to_vec();
            self.last_start = match state.status {
                WireStatus::Searching => Start::Search,
                WireStatus::Tracking | WireStatus::Lost => Start::Given,
            };
        }
        Ok(outcome)
    }

    /// Pings the board for its counters and returns the session's figures. The link stays
    /// usable (see [`Session::into_link`]).
    pub fn finish(&mut self) -> Result<LinkReport> {
        self.report.seconds = self.started.elapsed().as_secs_f64();
        for attempt in 1..=ATTEMPTS {
            let token = self.probes + attempt;
            self.link.send(&HostMessage::Ping(token))?;
            let deadline = Instant::now() + self.setup.reply_timeout;
            while let Some(message) = self.link.recv_until(deadline)? {
                match message {
                    BoardMessage::Pong(t) if t == token => {
                        self.report.pong = true;
                        return Ok(self.snapshot());
                    }
                    other => self.aside(other)?,
                }
            }
        }
        // The counters are a report, not the work: without them the report says so.
        self.report.pong = false;
        Ok(self.snapshot())
    }

    /// Ends the session, handing back the link (e.g. to listen on).
    pub fn into_link(self) -> Link {
        self.link
    }

    fn snapshot(&self) -> LinkReport {
        let mut report = self.report.clone();
        report.bytes_up = self.link.bytes_up();
        report.bytes_down = self.link.bytes_down();
        report.host_link = self.link.counters();
        report.host_joined_mid_frame = self.link.joined_mid_frame();
        report.board_name = crate::text::escape_control(&self.hello.board);
        report
    }

    /// Waits for `frame`'s `State` or `Dropped`. Without one in time, probes with a `Ping`:
    /// the board answers a ping after everything it received before, so a `Pong` without
    /// the frame's answer means the frame is lost (e.g. its last chunk was), while a slow
    /// answer still counts. A board that sends no byte at all through [`SILENT_FRAMES`]
    /// frames in a row is gone: an error.
    fn await_answer(&mut self, frame: u32) -> Result<FrameOutcome> {
        let bytes_before = self.link.bytes_down();
        if let Some(outcome) = self.answer_or(frame, None)? {
            return Ok(outcome);
        }
        self.probes += 1;
        let token = self.probes;
        self.link.send(&HostMessage::Ping(token))?;
        if let Some(outcome) = self.answer_or(frame, Some(token))? {
            return Ok(outcome);
        }
        if self.link.bytes_down() == bytes_before {
            self.silent += 1;
            if self.silent >= SILENT_FRAMES {
                bail!(
                    "the board on {} has sent nothing for {} frames ({:.0} s): is it still \
                     connected and running?",
                    self.link.path(),
                    self.silent,
                    2.0 * f64::from(self.silent) * self.setup.reply_timeout.as_secs_f64()
                );
            }
        } else {
            self.silent = 0;
        }
        Ok(FrameOutcome::Dropped(DropCause::NoReply))
    }

    /// Waits up to the reply timeout for `frame`'s answer, or for `Pong(token)` (which means
    /// there will be none); `None` when neither came.
    fn answer_or(&mut self, frame: u32, token: Option<u32>) -> Result<Option<FrameOutcome>> {
        let deadline = Instant::now() + self.setup.reply_timeout;
        loop {
            let Some(message) = self.link.recv_until(deadline)? else {
                return Ok(None);
            };
            if let BoardMessage::Pong(t) = message {
                if Some(t) == token {
                    return Ok(Some(FrameOutcome::Dropped(DropCause::NoReply)));
                }
                continue;
            }
            let outcome = self.answer(frame, message)?;
            if outcome.is_some() {
                self.silent = 0;
                return Ok(outcome);
            }
        }
    }

    /// `frame`'s outcome if `message` decides it; other messages are set aside.
    fn answer(&mut self, frame: u32, message: BoardMessage) -> Result<Option<FrameOutcome>> {
        Ok(Some(match message {
            BoardMessage::State(state) if state.frame == frame => FrameOutcome::Tracked(state),
            BoardMessage::Dropped(d) if d.frame == frame => {
                FrameOutcome::Dropped(DropCause::Board(d.reason))
            }
            BoardMessage::Hello(hello) => {
                // The board rebooted: it lost the frame in flight and its setup.
                self.check_hello(&hello)?;
                self.report.restarts += 1;
                let q = self.last_state.clone();
                self.hello = self.handshake(&q, self.last_start, Some(hello))?;
                FrameOutcome::Dropped(DropCause::BoardRestarted)
            }
            other => {
                self.aside(other)?;
                return Ok(None);
            }
        }))
    }

    /// A message nobody is waiting for: counters, stale answers, features.
    fn aside(&mut self, message: BoardMessage) -> Result<()> {
        match message {
            BoardMessage::Stats(stats) => self.report.board = Some(stats),
            BoardMessage::State(_) | BoardMessage::Dropped(_) => self.report.late_answers += 1,
            BoardMessage::Features(_) => self.report.features += 1,
            // They follow their frame's State, so they arrive while the next frame (or the
            // final ping) is awaited.
            BoardMessage::Hypotheses(h) => {
                self.report.count_hypotheses(&h);
                if let Some(kept) = self.hypotheses.as_mut() {
                    kept.push(h);
                }
            }
            BoardMessage::LinkEdges(_) | BoardMessage::PalmEdges(_) | BoardMessage::Measured(_) => {
                self.report.late_answers += 1
            }
            BoardMessage::Hello(hello) => {
                self.check_hello(&hello)?;
                self.hello = hello;
            }
            BoardMessage::Ack(_) | BoardMessage::Nak(..) | BoardMessage::Pong(_) => {}
        }
        Ok(())
    }

    /// `Configure` then `Reset` from `q` (tracking from it, or searching: `start`), each until
    /// answered; returns the `Hello` that came with the reset, or `known` (a `Hello` already
    /// received and checked) if that one was lost on the line. Without either, the reset is
    /// repeated (it restarts from the same state, so repeating is harmless).
    fn handshake(&mut self, q: &[f32], start: Start, known: Option<Hello>) -> Result<Hello> {
        let configure = HostMessage::Configure(Configure {
            camera: self.setup.camera,
            tracker: self.setup.tracker,
            features_every: self.setup.features_every,
            stats_every: self.setup.stats_every,
            search_evaluations_per_frame: self.setup.search_evaluations_per_frame,
            hypotheses: self.setup.hypotheses,
        });
        self.command(&configure, Command::Configure)?;
        // A search starts from the same base as the host's own (`track --init auto`).
        let q = match start {
            Start::Search => &self.setup.search_base[..],
            Start::Given => q,
        };
        let q: HVec<f32, MAX_STATES> = q.iter().copied().take(MAX_STATES).collect();
        let reset = HostMessage::Reset(Reset {
            q,
            free: self.setup.free,
            start,
        });
        for _ in 0..ATTEMPTS {
            if let Some(hello) = self.command(&reset, Command::Reset)?.or(known.clone()) {
                return Ok(hello);
            }
        }
        bail!(
            "board on {} acknowledged Reset {ATTEMPTS} times without a Hello",
            self.link.path()
        )
    }

    /// Sends `message` until `Ack(command)` comes back (at most [`ATTEMPTS`] times); returns
    /// the last `Hello` seen meanwhile.
    fn command(&mut self, message: &HostMessage<'_>, command: Command) -> Result<Option<Hello>> {
        let mut hello = None;
        for _ in 0..ATTEMPTS {
            self.link.send(message)?;
            let deadline = Instant::now() + self.setup.reply_timeout;
            while let Some(answer) = self.link.recv_until(deadline)? {
                match answer {
                    BoardMessage::Ack(c) if c == command => return Ok(hello),
                    BoardMessage::Nak(c, refusal) if c == command => {
                        bail!(
                            "board on {} refused {command:?}: {}",
                            self.link.path(),
                            refusal_text(refusal)
                        )
                    }
                    BoardMessage::Hello(h) => {
                        self.check_hello(&h)?;
                        hello = Some(h);
                    }
                    other => self.aside(other)?,
                }
            }
        }
        bail!(
            "no answer to {command:?} from a board on {} within {} x {:.1} s: is a digiteyes \
             board connected there (and at the same baud rate)?",
            self.link.path(),
            ATTEMPTS,
            self.setup.reply_timeout.as_secs_f64()
        )
    }

    /// Refuses a board of another protocol version or with another model.
    fn check_hello(&self, hello: &Hello) -> Result<()> {
        if hello.version != PROTOCOL_VERSION {
            bail!(
                "board {} on {} speaks protocol version {}, this host speaks version {}",
                crate::text::escape_control(&hello.board),
                self.link.path(),
                hello.version,
                PROTOCOL_VERSION
            );
        }
        if hello.model_digest != self.setup.model_digest {
            bail!(
                "board {} on {} tracks another model (digest {:#010x}) than the sequence's \
                 `{}` (digest {:#010x}): the board's is built in; track this sequence with \
                 `digiteyes track` instead",
                crate::text::escape_control(&hello.board),
                self.link.path(),
                hello.model_digest,
                self.setup.model_name,
                self.setup.model_digest
            );
        }
        Ok(())
    }
}

/// What a board's refusal means, for an error message.
fn refusal_text(refusal: Refusal) -> &'static str {
    match refusal {
        Refusal::BadCamera => "the camera is unusable (size or focal length)",
        Refusal::BadParameters => {
            "a tracker parameter is out of range, the search budget is 0, or the hypothesis \
             count is not 1 to 8"
        }
        Refusal::FrameTooLarge => {
            "the camera's frames (or their edge map for the search) do not fit the board's \
             buffers"
        }
        Refusal::BadState => "the state has the wrong length for the model or is not finite",
        Refusal::BadFreeMask => "a free state is not a state of the model",
        Refusal::NotConfigured => "it has no camera yet (Reset or Hold before Configure)",
    }
}

fn placeholder_hello() -> Hello {
    Hello {
        version: 0,
        board: heapless::String::new(),
        model_digest: 0,
        clock_hz: 0,
        capacities: digiteyes_core::protocol::Capacities {
            states: 0,
            max_states: 0,
            max_links: 0,
            max_frame_bytes: 0,
            max_chunk: 0,
            max_message: 0,
        },
    }
}

/// A board set up from a sequence description, with the link handed back for listening.
#[derive(Debug)]
pub struct SetUpBoard {
    /// The link, the board configured and reset.
    pub link: Link,
    /// The board's `Hello`.
    pub hello: Hello,
    /// The description it was set up from (model, cameras, initial and free states).
    pub sequence: Sequence,
}

/// Configures and resets the board on `link` from `path` (a `sequence.json`, or a sequence
/// folder holding one), for camera `camera` of a multi-camera description, tracking from the
/// initial state; says so on `out`. For a board with its own camera: `listen --setup`,
/// `ui --port --setup`.
pub fn set_up_board(
    link: Link,
    path: &Path,
    camera: Option<usize>,
    out: &mut dyn Write,
) -> Result<SetUpBoard> {
    set_up_board_starting(link, path, camera, Start::Given, out)
}

/// [`set_up_board`], starting as `start` says: from the initial state, or searching for the
/// hand (`listen --setup … --init auto`).
pub fn set_up_board_starting(
    link: Link,
    path: &Path,
    camera: Option<usize>,
    start: Start,
    out: &mut dyn Write,
) -> Result<SetUpBoard> {
    let json = if path.is_dir() {
        path.join(SEQUENCE_JSON)
    } else {
        path.to_path_buf()
    };
    let sequence = Sequence::open_description(&json)?;
    let mut setup = SessionSetup::from_sequence(&sequence, camera)?;
    setup.start = start;
    let session = Session::start(link, setup)?;
    writeln!(
        out,
        "board {} set up from {}",
        crate::text::escape_control(&session.hello().board),
        json.display()
    )?;
    let hello = session.hello().clone();
    Ok(SetUpBoard {
        link: session.into_link(),
        hello,
        sequence,
    })
}
