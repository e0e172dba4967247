//! The UI's shared picture of the hand: the newest state, the link's figures, the newest
//! camera frame. Sources (serial, UDP, a replay, a simulated board) write into it; the HTTP
//! server reads it. One mutex, held only to copy a few hundred bytes in or out.

use std::collections::{BTreeMap, VecDeque};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use digiteyes_core::camera::Camera;
use digiteyes_core::model::Model;
use digiteyes_core::protocol::{BoardMessage, DropReason, LinkCounters, Stats};
use digiteyes_core::status::Status;
use image::GrayImage;
use serde::Serialize;

use crate::link::DropCause;
use crate::render::{world_shapes, WorldShape};
use crate::state_names::state_label;

/// States/s is measured over this window of arrivals.
pub const RATE_WINDOW: Duration = Duration::from_secs(2);
/// No state for this long and the page says the signal is gone.
pub const SIGNAL_TIMEOUT: Duration = Duration::from_secs(2);

/// One tracked frame's state, as the UI shows it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShownState {
    /// Frame number.
    pub frame: u32,
    /// Every model state (quaternion, mm, rad).
    pub q: Vec<f32>,
    /// The tracker does not trust this state (true whenever `status` is not `tracking`).
    pub lost: bool,
    /// What the tracker claims of the frame, as its word: `searching`, `tracking` or `lost`
    /// (the page shows the hand solid, ghosted or not at all).
    #[serde(serialize_with = "status_word")]
    pub status: Status,
    /// Residual RMS of the last iteration (px).
    pub rms_px: f32,
    /// Features found in the last iteration.
    pub features_found: u16,
    /// Features expected in the last iteration.
    pub features_expected: u16,
    /// Gauss–Newton iterations run.
    pub iterations: u8,
}

impl From<&digiteyes_core::protocol::State> for ShownState {
    fn from(s: &digiteyes_core::protocol::State) -> Self {
        ShownState {
            frame: s.frame,
            q: s.q.to_vec(),
            lost: s.lost,
            status: s.status.into(),
            rms_px: s.rms_px,
            features_found: s.features_found,
            features_expected: s.features_expected,
            iterations: s.iterations,
        }
    }
}

/// One of the hypotheses a tracker carried after a frame, as the UI shows it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShownHypothesis {
    /// Its place among the frame's hypotheses (0: the best, the state shown).
    pub rank: u8,
    /// Its likelihood score less the lost penalty (0 with a single hypothesis).
    pub score: f32,
    /// Frames it has been carried.
    pub age: u32,
    /// Its state (quaternion, mm, rad).
    pub q: Vec<f32>,
}

/// A hypothesis other than the best, drawn ghosted behind the hand.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Ghost {
    /// Its place among the frame's hypotheses (1 and up).
    pub rank: u8,
    /// Its likelihood score less the lost penalty.
    pub score: f32,
    /// Frames it has been carried.
    pub age: u32,
    /// Its state (quaternion, mm, rad).
    pub q: Vec<f32>,
    /// The hand's solid shapes at that state (world, mm); empty when the state does not fit
    /// the model.
    pub shapes: Vec<WorldShape>,
}

/// A status as its word in the page's JSON (`Status::as_str`).
fn status_word<S: serde::Serializer>(status: &Status, serializer: S) -> Result<S::Ok, S::Error> {
    serializer.serialize_str(status.as_str())
}

/// A camera frame waiting to be drawn with the model over it (drawn only when asked for).
#[derive(Debug, Clone)]
pub struct CameraFrame {
    /// Frame number.
    pub frame: u32,
    /// The camera that took it.
    pub camera: Camera,
    /// The pixels (`camera.width × camera.height`).
    pub image: GrayImage,
    /// The state to draw over it.
    pub q: Vec<f32>,
}

/// What the page is told about the model once.
#[derive(Debug, Clone, Serialize)]
pub struct ModelInfo {
    /// Where the states come from, e.g. "serial /dev/ttyUSB0".
    pub source: String,
    /// A label per state, e.g. "q8 finger 1 MCP flexion (rad)".
    pub labels: Vec<String>,
    /// The states the tracker estimates (the others stay at their initial values).
    pub free: Vec<usize>,
}

/// The link's figures as the page shows them.
#[derive(Debug, Clone, Default, Serialize)]
pub struct LinkFigures {
    /// States received.
    pub states: u64,
    /// States per second over the last [`RATE_WINDOW`].
    pub states_per_s: f64,
    /// States the tracker flagged lost (searching ones included: no hand claimed).
    pub lost_states: u64,
    /// States whose status was `searching`.
    pub searching_states: u64,
    /// Frames not tracked, by reason.
    pub drops: BTreeMap<String, u64>,
    /// Total of `drops`.
    pub dropped: u64,
    /// CRC errors seen by this host's receiver (serial sources only).
    pub crc_errors: u32,
    /// Framing errors seen by this host's receiver.
    pub framing_errors: u32,
    /// The board's own counters, from its latest `Stats`.
    pub board: Option<Stats>,
    /// Datagrams or lines that were not a board message (UDP sources).
    pub unreadable: u64,
}

/// Everything `/api/state` returns.
#[derive(Debug, Clone, Serialize)]
pub struct Snapshot {
    /// Rises with every change; the page redraws only when it moved.
    pub seq: u64,
    /// The newest state, if any arrived.
    pub state: Option<ShownState>,
    /// Seconds since it arrived.
    pub age_s: Option<f64>,
    /// No state for [`SIGNAL_TIMEOUT`], or none yet.
    pub no_signal: bool,
    /// The hand's solid shapes at that state (world, mm).
    pub shapes: Vec<WorldShape>,
    /// The 3D mouse read off that state, when the mapper applies.
    pub mouse: Option<serde_json::Value>,
    /// The link's figures.
    pub link: LinkFigures,
    /// Number of the newest camera frame (fetch `/frame.png`), if frames are available.
    pub camera_frame: Option<u32>,
    /// Hypotheses the tracker carried after the shown state's frame, when the source tells
    /// (0: not told, or searching).
    pub hypotheses: u8,
    /// The best hypothesis' score on that frame, when the source tells.
    pub best_score: Option<f32>,
    /// The other hypotheses of that frame (rank 1 and up), drawn ghosted behind the hand; none
    /// while searching.
    pub ghosts: Vec<Ghost>,
}

/// Turns a state into the 3D-mouse reading the page shows; see [`Hub::set_mouse`].
pub type MouseReader = Box<dyn FnMut(&[f32]) -> Option<serde_json::Value> + Send>;

struct Inner {
    seq: u64,
    state: Option<(ShownState, Instant)>,
    shapes: Vec<WorldShape>,
    mouse: Option<serde_json::Value>,
    mouse_reader: Option<MouseReader>,
    arrivals: VecDeque<Instant>,
    link: LinkFigures,
    frame: Option<CameraFrame>,
    info: ModelInfo,
    /// The hypotheses of the last few frames told (newest last), at most
    /// [`HYPOTHESES_FRAMES_KEPT`]: a frame's state may arrive before or after them.
    hypotheses: VecDeque<FrameHypotheses>,
}

/// Frames whose hypotheses are kept waiting for (or showing with) their state.
pub const HYPOTHESES_FRAMES_KEPT: usize = 4;

/// The hypotheses a source told of one frame.
struct FrameHypotheses {
    frame: u32,
    count: u8,
    best_score: Option<f32>,
    ghosts: Vec<Ghost>,
}

/// The shared picture; clone the `Arc` to hand it to a source or the server.
pub struct Hub {
    model: Model,
    inner: Mutex<Inner>,
    /// `/api/state` answers served so far.
    polls_served: AtomicU64,
}

impl Hub {
    /// A hub for states of `model` estimating `free`, fed from `source` (shown on the page).
    pub fn new(model: Model, free: Vec<usize>, source: impl Into<String>) -> Arc<Hub> {
        let labels = (0..model.n_states()).map(state_label).collect();
        Arc::new(Hub {
            model,
            inner: Mutex::new(Inner {
                seq: 0,
                state: None,
                shapes: Vec::new(),
                mouse: None,
                mouse_reader: None,
                arrivals: VecDeque::new(),
                link: LinkFigures::default(),
                frame: None,
                hypotheses: VecDeque::new(),
                info: ModelInfo {
                    source: source.into(),
                    labels,
                    free,
                },
            }),
            polls_served: AtomicU64::new(0),
        })
    }

    /// The model the states belong to.
    pub fn model(&self) -> &Model {
        &self.model
    }

    fn lock(&self) -> MutexGuard<'_, Inner> {
        // A source thread that panicked mid-update leaves plain data behind: keep serving it.
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Reads the 3D mouse off every state from now on.
    pub fn set_mouse(&self, reader: MouseReader) {
        self.lock().mouse_reader = Some(reader);
    }

    /// Sets the free states (e.g. once a source learned them).
    pub fn set_free(&self, free: Vec<usize>) {
        let mut inner = self.lock();
        inner.info.free = free;
        inner.seq += 1;
    }

    /// Takes in one message from a board.
    pub fn push_message(&self, message: &BoardMessage) {
        match message {
            BoardMessage::State(s) => self.push_state(ShownState::from(s)),
            BoardMessage::Dropped(d) => self.push_drop(d.reason),
            BoardMessage::Stats(s) => {
                let mut inner = self.lock();
                inner.link.board = Some(*s);
                inner.seq += 1;
            }
            _ => {}
        }
    }

    /// Takes in one tracked state. A state of the wrong length for the model is shown as
    /// it came (values and flags) but with no 3D hand.
    pub fn push_state(&self, state: ShownState) {
        let shapes = world_shapes(&self.model, &state.q).unwrap_or_default();
        let now = Instant::now();
        let mut inner = self.lock();
        let mouse = match inner.mouse_reader.as_mut() {
            Some(read) => read(&state.q),
            None => None,
        };
        inner.mouse = mouse;
        inner.shapes = shapes;
        inner.link.states += 1;
        inner.link.lost_states += u64::from(state.lost);
        inner.link.searching_states += u64::from(state.status == Status::Searching);
        inner.arrivals.push_back(now);
        while inner
            .arrivals
            .front()
            .is_some_and(|t| now.duration_since(*t) > RATE_WINDOW)
        {
            inner.arrivals.pop_front();
        }
        inner.state = Some((state, now));
        inner.seq += 1;
    }

    /// Takes in the hypotheses carried after frame `frame`, best first (none: the tracker
    /// carried none, e.g. searching). They are shown with the state of the same frame,
    /// whether it comes before or after them; the best is that state, the others are ghosts.
    pub fn push_hypotheses(&self, frame: u32, hypotheses: &[ShownHypothesis]) {
        let ghosts = hypotheses
            .iter()
            .filter(|h| h.rank > 0)
            .map(|h| Ghost {
                rank: h.rank,
                score: h.score,
                age: h.age,
                q: h.q.clone(),
                shapes: world_shapes(&self.model, &h.q).unwrap_or_default(),
            })
            .collect();
        let best_score = hypotheses.iter().find(|h| h.rank == 0).map(|h| h.score);
        let mut inner = self.lock();
        inner.hypotheses.retain(|h| h.frame != frame);
        if inner.hypotheses.len() >= HYPOTHESES_FRAMES_KEPT {
            inner.hypotheses.pop_front();
        }
        inner.hypotheses.push_back(FrameHypotheses {
            frame,
            count: hypotheses.len().min(usize::from(u8::MAX)) as u8,
            best_score,
            ghosts,
        });
        inner.seq += 1;
    }

    /// Counts a frame the board did not track.
    pub fn push_drop(&self, reason: DropReason) {
        let mut inner = self.lock();
        let name = DropCause::Board(reason).to_string();
        *inner.link.drops.entry(name).or_default() += 1;
        inner.link.dropped += 1;
        inner.seq += 1;
    }

    /// Counts a frame lost for a reason the host saw (e.g. a timeout).
    pub fn push_host_drop(&self, reason: &str) {
        let mut inner = self.lock();
        *inner.link.drops.entry(reason.to_string()).or_default() += 1;
        inner.link.dropped += 1;
        inner.seq += 1;
    }

    /// Sets this host's receiver counters (serial sources).
    pub fn set_receiver(&self, counters: LinkCounters) {
        let mut inner = self.lock();
        if inner.link.crc_errors != counters.crc_errors
            || inner.link.framing_errors != counters.framing_errors
        {
            inner.link.crc_errors = counters.crc_errors;
            inner.link.framing_errors = counters.framing_errors;
            inner.seq += 1;
        }
    }

    /// Counts something received that was not a board message.
    pub fn push_unreadable(&self) {
        let mut inner = self.lock();
        inner.link.unreadable += 1;
        inner.seq += 1;
    }

    /// Sets the newest camera frame.
    pub fn push_frame(&self, frame: CameraFrame) {
        let mut inner = self.lock();
        inner.frame = Some(frame);
        inner.seq += 1;
    }

    /// The newest camera frame, if any.
    pub fn camera_frame(&self) -> Option<CameraFrame> {
        self.lock().frame.clone()
    }

    /// What the page is told about the model.
    pub fn info(&self) -> ModelInfo {
        self.lock().info.clone()
    }

    /// The snapshot a page polled for, counted in [`Hub::polls_served`].
    pub fn polled_snapshot(&self) -> Snapshot {
        let snapshot = self.snapshot();
        self.polls_served.fetch_add(1, Ordering::Relaxed);
        snapshot
    }

    /// How many snapshots pages have polled for: a test that drives a page can wait until the
    /// page has seen a state instead of guessing how long that takes.
    pub fn polls_served(&self) -> u64 {
        self.polls_served.load(Ordering::Relaxed)
    }

    /// Everything the page shows, now.
    pub fn snapshot(&self) -> Snapshot {
        let now = Instant::now();
        let inner = self.lock();
        let age = inner.state.as_ref().map(|(_, t)| now.duration_since(*t));
        let recent = inner
            .arrivals
            .iter()
            .filter(|t| now.duration_since(**t) <= RATE_WINDOW)
            .count();
        let mut link = inner.link.clone();
        link.states_per_s = recent as f64 / RATE_WINDOW.as_secs_f64();
        // The hypotheses of the shown state's frame only, and none while searching.
        let hypotheses = match &inner.state {
            Some((state, _)) if state.status != Status::Searching => inner
                .hypotheses
                .iter()
                .rev()
                .find(|h| h.frame == state.frame),
            _ => None,
        };
        Snapshot {
            seq: inner.seq,
            state: inner.state.as_ref().map(|(s, _)| s.clone()),
            age_s: age.map(|a| a.as_secs_f64()),
            no_signal: age.is_none_or(|a| a > SIGNAL_TIMEOUT),
            shapes: inner.shapes.clone(),
            mouse: inner.mouse.clone(),
            link,
            camera_frame: inner.frame.as_ref().map(|f| f.frame),
            hypotheses: hypotheses.map_or(0, |h| h.count),
            best_score: hypotheses.and_then(|h| h.best_score),
            ghosts: hypotheses.map_or_else(Vec::new, |h| h.ghosts.clone()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use digiteyes_core::protocol::{Dropped, State, WireStatus};

    fn state(frame: u32, q: &[f32], lost: bool) -> BoardMessage {
        BoardMessage::State(State {
            frame,
            timestamp: 0,
            q: heapless::Vec::from_slice(q).unwrap(),
            rms_px: 0.5,
            lost,
            features_found: 30,
            features_expected: 35,
            iterations: 4,
            track_ticks: 100,
            status: if lost {
                WireStatus::Lost
            } else {
                WireStatus::Tracking
            },
            search_evaluations: 0,
        })
    }

    fn rest() -> Vec<f32> {
        let mut q = vec![0.0; 28];
        q[0] = 1.0;
        q
    }

    #[test]
    fn states_drops_and_counters_add_up() {
        let hub = Hub::new(Model::hand().unwrap(), vec![4, 5], "test");
        let before = hub.snapshot();
        assert!(before.no_signal && before.state.is_none() && before.shapes.is_empty());
        hub.push_message(&state(1, &rest(), false));
        hub.push_message(&state(2, &rest(), true));
        hub.push_message(&BoardMessage::Dropped(Dropped {
            frame: 3,
            reason: DropReason::Superseded,
        }));
        hub.set_receiver(LinkCounters {
            crc_errors: 2,
            framing_errors: 1,
            ..LinkCounters::default()
        });
        let s = hub.snapshot();
        assert!(s.seq > before.seq);
        assert!(!s.no_signal);
        assert_eq!(s.state.as_ref().map(|s| (s.frame, s.lost)), Some((2, true)));
        assert_eq!(s.link.states, 2);
        assert_eq!(s.link.lost_states, 1);
        assert_eq!(s.link.dropped, 1);
        assert_eq!(s.link.drops.values().sum::<u64>(), 1);
        assert_eq!((s.link.crc_errors, s.link.framing_errors), (2, 1));
        assert_eq!(s.link.states_per_s, 2.0 / RATE_WINDOW.as_secs_f64());
        // The palm box and 15 finger and thumb capsules.
        assert_eq!(s.shapes.len(), 16);
    }

    #[test]
    fn a_state_that_does_not_fit_the_model_is_shown_without_a_hand() {
        let hub = Hub::new(Model::hand().unwrap(), vec![], "test");
        hub.push_message(&state(7, &[1.0, 0.0, 0.0], false));
        let mut q = rest();
        q[9] = f32::NAN;
        let s = hub.snapshot();
        assert_eq!(s.state.map(|s| s.q.len()), Some(3));
        assert!(s.shapes.is_empty());
        hub.push_message(&state(8, &q, false));
        assert!(hub.snapshot().shapes.is_empty(), "NaN state drew a hand");
    }

    fn shown_state(frame: u32, q: Vec<f32>, status: Status) -> ShownState {
        ShownState {
            frame,
            q,
            lost: status != Status::Tracking,
            status,
            rms_px: 0.5,
            features_found: 30,
            features_expected: 35,
            iterations: 4,
        }
    }

    #[test]
    fn hypotheses_are_shown_with_their_own_frame_and_never_while_searching() {
        let hub = Hub::new(Model::hand().unwrap(), vec![], "test");
        let mut bent = rest();
        bent[8] = 1.0;
        let hypotheses = [
            ShownHypothesis {
                rank: 0,
                score: 0.9,
                age: 5,
                q: rest(),
            },
            ShownHypothesis {
                rank: 1,
                score: 0.85,
                age: 0,
                q: bent.clone(),
            },
        ];
        // Told before their state arrives: not shown with the previous frame's state, whose
        // own are still shown.
        hub.push_state(shown_state(3, rest(), Status::Tracking));
        hub.push_hypotheses(3, &hypotheses[..1]);
        hub.push_hypotheses(4, &hypotheses);
        assert!(hub.snapshot().ghosts.is_empty());
        assert_eq!(hub.snapshot().hypotheses, 1);
        hub.push_state(shown_state(4, rest(), Status::Tracking));
        let s = hub.snapshot();
        assert_eq!((s.hypotheses, s.best_score), (2, Some(0.9)));
        assert_eq!(s.ghosts.len(), 1);
        assert_eq!((s.ghosts[0].rank, s.ghosts[0].q[8]), (1, 1.0));
        assert_eq!(s.ghosts[0].shapes.len(), 16);
        // The next frame without hypotheses told: none shown.
        hub.push_state(shown_state(5, rest(), Status::Tracking));
        assert!(hub.snapshot().ghosts.is_empty());
        // Searching: none, even when told.
        hub.push_hypotheses(6, &hypotheses);
        hub.push_state(shown_state(6, rest(), Status::Searching));
        assert!(hub.snapshot().ghosts.is_empty());
        let json = serde_json::to_value(hub.snapshot()).unwrap();
        assert_eq!(json["ghosts"], serde_json::json!([]));
    }

    #[test]
    fn the_mouse_reader_sees_every_state() {
        let hub = Hub::new(Model::hand().unwrap(), vec![], "test");
        hub.set_mouse(Box::new(|q| Some(serde_json::json!({ "x_mm": q[4] }))));
        let mut q = rest();
        q[4] = 12.5;
        hub.push_message(&state(1, &q, false));
        assert_eq!(
            hub.snapshot().mouse,
            Some(serde_json::json!({ "x_mm": 12.5 }))
        );
    }
}
