//! The board loop: host commands in, frames tracked, states out.

use core::convert::Infallible;

use digiteyes_core::acquire::AcquireConfig;
use digiteyes_core::auto_tracker::{AutoError, AutoTracker};
use digiteyes_core::camera::Camera;
use digiteyes_core::config::MAX_STATES;
use digiteyes_core::estimator::FreeMask;
use digiteyes_core::frame::FrameView;
use digiteyes_core::hypotheses::HypothesesConfig;
use digiteyes_core::measurement::measure_links;
use digiteyes_core::model::Model;
use digiteyes_core::protocol::{
    encode, model_digest, BoardMessage, Capacities, Command, Configure, Decoder, DropReason,
    Dropped, Features, FrameChunk, Hello, HostMessage, Hypotheses, Measure, Measured, Refusal,
    Reset, Start, State, Stats, WireHypothesis, MAX_CHUNK, MAX_MESSAGE, PROTOCOL_VERSION,
};
use digiteyes_core::remote::MeasureWork;
use digiteyes_core::status::Status;
use digiteyes_core::tracker::{FrameReport, TrackerConfig, TrackerError};
use embedded_hal::delay::DelayNs;
use embedded_hal::digital::OutputPin;
use embedded_io::{Read, ReadReady, Write};
use heapless::{String, Vec};

use crate::clock::Clock;
use crate::log::{info, log_warn};
use crate::memory::{hypotheses_config, search_config, Buffers};
use crate::overlay;
use crate::source::FrameSource;
use crate::upload::{ChunkOutcome, Upload};

/// Bytes read from the serial port per `read` call.
const READ_BLOCK: usize = 64;

/// The camera and parameters of the last accepted `Configure`.
#[derive(Debug, Clone, Copy)]
struct Setup {
    camera: Camera,
    config: TrackerConfig,
    /// The search's parameters (its budget from `Configure`, the rest the board's).
    acquire: AcquireConfig,
    /// The hypotheses tracked (their count from `Configure`, the rest the board's).
    hypotheses: HypothesesConfig,
    features_every: u16,
    stats_every: u16,
}

/// A frame the board has just tracked, as its [`Board::set_tap`] tap sees it: handed over
/// right after tracking and before the frame's `State` is sent, so a host that has the state
/// knows the tap has had the frame.
#[derive(Debug, Clone, Copy)]
pub struct Tracked<'a> {
    /// The frame's number (as uploaded, or the camera source's).
    pub frame: u32,
    /// The camera it was tracked with (as configured).
    pub camera: &'a Camera,
    /// The tracker parameters it was tracked with (as configured).
    pub config: &'a TrackerConfig,
    /// The frame: 8-bit grey, packed, `camera.width × camera.height`.
    pub pixels: &'a [u8],
    /// The state tracked (the `State` message's `q`: quaternion, mm, rad).
    pub q: &'a [f32],
    /// What the tracker reported for it (`lost` whenever no hand is claimed).
    pub report: &'a FrameReport,
    /// What the board claims of the frame (the `State` message's `status`).
    pub status: Status,
    /// The search's work on the frame, in evaluations (0 while tracking).
    pub search_evaluations: u16,
}

/// Where a board hands each tracked frame ([`Board::set_tap`]). It runs inside the board
/// loop: whatever it does delays the frame's `State`.
pub type Tap<'m> = &'m mut (dyn FnMut(&Tracked<'_>) + Send);

/// Everything but the receiver, so a received message (which borrows the receiver's buffer)
/// can be handled while the rest of the board changes.
struct Node<'m, S, F, L, C> {
    name: &'static str,
    model: Option<Model>,
    frame: &'m mut [u8],
    overlay: Option<&'m mut [u8]>,
    /// The search's edge map (`Buffers::edge_map`).
    edge_map: &'m mut [u8],
    overlay_ready: bool,
    tap: Option<Tap<'m>>,
    serial: S,
    source: F,
    led: L,
    clock: C,
    tx: [u8; MAX_MESSAGE],
    setup: Option<Setup>,
    /// The status machine: tracking, or searching for the hand (`Reset`'s `start`).
    tracker: Option<AutoTracker>,
    /// Set by `Hold`: complete frames are held for `Measure` instead of tracked.
    measuring: Option<MeasureWork>,
    /// The frame held for `Measure`: the last one completed while measuring.
    held: Option<u32>,
    upload: Upload,
    stats: Stats,
}

/// One board: a tracker that finds the hand itself, its buffers and its serial link.
pub struct Board<'m, S, F, L, C> {
    rx: Decoder<MAX_MESSAGE>,
    node: Node<'m, S, F, L, C>,
}

impl<'m, S, F, L, C> Board<'m, S, F, L, C>
where
    S: Read + Write + ReadReady,
    F: FrameSource,
    L: OutputPin,
    C: Clock,
{
    /// A board named `name` (in `Hello`) tracking the built-in hand model, in `buffers`
    /// (the frame, the optional overlay, the search's edge map: [`Buffers`]).
    pub fn new(
        name: &'static str,
        buffers: Buffers<'m>,
        serial: S,
        source: F,
        led: L,
        clock: C,
    ) -> Self {
        Board {
            rx: Decoder::new(),
            node: Node {
                name,
                model: Model::hand().ok(),
                frame: buffers.frame,
                overlay: buffers.overlay,
                edge_map: buffers.edge_map,
                overlay_ready: false,
                tap: None,
                serial,
                source,
                led,
                clock,
                tx: [0; MAX_MESSAGE],
                setup: None,
                tracker: None,
                measuring: None,
                held: None,
                upload: Upload::new(),
                stats: Stats::default(),
            },
        }
    }

    /// Announces the board with `Hello`; call once at boot.
    pub fn start(&mut self) -> Result<(), S::Error> {
        info!("digiteyes board up");
        self.node.set_led(false);
        self.node.hello()
    }

    /// One pass of the loop: drains the serial bytes that are ready (never waits for more),
    /// handles each message, and tracks a camera frame if one is ready. Returns whether it did
    /// anything.
    pub fn poll(&mut self) -> Result<bool, S::Error> {
        let mut busy = false;
        let mut block = [0u8; READ_BLOCK];
        while self.node.serial.read_ready()? {
            let n = self.node.serial.read(&mut block)?;
            if n == 0 {
                break;
            }
            busy = true;
            let mut rest = block.get(..n).unwrap_or_default();
            while !rest.is_empty() {
                let (used, out) = self.rx.feed::<HostMessage>(rest);
                rest = rest.get(used..).unwrap_or_default();
                match out {
                    Some(Ok(message)) => self.node.handle(message)?,
                    Some(Err(_e)) => log_warn!("link: {}", _e),
                    None => {}
                }
            }
            self.node.stats.link = self.rx.counters();
        }
        busy |= self.node.poll_camera()?;
        self.node.stats.link = self.rx.counters();
        Ok(busy)
    }

    /// [`start`](Self::start), then [`poll`](Self::poll) forever, sleeping `idle_us` whenever
    /// a pass found nothing to do. Returns only on a serial error.
    pub fn run<D: DelayNs>(&mut self, delay: &mut D, idle_us: u32) -> Result<Infallible, S::Error> {
        self.start()?;
        loop {
            if !self.poll()? {
                delay.delay_us(idle_us);
            }
        }
    }

    /// The counters since boot.
    pub fn stats(&self) -> Stats {
        let mut stats = self.node.stats;
        stats.link = self.rx.counters();
        stats
    }

    /// The last tracked frame with the model drawn in, when an overlay buffer was given.
    pub fn overlay(&self) -> Option<&[u8]> {
        let setup = self.node.setup.as_ref()?;
        let n = setup.camera.width as usize * setup.camera.height as usize;
        self.node
            .overlay
            .as_deref()
            .filter(|_| self.node.overlay_ready)?
            .get(..n)
    }

    /// Hands every frame the board tracks from now on to `tap` (a debug view, a recorder),
    /// replacing any earlier tap. Frames dropped untracked are not handed over.
    pub fn set_tap(&mut self, tap: Tap<'m>) {
        self.node.tap = Some(tap);
    }

    /// The serial port (e.g. to inject bytes in a test).
    pub fn serial_mut(&mut self) -> &mut S {
        &mut self.node.serial
    }
}

impl<S, F, L, C> Node<'_, S, F, L, C>
where
    S: Read + Write + ReadReady,
    F: FrameSource,
    L: OutputPin,
    C: Clock,
{
    fn handle(&mut self, message: HostMessage<'_>) -> Result<(), S::Error> {
        match message {
            HostMessage::Configure(configure) => self.configure(&configure),
            HostMessage::Reset(reset) => self.reset(&reset),
            HostMessage::FrameChunk(chunk) => self.chunk(&chunk),
            HostMessage::Ping(token) => {
                let stats = self.stats;
                self.send(&BoardMessage::Stats(stats))?;
                self.send(&BoardMessage::Pong(token))
            }
            HostMessage::Hold => self.hold(),
            HostMessage::Measure(measure) => self.measure(&measure),
        }
    }

    /// Leaves tracking for measuring: frames are held for `Measure` (one board per camera).
    #[inline(never)]
    fn hold(&mut self) -> Result<(), S::Error> {
        if self.setup.is_none() {
            return self.send(&BoardMessage::Nak(Command::Hold, Refusal::NotConfigured));
        }
        self.tracker = None;
        if self.measuring.is_none() {
            self.measuring = Some(MeasureWork::new());
        }
        self.held = None;
        self.abandon_upload()?;
        self.send(&BoardMessage::Ack(Command::Hold))
    }

    /// Searches the held frame at the host's state and sends what each link showed.
    fn measure(&mut self, measure: &Measure) -> Result<(), S::Error> {
        let not_held = Measured {
            frame: measure.frame,
            iteration: measure.iteration,
            held: false,
            links: 0,
            silhouette: None,
        };
        let ready = !self.upload.in_progress() && self.held == Some(measure.frame);
        let (Some(setup), Some(work), Some(model), true) = (
            self.setup,
            self.measuring.as_mut(),
            self.model.as_ref(),
            ready,
        ) else {
            return self.send(&BoardMessage::Measured(not_held));
        };
        let (w, h) = (setup.camera.width as usize, setup.camera.height as usize);
        let pixels = self.frame.get(..w * h).unwrap_or_default();
        let Ok(view) = FrameView::packed(pixels, w, h) else {
            return self.send(&BoardMessage::Measured(not_held));
        };
        let (tx, serial, stats) = (&mut self.tx, &mut self.serial, &mut self.stats);
        let mut failed = None;
        let answer = work.measure(
            model,
            &setup.camera,
            &view,
            &setup.config,
            measure,
            |message| {
                if failed.is_none() {
                    if let Err(e) = send_on(serial, tx, stats, &message) {
                        failed = Some(e);
                    }
                }
            },
        );
        if let Some(e) = failed {
            return Err(e);
        }
        self.send(&BoardMessage::Measured(answer))
    }

    // Set-up builds a ~30 KB tracker by value; kept out of line so that the frame path does
    // not reserve that stack too (measured on the emulated M7: 69 KB → 15 KB per frame).
    #[inline(never)]
    fn configure(&mut self, configure: &Configure) -> Result<(), S::Error> {
        match self.apply_configure(configure) {
            Ok(()) => {
                self.abandon_upload()?;
                self.send(&BoardMessage::Ack(Command::Configure))
            }
            Err(refusal) => self.send(&BoardMessage::Nak(Command::Configure, refusal)),
        }
    }

    fn apply_configure(&mut self, configure: &Configure) -> Result<(), Refusal> {
        let camera = configure
            .camera
            .to_camera()
            .map_err(|_| Refusal::BadCamera)?;
        let config = configure
            .tracker
            .to_config()
            .map_err(|_| Refusal::BadParameters)?;
        if configure.search_evaluations_per_frame == 0 || !configure.hypotheses.is_valid() {
            return Err(Refusal::BadParameters);
        }
        let acquire = search_config(configure.search_evaluations_per_frame);
        let hypotheses = hypotheses_config(configure);
        if configure.camera.frame_bytes() > self.frame.len()
            || AutoTracker::edge_bytes_needed(&camera, &acquire) > self.edge_map.len()
        {
            return Err(Refusal::FrameTooLarge);
        }
        let unchanged = self
            .setup
            .is_some_and(|s| s.camera == camera && s.config == config && s.acquire == acquire);
        if !unchanged {
            // Keep the state, the free states and the status with the new camera and
            // parameters. `AutoTracker` cannot be reconfigured in place, so the motion (the
            // velocity of the next prediction) starts over; a `Configure` that changes
            // neither keeps everything (docs/protocol.md §6).
            rebuild(&mut self.tracker, camera, config, acquire, hypotheses)?;
        } else if let Some(auto) = self.tracker.as_mut() {
            // Only the count (or nothing) changed: the status machine keeps its motion, and
            // the hypotheses beyond a smaller count are dropped.
            auto.set_hypotheses(hypotheses);
        }
        self.setup = Some(Setup {
            camera,
            config,
            acquire,
            hypotheses,
            features_every: configure.features_every,
            stats_every: configure.stats_every,
        });
        Ok(())
    }

    #[inline(never)]
    fn reset(&mut self, reset: &Reset) -> Result<(), S::Error> {
        let built = match self.setup {
            None => Err(Refusal::NotConfigured),
            Some(setup) => self.build_tracker(&setup, &reset.q, reset.free, reset.start),
        };
        match built {
            Ok(()) => {
                self.measuring = None;
                self.held = None;
                self.abandon_upload()?;
                self.hello()?;
                self.send(&BoardMessage::Ack(Command::Reset))
            }
            Err(refusal) => self.send(&BoardMessage::Nak(Command::Reset, refusal)),
        }
    }

    /// Builds the status machine for `setup` from `q` into `self.tracker` (the old one kept
    /// on a refusal). Built where it is kept, not returned: the tracker is tens of KB, and
    /// every copy of it by value costs that much stack (docs/boards/qemu-m7.md, "Stack").
    fn build_tracker(
        &mut self,
        setup: &Setup,
        q: &[f32],
        free: u32,
        start: Start,
    ) -> Result<(), Refusal> {
        let model = self.model.clone().ok_or(Refusal::BadState)?;
        if q.len() != model.n_states() || q.iter().any(|v| !v.is_finite()) {
            return Err(Refusal::BadState);
        }
        let cameras = [setup.camera];
        let (free, config, acquire) = (FreeMask(free), setup.config, setup.acquire);
        let built = match start {
            Start::Given => AutoTracker::tracking(model, &cameras, q, free, config, acquire),
            Start::Search => AutoTracker::new(model, &cameras, q, free, config, acquire),
        };
        into_slot(&mut self.tracker, built, setup.hypotheses)
    }

    /// Drops and reports a partly uploaded frame: after a new setup its chunks no longer fit.
    fn abandon_upload(&mut self) -> Result<(), S::Error> {
        match self.upload.restart() {
            Some(frame) => self.report_drop(Dropped {
                frame,
                reason: DropReason::Superseded,
            }),
            None => Ok(()),
        }
    }

    fn chunk(&mut self, chunk: &FrameChunk<'_>) -> Result<(), S::Error> {
        let engaged = self.tracker.is_some() || self.measuring.is_some();
        let expected = match (&self.setup, engaged) {
            (Some(setup), true) => {
                let (w, h) = (setup.camera.width, setup.camera.height);
                Some((w as u16, h as u16))
            }
            _ => None,
        };
        if self.held != Some(chunk.frame) {
            // The buffer is being overwritten: the frame held so far is gone.
            self.held = None;
        }
        let (superseded, outcome) = self.upload.accept(chunk, expected, self.frame);
        if let Some(dropped) = superseded {
            self.report_drop(dropped)?;
        }
        match outcome {
            ChunkOutcome::Partial | ChunkOutcome::Ignored => Ok(()),
            ChunkOutcome::Stale => {
                self.stats.stale_chunks = self.stats.stale_chunks.saturating_add(1);
                Ok(())
            }
            ChunkOutcome::Dropped(dropped) => self.report_drop(dropped),
            ChunkOutcome::Complete { frame, .. } if self.measuring.is_some() => {
                self.held = Some(frame);
                Ok(())
            }
            ChunkOutcome::Complete { frame, .. } => self.track(frame),
        }
    }

    fn poll_camera(&mut self) -> Result<bool, S::Error> {
        let (Some(setup), Some(_)) = (&self.setup, &self.tracker) else {
            return Ok(false);
        };
        if self.upload.in_progress() {
            return Ok(false);
        }
        let (w, h) = (setup.camera.width as u16, setup.camera.height as u16);
        let n = usize::from(w) * usize::from(h);
        let Some(buffer) = self.frame.get_mut(..n) else {
            return Ok(false);
        };
        match self.source.poll_frame(buffer, w, h) {
            Ok(Some(frame)) => self.track(frame).map(|()| true),
            Ok(None) => Ok(false),
            Err(_) => {
                self.stats.bad_frames += 1;
                Ok(false)
            }
        }
    }

    fn track(&mut self, frame: u32) -> Result<(), S::Error> {
        let (Some(setup), Some(tracker)) = (self.setup, self.tracker.as_mut()) else {
            return self.report_drop(Dropped {
                frame,
                reason: DropReason::NotReady,
            });
        };
        let (w, h) = (setup.camera.width as usize, setup.camera.height as usize);
        let timestamp = self.clock.ticks();
        let pixels = self.frame.get(..w * h).unwrap_or_default();
        let outcome = match FrameView::packed(pixels, w, h) {
            Ok(view) => tracker.step(&[view], &mut [&mut *self.edge_map]),
            Err(e) => Err(AutoError::Tracker(TrackerError::Frame(e))),
        };
        let track_ticks = self.clock.ticks().saturating_sub(timestamp);
        let outcome = match outcome {
            Ok(outcome) => outcome,
            Err(_) => {
                return self.report_drop(Dropped {
                    frame,
                    reason: DropReason::TrackerError,
                })
            }
        };
        let report = outcome.report;
        let status = outcome.status;
        self.stats.frames += 1;
        self.stats.iterations += u32::from(report.iterations);
        self.stats.lost += u32::from(report.lost);
        let q = Vec::from_slice(tracker.state()).unwrap_or_default();
        let model = tracker.tracker().model();
        if let Some(out) = self.overlay.as_deref_mut() {
            overlay::draw(model, &setup.camera, tracker.state(), pixels, out);
            self.overlay_ready = true;
        }
        if let Some(tap) = self.tap.as_deref_mut() {
            tap(&Tracked {
                frame,
                camera: &setup.camera,
                config: &setup.config,
                pixels,
                q: &q,
                report: &report,
                status,
                search_evaluations: outcome.evaluated,
            });
        }
        let measurements = (setup.features_every != 0
            && self.stats.frames % u32::from(setup.features_every) == 0)
            .then(|| match FrameView::packed(pixels, w, h) {
                Ok(view) => measure_links(
                    model,
                    &setup.camera,
                    tracker.state(),
                    &view,
                    &setup.config.features,
                ),
                Err(_) => Vec::new(),
            });
        // With several hypotheses, they follow the State: best first, none while searching
        // (no hand claimed, so none carried).
        let carried = (setup.hypotheses.count > 1).then(|| {
            let list = match status {
                Status::Searching => &[][..],
                Status::Tracking | Status::Lost => tracker.hypotheses(),
            };
            Hypotheses {
                frame,
                hypotheses: list.iter().map(WireHypothesis::from).collect(),
            }
        });
        self.set_led(status.claims_hand());
        self.send(&BoardMessage::State(State {
            frame,
            timestamp,
            q,
            rms_px: report.rms_px,
            // The status machine sets `lost` on every frame that claims no hand; kept tied to
            // the status here too, so the two can never disagree on the wire.
            lost: report.lost || !status.claims_hand(),
            features_found: report.features_found,
            features_expected: report.features_expected,
            iterations: report.iterations,
            track_ticks: u32::try_from(track_ticks).unwrap_or(u32::MAX),
            status: status.into(),
            search_evaluations: outcome.evaluated,
        }))?;
        if let Some(hypotheses) = carried {
            self.send(&BoardMessage::Hypotheses(hypotheses))?;
        }
        if let Some(links) = measurements {
            self.send(&BoardMessage::Features(Features {
                frame,
                camera: 0,
                links,
            }))?;
        }
        if setup.stats_every != 0 && self.stats.frames % u32::from(setup.stats_every) == 0 {
            let stats = self.stats;
            self.send(&BoardMessage::Stats(stats))?;
        }
        Ok(())
    }

    fn report_drop(&mut self, dropped: Dropped) -> Result<(), S::Error> {
        self.stats.dropped.record(&dropped.reason);
        if matches!(
            dropped.reason,
            DropReason::WrongSize(..) | DropReason::TooLarge
        ) {
            self.stats.bad_frames += 1;
        }
        self.send(&BoardMessage::Dropped(dropped))
    }

    fn hello(&mut self) -> Result<(), S::Error> {
        let model = self.model.as_ref();
        let hello = Hello {
            version: PROTOCOL_VERSION,
            board: String::try_from(self.name).unwrap_or_default(),
            model_digest: model.map_or(0, model_digest),
            clock_hz: self.clock.hz(),
            capacities: Capacities {
                states: model.map_or(0, |m| m.n_states() as u8),
                max_states: MAX_STATES as u8,
                max_links: digiteyes_core::config::MAX_LINKS as u8,
                max_frame_bytes: u32::try_from(self.frame.len()).unwrap_or(u32::MAX),
                max_chunk: MAX_CHUNK as u16,
                max_message: MAX_MESSAGE as u16,
            },
        };
        self.send(&BoardMessage::Hello(hello))
    }

    fn send(&mut self, message: &BoardMessage) -> Result<(), S::Error> {
        send_on(&mut self.serial, &mut self.tx, &mut self.stats, message)
    }

    fn set_led(&mut self, on: bool) {
        // A status LED that fails to switch is not worth stopping the tracker for.
        let _ = if on {
            self.led.set_high()
        } else {
            self.led.set_low()
        };
    }
}

/// The tracker in `slot` (if any) again with a new camera and parameters, from its state, free
/// states and status (tracking from its state, or searching with its state as the fixed
/// states' values); on a refusal the old one stays.
fn rebuild(
    slot: &mut Option<AutoTracker>,
    camera: Camera,
    config: TrackerConfig,
    acquire: AcquireConfig,
    hypotheses: HypothesesConfig,
) -> Result<(), Refusal> {
    let Some(auto) = slot.as_ref() else {
        return Ok(());
    };
    let tracker = auto.tracker();
    let (model, free, cameras) = (tracker.model().clone(), tracker.free(), [camera]);
    let q: Vec<f32, MAX_STATES> = auto.state().iter().copied().collect();
    let built = match auto.status() {
        Status::Tracking | Status::Lost => {
            AutoTracker::tracking(model, &cameras, &q, free, config, acquire)
        }
        Status::Searching => AutoTracker::new(model, &cameras, &q, free, config, acquire),
    };
    into_slot(slot, built, hypotheses)
}

/// Moves a tracker just built into `slot` with `hypotheses` set, or keeps the slot as it was
/// and gives the refusal for the error. The value goes from the builder's result straight to
/// its slot: one copy of it on the stack, not one per step.
fn into_slot(
    slot: &mut Option<AutoTracker>,
    built: Result<AutoTracker, AutoError>,
    hypotheses: HypothesesConfig,
) -> Result<(), Refusal> {
    match built {
        Ok(auto) => {
            slot.insert(auto).set_hypotheses(hypotheses);
            Ok(())
        }
        Err(e) => Err(refusal_of(e)),
    }
}

/// The refusal for a tracker that could not be built.
fn refusal_of(e: AutoError) -> Refusal {
    match e {
        AutoError::Tracker(TrackerError::BadFreeState(_)) => Refusal::BadFreeMask,
        AutoError::Tracker(TrackerError::Camera(_) | TrackerError::CameraCount) => {
            Refusal::BadCamera
        }
        AutoError::Tracker(TrackerError::State(_)) => Refusal::BadState,
        // Not returned when a tracker is built (they are about frames given to `step`); a
        // state the tracker cannot start from is the nearest refusal.
        AutoError::Tracker(TrackerError::FrameCount | TrackerError::Frame(_))
        | AutoError::EdgeMap(_)
        | AutoError::BufferCount => Refusal::BadState,
    }
}

/// Encodes `message` into `tx` and writes it to `serial`; a message too large for `tx` is
/// counted in `stats.capacity_overflows`, not sent.
fn send_on<S: Write>(
    serial: &mut S,
    tx: &mut [u8; MAX_MESSAGE],
    stats: &mut Stats,
    message: &BoardMessage,
) -> Result<(), S::Error> {
    match encode(message, tx) {
        Ok(bytes) => {
            serial.write_all(bytes)?;
            serial.flush()
        }
        Err(_) => {
            stats.capacity_overflows += 1;
            Ok(())
        }
    }
}
