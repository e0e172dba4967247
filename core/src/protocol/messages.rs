//! The messages of the board link, in both directions.
//!
//! The wire form of every type here is postcard's (docs/protocol.md): enum variants are
//! varint indices in declaration order, so **new variants and fields go at the end** and the
//! [`PROTOCOL_VERSION`](super::PROTOCOL_VERSION) rises whenever a layout changes.

use heapless::{String, Vec};
use serde::{Deserialize, Serialize};

use super::params::{CameraParams, TrackerParams};
use crate::acquire::AcquireConfig;
use crate::config::{MAX_HYPOTHESES, MAX_LINKS, MAX_SLICES_PER_LINK, MAX_STATES};
use crate::features::MAX_LINK_EDGES;
use crate::hypotheses::{HypothesesConfig, Hypothesis};
use crate::status::Status;

/// Longest board name in [`Hello`] (bytes of UTF-8).
pub const MAX_BOARD_NAME: usize = 24;

/// Board → host.
// `Features` is ~1.5 KB and the rest are small; without an allocator there is nothing to box
// into, and a board holds one message at a time.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum BoardMessage {
    /// Sent at boot and in answer to every [`HostMessage::Reset`]: who the board is.
    Hello(Hello),
    /// The estimated hand state for one tracked frame.
    State(State),
    /// The image features measured on one frame (what a stereo host fuses).
    Features(Features),
    /// Running counters; sent every `stats_every` frames and in answer to a `Ping`.
    Stats(Stats),
    /// A frame that will not be tracked, and why.
    Dropped(Dropped),
    /// A command was carried out.
    Ack(Command),
    /// A command was refused; the board's previous settings stay in force.
    Nak(Command, Refusal),
    /// The answer to [`HostMessage::Ping`], carrying its token.
    Pong(u32),
    /// What the search of one link found, in answer to [`HostMessage::Measure`]
    /// (version 3).
    LinkEdges(LinkEdges),
    /// The end of the answer to a [`HostMessage::Measure`] (version 3).
    Measured(Measured),
    /// The hypotheses the board carries after a frame, best first: sent right after the
    /// frame's [`State`] whenever [`Configure::hypotheses`] is more than 1 (version 5).
    Hypotheses(Hypotheses),
    /// What the slices across one edge of the palm's image outline found, in answer to
    /// [`HostMessage::Measure`] when the tracker parameters ask for palm edges (version 6).
    PalmEdges(PalmEdges),
}

/// Host → board.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum HostMessage<'a> {
    /// Start afresh, estimating the `free` states: tracking from a state, or searching for
    /// the hand ([`Start`], version 4).
    Reset(Reset),
    /// The camera and the tracker parameters. Needed once before frames are tracked.
    Configure(Configure),
    /// A piece of a frame uploaded over the link.
    #[serde(borrow)]
    FrameChunk(FrameChunk<'a>),
    /// Asks for a [`BoardMessage::Stats`] and a [`BoardMessage::Pong`] with this token, sent
    /// after everything the board received before the ping has been handled.
    Ping(u32),
    /// From now on hold each complete frame for [`HostMessage::Measure`] instead of tracking
    /// it (the board forgets its tracker; a `Reset` makes it track again). Answered by
    /// `Ack(Hold)`, or `Nak(Hold, NotConfigured)` before a `Configure` (version 3).
    Hold,
    /// Search the held frame at a state and send what was found: a
    /// [`BoardMessage::LinkEdges`] per link with anything to say, a
    /// [`BoardMessage::PalmEdges`] per palm outline edge with anything to say (version 6),
    /// then [`BoardMessage::Measured`] (version 3).
    Measure(Measure),
}

/// The host commands that are answered by [`BoardMessage::Ack`] or [`BoardMessage::Nak`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Command {
    /// [`HostMessage::Reset`].
    Reset,
    /// [`HostMessage::Configure`].
    Configure,
    /// [`HostMessage::Hold`] (version 3).
    Hold,
}

/// Why a command was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Refusal {
    /// The camera is unusable (zero size, non-finite or non-positive focal length, …).
    BadCamera,
    /// A tracker parameter is out of range.
    BadParameters,
    /// The camera's frames do not fit the board's frame buffer.
    FrameTooLarge,
    /// The state has the wrong length for the model or is not finite.
    BadState,
    /// A `free` bit names no state of the model.
    BadFreeMask,
    /// `Reset` before `Configure`: the board has no camera yet.
    NotConfigured,
}

/// Fixed capacities of the board, so a host can stay within them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Capacities {
    /// States of the model (28 for the whole hand).
    pub states: u8,
    /// Most states a message can carry ([`MAX_STATES`]).
    pub max_states: u8,
    /// Most model links, the rows of a model ([`MAX_LINKS`]). Was `max_frames`: the same
    /// position in the encoding, so the rename changed no byte.
    pub max_links: u8,
    /// Largest frame the board's buffer holds (bytes = width × height).
    pub max_frame_bytes: u32,
    /// Largest `FrameChunk` payload (bytes).
    pub max_chunk: u16,
    /// Largest encoded message the board can receive (bytes, delimiters included).
    pub max_message: u16,
}

/// Who the board is.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Hello {
    /// The board's [`PROTOCOL_VERSION`](super::PROTOCOL_VERSION); a host refuses others.
    pub version: u8,
    /// e.g. `qemu-m7`, `linux`.
    pub board: String<MAX_BOARD_NAME>,
    /// [`model_digest`](super::model_digest) of the board's model.
    pub model_digest: u32,
    /// Ticks per second of the board clock used in [`State::timestamp`] and
    /// [`State::track_ticks`].
    pub clock_hz: u32,
    /// The board's fixed capacities.
    pub capacities: Capacities,
}

/// The estimated hand state for one frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct State {
    /// The frame number given by the frame's source.
    pub frame: u32,
    /// Board clock (ticks of [`Hello::clock_hz`]) when the frame was complete.
    pub timestamp: u64,
    /// The state after tracking: every model state (quaternion, mm, rad).
    pub q: Vec<f32, MAX_STATES>,
    /// Residual RMS of the last iteration (px).
    pub rms_px: f32,
    /// The tracker does not trust this state.
    pub lost: bool,
    /// Features found in the last iteration.
    pub features_found: u16,
    /// Features expected in the last iteration.
    pub features_expected: u16,
    /// Gauss–Newton iterations run.
    pub iterations: u8,
    /// Board clock ticks spent tracking this frame.
    pub track_ticks: u32,
    /// What the board claims of this frame (version 4): only [`WireStatus::Tracking`] claims
    /// a hand; `lost` is true whenever the status is not `Tracking`.
    pub status: WireStatus,
    /// The search's work on this frame, in evaluations (one hypothesis scored counts 1; see
    /// `acquire::AcquireConfig::evaluations_per_frame`): 0 on a tracking frame (version 4).
    pub search_evaluations: u16,
}

/// The tracker's status after a frame, as it crosses the link (version 4): a wire type of
/// its own, converted to and from [`Status`], so the core's type can change without changing
/// the protocol.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WireStatus {
    /// No hand claimed: the board searches for it.
    Searching,
    /// The hand is tracked.
    Tracking,
    /// The hand was tracked and this frame lost it (the last good state is held).
    Lost,
}

impl From<Status> for WireStatus {
    fn from(status: Status) -> Self {
        match status {
            Status::Searching => WireStatus::Searching,
            Status::Tracking => WireStatus::Tracking,
            Status::Lost => WireStatus::Lost,
        }
    }
}

impl From<WireStatus> for Status {
    fn from(status: WireStatus) -> Self {
        match status {
            WireStatus::Searching => Status::Searching,
            WireStatus::Tracking => Status::Tracking,
            WireStatus::Lost => Status::Lost,
        }
    }
}

/// A measured axis line in the image: a point on it and its unit direction (px).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AxisLine {
    /// A point on the line (px).
    pub point: [f32; 2],
    /// Unit direction (from the link's base towards its tip).
    pub direction: [f32; 2],
}

/// What was measured for one link.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LinkMeasurement {
    /// Index of the model frame (link).
    pub link: u8,
    /// The link's measured axis, when enough edges were found.
    pub axis: Option<AxisLine>,
    /// The measured fingertip (px), for tip links.
    pub tip: Option<[f32; 2]>,
}

/// The features of one frame of one camera.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Features {
    /// The frame number.
    pub frame: u32,
    /// The camera (its index on the host; a board tracks one camera).
    pub camera: u8,
    /// One entry per link that was measured.
    pub links: Vec<LinkMeasurement, MAX_LINKS>,
}

/// Frames that were not tracked, by reason.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DropCounts {
    /// A chunk went missing (a gap in the offsets): see [`DropReason::Incomplete`].
    pub incomplete: u32,
    /// Not the configured camera's size.
    pub wrong_size: u32,
    /// Larger than the board's frame buffer.
    pub too_large: u32,
    /// Arrived before `Configure` and `Reset`.
    pub not_ready: u32,
    /// A newer frame began before this one was complete.
    pub superseded: u32,
    /// The tracker refused the frame.
    pub tracker_error: u32,
}

impl DropCounts {
    /// Counts one frame dropped for `reason` (saturating).
    pub fn record(&mut self, reason: &DropReason) {
        let counter = match reason {
            DropReason::Incomplete => &mut self.incomplete,
            DropReason::WrongSize(..) => &mut self.wrong_size,
            DropReason::TooLarge => &mut self.too_large,
            DropReason::NotReady => &mut self.not_ready,
            DropReason::Superseded => &mut self.superseded,
            DropReason::TrackerError => &mut self.tracker_error,
        };
        *counter = counter.saturating_add(1);
    }

    /// Frames dropped for any reason (saturating).
    pub fn total(&self) -> u32 {
        [
            self.incomplete,
            self.wrong_size,
            self.too_large,
            self.not_ready,
            self.superseded,
            self.tracker_error,
        ]
        .iter()
        .fold(0u32, |sum, n| sum.saturating_add(*n))
    }
}

/// Link error counters of one receiver.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LinkCounters {
    /// Messages decoded.
    pub messages: u32,
    /// Frames whose CRC-32 did not match.
    pub crc_errors: u32,
    /// Frames that were not valid COBS.
    pub framing_errors: u32,
    /// Frames with a good CRC that did not decode as a message (a newer protocol?).
    pub decode_errors: u32,
    /// Frames longer than the receive buffer.
    pub overflows: u32,
}

/// The board's running counters since boot.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Stats {
    /// Frames tracked.
    pub frames: u32,
    /// Gauss–Newton iterations run, in all.
    pub iterations: u32,
    /// Tracked frames reported `lost`.
    pub lost: u32,
    /// Frames not tracked, by reason.
    pub dropped: DropCounts,
    /// Frames rejected as malformed (wrong size, too large, chunk beyond the frame).
    pub bad_frames: u32,
    /// The board's receiver.
    pub link: LinkCounters,
    /// Capacity overflows: a message too large for the transmit buffer, features truncated.
    pub capacity_overflows: u32,
    /// `FrameChunk`s ignored because their frame number was below the frame under way (an
    /// older frame, or one already answered): never answered again (protocol version 2).
    pub stale_chunks: u32,
}

/// Why a frame was not tracked.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DropReason {
    /// A chunk went missing: the next chunk did not start where the last one ended.
    Incomplete,
    /// The frame is not the configured camera's size (its width and height).
    WrongSize(u16, u16),
    /// The frame is larger than the board's frame buffer, or a chunk runs past its end.
    TooLarge,
    /// The board had no camera (`Configure`) or no state (`Reset`) yet.
    NotReady,
    /// A chunk of a newer frame arrived before this one was complete.
    Superseded,
    /// The tracker refused the frame.
    TrackerError,
}

/// A frame that will not be tracked.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Dropped {
    /// The frame number.
    pub frame: u32,
    /// Why.
    pub reason: DropReason,
}

/// Start afresh: tracking from a given state, or searching for the hand.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Reset {
    /// Every model state (quaternion, mm, rad).
    pub q: Vec<f32, MAX_STATES>,
    /// Bit `i` set: state `i` is estimated; the others stay as given. Naming any quaternion
    /// state frees all four.
    pub free: u32,
    /// Where to start (version 4): from `q`, or by searching for the free states.
    pub start: Start,
}

/// How a [`Reset`] starts the board (version 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Start {
    /// Track from the given state (the status starts `Tracking`).
    Given,
    /// Search for the hand (the status starts `Searching`): the free states' given values
    /// are ignored, the fixed states keep theirs.
    Search,
}

/// The camera and how to track.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Configure {
    /// The board's camera (frames must be its size).
    pub camera: CameraParams,
    /// Tracker parameters.
    pub tracker: TrackerParams,
    /// Send [`BoardMessage::Features`] every this many frames (0: never).
    pub features_every: u16,
    /// Send [`BoardMessage::Stats`] every this many frames (0: only when pinged).
    pub stats_every: u16,
    /// The search's budget per frame and camera, in evaluations, at least 1 (version 4;
    /// `acquire`'s `AcquireConfig::evaluations_per_frame`; default
    /// [`default_search_evaluations`]): a searching board answers every frame after at most
    /// this much search work (and the one hypothesis under way).
    pub search_evaluations_per_frame: u16,
    /// The hypotheses the tracker carries and what they may cost (versions 5, 9 and 10; on
    /// the wire, its fields in order, as if they were `Configure`'s own).
    pub hypotheses: HypothesesParams,
}

/// How many hypotheses a board's tracker carries and what the ones other than the best may
/// cost: the part of [`hypotheses::HypothesesConfig`](HypothesesConfig) a host chooses. Its
/// [`Default`] is the tracker's own.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HypothesesParams {
    /// Hypotheses carried between frames, 1..=[`MAX_HYPOTHESES`] (version 5;
    /// `HypothesesConfig::count`): 1 is the single tracker, bit for bit; more make the board
    /// send [`BoardMessage::Hypotheses`] after every `State`. 0 or more than
    /// [`MAX_HYPOTHESES`] is refused (`Nak(Configure, BadParameters)`).
    pub count: u8,
    /// With more than one hypothesis, they are scored, sampled around and merged on one frame
    /// in this many, at least 1 (version 9; `HypothesesConfig::score_every_frames`; default
    /// every frame): the rest of K > 1's cost is paid on those frames only, so a board can keep
    /// its frame rate with K = 2 (docs/hypotheses.md, "Scoring one frame in S"). 0 is refused
    /// (`Nak(Configure, BadParameters)`); with one hypothesis it changes nothing.
    pub score_every: u8,
    /// Gauss–Newton iterations at most for each new sample on the frame it is drawn (version
    /// 10; `HypothesesConfig::sample_iterations`; 0, the default: the tracker's own number, as
    /// is any number at or above it). With one hypothesis it changes nothing.
    pub sample_iterations: u8,
    /// Gauss–Newton iterations at most for each carried hypothesis other than the best
    /// (version 10; `HypothesesConfig::other_iterations`; 0, the default: the tracker's own).
    /// The best always takes the tracker's own number. With both caps at 2, K = 4 scored one
    /// frame in 4 costs a 480 MHz M7 about 23 ms a frame on the mean (docs/hypotheses.md,
    /// "Fewer iterations for the hypotheses other than the best").
    pub other_iterations: u8,
    /// Whether each scored frame also weighs the best with each finger's update undone and
    /// with every finger's undone (version 10; `HypothesesConfig::keep_fingers`; default true).
    /// Off saves up to six candidates' scores a scored frame (docs/hypotheses.md, "Two
    /// hypotheses within a board's frame budget").
    pub keep_fingers: bool,
}

impl Default for HypothesesParams {
    fn default() -> Self {
        let own = HypothesesConfig::default();
        HypothesesParams {
            count: own.count,
            score_every: own.score_every_frames.max(1),
            sample_iterations: own.sample_iterations,
            other_iterations: own.other_iterations,
            keep_fingers: own.keep_fingers,
        }
    }
}

impl HypothesesParams {
    /// Whether a board takes these: a count in 1..=[`MAX_HYPOTHESES`] and a scoring period of
    /// at least 1 (the caps take any value).
    pub fn is_valid(&self) -> bool {
        hypotheses_in_range(self.count) && self.score_every >= 1
    }

    /// `base` with these parameters in place of its own (the rest of `base` kept).
    pub fn over(&self, base: HypothesesConfig) -> HypothesesConfig {
        HypothesesConfig {
            count: self.count,
            score_every_frames: self.score_every,
            sample_iterations: self.sample_iterations,
            other_iterations: self.other_iterations,
            keep_fingers: self.keep_fingers,
            ..base
        }
    }
}

impl Configure {
    /// `camera` tracked under `tracker`, everything else as a host sends it by default: no
    /// `Features` or `Stats` unasked, the search's budget, the tracker's own hypotheses (count,
    /// scoring period, caps and finger-undo). Name the rest with struct update syntax.
    pub fn new(camera: CameraParams, tracker: TrackerParams) -> Self {
        Configure {
            camera,
            tracker,
            features_every: 0,
            stats_every: 0,
            search_evaluations_per_frame: default_search_evaluations(),
            hypotheses: HypothesesParams::default(),
        }
    }
}

/// The search budget per frame a host sends by default: the search's own default.
pub fn default_search_evaluations() -> u16 {
    AcquireConfig::default().evaluations_per_frame
}

/// Whether `count` is a hypothesis count a board takes: 1..=[`MAX_HYPOTHESES`].
pub fn hypotheses_in_range(count: u8) -> bool {
    (1..=MAX_HYPOTHESES).contains(&usize::from(count))
}

/// A piece of an 8-bit grey frame, rows top to bottom, packed (stride = width).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct FrameChunk<'a> {
    /// The frame number; all chunks of a frame carry the same one.
    pub frame: u32,
    /// Frame width (px).
    pub width: u16,
    /// Frame height (px).
    pub height: u16,
    /// Byte offset of `data` in the frame; chunks arrive in order, without gaps.
    pub offset: u32,
    /// The bytes (at most [`MAX_CHUNK`](super::MAX_CHUNK)).
    pub data: &'a [u8],
}

/// Search the held frame `frame` at state `q` (one iteration of a stereo host's loop).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Measure {
    /// The frame to search: the last one uploaded and complete.
    pub frame: u32,
    /// The iteration of the host's loop on this frame, from 0: the first searches with the
    /// configured windows, later ones narrow each link's window to what its last search on
    /// this frame needed. Echoed in the answer, so a late answer is never taken for another.
    pub iteration: u8,
    /// The state to search at: every model state (quaternion, mm, rad).
    pub q: Vec<f32, MAX_STATES>,
}

/// One silhouette edge point found on a slice (a [`features::EdgePoint`](crate::features::EdgePoint)
/// without its strength, which no estimate uses).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WireEdge {
    /// Where the slice crosses the axis, as a fraction of the axis from its base to its tip.
    pub s: f32,
    /// The side of the axis: +1 or −1.
    pub side: i8,
    /// The edge in the image (px).
    pub position: [f32; 2],
}

/// What the search of one link found (its `LinkFeatures`, as the in-process tracker uses
/// them), in answer to a [`Measure`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LinkEdges {
    /// The frame searched.
    pub frame: u32,
    /// The [`Measure::iteration`] answered.
    pub iteration: u8,
    /// The link's place among the links in view at the measured state (table order).
    pub index: u8,
    /// The model frame (link) it is.
    pub link: u8,
    /// The edge points found, in search order.
    pub edges: Vec<WireEdge, MAX_LINK_EDGES>,
    /// The fingertip found (px), for a distal link.
    pub tip: Option<[f32; 2]>,
    /// Edges and tips the model predicted visible and in the frame.
    pub expected: u16,
    /// Predicted edges and tips hidden by a nearer part of the hand.
    pub masked: u16,
}

/// What the slices across one edge of the palm box's image outline found (the features the
/// in-process tracker uses for it), in answer to a [`Measure`] (version 6). The edge is named
/// by the two box corners it joins (`palm_outline::HullEdge::corners`): the host computes the
/// same outline at the same state and looks the edge up by them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PalmEdges {
    /// The frame searched.
    pub frame: u32,
    /// The [`Measure::iteration`] answered.
    pub iteration: u8,
    /// The box corners the outline edge joins, in outline order (each 0–7).
    pub corners: [u8; 2],
    /// The edge points found, in search order (`s` along the edge from `corners[0]`, `side`
    /// the edge's outward side).
    pub edges: Vec<WireEdge, MAX_SLICES_PER_LINK>,
    /// Slices the model predicted visible and in the frame.
    pub expected: u16,
    /// Slices masked: hidden by a nearer link, or with a link just outside the edge.
    pub masked: u16,
}

/// The end of an answer to a [`Measure`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Measured {
    /// The frame asked for.
    pub frame: u32,
    /// The [`Measure::iteration`] answered.
    pub iteration: u8,
    /// Whether the board holds that frame; `false`: nothing was searched.
    pub held: bool,
    /// [`LinkEdges`] and [`PalmEdges`] messages sent for this measure.
    pub links: u8,
    /// The silhouette agreement at the measured state (0..=1), when the tracker parameters
    /// ask for it (`silhouette_grid` > 0) and it can be scored.
    pub silhouette: Option<f32>,
}

/// One hypothesis the board carries (version 5).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WireHypothesis {
    /// Its likelihood score on the frame, less the lost penalty (likelihood units, at most 1;
    /// `hypotheses::Hypothesis::score`).
    pub score: f32,
    /// Frames it has been carried (0: sampled on this frame).
    pub age: u32,
    /// Its state: every model state (quaternion, mm, rad).
    pub q: Vec<f32, MAX_STATES>,
}

impl From<&Hypothesis> for WireHypothesis {
    fn from(h: &Hypothesis) -> Self {
        WireHypothesis {
            score: h.score,
            age: h.age,
            q: h.memory.state.clone(),
        }
    }
}

/// The hypotheses carried after one frame, best first (version 5): the first is the `State`'s
/// `q`. Empty on a frame whose status is `Searching` (no hand is claimed, so none is carried).
/// At most [`MAX_HYPOTHESES`] × [`MAX_STATES`] states: 1,122 bytes encoded at most, within
/// [`MAX_MESSAGE`](super::MAX_MESSAGE).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Hypotheses {
    /// The frame, as in its `State`.
    pub frame: u32,
    /// Best first.
    pub hypotheses: Vec<WireHypothesis, MAX_HYPOTHESES>,
}
