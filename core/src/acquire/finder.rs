//! The search and its leaves' judgement in one place, for a status machine to call on every
//! searching frame: [`Finder::step`] moves the [`Acquirer`] on within its budget; once the
//! search has ended, it refines [`FinderConfig::leaves_per_frame`] of its leaves per frame by
//! the tracker's own Gauss–Newton (`Tracker::restart_fresh` then `Tracker::track`) and
//! [judges](super::accept) each; the best accepted leaf is handed to the tracker, and when
//! every leaf is refused the search starts over.

use heapless::Vec;

use crate::config::{MAX_CAMERAS, MAX_STATES};
use crate::estimator::Robust;
use crate::frame::FrameView;
use crate::likelihood::{EdgeMap, Scene};
use crate::motion::PriorWeights;
use crate::tracker::{FrameReport, RefineOverrides, Tracker, TrackerConfig, TrackerError};

use super::accept::{AcceptConfig, LeafScore, Verdict};
use super::{Acquirer, Progress, MAX_KEEP};

/// How leaves are refined and judged.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FinderConfig {
    /// Leaves refined by Gauss–Newton per frame (each costs about one tracking frame).
    pub leaves_per_frame: u8,
    /// Leaves refined per search, at most (the best first).
    pub leaves: u8,
    /// Times the tracker runs on the frame from each leaf (each up to its iteration limit):
    /// a leaf farther than one frame's iterations reach converges in the next.
    pub passes_per_leaf: u8,
    /// Gauss–Newton iterations at most in each pass of a leaf's or a local re-acquisition's
    /// start's refinement, whatever the tracker's own [`TrackerConfig::iterations`] (0: the
    /// tracker's). A leaf starts farther from the hand than a tracked frame's prediction, and
    /// the search's bars were set on leaves refined by 8.
    pub refine_iterations: u8,
    /// The acceptance thresholds.
    pub accept: AcceptConfig,
    /// Re-place each leaf on the bright region of the frame it is refined on before
    /// Gauss–Newton ([`Acquirer::replace`]): the search spans several frames and the hand
    /// moves on meanwhile.
    pub replace_leaves: bool,
    /// Frames the status machine carries the accepted leaf together with the search's other
    /// leaves ([`Finder::found_leaves`]) as hypotheses, the likelihood choosing among them
    /// every frame, before it drops back to its configured count (0: none).
    pub confirm_frames: u8,
    /// Hypotheses carried while confirming, at most (the accepted leaf among them).
    pub confirm_hypotheses: u8,
    /// A leaf refined alongside the accepted one joins it as a hypothesis when it scores at
    /// least this (and Gauss–Newton did not lose it).
    pub alternative_score: f32,
    /// The mean score over the confirming frames the best hypothesis needs for the hand to
    /// be kept; under it the hand is given up and searched for again (0: always kept).
    pub confirm_min_score: f32,
    /// The robust weight of a leaf's refinement, in place of the tracker's own: a leaf starts
    /// several px from the hand, where a weight that falls to zero (Tukey) pulls nothing.
    pub leaf_robust: Robust,
    /// The edge-direction test of a leaf's refinement, in place of the tracker's own
    /// ([`FeatureConfig::max_edge_angle_rad`](crate::features::FeatureConfig::max_edge_angle_rad);
    /// rad, π/2: off): a leaf starts turned from the hand, where the image's edges run at an
    /// angle to the predicted ones and the test would refuse the edges that pull it in.
    pub leaf_max_edge_angle_rad: f32,
    /// Whether a leaf's refinement bounds its steps at the joints' ranges, in place of the
    /// tracker's own [`EstimatorConfig::bounded_step`](crate::estimator::EstimatorConfig::bounded_step)
    /// (default false: the plain step, whatever the tracker's). The acceptance's bars were set
    /// from the scores of leaves refined by the plain step, and the bounded step fits a leaf
    /// to clutter better: on 2,000 hand-free frames of one mono rig its best leaf scored
    /// 0.936, over the one-camera bar of 0.93, against 0.915 (`docs/recovery.md`).
    pub leaf_bounded_step: bool,
    /// The share of the tracker's prior toward the predicted state that a leaf's refinement
    /// keeps, with two or more cameras (`[0]`) and with one (`[1]`); default 1, the
    /// tracker's own. A leaf is restarted fresh, so its prior pulls toward the leaf itself:
    /// toward the library's finger pose the search guessed, not toward a motion the hand
    /// made. Measured and left at 1 (`docs/recovery.md`, "Motions off mid-range"): without it
    /// stereo acquires a few more hands whose fingers are far from the library's poses but
    /// claims 13 % more wrong frames, and one camera fits leaves to clutter over the
    /// acceptance's bar.
    pub leaf_prior_share: [f32; 2],
    /// The same for the local re-acquisition's starts (1: the tracker's own), which are made
    /// from the last good state of a track, not guessed.
    pub local_prior_share: f32,
    /// The local re-acquisition after a loss also starts from the last good palm with the
    /// library's finger pose that scores best on the frame: the hand's fingers move on while
    /// it is hidden, and Gauss–Newton from the old ones can settle on a wrong pose.
    pub local_library_pose: bool,
    /// Starts refined per frame of local re-acquisition, at most (each costs
    /// `LOCAL_REFINE_PASSES` tracker passes): the followed one and the library's first, then
    /// the slid and the placed variant, these two in turn when not all fit.
    pub local_starts: u8,
    /// With two or more cameras, the local re-acquisition gives way to the global search
    /// after this many of its frames refined a start that Gauss–Newton did not lose (the hand
    /// is back in view) without accepting any (0: only after all its frames): a hand back in
    /// view that it cannot take has turned or moved farther than its variants reach. With one
    /// camera it runs all its frames: a single view's global search acquires too rarely
    /// (measured: `docs/recovery.md`).
    pub local_frames_in_view: u8,
    /// An accepted leaf (or local start) is claimed only once the next frame confirms it:
    /// the tracker does not lose it there and its worst camera scores at most this under the
    /// acceptance's worst camera (likelihood units); else the search goes on. A hypothesis
    /// fitted to clutter or noise by Gauss–Newton rarely survives a second frame; the hand
    /// does. `None`: claimed on the accepting frame itself.
    pub probation_max_drop: Option<f32>,
    /// How far the local re-acquisition's variants move the last good palm nearer and
    /// farther along the first camera's ray, as a share of its distance, with two or more
    /// cameras (`[0]`, 0.15) and with one (`[1]`, 0: not moved). One camera sees the hand's
    /// depth only through its size, and bent fingers make a nearer hand look like a farther
    /// one: a palm moved 15 % nearer was refined, accepted and held there, 90 mm from the
    /// hand and never flagged (measured: `docs/recovery.md`).
    pub local_depth_share: [f32; 2],
    /// How far (rad) the local re-acquisition's variants turn the last good palm about each
    /// of its axes (default [`LOCAL_TURN_RAD`], 0.7). While the hand is hidden the palm turns
    /// on: at 0.3 rad the held palm of a hand that came back rolled 40–50° about its finger
    /// axis was refined into a wrong hand and held (`docs/recovery.md`, "A wider turn among
    /// the local starts").
    pub local_turn_rad: f32,
    /// While confirming, another hypothesis replaces the best when its ranked score is this
    /// much more (likelihood units; default 0: the running mean below already keeps the
    /// output from flickering; the tracker's hypotheses use
    /// [`HypothesesConfig::switch_margin`](crate::hypotheses::HypothesesConfig::switch_margin)).
    pub confirm_switch_margin: f32,
    /// While confirming, how much of each hypothesis' past scores its rank keeps (default
    /// 0.6; [`HypothesesConfig::score_memory`](crate::hypotheses::HypothesesConfig::score_memory)):
    /// near leaves differ by less than a frame's noise on any one frame, and the one better
    /// over the confirming frames is the hand more often than the one better on the last.
    pub confirm_score_memory: f32,
    /// After an acquisition (a leaf or a local re-acquisition's start accepted), the tracker
    /// runs this many frames without its prior on the palm's position (default 15; 0: with
    /// it throughout). The prior holds the palm where the start put it wherever the images
    /// constrain it weakly, and one camera sees the hand's depth only through its size: an
    /// accepted leaf a few per cent off in depth was held there, its fingers bent to make up
    /// the size, instead of settling onto the hand. Afterwards the prior is back, so a long
    /// track's depth does not wander (`docs/recovery.md`, "The palm settles freely after an
    /// acquisition").
    pub settle_frames: u8,
    /// After the global search's acceptance, the confirm phase also carries the accepted
    /// state with its palm moved this share of its distance farther from and nearer to the
    /// first camera, with two or more cameras (`[0]`, default 0: not carried) and with one
    /// (`[1]`, default 0.08: 0.12 until stop 55, when 0.08 acquired 2,411 of 3,600 fresh
    /// seeds against 2,385, 57 gained and 31 lost, with 3.8 % fewer wrong claimed frames; on
    /// seed 9657, 1.1 m away, its nearer variant led from the first frame where at 0.12 the
    /// leaf, 125 mm beyond the hand, led for three; `docs/recovery.md`, "The depth share
    /// again"); a share outside (0, 1) carries none. A leaf's depth is guessed
    /// from its size under a library finger pose, and one camera sees depth only through
    /// that size: the variant refined over the confirming frames scores above a leaf placed
    /// at the wrong depth. Not after a local re-acquisition, whose starts keep the depth the
    /// track had: there a variant was taken 80–95 mm off and held, unflagged
    /// (`docs/recovery.md`, "One camera's confirm phase tries the depth again").
    pub confirm_depth_share: [f32; 2],
    /// While the confirm phase carries the depth variants, two hypotheses whose palms lie
    /// this share of the variants' offset or more apart in depth (along the first camera's
    /// ray) are rival readings of the depth (default 0.5: 4 % of the distance at the default
    /// share); not a number, or ≤ 0: none are.
    pub confirm_rival_share: f32,
    /// A confirm frame on which a rival of the best hypothesis
    /// ([`FinderConfig::confirm_rival_share`]) ranks within this of it is *undecided*: not
    /// claimed (reported searching and lost, the last claimed state held), as on probation;
    /// the tracking goes on unchanged. One camera sees depth only through the hand's size,
    /// and a leaf 125 mm beyond the hand scored level with its variant at the hand's depth to
    /// four decimals. Default 0.005 on the running mean, about one frame's noise: on 2,400
    /// fresh mono acquisitions, 12 % fewer frames claimed with the palm over 100 mm off, the
    /// claim four or five frames later on a quarter of them (`docs/recovery.md`, "A confirm
    /// phase that weighs two depths alike"). Negative or NaN: every frame claimed; infinite:
    /// none while a rival is carried.
    pub confirm_rival_margin: f32,
    /// Temporal consistency in depth while the confirm phase carries depth variants after
    /// the hand was lost: the accepted state moved along the first camera's ray to the depth
    /// of the last claimed state joins the hypotheses (when it lies a rival's distance or
    /// more from the accepted one), and each hypothesis' score loses this much per unit of
    /// its palm's relative distance in depth from that last claimed palm, up to
    /// [`FinderConfig::confirm_held_band`] ([`DepthAnchor`](crate::hypotheses::DepthAnchor);
    /// 0, negative or NaN: neither). Default 1: on 160 fresh mono seeds hidden for 90 frames
    /// (so the global search takes them back), frames claimed after the return with the palm
    /// over 100 mm from the truth fell from 404 to 3 and over 30 mm from 2,626 to 782, and the
    /// hand was taken back on 70 of the 143 tracked to the blackout instead of 65
    /// (`docs/recovery.md`, "The depth the hand was last claimed at").
    pub confirm_held_weight: f32,
    /// The relative distance in depth past which [`FinderConfig::confirm_held_weight`]'s
    /// penalty grows no more (default 0.12: one camera reads a hand 8–11 % nearer or
    /// farther, its fingers bent to match, as well as the right one). Beyond it the penalty is
    /// flat, so among hypotheses there the image decides, as for a hand that came back at
    /// another depth (by design: the sweep's motions stay within the band). Not positive, or
    /// NaN: no penalty.
    pub confirm_held_band: f32,
    /// A leaf of the global search refused by the acceptance but scoring at least this, with
    /// two or more cameras (`[0]`) and with one (`[1]`), is pursued: refined again on each of
    /// the next [`FinderConfig::pursue_frames`] searching frames (one tracker pass a frame),
    /// beside the search, and judged by the same acceptance every time; it is dropped when
    /// it scores under this. One camera's leaves come within a few pixels of the hand but
    /// score under the bar on the frame they are refined on, and Gauss–Newton on the next
    /// frames brings some onto it (`docs/recovery.md`, "A refused leaf pursued").
    pub pursue_score: [f32; 2],
    /// Frames a refused leaf is pursued for, with two or more cameras (`[0]`, default 0:
    /// never) and with one (`[1]`, default 2). More frames acquire a little more and let a
    /// leaf creep onto a still cluttered scene: at 6, 148 of 1,000 hand-free frames of one
    /// still scene were claimed.
    pub pursue_frames: [u8; 2],
    /// When a confirm phase ends, each finger of its best is given the library's pose that
    /// scores best on the frame ([`Acquirer::polish_fingers`](super::Acquirer::polish_fingers));
    /// when that raises the score by more than this, with two or more cameras (`[0]`) and
    /// with one (`[1]`), the polished state is carried beside the best for another
    /// [`FinderConfig::confirm_frames`] frames (negative or NaN: never polished). Default 0
    /// with two cameras, off with one: two cameras' re-acquisitions after a blackout are
    /// held off the hand with the palm right and a finger or two wrong, and polished they
    /// came back more often (288 of 323 seeds against 281); one camera's likelihood cannot
    /// tell a polished finger from a wrong one (mono acquisition 463 of 600 either way;
    /// `docs/recovery.md`, "The fingers polished after a confirm phase").
    pub polish_margin: [f32; 2],
}

impl FinderConfig {
    /// The share of the palm's distance that the confirm phase's depth variants move it, with
    /// `n_cameras` cameras ([`FinderConfig::confirm_depth_share`]); `None` when none are
    /// carried (a share outside (0, 1): 1 or more would put the nearer palm at or behind the
    /// camera).
    pub fn confirm_depth(&self, n_cameras: usize) -> Option<f32> {
        let share = self.confirm_depth_share[usize::from(n_cameras < 2)];
        (share > 0.0 && share < 1.0).then_some(share)
    }

    /// How far apart (mm) in depth two confirm-phase hypotheses are rivals after an
    /// acceptance `leaf_depth_mm` from the first camera with `n_cameras` cameras
    /// ([`FinderConfig::confirm_rival_share`]); `None`: no rivals (no depth variants, the
    /// share off, or the margin negative or NaN).
    pub fn confirm_rival_mm(&self, n_cameras: usize, leaf_depth_mm: f32) -> Option<f32> {
        let variants = self.confirm_depth(n_cameras)?;
        let share = self.confirm_rival_share;
        (share > 0.0 && self.confirm_rival_margin >= 0.0)
            .then_some(share * variants * leaf_depth_mm)
    }

    /// Hypotheses the confirm phase may carry after the global search's acceptance with
    /// `n_cameras` cameras: [`FinderConfig::confirm_hypotheses`], and the two depth variants
    /// when they are carried.
    pub fn confirm_capacity(&self, n_cameras: usize) -> u8 {
        let variants = if self.confirm_depth(n_cameras).is_some() {
            DEPTH_VARIANTS + HELD_VARIANTS * u8::from(self.confirm_held_weight > 0.0)
        } else {
            0
        };
        self.confirm_hypotheses.saturating_add(variants)
    }

    /// How much [`FinderConfig::polish_margin`] asks of a polished state with `n_cameras`
    /// cameras; `None`: not polished.
    pub fn polish(&self, n_cameras: usize) -> Option<f32> {
        let margin = self.polish_margin[usize::from(n_cameras < 2)];
        (margin >= 0.0).then_some(margin)
    }

    /// What a leaf's refinement runs the tracker under, from the tracker's own `config` and
    /// cameras: this search's robust weight, edge test and step, and
    /// [`FinderConfig::leaf_prior_share`] of its prior.
    pub fn leaf_overrides(&self, config: &TrackerConfig, n_cameras: usize) -> RefineOverrides {
        let share = self.leaf_prior_share[usize::from(n_cameras < 2)];
        self.overrides(config, share)
    }

    /// What a local re-acquisition's start's refinement runs the tracker under: as a leaf's,
    /// with [`FinderConfig::local_prior_share`] of the tracker's prior.
    pub fn local_overrides(&self, config: &TrackerConfig) -> RefineOverrides {
        self.overrides(config, self.local_prior_share)
    }

    fn overrides(&self, config: &TrackerConfig, prior_share: f32) -> RefineOverrides {
        let own = config.motion.prior;
        let share = if prior_share.is_finite() {
            prior_share.clamp(0.0, 1.0)
        } else {
            1.0
        };
        RefineOverrides {
            robust: self.leaf_robust,
            max_edge_angle_rad: self.leaf_max_edge_angle_rad,
            bounded_step: self.leaf_bounded_step,
            prior: PriorWeights {
                quaternion: own.quaternion * share,
                translation: own.translation * share,
                joint: own.joint * share,
            },
            iterations: self.refine_iterations,
        }
    }
}

impl Default for FinderConfig {
    fn default() -> Self {
        FinderConfig {
            leaves_per_frame: 2,
            leaves: 4,
            passes_per_leaf: 2,
            refine_iterations: 8,
            accept: AcceptConfig::default(),
            replace_leaves: true,
            confirm_frames: 5,
            confirm_hypotheses: 4,
            alternative_score: 0.85,
            confirm_min_score: 0.0,
            leaf_robust: Robust::Huber(2.0),
            leaf_max_edge_angle_rad: core::f32::consts::FRAC_PI_2,
            leaf_bounded_step: false,
            leaf_prior_share: [1.0, 1.0],
            local_prior_share: 1.0,
            local_library_pose: true,
            local_starts: 3,
            local_frames_in_view: 8,
            probation_max_drop: Some(0.10),
            local_depth_share: [0.15, 0.0],
            local_turn_rad: LOCAL_TURN_RAD,
            confirm_switch_margin: 0.0,
            confirm_score_memory: 0.6,
            settle_frames: 15,
            confirm_depth_share: [0.0, 0.08],
            confirm_rival_share: 0.5,
            confirm_rival_margin: 0.005,
            confirm_held_weight: 1.0,
            confirm_held_band: 0.12,
            pursue_score: [0.85, 0.88],
            pursue_frames: [0, 2],
            polish_margin: [0.0, -1.0],
        }
    }
}

/// How far the local re-acquisition's variants turn the last good state's palm by default
/// (rad; [`FinderConfig::local_turn_rad`]).
pub const LOCAL_TURN_RAD: f32 = 0.7;

/// Depth variants the confirm phase carries, when it carries them: the palm farther and
/// nearer.
pub const DEPTH_VARIANTS: u8 = 2;

/// Hypotheses the confirm phase adds at the last claimed state's depth, when it adds them
/// ([`FinderConfig::confirm_held_weight`]).
pub const HELD_VARIANTS: u8 = 1;

/// What one searching frame did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FinderStep {
    /// No hand claimed.
    Searching {
        /// Evaluations the search spent on this frame.
        evaluated: u16,
        /// Leaves refined on this frame.
        refined: u8,
        /// The best judgement of a leaf refined on this frame, if any was.
        best_leaf: Option<Verdict>,
    },
    /// A refined leaf was accepted: the tracker holds it (restarted fresh) and tracks from it
    /// on the next frame.
    Found {
        /// Its judgement.
        verdict: Verdict,
        /// The tracker's report of its refinement on this frame.
        report: FrameReport,
    },
}

/// The search, its leaves' refinement and acceptance.
#[derive(Debug, Clone)]
pub struct Finder {
    acquirer: Acquirer,
    config: FinderConfig,
    /// Leaves still to refine, the best last (popped first).
    leaves: Vec<[f32; MAX_STATES], MAX_KEEP>,
    /// The best leaf refined on the last frame, and its judgement.
    last: Option<(Verdict, [f32; MAX_STATES])>,
    /// After [`FinderStep::Found`]: the accepted leaf, then the leaves refined with it that
    /// scored at least [`FinderConfig::alternative_score`], then the leaves not yet refined
    /// (best first).
    found: Vec<[f32; MAX_STATES], MAX_KEEP>,
}

impl Finder {
    /// A finder around `acquirer`.
    pub fn new(acquirer: Acquirer, config: FinderConfig) -> Self {
        Finder {
            acquirer,
            config,
            leaves: Vec::new(),
            last: None,
            found: Vec::new(),
        }
    }

    /// The search.
    pub fn acquirer(&self) -> &Acquirer {
        &self.acquirer
    }

    /// The parameters.
    pub fn config(&self) -> &FinderConfig {
        &self.config
    }

    /// The search, to place or score hypotheses outside its own steps (the local
    /// re-acquisition).
    pub fn acquirer_mut(&mut self) -> &mut Acquirer {
        &mut self.acquirer
    }

    /// New parameters for the leaves refined from now on.
    pub fn set_config(&mut self, config: FinderConfig) {
        self.config = config;
    }

    /// New acceptance thresholds for the leaves judged from now on.
    pub fn set_accept(&mut self, accept: AcceptConfig) {
        self.config.accept = accept;
    }

    /// The best leaf refined on the last frame (the whole state) and its judgement, if a
    /// leaf was refined on it.
    pub fn last_leaf(&self) -> Option<&(Verdict, [f32; MAX_STATES])> {
        self.last.as_ref()
    }

    /// After [`FinderStep::Found`], the leaves worth carrying as hypotheses: the accepted
    /// one first (refined on the frame), then the other good refined leaves, then the
    /// leaves not yet refined; empty otherwise.
    pub fn found_leaves(&self) -> &[[f32; MAX_STATES]] {
        &self.found
    }

    /// Starts over (the hand was lost).
    pub fn restart(&mut self) {
        self.acquirer.restart();
        self.leaves.clear();
    }

    /// One searching frame: `frames[i]` is camera `i`'s and `edges[i]` its edge map (built
    /// once for this frame). `tracker` is used to refine leaves; after [`FinderStep::Found`]
    /// it holds the accepted state, otherwise its state is not to be trusted.
    pub fn step(
        &mut self,
        tracker: &mut Tracker,
        frames: &[FrameView<'_>],
        edges: &[EdgeMap<'_>],
    ) -> Result<FinderStep, TrackerError> {
        self.step_after(tracker, frames, edges, 0)
    }

    /// [`Finder::step`] on a frame that has already spent `spent` evaluations of the
    /// search's budget elsewhere: the search spends only what is left
    /// ([`Acquirer::step_after`]), and a frame of leaves refines one leaf fewer (at least
    /// one) when anything was spent.
    pub fn step_after(
        &mut self,
        tracker: &mut Tracker,
        frames: &[FrameView<'_>],
        edges: &[EdgeMap<'_>],
        spent: u16,
    ) -> Result<FinderStep, TrackerError> {
        self.last = None;
        self.found.clear();
        if self.leaves.is_empty() {
            let progress = self.acquirer.step_after(
                &Scene::new(tracker.model(), tracker.cameras(), frames, edges),
                spent,
            );
            let evaluated = match progress {
                Progress::Searching { evaluated } => evaluated,
                Progress::Found(_) => {
                    let take = usize::from(self.config.leaves.max(1));
                    for c in self.acquirer.best().iter().take(take).rev() {
                        // At most MAX_KEEP: cannot overflow.
                        let _ = self.leaves.push(c.q);
                    }
                    // What the search's last step spent on this frame.
                    self.acquirer.last_step_cost
                }
            };
            // The leaves are refined from the next frame on: this one's budget is spent.
            return Ok(FinderStep::Searching {
                evaluated,
                refined: 0,
                best_leaf: None,
            });
        }
        let n = tracker.model().n_states().min(MAX_STATES);
        let mut refined_now: Vec<(Verdict, [f32; MAX_STATES], FrameReport), MAX_KEEP> = Vec::new();
        // Work spent elsewhere on this frame takes one leaf's place (at least one is refined).
        let most = self
            .config
            .leaves_per_frame
            .max(1)
            .saturating_sub(u8::from(spent > 0))
            .max(1);
        while refined_now.len() < usize::from(most) {
            let Some(mut leaf) = self.leaves.pop() else {
                break;
            };
            if self.config.replace_leaves {
                let cameras = tracker.cameras();
                let n_cameras = cameras.len().min(MAX_CAMERAS);
                self.acquirer
                    .replace(tracker.model(), &cameras[..n_cameras], edges, &mut leaf);
            }
            let (verdict, q, report) = self.refine(tracker, frames, edges, &leaf, n)?;
            // At most leaves_per_frame ≤ MAX_KEEP items are kept; a full list drops the rest.
            let _ = refined_now.push((verdict, q, report));
        }
        let refined = refined_now.len() as u8;
        let best = refined_now
            .iter()
            .enumerate()
            .max_by(|(_, (a, _, _)), (_, (b, _, _))| {
                (a.accepted, a.score)
                    .partial_cmp(&(b.accepted, b.score))
                    .unwrap_or(core::cmp::Ordering::Equal)
            })
            .map(|(i, _)| i);
        self.last = best
            .and_then(|i| refined_now.get(i))
            .map(|(v, q, _)| (*v, *q));
        match best.and_then(|i| refined_now.get(i).map(|b| (i, *b))) {
            Some((i, (verdict, q, report))) if verdict.accepted => {
                tracker.restart_fresh(&q[..n])?;
                self.found.clear();
                let _ = self.found.push(q);
                for (j, (v, other, _)) in refined_now.iter().enumerate() {
                    if j != i && !v.lost && v.score >= self.config.alternative_score {
                        let _ = self.found.push(*other);
                    }
                }
                while let Some(leaf) = self.leaves.pop() {
                    if self.found.push(leaf).is_err() {
                        break;
                    }
                }
                self.leaves.clear();
                Ok(FinderStep::Found { verdict, report })
            }
            best => {
                if self.leaves.is_empty() {
                    self.acquirer.restart();
                }
                Ok(FinderStep::Searching {
                    evaluated: 0,
                    refined,
                    best_leaf: best.map(|(_, (v, _, _))| v),
                })
            }
        }
    }

    /// `leaf` refined by the tracker's Gauss–Newton ([`FinderConfig::passes_per_leaf`] fresh
    /// passes on the frame, weighted by [`FinderConfig::leaf_robust`] with the edge test of
    /// [`FinderConfig::leaf_max_edge_angle_rad`] and [`FinderConfig::leaf_bounded_step`]), scored in every
    /// camera and judged. The tracker keeps its own robust weight afterwards.
    fn refine(
        &mut self,
        tracker: &mut Tracker,
        frames: &[FrameView<'_>],
        edges: &[EdgeMap<'_>],
        leaf: &[f32; MAX_STATES],
        n: usize,
    ) -> Result<(Verdict, [f32; MAX_STATES], FrameReport), TrackerError> {
        let overrides = self
            .config
            .leaf_overrides(tracker.config(), tracker.cameras().len());
        tracker.restart_fresh(&leaf[..n])?;
        let mut report = tracker.track_under(&overrides, frames)?;
        for _ in 1..self.config.passes_per_leaf.max(1) {
            if report.lost {
                break;
            }
            // Again from where it got to, as a fresh start (no velocity from the pass).
            let mut q = [0.0f32; MAX_STATES];
            for (d, s) in q.iter_mut().zip(tracker.state()) {
                *d = *s;
            }
            tracker.restart_fresh(&q[..n])?;
            report = tracker.track_under(&overrides, frames)?;
        }
        let mut q = [0.0f32; MAX_STATES];
        for (d, s) in q.iter_mut().zip(tracker.state()) {
            *d = *s;
        }
        let accept = self.config.accept;
        let leaf = if report.lost {
            LeafScore::default()
        } else {
            let cameras = tracker.cameras();
            let n_cameras = cameras.len().min(MAX_CAMERAS);
            let scene = Scene::new(tracker.model(), &cameras[..n_cameras], frames, edges);
            self.acquirer.leaf_score(&scene, &q, &accept)
        };
        Ok((
            accept.judge(tracker.cameras().len(), leaf, report.lost),
            q,
            report,
        ))
    }
}
