//! The tracker that finds the hand itself: the [`Status`] machine around the anytime
//! [search](crate::acquire) and the Gauss–Newton [tracker](crate::tracker) (issue 10).
//!
//! - **Searching**: each frame moves the [`Finder`] on within its budget: the search places
//!   and scores hypotheses; when it is over, its best leaves are refined by the tracker's
//!   Gauss–Newton on the frames that follow and judged by the likelihood in every camera
//!   ([`AcceptConfig`]); an accepted leaf is taken for the hand — claimed from the next
//!   frame, if that frame confirms it ([`FinderConfig::probation_max_drop`]), and with one
//!   camera not while the confirm phase still weighs two depths alike
//!   ([`FinderConfig::confirm_rival_margin`]) — and when every leaf is refused the search
//!   starts over. With one camera, a refused leaf that
//!   scored at least [`FinderConfig::pursue_score`] is *pursued*: refined again and judged on
//!   each of the next [`FinderConfig::pursue_frames`] searching frames ([`PURSUIT_PASSES`]
//!   tracker pass a frame), beside the search, which spends [`PURSUIT_EVALUATIONS_PER_CAMERA`]
//!   less of its budget on those frames.
//! - **Tracking**: the tracker runs — one hypothesis, or several ([`MultiTracker`], set by
//!   [`AutoTracker::set_hypotheses`]); a lost frame makes the status [`Status::Lost`]. Every
//!   few frames (eight at 320×240) the [watch](crate::watch) scores the tracked state by the likelihood in every
//!   camera; a state some camera does not support is a lost frame too, and is checked again
//!   on every frame until a check passes (not with [`Recovery::Never`], the plain tracker).
//! - **Lost**: the tracker still runs (holding its last good state); a frame not lost makes it
//!   `Tracking` again, [`LOST_FRAMES_BEFORE_SEARCH`] lost frames in a row make it `Searching`
//!   (unless [`Recovery::Never`]: then it stays `Lost`, as the plain tracker does).
//! - **Searching after a loss** first tries a *local re-acquisition* for
//!   [`LOCAL_SEARCH_FRAMES`] frames (the hand does not go far while it is hidden for a second
//!   or two): each frame, a variant of the last good state is slid over the first camera's
//!   edge map within [`LOCAL_WINDOW`] of the frame's width of where it projects
//!   ([`Acquirer::place`]) and placed on the bright regions ([`Acquirer::replace`]), its palm
//!   is given the library's finger pose that scores best ([`Acquirer::best_pose`]), and the
//!   last frame's best is followed; at most [`FinderConfig::local_starts`] of these are
//!   refined by the tracker's Gauss–Newton ([`LOCAL_REFINE_PASSES`] passes on the frame), and
//!   the best taken for the hand if the search's acceptance test takes it. The work per frame
//!   is bounded: one slide, one placement, the library's poses scored once, and
//!   `local_starts` × [`LOCAL_REFINE_PASSES`] tracker passes. Only then does the global
//!   search run — or, with two or more cameras, sooner, once
//!   [`FinderConfig::local_frames_in_view`] local frames have refined a start (the hand is
//!   back in view) without accepting any.
//! - While searching (and on the frames an acquisition is not yet claimed),
//!   [`AutoTracker::state`] holds the last state that claimed the hand (the base state before
//!   the first acquisition), never a refused hypothesis.
//!
//! The edge maps the search (and several hypotheses) need live in the caller's buffers, one
//! per camera, of [`AutoTracker::edge_bytes_needed`] bytes; only searching frames, and
//! tracking frames with several hypotheses, build them.

use core::fmt;

use heapless::Vec;

use crate::acquire::{
    AcceptConfig, AcquireConfig, Acquirer, Finder, FinderConfig, FinderStep, LeafScore,
    WorkingVolume, DEPTH_VARIANTS, HELD_VARIANTS, LOCAL_VARIANTS, MAX_KEEP,
};
use crate::camera::{palm_depth_mm, Camera};
use crate::config::{MAX_CAMERAS, MAX_HYPOTHESES, MAX_STATES};
use crate::estimator::FreeMask;
use crate::frame::FrameView;
use crate::hypotheses::fingers::Fingers;
use crate::hypotheses::{DepthAnchor, HypothesesConfig, Hypothesis, MultiReport, MultiTracker};
use crate::likelihood::{BuiltEdges, EdgeMap, LikelihoodConfig, LikelihoodError, Reads, Scene};
use crate::model::Model;
use crate::motion::PriorWeights;
pub use crate::status::Status;
use crate::tracker::{FrameReport, TrackMemory, Tracker, TrackerConfig, TrackerError};
use crate::watch::{Watch, WatchConfig};

/// Lost frames in a row after which the tracker gives the hand up and searches again.
pub const LOST_FRAMES_BEFORE_SEARCH: u32 = 10;

/// Searching frames after a loss spent on the local re-acquisition before the global search,
/// at most: two seconds at 30 frames/s, after the [`LOST_FRAMES_BEFORE_SEARCH`] lost frames
/// (fewer when the hand is back in view and not taken: [`FinderConfig::local_frames_in_view`]).
pub const LOCAL_SEARCH_FRAMES: u32 = 60;

/// Half the side of the window the local re-acquisition slides the last good state over, as a
/// share of the frame's width (0.25: ±80 px at 320×240).
pub const LOCAL_WINDOW: f32 = 0.25;

/// Gauss–Newton passes (each a whole tracker frame, restarted fresh) over a placed state in
/// the local re-acquisition.
pub const LOCAL_REFINE_PASSES: u32 = 2;

/// Tracker passes a pursued leaf is refined by on a frame ([`FinderConfig::pursue_frames`]).
pub const PURSUIT_PASSES: u32 = 1;

/// What pursuing a refused leaf on a frame ([`PURSUIT_PASSES`] tracker passes and a score)
/// costs against the search's budget, in evaluations per camera: a tracker pass costs about
/// as much as 16 of the search's scores.
pub const PURSUIT_EVALUATIONS_PER_CAMERA: u16 = 20;

/// A refined local hypothesis scoring at least this (but under the acceptance score) is
/// followed to the next frame, where it is refined again: a hand half back in view, or moved
/// far from the last good state, is then closed in on over a few frames.
pub const LOCAL_FOLLOW_SCORE: f32 = 0.8;

/// [`Acquirer::variant`]'s palm moved farther from the first camera.
const DEPTH_FARTHER: u32 = 7;
/// [`Acquirer::variant`]'s palm moved nearer to the first camera.
const DEPTH_NEARER: u32 = 8;

/// What the tracker does once the hand has been lost for [`LOST_FRAMES_BEFORE_SEARCH`] frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Recovery {
    /// Search again: first locally around the last good state, then globally.
    #[default]
    Search,
    /// Never search: stay [`Status::Lost`] and keep tracking, as the plain tracker does.
    Never,
}

/// Depth (mm) along a camera's axis of the default working volume when no camera sees the
/// world origin.
pub const FALLBACK_DEPTH_MM: f32 = 600.0;

/// Why a frame could not be used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum AutoError {
    /// The tracker refused the frames or a state.
    Tracker(TrackerError),
    /// An edge map could not be built (e.g. a buffer too small).
    EdgeMap(LikelihoodError),
    /// Fewer edge-map buffers than cameras.
    BufferCount,
}

impl fmt::Display for AutoError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Tracker(e) => write!(f, "tracker: {e}"),
            Self::EdgeMap(e) => write!(f, "edge map: {e}"),
            Self::BufferCount => f.write_str("one edge-map buffer per camera is needed"),
        }
    }
}

impl core::error::Error for AutoError {}

impl From<TrackerError> for AutoError {
    fn from(e: TrackerError) -> Self {
        AutoError::Tracker(e)
    }
}

/// One frame's outcome.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AutoReport {
    /// The status after this frame.
    pub status: Status,
    /// The tracker's report (`lost` set whenever no hand is claimed).
    pub report: FrameReport,
    /// Hypotheses the search scored on this frame.
    pub evaluated: u16,
    /// The mean likelihood score of the best leaf (or local hypothesis) refined on this
    /// frame, accepted or not.
    pub leaf_score: Option<f32>,
    /// The frame was spent on the local re-acquisition around the last good state.
    pub local: bool,
    /// A leaf (or local start) was accepted on this frame: the hand is claimed on it, or on
    /// [probation](FinderConfig::probation_max_drop) once the next frame confirms it.
    pub accepted: bool,
    /// Hypotheses carried to the next frame (1 with a single hypothesis and while searching).
    pub hypotheses: u8,
    /// The best hypothesis' likelihood score on a tracking frame with several hypotheses
    /// (0 otherwise).
    pub best_score: f32,
    /// The best hypothesis is not the previous frame's best (a tracking frame with several
    /// hypotheses whose ranking changed; false otherwise).
    pub switched: bool,
    /// The tracked state's likelihood score in its worst camera, on a frame the
    /// [watch](crate::watch) checked (a score under its bar made the frame lost).
    pub watch_score: Option<f32>,
}

impl AutoReport {
    /// The report of a frame the tracker ran on (tracking, lost, or refuted): `report` for
    /// the status `status`, with the hypotheses' figures from `multi`.
    fn tracked(
        status: Status,
        report: FrameReport,
        multi: &MultiReport,
        watch_score: Option<f32>,
    ) -> Self {
        AutoReport {
            status,
            report,
            hypotheses: multi.count,
            best_score: multi.score,
            switched: multi.switched,
            watch_score,
            ..AutoReport::default()
        }
    }
}

/// A leaf accepted on the last frame and not yet claimed
/// ([`FinderConfig::probation_max_drop`]): what the frame after it is judged against.
#[derive(Debug, Clone, Copy)]
struct Probation {
    /// The accepted leaf's worst camera's likelihood score.
    worst_camera: f32,
    /// Local re-acquisition frames that were left, gone on with if the next frame refutes it.
    local_left: u32,
}

/// A hypothesis refined on this frame: its state, its mean and worst camera's likelihood
/// score (and reverse term, when the acceptance asks for it), and the tracker's report of
/// its last pass.
#[derive(Clone, Copy)]
struct Refined {
    score: f32,
    worst_camera: f32,
    reverse_px: Option<f32>,
    q: [f32; MAX_STATES],
    report: FrameReport,
}

impl Refined {
    /// What the acceptance reads of it.
    fn leaf(&self) -> LeafScore {
        LeafScore {
            score: self.score,
            worst_camera: self.worst_camera,
            reverse_px: self.reverse_px,
        }
    }
}

/// Where a start of the local re-acquisition comes from.
#[derive(Clone, Copy)]
enum LocalStart {
    /// The best refined start of the last frame.
    Followed,
    /// The last good palm with the library's best finger pose
    /// ([`FinderConfig::local_library_pose`]).
    Library,
    /// The variant slid over the first camera's edge map ([`Acquirer::place`]).
    Slid,
    /// The variant placed on the bright regions ([`Acquirer::replace`]).
    Placed,
}

/// `state` (one value per model state) in a whole state's array, the rest 0.
fn padded(state: &[f32]) -> [f32; MAX_STATES] {
    let mut q = [0.0f32; MAX_STATES];
    for (d, s) in q.iter_mut().zip(state) {
        *d = *s;
    }
    q
}

/// One edge map per camera, with its bright region, for the search: `frames[i]`'s, built
/// into `edge_buffers[i]`.
fn edge_maps<'b>(
    edge_buffers: &'b mut [&mut [u8]],
    frames: &[FrameView<'_>],
    likelihood: &LikelihoodConfig,
) -> Result<Vec<EdgeMap<'b>, MAX_CAMERAS>, AutoError> {
    if edge_buffers.len() < frames.len() {
        return Err(AutoError::BufferCount);
    }
    let mut maps = Vec::new();
    for (buffer, frame) in edge_buffers.iter_mut().zip(frames) {
        let map = EdgeMap::build(buffer, frame, likelihood).map_err(AutoError::EdgeMap)?;
        if maps.push(map).is_err() {
            return Err(AutoError::Tracker(TrackerError::CameraCount));
        }
    }
    Ok(maps)
}

/// One edge map per camera for a score that reads camera `i`'s as `reads[i]` says, without
/// the bright region a score never reads ([`EdgeMap::build_edges_for`]): the maps `built` on
/// this frame already ([`MultiTracker::take_built_edges`]: `edge_buffers` untouched since)
/// opened again instead of built a second time, when they are one per camera, of these
/// frames' sizes under `likelihood`, and cover those reads.
fn reopened_edge_maps<'b>(
    edge_buffers: &'b mut [&mut [u8]],
    frames: &[FrameView<'_>],
    likelihood: &LikelihoodConfig,
    built: &[BuiltEdges],
    reads: &[Reads; MAX_CAMERAS],
) -> Result<Vec<EdgeMap<'b>, MAX_CAMERAS>, AutoError> {
    if edge_buffers.len() < frames.len() {
        return Err(AutoError::BufferCount);
    }
    let reuse = built.len() == frames.len()
        && built
            .iter()
            .zip(frames)
            .zip(reads)
            .all(|((b, frame), r)| b.fits(frame, likelihood) && b.covers(r, likelihood));
    let mut maps = Vec::new();
    for (k, ((buffer, frame), r)) in edge_buffers.iter_mut().zip(frames).zip(reads).enumerate() {
        let map = match built.get(k) {
            Some(b) if reuse => EdgeMap::reopen(buffer, *b),
            _ => EdgeMap::build_edges_for(buffer, frame, likelihood, *r),
        }
        .map_err(AutoError::EdgeMap)?;
        if maps.push(map).is_err() {
            return Err(AutoError::Tracker(TrackerError::CameraCount));
        }
    }
    Ok(maps)
}

/// A tracker that finds the hand, tracks it, and finds it again.
#[derive(Debug, Clone)]
pub struct AutoTracker {
    multi: MultiTracker,
    finder: Finder,
    status: Status,
    lost_run: u32,
    /// The state of the last frame that claimed the hand (the base before any).
    held: [f32; MAX_STATES],
    /// Whether `held` is a tracked state (else the base).
    ever_tracked: bool,
    /// Searching frames of local re-acquisition left before the global search.
    local_left: u32,
    /// The best refined local hypothesis of the last frame, when it scored at least
    /// [`LOCAL_FOLLOW_SCORE`]: refined again on the next.
    following: Option<[f32; MAX_STATES]>,
    /// A refused leaf of the global search still pursued, the searching frames left
    /// ([`FinderConfig::pursue_frames`]) and its last score.
    pursued: Option<([f32; MAX_STATES], u8, f32)>,
    /// Local re-acquisition frames since the loss on which a start was refined without being
    /// lost (the hand is back in view) but none was accepted.
    local_in_view: u32,
    recovery: Recovery,
    /// The image's check on the track.
    watch: Watch,
    /// The state at the last check the track passed (or at its start).
    vouched: heapless::Vec<f32, MAX_STATES>,
    /// The hypotheses' parameters as configured ([`AutoTracker::set_hypotheses`]); while
    /// confirming an acquisition the tracker carries more.
    hypotheses: HypothesesConfig,
    /// Tracking frames left in which the search's other leaves are carried as hypotheses
    /// beside the accepted one ([`FinderConfig::confirm_frames`]).
    confirm_left: u32,
    /// Frames left that the tracker runs without its prior on the palm's position, after an
    /// acquisition ([`FinderConfig::settle_frames`]).
    settle_left: u32,
    /// The best hypothesis' scores summed over the confirming frames so far, and how many.
    confirm_scores: (f32, u32),
    /// Confirm phases still to end in a polish of the fingers
    /// ([`FinderConfig::polish_margin`]).
    polish_left: u8,
    /// A leaf accepted on the last frame, claimed only if this frame confirms it.
    probation: Option<Probation>,
    /// While a confirm phase carries depth variants: how far apart (mm) two hypotheses' palms
    /// must lie in depth to be rival readings of it ([`FinderConfig::confirm_rival_share`]).
    rival_depth_mm: Option<f32>,
    /// On the last frame a rival scored within [`FinderConfig::confirm_rival_margin`] of the
    /// best: not claimed.
    undecided: bool,
}

impl AutoTracker {
    /// A tracker for `model` seen by `cameras`, starting by searching: the states in `free`
    /// are searched for, the others kept at `base` (one value per model state).
    pub fn new(
        model: Model,
        cameras: &[Camera],
        base: &[f32],
        free: FreeMask,
        config: TrackerConfig,
        acquire: AcquireConfig,
    ) -> Result<Self, AutoError> {
        AutoTracker::started(
            model,
            cameras,
            base,
            free,
            config,
            acquire,
            Status::Searching,
        )
    }

    /// A tracker for `model` seen by `cameras` that starts by tracking from `initial` (a known
    /// state of the first frame), and searches only once the hand is lost.
    pub fn tracking(
        model: Model,
        cameras: &[Camera],
        initial: &[f32],
        free: FreeMask,
        config: TrackerConfig,
        acquire: AcquireConfig,
    ) -> Result<Self, AutoError> {
        AutoTracker::started(
            model,
            cameras,
            initial,
            free,
            config,
            acquire,
            Status::Tracking,
        )
    }

    /// [`AutoTracker::new`] (`status` searching) or [`AutoTracker::tracking`] (tracking from
    /// `base`), built once and returned without a further copy: the value is tens of KB, and
    /// a small board pays every copy in stack.
    fn started(
        model: Model,
        cameras: &[Camera],
        base: &[f32],
        free: FreeMask,
        config: TrackerConfig,
        acquire: AcquireConfig,
        status: Status,
    ) -> Result<Self, AutoError> {
        let start = Tracker::checked_start(&model, cameras, base, free)?;
        let volume = WorkingVolume::from_cameras(cameras, FALLBACK_DEPTH_MM);
        let acquirer = Acquirer::new(&model, base, start.free, volume, acquire);
        let held = padded(&start.state);
        // A fresh tracker's memory: its start state, no motion, no silhouette reference.
        let memory = TrackMemory {
            state: start.state.clone(),
            velocity: None,
            silhouette_reference: None,
        };
        let fingers = Fingers::of(&model);
        let tracking = status == Status::Tracking;
        let vouched = if tracking {
            start.state.clone()
        } else {
            heapless::Vec::new()
        };
        Ok(AutoTracker {
            multi: MultiTracker::around(
                Tracker::started(model, start, config),
                memory,
                fingers,
                HypothesesConfig::default(),
            ),
            finder: Finder::new(acquirer, FinderConfig::default()),
            status,
            lost_run: 0,
            held,
            ever_tracked: tracking,
            local_left: 0,
            following: None,
            pursued: None,
            local_in_view: 0,
            recovery: Recovery::Search,
            watch: Watch::new(WatchConfig::default()),
            vouched,
            hypotheses: HypothesesConfig::default(),
            confirm_left: 0,
            settle_left: 0,
            confirm_scores: (0.0, 0),
            polish_left: 0,
            probation: None,
            rival_depth_mm: None,
            undecided: false,
        })
    }

    /// Bytes of edge-map buffer camera `camera` needs.
    pub fn edge_bytes_needed(camera: &Camera, acquire: &AcquireConfig) -> usize {
        EdgeMap::bytes_needed(
            camera.width as usize,
            camera.height as usize,
            acquire.likelihood.stride_px,
        )
    }

    /// Sets the thresholds a refined leaf (or local hypothesis) must reach to be taken for
    /// the hand.
    pub fn set_accept(&mut self, accept: AcceptConfig) {
        self.finder.set_accept(accept);
    }

    /// Sets how the search's leaves are refined and judged (its acceptance thresholds
    /// included).
    pub fn set_finder(&mut self, config: FinderConfig) {
        self.finder.set_config(config);
    }

    /// The acceptance thresholds.
    pub fn accept(&self) -> AcceptConfig {
        self.finder.config().accept
    }

    /// Sets how the image checks the track ([`crate::watch`]; `every_frames` 0: never).
    pub fn set_watch(&mut self, config: WatchConfig) {
        self.watch = Watch::new(config);
    }

    /// Sets what happens once the hand is lost for [`LOST_FRAMES_BEFORE_SEARCH`] frames.
    pub fn set_recovery(&mut self, recovery: Recovery) {
        self.recovery = recovery;
    }

    /// Sets how many hypotheses are tracked (one: the single tracker, bit for bit). Their
    /// likelihood uses the search's edge-map buffers, so its stride must be the search's.
    pub fn set_hypotheses(&mut self, config: HypothesesConfig) {
        self.hypotheses = config;
        if self.confirm_left == 0 {
            self.multi.set_config(config);
        }
    }

    /// The hypotheses carried while tracking, best first (the last frame's).
    pub fn hypotheses(&self) -> &[Hypothesis] {
        self.multi.hypotheses()
    }

    /// The state to report for the last frame: the tracker's while tracking or lost; while
    /// searching, the last state that claimed the hand (the base before the first
    /// acquisition), never a hypothesis under test (nor one accepted and not yet confirmed).
    pub fn state(&self) -> &[f32] {
        let tracker = self.multi.tracker();
        match self.status() {
            Status::Searching => &self.held[..tracker.state().len().min(MAX_STATES)],
            Status::Tracking | Status::Lost => tracker.state(),
        }
    }

    /// The status after the last frame (searching while an accepted leaf awaits the next
    /// frame's confirmation, and while a confirm phase's best is
    /// [undecided in depth](FinderConfig::confirm_rival_margin)).
    pub fn status(&self) -> Status {
        if self.probation.is_some() || self.undecided {
            Status::Searching
        } else {
            self.status
        }
    }

    /// The tracker (its model, cameras, free states).
    pub fn tracker(&self) -> &Tracker {
        self.multi.tracker()
    }

    /// The search.
    pub fn acquirer(&self) -> &Acquirer {
        self.finder.acquirer()
    }

    /// The search and its leaves' judgement.
    pub fn finder(&self) -> &Finder {
        &self.finder
    }

    /// One instant: `frames[i]` is camera `i`'s, `edge_buffers[i]` its edge map's buffer.
    pub fn step(
        &mut self,
        frames: &[FrameView<'_>],
        edge_buffers: &mut [&mut [u8]],
    ) -> Result<AutoReport, AutoError> {
        self.undecided = false;
        match self.status {
            Status::Searching => self.search(frames, edge_buffers),
            Status::Tracking | Status::Lost => self.follow(frames, edge_buffers),
        }
    }

    /// A tracking or lost frame: the tracker runs, the status follows its `lost` flag.
    #[inline(never)] // a stage of the status machine: kept whole so profiles can attribute its cost
    fn follow(
        &mut self,
        frames: &[FrameView<'_>],
        edge_buffers: &mut [&mut [u8]],
    ) -> Result<AutoReport, AutoError> {
        let multi = self.track_hypotheses(frames, edge_buffers)?;
        if !multi.report.lost {
            self.refine_shading(frames)?;
        }
        // The maps the hypotheses were scored on, if they were: each check below opens them
        // again instead of building its own (nothing else writes the buffers this frame).
        let built = self.multi.take_built_edges();
        let mut watch_score = None;
        if let Some(probation) = self.probation.take() {
            let confirmed = !multi.report.lost && {
                let worst = self.worst_camera_score(frames, edge_buffers, &built)?;
                watch_score = Some(worst);
                let drop = self
                    .finder
                    .config()
                    .probation_max_drop
                    .unwrap_or(f32::INFINITY);
                worst >= probation.worst_camera - drop
            };
            if !confirmed {
                return Ok(self.search_again(multi, probation.local_left, watch_score));
            }
        }
        let mut refuted = false;
        let undecided = self.confirm_left > 0 && self.depth_undecided();
        if self.confirm_left > 0 {
            self.confirm_left -= 1;
            self.confirm_scores.0 += multi.score;
            self.confirm_scores.1 += 1;
            if self.confirm_left == 0 {
                // The best of the leaves carried goes on alone (or with the configured count),
                // unless it scored too little over the frames it was confirmed on.
                self.multi.set_config(self.hypotheses);
                let (sum, n) = self.confirm_scores;
                refuted = sum / (n.max(1) as f32) < self.finder.config().confirm_min_score;
                if !refuted && !multi.report.lost && self.polish_left > 0 {
                    self.polish_left -= 1;
                    self.polish(frames, edge_buffers, &built)?;
                }
            }
        }
        let mut report = multi.report;
        if refuted && self.recovery == Recovery::Search {
            // Not the hand after all: search again from scratch.
            return Ok(self.search_again(multi, 0, None));
        }
        if !report.lost && self.recovery == Recovery::Search && self.watch.due() {
            // The probation's score is the search's: reused only when the watch scores alike
            // and reads nothing more.
            let scores_alike = self.watch.config().reverse_weight
                == self.finder.acquirer().config().likelihood.reverse_weight
                && !self.watch.weighs_reverse();
            let (worst, reverse_px) = match watch_score {
                Some(worst) if scores_alike => (worst, None),
                _ => self.watch_check(frames, edge_buffers, &built)?,
            };
            watch_score = Some(worst);
            if self.watch.judge(worst, reverse_px) {
                if !undecided {
                    self.vouched = self.multi.tracker().memory().state;
                }
            } else {
                // The image does not support the track: a lost frame, and what was last
                // vouched for is what the hand is held at.
                report.lost = true;
                let n = self.vouched.len().min(MAX_STATES);
                self.held[..n].copy_from_slice(&self.vouched[..n]);
            }
        }
        if report.lost {
            self.lost_run = self.lost_run.saturating_add(1);
            self.status = if self.lost_run >= LOST_FRAMES_BEFORE_SEARCH
                && self.recovery == Recovery::Search
            {
                self.finder.restart();
                self.following = None;
                self.pursued = None;
                self.confirm_left = 0;
                self.settle_left = 0;
                self.polish_left = 0;
                self.multi.set_config(self.hypotheses);
                self.local_in_view = 0;
                self.local_left = if self.ever_tracked {
                    LOCAL_SEARCH_FRAMES
                } else {
                    0
                };
                Status::Searching
            } else {
                Status::Lost
            };
        } else if undecided {
            // Neither lost nor claimed: the confirm phase is still choosing the depth.
            self.lost_run = 0;
            self.status = Status::Tracking;
            self.undecided = true;
            report.lost = true;
        } else {
            self.lost_run = 0;
            self.status = Status::Tracking;
            self.hold_tracked();
        }
        Ok(AutoReport::tracked(
            self.status(),
            report,
            &multi,
            watch_score,
        ))
    }

    /// A finger of the tracked state moved where the hand's shading says it lies
    /// ([`Tracker::refine_shading`]; off by default).
    #[inline(never)] // a stage of the status machine: kept whole so profiles can attribute its cost
    fn refine_shading(&mut self, frames: &[FrameView<'_>]) -> Result<(), AutoError> {
        self.multi
            .refine_shading(frames)
            .map_err(AutoError::Tracker)?;
        Ok(())
    }

    /// The hand claimed (or about to be) was not the hand after all: the search goes on, the
    /// local re-acquisition for `local_left` more frames, else the global search from scratch.
    fn search_again(
        &mut self,
        multi: MultiReport,
        local_left: u32,
        watch_score: Option<f32>,
    ) -> AutoReport {
        self.finder.restart();
        self.following = None;
        self.pursued = None;
        self.confirm_left = 0;
        self.settle_left = 0;
        self.polish_left = 0;
        self.multi.set_config(self.hypotheses);
        self.local_left = local_left;
        self.lost_run = 0;
        self.status = Status::Searching;
        let report = FrameReport {
            lost: true,
            ..multi.report
        };
        AutoReport::tracked(self.status, report, &multi, watch_score)
    }

    /// The tracked state's likelihood score in its worst camera, on each camera's edge map
    /// (`built` on this frame already, else built for it).
    fn worst_camera_score(
        &mut self,
        frames: &[FrameView<'_>],
        edge_buffers: &mut [&mut [u8]],
        built: &[BuiltEdges],
    ) -> Result<f32, AutoError> {
        let likelihood = self.finder.acquirer().config().likelihood;
        let (worst, _) =
            self.worst_camera_score_under(frames, edge_buffers, built, &likelihood, false)?;
        Ok(worst)
    }

    /// What a check of the watch reads of the tracked state: its worst camera score under the
    /// watch's likelihood (the search's, with the watch's weight of the reverse term), and
    /// its worst camera's reverse term when the watch has a bar on it.
    fn watch_check(
        &mut self,
        frames: &[FrameView<'_>],
        edge_buffers: &mut [&mut [u8]],
        built: &[BuiltEdges],
    ) -> Result<(f32, Option<f32>), AutoError> {
        let likelihood = LikelihoodConfig {
            reverse_weight: self.watch.config().reverse_weight,
            ..self.finder.acquirer().config().likelihood
        };
        let reverse = self.watch.weighs_reverse();
        self.worst_camera_score_under(frames, edge_buffers, built, &likelihood, reverse)
    }

    /// The tracked state's worst camera score under `likelihood` (whose edge maps are the
    /// search's), and its worst camera's reverse term if `reverse` asks for it.
    fn worst_camera_score_under(
        &mut self,
        frames: &[FrameView<'_>],
        edge_buffers: &mut [&mut [u8]],
        built: &[BuiltEdges],
        likelihood: &LikelihoodConfig,
        reverse: bool,
    ) -> Result<(f32, Option<f32>), AutoError> {
        let tracker = self.multi.tracker();
        let q = padded(tracker.state());
        let mut reads = [Reads::Nowhere; MAX_CAMERAS];
        self.finder
            .acquirer_mut()
            .add_reads(tracker.model(), tracker.cameras(), &q, &mut reads);
        let maps = reopened_edge_maps(edge_buffers, frames, likelihood, built, &reads)?;
        let scene = Scene::new(tracker.model(), tracker.cameras(), frames, &maps);
        let acquirer = self.finder.acquirer_mut();
        let (_, worst) = acquirer.score_cameras_under(&scene, &q, likelihood);
        let reverse_px = if reverse {
            acquirer.worst_reverse_px(&scene, &q)
        } else {
            None
        };
        Ok((worst, reverse_px))
    }

    /// Whether a hypothesis whose palm lies [`AutoTracker::rival_depth_mm`] or more nearer to
    /// or farther from the first camera than the best's ranks within
    /// [`FinderConfig::confirm_rival_margin`] of the best (a depth or score not a number
    /// counts as such a rival); false without rivals to look for.
    fn depth_undecided(&self) -> bool {
        let Some(apart_mm) = self.rival_depth_mm else {
            return false;
        };
        let tracker = self.multi.tracker();
        let cameras = tracker.cameras();
        let margin = self.finder.config().confirm_rival_margin;
        let mut hypotheses = self.multi.hypotheses().iter();
        let Some(best) = hypotheses.next() else {
            return false;
        };
        let depth = |h: &Hypothesis| palm_depth_mm(cameras, &h.memory.state).unwrap_or(f32::NAN);
        let ranked = |h: &Hypothesis| h.ranked_score.unwrap_or(h.score);
        let (best_mm, best_score) = (depth(best), ranked(best));
        // A depth or score not a number counts as a rival's.
        let apart = |h: &Hypothesis| {
            let mm = (depth(h) - best_mm).abs();
            mm.is_nan() || mm >= apart_mm
        };
        let alike = |h: &Hypothesis| {
            let floor = best_score - margin;
            let score = ranked(h);
            floor.is_nan() || score.is_nan() || score >= floor
        };
        hypotheses.any(|h| apart(h) && alike(h))
    }

    /// Keeps the tracker's state as the last that claimed the hand.
    fn hold_tracked(&mut self) {
        for (h, s) in self.held.iter_mut().zip(self.multi.tracker().state()) {
            *h = *s;
        }
        self.ever_tracked = true;
    }

    /// The tracker holds the hand (refined on this frame, its worst camera scoring
    /// `worst_camera`): the status becomes `Tracking`, and the hand is claimed now — or, on
    /// [probation](FinderConfig::probation_max_drop), once the next frame confirms it.
    /// Returns whether it is claimed now.
    fn found(&mut self, worst_camera: f32) -> bool {
        let local_left = self.local_left;
        self.pursued = None;
        self.confirm_left = 0;
        self.polish_left = 0;
        self.multi.set_config(self.hypotheses);
        self.multi.adopt();
        self.watch.clear();
        self.vouched = self.multi.tracker().memory().state;
        self.status = Status::Tracking;
        self.lost_run = 0;
        self.local_left = 0;
        if self.finder.config().probation_max_drop.is_some() {
            self.probation = Some(Probation {
                worst_camera,
                local_left,
            });
            false
        } else {
            self.hold_tracked();
            true
        }
    }

    /// The hypotheses tracked on a frame, without the prior on the palm's position while an
    /// acquisition settles ([`FinderConfig::settle_frames`]).
    fn track_hypotheses(
        &mut self,
        frames: &[FrameView<'_>],
        edge_buffers: &mut [&mut [u8]],
    ) -> Result<MultiReport, AutoError> {
        if self.settle_left == 0 {
            return self.multi.track(frames, edge_buffers);
        }
        self.settle_left -= 1;
        let own = self.multi.tracker().config().motion.prior;
        let settling = PriorWeights {
            translation: 0.0,
            ..own
        };
        // `own` was valid when the tracker was configured, so `settling` is too.
        self.multi.tracker_mut().set_prior(settling);
        let multi = self.multi.track(frames, edge_buffers);
        self.multi.tracker_mut().set_prior(own);
        multi
    }

    /// After a leaf is accepted: when [`FinderConfig::confirm_frames`] asks, the other good
    /// leaves (`others`: the search's, or the local re-acquisition's other starts) join it as
    /// hypotheses for that many frames, so the likelihood over several frames (and each
    /// leaf's Gauss–Newton on each) chooses among them.
    ///
    /// With `depth_variants` (the global search's acceptances), the accepted state moved
    /// nearer and farther along the first camera's ray joins them
    /// ([`FinderConfig::confirm_depth_share`]).
    fn confirm(
        &mut self,
        others: &[[f32; MAX_STATES]],
        depth_variants: bool,
    ) -> Result<(), AutoError> {
        let finder = *self.finder.config();
        self.settle_left = u32::from(finder.settle_frames);
        self.polish_left = u8::from(
            finder
                .polish(self.multi.tracker().cameras().len())
                .is_some(),
        );
        self.carry(others, depth_variants)
    }

    /// The confirm phase has ended: its best, each finger given the library's best-scoring
    /// pose, joins it for another confirm phase when that scores more by
    /// [`FinderConfig::polish_margin`].
    fn polish(
        &mut self,
        frames: &[FrameView<'_>],
        edge_buffers: &mut [&mut [u8]],
        built: &[BuiltEdges],
    ) -> Result<(), AutoError> {
        let n_cameras = self.multi.tracker().cameras().len();
        let Some(margin) = self.finder.config().polish(n_cameras) else {
            return Ok(());
        };
        let likelihood = self.finder.acquirer().config().likelihood;
        // The fingers' library poses may reach anywhere: the whole frame's maps.
        let reads = [Reads::Everywhere; MAX_CAMERAS];
        let maps = reopened_edge_maps(edge_buffers, frames, &likelihood, built, &reads)?;
        let tracker = self.multi.tracker();
        let q = padded(tracker.state());
        let scene = Scene::new(tracker.model(), tracker.cameras(), frames, &maps);
        let (polished, score, before) = self.finder.acquirer_mut().polish_fingers(&scene, &q);
        if score > before + margin {
            self.carry(&[polished], false)?;
        }
        Ok(())
    }

    /// Carries `others` beside the tracker's present state as hypotheses for
    /// [`FinderConfig::confirm_frames`] frames; with `depth_variants`, the present state moved
    /// nearer and farther along the first camera's ray first
    /// ([`FinderConfig::confirm_depth_share`]), and, when the hand was claimed before, moved
    /// to the depth it was last claimed at, which all of them are then ranked toward
    /// ([`FinderConfig::confirm_held_weight`]).
    fn carry(
        &mut self,
        others: &[[f32; MAX_STATES]],
        depth_variants: bool,
    ) -> Result<(), AutoError> {
        let finder = *self.finder.config();
        let tracker = self.multi.tracker();
        let depth_share = if depth_variants {
            finder.confirm_depth(tracker.cameras().len())
        } else {
            None
        };
        self.rival_depth_mm = depth_share.and_then(|_| {
            let depth_mm = palm_depth_mm(tracker.cameras(), tracker.state())?;
            finder.confirm_rival_mm(tracker.cameras().len(), depth_mm)
        });
        let mut carried: Vec<
            [f32; MAX_STATES],
            { MAX_KEEP + (DEPTH_VARIANTS + HELD_VARIANTS) as usize },
        > = Vec::new();
        // The last claimed depth, when the hand was claimed before and the weight asks.
        let weighed = depth_share.is_some() && finder.confirm_held_weight > 0.0;
        let held_mm = if weighed && self.ever_tracked {
            palm_depth_mm(tracker.cameras(), &self.held).filter(|mm| mm.is_finite() && *mm > 0.0)
        } else {
            None
        };
        let mut anchor = None;
        if let (Some(held_mm), Some(depth_mm)) =
            (held_mm, palm_depth_mm(tracker.cameras(), tracker.state()))
        {
            anchor = Some(DepthAnchor {
                depth_mm: held_mm,
                weight: finder.confirm_held_weight,
                band: finder.confirm_held_band,
            });
            let apart = self.rival_depth_mm.unwrap_or(0.0);
            if (held_mm - depth_mm).abs() >= apart && depth_mm > 0.0 {
                let q = padded(tracker.state());
                let share = held_mm / depth_mm - 1.0;
                let moved = self.finder.acquirer().variant(
                    tracker.cameras(),
                    &q,
                    DEPTH_FARTHER,
                    0.0,
                    share,
                );
                let _ = carried.push(moved);
            }
        }
        if let Some(share) = depth_share {
            let q = padded(tracker.state());
            for k in [DEPTH_FARTHER, DEPTH_NEARER] {
                let moved = self
                    .finder
                    .acquirer()
                    .variant(tracker.cameras(), &q, k, 0.0, share);
                let _ = carried.push(moved);
            }
        }
        for q in others {
            let _ = carried.push(*q);
        }
        let others = &carried[..];
        if finder.confirm_frames == 0 || others.is_empty() {
            return Ok(());
        }
        let capacity = if depth_share.is_some() {
            finder.confirm_capacity(tracker.cameras().len())
        } else {
            finder.confirm_hypotheses
        };
        let count = capacity
            .max(self.hypotheses.count)
            .min(MAX_HYPOTHESES as u8);
        // The leaves themselves are compared: nothing sampled around them (a confirming frame
        // costs one tracker pass and one score per leaf), by their image alone (a leaf has no
        // motion yet for the temporal term to weigh).
        self.multi.set_config(HypothesesConfig {
            count,
            spawn_per_frame: 0,
            jumps_per_frame: 0,
            keep_fingers: false,
            motion_weight: 0.0,
            score_every_frames: 1,
            switch_margin: finder.confirm_switch_margin,
            score_memory: finder.confirm_score_memory,
            // The search's leaves are judged by the search's likelihood, whatever the
            // tracker's hypotheses weigh.
            likelihood: self.finder.acquirer().config().likelihood,
            depth_anchor: anchor,
            ..self.hypotheses
        });
        self.multi.seed(others)?;
        self.confirm_left = u32::from(finder.confirm_frames);
        self.confirm_scores = (0.0, 0);
        Ok(())
    }

    /// One frame of local re-acquisition: the hypothesis followed from the last frame (if
    /// any), the last good palm under the library's best-scoring finger pose
    /// ([`FinderConfig::local_library_pose`]), and a variant of the last good state (itself on
    /// every other frame, else turned or moved in depth: [`Acquirer::variant`]) slid over the
    /// first camera's edge map near where it projects or placed on the frame's bright
    /// regions; the first [`FinderConfig::local_starts`] of these are refined by Gauss–Newton
    /// and scored over every camera; the best is accepted if the acceptance test takes it,
    /// else followed to the next frame if it reaches [`LOCAL_FOLLOW_SCORE`].
    #[inline(never)] // a stage of the status machine: kept whole so profiles can attribute its cost
    fn local_search(
        &mut self,
        frames: &[FrameView<'_>],
        maps: &[EdgeMap<'_>],
        out: &mut AutoReport,
    ) -> Result<(), AutoError> {
        let frame = LOCAL_SEARCH_FRAMES.saturating_sub(self.local_left);
        self.local_left = self.local_left.saturating_sub(1);
        out.local = true;
        let n = self.multi.tracker().model().n_states().min(MAX_STATES);
        let k = if frame.is_multiple_of(2) {
            0
        } else {
            1 + (frame / 2) % (LOCAL_VARIANTS - 1)
        };
        let turn_rad = self.finder.config().local_turn_rad;
        let seed = {
            let tracker = self.multi.tracker();
            let [shared, one_camera] = self.finder.config().local_depth_share;
            let depth_share = if tracker.cameras().len() >= 2 {
                shared
            } else {
                one_camera
            };
            self.finder
                .acquirer()
                .variant(tracker.cameras(), &self.held, k, turn_rad, depth_share)
        };
        let followed = self.following.take();
        let replaced = {
            let tracker = self.multi.tracker();
            let cameras = tracker.cameras();
            let mut q = seed;
            self.finder
                .acquirer_mut()
                .replace(
                    tracker.model(),
                    &cameras[..cameras.len().min(MAX_CAMERAS)],
                    maps,
                    &mut q,
                )
                .then_some(q)
        };
        let library = if self.finder.config().local_library_pose {
            let tracker = self.multi.tracker();
            let palm = replaced.unwrap_or(seed);
            let scene = Scene::new(tracker.model(), tracker.cameras(), frames, maps);
            let (q, _) = self.finder.acquirer_mut().best_pose(&scene, &palm);
            Some(q)
        } else {
            None
        };
        let order = if frame.is_multiple_of(2) {
            [
                LocalStart::Followed,
                LocalStart::Library,
                LocalStart::Slid,
                LocalStart::Placed,
            ]
        } else {
            [
                LocalStart::Followed,
                LocalStart::Library,
                LocalStart::Placed,
                LocalStart::Slid,
            ]
        };
        let most = usize::from(self.finder.config().local_starts);
        let mut refined: Vec<Refined, 4> = Vec::new();
        for start in order {
            if refined.len() >= most {
                break;
            }
            let tracker = self.multi.tracker();
            let q = match start {
                LocalStart::Slid => match (maps.first(), tracker.cameras().first().copied()) {
                    (Some(map), Some(camera)) => {
                        let near_px = camera.width as f32 * LOCAL_WINDOW;
                        self.finder
                            .acquirer_mut()
                            .place(tracker.model(), &camera, map, seed, Some(near_px))
                            .map(|placed| placed.q)
                    }
                    _ => None,
                },
                LocalStart::Placed => replaced,
                LocalStart::Followed => followed,
                LocalStart::Library => library,
            };
            let Some(q) = q else { continue };
            let r = self.refine(frames, maps, q, n, LOCAL_REFINE_PASSES)?;
            out.evaluated = out.evaluated.saturating_add(1);
            let _ = refined.push(r);
        }
        refined.sort_unstable_by(|a, b| b.score.total_cmp(&a.score));
        let Some(best) = refined.first() else {
            return Ok(());
        };
        let (score, q, report) = (best.score, best.q, best.report);
        out.leaf_score = Some(score);
        let finder = *self.finder.config();
        let cameras = self.multi.tracker().cameras().len();
        let verdict = finder.accept.judge(cameras, best.leaf(), report.lost);
        if verdict.accepted {
            let mut others: Vec<[f32; MAX_STATES], 3> = Vec::new();
            for r in refined.iter().skip(1) {
                if !r.report.lost && r.score >= finder.alternative_score {
                    let _ = others.push(r.q);
                }
            }
            self.multi.tracker_mut().restart_fresh(&q[..n])?;
            let claimed = self.found(best.worst_camera);
            // Started from the last good state's depth, not one a leaf guessed.
            self.confirm(&others, false)?;
            out.accepted = true;
            out.status = self.status();
            out.report = FrameReport {
                lost: !claimed,
                ..report
            };
        } else {
            if score >= LOCAL_FOLLOW_SCORE {
                self.following = Some(q);
            }
            if score > 0.0 {
                self.local_in_view = self.local_in_view.saturating_add(1);
                // One camera's global search acquires too rarely to give the local one up
                // early (FinderConfig::local_frames_in_view).
                let most = if self.multi.tracker().cameras().len() >= 2 {
                    u32::from(finder.local_frames_in_view)
                } else {
                    0
                };
                if most > 0 && self.local_in_view >= most {
                    self.local_left = 0;
                    self.following = None;
                }
            }
        }
        Ok(())
    }

    /// `start` refined by `passes` fresh tracker passes on this frame (under
    /// the search's [`FinderConfig::leaf_robust`] and edge test), and its mean and worst camera's
    /// likelihood score (0 when the tracker calls it lost).
    fn refine(
        &mut self,
        frames: &[FrameView<'_>],
        maps: &[EdgeMap<'_>],
        start: [f32; MAX_STATES],
        n: usize,
        passes: u32,
    ) -> Result<Refined, AutoError> {
        let mut q = start;
        let mut report = FrameReport::default();
        let overrides = self
            .finder
            .config()
            .local_overrides(self.multi.tracker().config());
        let tracker = self.multi.tracker_mut();
        for _ in 0..passes.max(1) {
            tracker.restart_fresh(&q[..n])?;
            report = tracker.track_under(&overrides, frames)?;
            q[..n].copy_from_slice(&tracker.state()[..n]);
            if report.lost {
                return Ok(Refined {
                    score: 0.0,
                    worst_camera: 0.0,
                    reverse_px: None,
                    q,
                    report,
                });
            }
        }
        let tracker = self.multi.tracker();
        let scene = Scene::new(tracker.model(), tracker.cameras(), frames, maps);
        let accept = self.finder.config().accept;
        let LeafScore {
            score,
            worst_camera,
            reverse_px,
        } = self.finder.acquirer_mut().leaf_score(&scene, &q, &accept);
        Ok(Refined {
            score,
            worst_camera,
            reverse_px,
            q,
            report,
        })
    }

    /// The refused leaf pursued ([`FinderConfig::pursue_frames`]), refined again on this
    /// frame and judged: returns whether it was accepted (the hand is found, its confirm
    /// phase begun).
    fn pursue(
        &mut self,
        frames: &[FrameView<'_>],
        maps: &[EdgeMap<'_>],
        out: &mut AutoReport,
    ) -> Result<bool, AutoError> {
        let Some((q, left, _)) = self.pursued.take() else {
            return Ok(false);
        };
        let n = self.multi.tracker().model().n_states().min(MAX_STATES);
        let r = self.refine(frames, maps, q, n, PURSUIT_PASSES)?;
        out.evaluated = out.evaluated.saturating_add(1);
        let finder = *self.finder.config();
        let cameras = self.multi.tracker().cameras().len();
        let verdict = finder.accept.judge(cameras, r.leaf(), r.report.lost);
        let rig = usize::from(cameras < 2);
        if verdict.accepted {
            self.finder.restart();
            self.multi.tracker_mut().restart_fresh(&r.q[..n])?;
            let claimed = self.found(r.worst_camera);
            self.confirm(&[], true)?;
            out.leaf_score = Some(r.score);
            out.accepted = true;
            out.status = self.status();
            out.report = FrameReport {
                lost: !claimed,
                ..r.report
            };
            return Ok(true);
        }
        out.leaf_score = Some(r.score);
        let bar = finder.pursue_score[rig];
        if left > 1 && !r.report.lost && r.score >= bar {
            self.pursued = Some((r.q, left - 1, r.score));
        }
        Ok(false)
    }

    /// A searching frame: the search moves on, or some of its leaves are refined and judged.
    #[inline(never)] // a stage of the status machine: kept whole so profiles can attribute its cost
    fn search(
        &mut self,
        frames: &[FrameView<'_>],
        edge_buffers: &mut [&mut [u8]],
    ) -> Result<AutoReport, AutoError> {
        if frames.len() != self.multi.tracker().cameras().len() {
            return Err(AutoError::Tracker(TrackerError::FrameCount));
        }
        let config = *self.finder.acquirer().config();
        let maps = edge_maps(edge_buffers, frames, &config.likelihood)?;
        let mut out = AutoReport {
            status: Status::Searching,
            report: FrameReport {
                lost: true,
                ..FrameReport::default()
            },
            hypotheses: 1,
            ..AutoReport::default()
        };
        if self.local_left > 0 {
            self.local_search(frames, &maps, &mut out)?;
            return Ok(out);
        }
        let pursued = self.pursued.is_some();
        if self.pursue(frames, &maps, &mut out)? {
            return Ok(out);
        }
        let spent = if pursued {
            PURSUIT_EVALUATIONS_PER_CAMERA.saturating_mul(frames.len() as u16)
        } else {
            0
        };
        match self
            .finder
            .step_after(self.multi.tracker_mut(), frames, &maps, spent)?
        {
            FinderStep::Searching {
                evaluated,
                best_leaf,
                ..
            } => {
                out.evaluated = out.evaluated.saturating_add(evaluated);
                if let Some(v) = best_leaf {
                    out.leaf_score = Some(out.leaf_score.map_or(v.score, |s| s.max(v.score)));
                }
                let finder = *self.finder.config();
                let cameras = self.multi.tracker().cameras().len();
                let rig = usize::from(cameras < 2);
                let (bar, pursue_frames) = (finder.pursue_score[rig], finder.pursue_frames[rig]);
                if let (Some(v), Some((_, q))) = (best_leaf, self.finder.last_leaf()) {
                    // A leaf replaces the one pursued only if it scores more.
                    let better = self.pursued.is_none_or(|(_, _, score)| v.score > score);
                    if pursue_frames > 0 && !v.lost && v.score >= bar && better {
                        self.pursued = Some((*q, pursue_frames, v.score));
                    }
                }
            }
            FinderStep::Found { verdict, report } => {
                let claimed = self.found(verdict.worst_camera);
                let mut others: Vec<[f32; MAX_STATES], MAX_KEEP> = Vec::new();
                for q in self.finder.found_leaves().iter().skip(1) {
                    let _ = others.push(*q);
                }
                self.confirm(&others, true)?;
                out.leaf_score = Some(verdict.score);
                out.accepted = true;
                out.status = self.status();
                out.report = FrameReport {
                    lost: !claimed,
                    ..report
                };
            }
        }
        Ok(out)
    }
}
