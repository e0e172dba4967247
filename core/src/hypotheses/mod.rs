//! Several hypotheses through ambiguity (after Cham & Rehg's multiple-hypothesis tracker).
//!
//! A single Gauss–Newton track commits to one reading of every frame; where the image is
//! ambiguous (a finger seen end-on, fingers crossing, a palm's tilt weakly seen by one camera)
//! it may commit to the wrong one and drift. Here up to [`HypothesesConfig::count`] states are
//! carried between frames, each with its own motion. Every frame:
//!
//! 1. each hypothesis is tracked by the same Gauss–Newton loop (one [`Tracker`], its memory
//!    swapped per hypothesis);
//! 2. new hypotheses are sampled on either side of the best along the directions its normal
//!    equations constrain least ([`weak`]), and refined by the loop on the same frame;
//! 3. every hypothesis is scored by the image [likelihood](crate::likelihood), less a penalty
//!    when the tracker flagged its frame lost;
//! 4. near-duplicates are merged into the better ([`merge`]), the best `count` kept; the best
//!    is the output, and a challenger replaces the previous best only when it scores
//!    [`HypothesesConfig::switch_margin`] more.
//!
//! With one hypothesis nothing is sampled or scored: the output is the single tracker's, bit
//! for bit. The edge maps the likelihood needs live in the caller's buffers, one per camera.

pub mod config;
pub mod depth_anchor;
pub mod fingers;
pub mod jump;
pub mod merge;
mod rank;
pub mod score;
pub mod weak;

use heapless::Vec;

pub use config::{HypothesesConfig, Spread};
pub use depth_anchor::DepthAnchor;

use crate::auto_tracker::AutoError;
use crate::camera::{palm_depth_mm, Camera};
use crate::config::{MAX_CAMERAS, MAX_CANDIDATES, MAX_HYPOTHESES};
use crate::estimator::FreeMask;
use crate::frame::FrameView;
use crate::likelihood::shading_refine::RefineOutcome;
use crate::likelihood::{BuiltEdges, EdgeMap, Reads, Scene};
use crate::state::{clamp_to_limit, renormalise_quaternion};
use crate::tracker::{FrameReport, TrackMemory, Tracker, TrackerError};
use score::StateScorer;

/// One hypothesis: what the tracker knows of the hand under it, its last frame, its score.
#[derive(Debug, Clone, PartialEq)]
pub struct Hypothesis {
    /// The tracker's memory under this hypothesis (its state is the hypothesis).
    pub memory: TrackMemory,
    /// The tracker's report of its last frame.
    pub report: FrameReport,
    /// The likelihood score of its last frame, less the lost penalty (0 with one hypothesis).
    pub score: f32,
    /// The score as ranked: its running mean over the frames it was scored on, the past
    /// weighted by [`HypothesesConfig::score_memory`] (`None` until first scored).
    pub ranked_score: Option<f32>,
    /// Frames it has been carried (0 when sampled on this frame).
    pub age: u32,
}

impl Hypothesis {
    /// A hypothesis of `memory` not yet tracked on any frame: no report, unscored, age 0.
    pub fn fresh(memory: TrackMemory) -> Self {
        Hypothesis {
            memory,
            report: FrameReport::default(),
            score: 0.0,
            ranked_score: None,
            age: 0,
        }
    }
}

/// What one frame did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MultiReport {
    /// The best hypothesis' frame.
    pub report: FrameReport,
    /// The best hypothesis' score (0 with one hypothesis).
    pub score: f32,
    /// Hypotheses carried to the next frame.
    pub count: u8,
    /// Hypotheses sampled on this frame.
    pub sampled: u8,
    /// Candidates left out on this frame: merged into a better near-duplicate, or beyond
    /// the count kept.
    pub dropped: u8,
    /// The best is not the previous frame's best.
    pub switched: bool,
}

/// A tracker carrying several hypotheses.
#[derive(Debug, Clone)]
pub struct MultiTracker {
    tracker: Tracker,
    config: HypothesesConfig,
    /// Best first; the tracker holds the best's memory between frames.
    hypotheses: Vec<Hypothesis, MAX_HYPOTHESES>,
    scorer: StateScorer,
    fingers: fingers::Fingers,
    /// Frames tracked since the last scored one ([`HypothesesConfig::score_every_frames`]).
    since_scored: u8,
    /// The edge maps the last [`MultiTracker::track`] built into the caller's buffers, one
    /// per camera (empty when it built none): [`MultiTracker::take_built_edges`].
    built: Vec<BuiltEdges, MAX_CAMERAS>,
}

impl MultiTracker {
    /// Hypotheses around `tracker`, which starts as the only one.
    pub fn new(tracker: Tracker, config: HypothesesConfig) -> Self {
        let memory = tracker.memory();
        let fingers = fingers::Fingers::of(tracker.model());
        MultiTracker::around(tracker, memory, fingers, config)
    }

    /// [`MultiTracker::new`] with `tracker`'s memory and its model's fingers given, so that a
    /// tracker built in the call goes straight into its place.
    #[inline]
    pub(crate) fn around(
        tracker: Tracker,
        memory: TrackMemory,
        fingers: fingers::Fingers,
        config: HypothesesConfig,
    ) -> Self {
        let mut hypotheses = Vec::new();
        let _ = hypotheses.push(Hypothesis::fresh(memory));
        MultiTracker {
            tracker,
            config,
            hypotheses,
            scorer: StateScorer::new(),
            fingers,
            since_scored: 0,
            built: Vec::new(),
        }
    }

    /// The edge maps the last [`MultiTracker::track`] built into its `edge_buffers`, one per
    /// camera, to open again with [`EdgeMap::reopen`] while those buffers are untouched (the
    /// rest of the same frame's step); empty when it built none (one hypothesis, or a frame
    /// not scored). Taken: a second call returns none.
    pub fn take_built_edges(&mut self) -> Vec<BuiltEdges, MAX_CAMERAS> {
        core::mem::take(&mut self.built)
    }

    /// The hypotheses carried, best first.
    pub fn hypotheses(&self) -> &[Hypothesis] {
        &self.hypotheses
    }

    /// The tracker, holding the best hypothesis.
    pub fn tracker(&self) -> &Tracker {
        &self.tracker
    }

    /// The tracker, for a caller that moves it outside the hypotheses (the search refining
    /// a leaf): call [`MultiTracker::adopt`] before the next frame, else the hypotheses
    /// carried are the ones from before.
    pub fn tracker_mut(&mut self) -> &mut Tracker {
        &mut self.tracker
    }

    /// [`Tracker::refine_shading`] on the best hypothesis (the tracker's), which then carries
    /// the state as moved.
    pub fn refine_shading(
        &mut self,
        frames: &[FrameView<'_>],
    ) -> Result<RefineOutcome, TrackerError> {
        let outcome = self.tracker.refine_shading(frames)?;
        if outcome.moves > 0 {
            if let Some(best) = self.hypotheses.first_mut() {
                best.memory = self.tracker.memory();
            }
        }
        Ok(outcome)
    }

    /// Forgets every hypothesis but the tracker's present memory, which becomes the only one.
    pub fn adopt(&mut self) {
        self.hypotheses.clear();
        let _ = self
            .hypotheses
            .push(Hypothesis::fresh(self.tracker.memory()));
    }

    /// Carries the tracker's present memory (first, the best) and then `others` (whole
    /// states, one value per model state used) as the hypotheses, each of the others with
    /// fresh memory (no motion, no silhouette reference), up to the configured count: several
    /// readings of one frame (the search's leaves) for the likelihood to choose among over
    /// the frames to come. A state that cannot be posed is left out. The tracker keeps
    /// holding the first.
    pub fn seed(
        &mut self,
        others: &[[f32; crate::config::MAX_STATES]],
    ) -> Result<(), TrackerError> {
        let first = self.tracker.memory();
        let n = first.state.len();
        self.adopt();
        for q in others {
            if self.hypotheses.len() >= self.config.count() {
                break;
            }
            if self.tracker.restart_fresh(&q[..n]).is_err() {
                continue;
            }
            let _ = self
                .hypotheses
                .push(Hypothesis::fresh(self.tracker.memory()));
        }
        self.tracker.restore(&first)
    }

    /// New parameters for the frames to come; the hypotheses beyond the new count are dropped.
    pub fn set_config(&mut self, config: HypothesesConfig) {
        self.config = config;
        self.hypotheses.truncate(config.count());
    }

    /// The best state (quaternion, mm, rad).
    pub fn state(&self) -> &[f32] {
        self.tracker.state()
    }

    /// The parameters.
    pub fn config(&self) -> &HypothesesConfig {
        &self.config
    }

    /// New cameras for the frames to come (the tracker's other parameters kept), for every
    /// hypothesis.
    pub fn reconfigure(&mut self, cameras: &[Camera]) -> Result<(), TrackerError> {
        let config = *self.tracker.config();
        self.tracker.reconfigure(cameras, config)
    }

    /// Restarts from one hypothesis at `state`, forgetting the motion and the others.
    pub fn reset(&mut self, state: &[f32]) -> Result<(), TrackerError> {
        self.tracker.reset(state)?;
        self.adopt();
        Ok(())
    }

    /// One instant: `frames[i]` is camera `i`'s, `edge_buffers[i]` its edge map's buffer
    /// (unused, and may be empty, with one hypothesis).
    pub fn track(
        &mut self,
        frames: &[FrameView<'_>],
        edge_buffers: &mut [&mut [u8]],
    ) -> Result<MultiReport, AutoError> {
        self.built.clear();
        if self.config.count() == 1 {
            let report = self.tracker.track(frames)?;
            if let Some(h) = self.hypotheses.first_mut() {
                h.memory = self.tracker.memory();
                h.report = report;
                h.age += 1;
            }
            return Ok(MultiReport {
                report,
                count: 1,
                ..MultiReport::default()
            });
        }
        if frames.len() != self.tracker.cameras().len() {
            return Err(AutoError::Tracker(TrackerError::FrameCount));
        }
        if edge_buffers.len() < frames.len() {
            return Err(AutoError::BufferCount);
        }
        if !self.scoring_due() {
            return self.carry(frames);
        }
        let likelihood = self.config.likelihood;
        // The maps are built once the candidates are known (step 3); a buffer that could not
        // hold one fails the frame before any hypothesis moves.
        for (buffer, frame) in edge_buffers.iter().zip(frames) {
            EdgeMap::check_buffer(buffer.len(), frame, &likelihood).map_err(AutoError::EdgeMap)?;
        }
        let mut candidates: Vec<Hypothesis, MAX_CANDIDATES> = Vec::new();
        // `parents[c]`: the carried hypothesis candidate `c` descends from.
        let mut parents: Vec<usize, MAX_CANDIDATES> = Vec::new();
        let n = self.tracker.model().n_states();
        let mut samples = Vec::<TrackMemory, { crate::config::MAX_SPAWN }>::new();
        let mut undone = Vec::<Hypothesis, { fingers::MAX_FINGERS + 1 }>::new();
        // 1. Every hypothesis through the loop; the weak directions of the best.
        for (index, h) in self.hypotheses.iter().enumerate() {
            self.tracker.restore(&h.memory)?;
            let cap = self.config.carried_iterations(index);
            let report = self.tracker.track_at_most(cap, frames)?;
            let memory = self.tracker.memory();
            if index == 0 {
                let spawn = self.config.spawn();
                let normal = self.tracker.normal_equations();
                let free = self.tracker.free();
                let spread = &self.config.spread;
                let mut directions: Vec<weak::WeakDirection, { crate::config::MAX_SPAWN }> =
                    Vec::new();
                if spawn > 0 {
                    if let Some((_, d)) =
                        weak::most_ambiguous_finger(normal, n, free, &self.fingers, spread)
                    {
                        let _ = directions.push(d);
                    }
                    let rest = spawn.div_ceil(2).saturating_sub(directions.len());
                    for d in weak::weakest(normal, n, free, spread, rest) {
                        let _ = directions.push(d);
                    }
                }
                'sampling: for d in &directions {
                    for sign in [1.0f32, -1.0] {
                        if samples.len() >= spawn {
                            break 'sampling;
                        }
                        let mut sample = memory.clone();
                        for (i, v) in sample.state.iter_mut().enumerate() {
                            let moved = *v + sign * self.config.spawn_step * d.direction[i];
                            *v = clamp_to_limit(self.tracker.model(), i, moved);
                        }
                        renormalise_quaternion(&mut sample.state);
                        sample.velocity = None;
                        let _ = samples.push(sample);
                    }
                }
                let jumps = jump::finger_jumps(
                    self.tracker.model(),
                    self.tracker.cameras(),
                    &self.fingers,
                    &memory.state,
                    self.config.jump_min_turn_rad,
                    self.config.jump_max_moved_px,
                    self.config.jumps(),
                );
                for j in &jumps {
                    let mut sample = memory.clone();
                    sample.state.copy_from_slice(&j.state[..n]);
                    sample.velocity = None;
                    // Past MAX_SPAWN samples and jumps together, the jump is left out.
                    let _ = samples.push(sample);
                }
            }
            let kept_fingers = if index == 0 && self.config.keep_fingers {
                self.fingers.count() + 1
            } else {
                0
            };
            for f in 0..kept_fingers {
                // Finger `f` (or every finger, for f == count) back where it was.
                let mut kept = memory.clone();
                for s in 0..n {
                    let undo = if f == self.fingers.count() {
                        s >= crate::model::BASE_STATES
                    } else {
                        self.fingers.contains(f, s)
                    };
                    if undo {
                        kept.state[s] = h.memory.state[s];
                        if let Some(v) = kept.velocity.as_mut() {
                            v[s] = 0.0;
                        }
                    }
                }
                let _ = undone.push(Hypothesis {
                    memory: kept,
                    report,
                    score: 0.0,
                    ranked_score: None,
                    age: 0,
                });
            }
            let _ = candidates.push(Hypothesis {
                memory,
                report,
                score: 0.0,
                ranked_score: h.ranked_score,
                age: h.age + 1,
            });
            let _ = parents.push(index);
        }
        for u in undone {
            let _ = candidates.push(u);
            let _ = parents.push(0);
        }
        // 2. The samples refined on this frame, carrying on with the best's motion.
        let parent_velocity = candidates.first().and_then(|c| c.memory.velocity);
        let mut sampled = 0u8;
        for sample in &samples {
            if self.tracker.restore(sample).is_err() {
                continue;
            }
            let report = self
                .tracker
                .track_at_most(self.config.sample_iterations, frames)?;
            let mut memory = self.tracker.memory();
            memory.velocity = parent_velocity;
            sampled += 1;
            let _ = candidates.push(Hypothesis {
                memory,
                report,
                score: 0.0,
                ranked_score: None,
                age: 0,
            });
            let _ = parents.push(0);
        }
        // 3. Scores, on maps of the cells the candidates' scores read.
        let mut reads = [Reads::Nowhere; MAX_CAMERAS];
        for c in &candidates {
            self.scorer.add_reads(
                self.tracker.model(),
                self.tracker.cameras(),
                &c.memory.state,
                &mut reads,
            );
        }
        let mut maps: Vec<EdgeMap<'_>, MAX_CAMERAS> = Vec::new();
        for ((buffer, frame), reads) in edge_buffers.iter_mut().zip(frames).zip(reads) {
            let map = EdgeMap::build_edges_for(buffer, frame, &likelihood, reads)
                .map_err(AutoError::EdgeMap)?;
            let built = map.built(frame, &likelihood);
            if maps.push(map).is_err() {
                return Err(AutoError::Tracker(TrackerError::CameraCount));
            }
            // As many as `maps` holds, so never full here.
            let _ = self.built.push(built);
        }
        let free = self.tracker.free();
        for (c, &parent) in candidates.iter_mut().zip(&parents) {
            let scene = Scene::new(self.tracker.model(), self.tracker.cameras(), frames, &maps);
            let mut score = self.scorer.score(&scene, &c.memory.state, &likelihood);
            if c.report.lost {
                score -= self.config.lost_penalty;
            }
            if self.config.motion_weight > 0.0 {
                if let Some(p) = self.hypotheses.get(parent) {
                    score -= self.config.motion_weight
                        * departure(&c.memory.state, &p.memory, free, &self.config.spread);
                }
            }
            if let Some(anchor) = self.config.depth_anchor {
                let depth_mm = palm_depth_mm(self.tracker.cameras(), &c.memory.state);
                score -= anchor.penalty(depth_mm.unwrap_or(f32::NAN));
            }
            c.score = score;
            c.ranked_score = Some(rank::ranked_score(
                c.ranked_score,
                score,
                self.config.score_memory,
            ));
        }
        // 4. Merge and keep; the previous best keeps its place unless clearly beaten.
        let mut ranking = [0.0f32; MAX_CANDIDATES];
        for (r, c) in ranking.iter_mut().zip(&candidates) {
            *r = c.ranked_score.unwrap_or(c.score);
        }
        if let Some(r) = ranking.first_mut() {
            *r += self.config.switch_margin;
        }
        let mut order = [0usize; MAX_CANDIDATES];
        let mut kept = merge::pick(
            &ranking[..candidates.len()],
            |i| &candidates[i].memory.state[..],
            &self.config.spread,
            self.config.merge_distance,
            self.config.count(),
            &mut order,
        );
        if kept == 0 {
            kept = 1; // cannot happen (one is always kept), but the previous best stays
            order[0] = 0;
        }
        self.hypotheses.clear();
        for &i in &order[..kept] {
            let _ = self.hypotheses.push(candidates[i].clone());
        }
        let best = &candidates[order[0]];
        self.tracker.restore(&best.memory)?;
        Ok(MultiReport {
            report: best.report,
            score: best.score,
            count: kept as u8,
            sampled,
            dropped: (candidates.len() - kept).min(usize::from(u8::MAX)) as u8,
            switched: order[0] != 0,
        })
    }

    /// Whether this frame is scored: one in [`HypothesesConfig::score_every_frames`], the
    /// first after a seeding, and every frame after one whose best was flagged lost.
    fn scoring_due(&mut self) -> bool {
        let every = self.config.score_every_frames.max(1);
        let doubted = self.hypotheses.first().is_some_and(|h| h.report.lost);
        let fresh = self.hypotheses.iter().all(|h| h.age == 0);
        if doubted || fresh || self.since_scored.saturating_add(1) >= every {
            self.since_scored = 0;
            true
        } else {
            self.since_scored += 1;
            false
        }
    }

    /// A frame between scored ones: every hypothesis tracked, in its rank, with its last
    /// score; nothing sampled, merged or dropped.
    fn carry(&mut self, frames: &[FrameView<'_>]) -> Result<MultiReport, AutoError> {
        if self.hypotheses.is_empty() {
            self.adopt();
        }
        for (index, h) in self.hypotheses.iter_mut().enumerate() {
            self.tracker.restore(&h.memory)?;
            let cap = self.config.carried_iterations(index);
            h.report = if index > 0 && self.config.light_others {
                self.tracker.track_light(cap, frames)?
            } else {
                self.tracker.track_at_most(cap, frames)?
            };
            h.memory = self.tracker.memory();
            h.age += 1;
        }
        let (report, score) = match self.hypotheses.first() {
            Some(best) => {
                self.tracker.restore(&best.memory)?;
                (best.report, best.score)
            }
            None => (FrameReport::default(), 0.0), // never: adopted above
        };
        Ok(MultiReport {
            report,
            score,
            count: self.hypotheses.len() as u8,
            ..MultiReport::default()
        })
    }
}

/// How far `state` departs from what `parent` predicts (its state moved on by its velocity):
/// the sum over the free states of the squared difference in [`Spread`] units. States whose
/// unit is not a positive number, and differences that are not finite, count nothing.
fn departure(state: &[f32], parent: &TrackMemory, free: FreeMask, spread: &Spread) -> f32 {
    let mut sum = 0.0f32;
    for (i, (now, was)) in state.iter().zip(&parent.state).enumerate() {
        let unit = spread.for_state(i);
        let positive = unit.is_finite() && unit > 0.0;
        if !free.contains(i) || !positive {
            continue;
        }
        let moved = parent.velocity.as_ref().map_or(0.0, |v| v[i]);
        let d = (now - (was + moved)) / unit;
        if d.is_finite() {
            sum += d * d;
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    fn memory(state: &[f32], velocity: Option<[f32; crate::config::MAX_STATES]>) -> TrackMemory {
        TrackMemory {
            state: state.iter().copied().collect(),
            velocity,
            silhouette_reference: None,
        }
    }

    #[test]
    fn departure_is_zero_on_the_prediction_and_counts_spread_units() {
        let spread = Spread::default();
        let free = FreeMask::all(9);
        let parent_state = [1.0, 0.0, 0.0, 0.0, 10.0, 20.0, 30.0, 0.5, 0.2];
        let mut velocity = [0.0f32; crate::config::MAX_STATES];
        velocity[7] = 0.1;
        velocity[4] = 2.0;
        let parent = memory(&parent_state, Some(velocity));
        let mut predicted = parent_state;
        predicted[7] = 0.6;
        predicted[4] = 12.0;
        assert_eq!(departure(&predicted, &parent, free, &spread), 0.0);
        // One joint a unit (0.35 rad) and the translation half a unit (5 mm) off: 1 + 0.25.
        let mut moved = predicted;
        moved[8] += 0.35;
        moved[5] -= 5.0;
        let d = departure(&moved, &parent, free, &spread);
        assert!((d - 1.25).abs() < 1e-4, "{d}");
        // States that are not free do not count; no velocity predicts no motion.
        let joints_fixed = FreeMask::from_states(&[0, 1, 2, 3, 4, 5, 6, 7]).unwrap();
        assert!((departure(&moved, &parent, joints_fixed, &spread) - 0.25).abs() < 1e-4);
        let still = memory(&parent_state, None);
        assert_eq!(departure(&parent_state, &still, free, &spread), 0.0);
        // A unit of zero or NaN, or a state that is not finite, never makes the score NaN.
        let broken = Spread {
            joint_rad: 0.0,
            translation_mm: f32::NAN,
            ..spread
        };
        assert_eq!(departure(&moved, &parent, free, &broken), 0.0);
        let mut bad = moved;
        bad[8] = f32::INFINITY;
        assert!((departure(&bad, &parent, free, &spread) - 0.25).abs() < 1e-4);
    }
}
