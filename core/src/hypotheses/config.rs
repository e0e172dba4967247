//! How many hypotheses, how they are sampled, merged and chosen.

use super::DepthAnchor;
use crate::config::{MAX_HYPOTHESES, MAX_JUMPS, MAX_SPAWN};
use crate::likelihood::LikelihoodConfig;
use crate::state::StateKind;

/// The size of a "unit" change of each kind of state: weak directions are found in these
/// units (so millimetres and radians compare), samples step in them, and two hypotheses closer
/// than [`HypothesesConfig::merge_distance`] of them in every state are one.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Spread {
    /// One quaternion component (unitless; 0.05 is about 6° of palm rotation).
    pub quaternion: f32,
    /// One translation state (mm).
    pub translation_mm: f32,
    /// One joint angle (rad).
    pub joint_rad: f32,
}

impl Spread {
    /// The unit of state `i`.
    #[inline]
    pub fn for_state(&self, i: usize) -> f32 {
        StateKind::of(i).pick(self.quaternion, self.translation_mm, self.joint_rad)
    }
}

impl Default for Spread {
    fn default() -> Self {
        Spread {
            quaternion: 0.05,
            translation_mm: 10.0,
            joint_rad: 0.35,
        }
    }
}

/// Parameters of the multiple-hypothesis tracker.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HypothesesConfig {
    /// Hypotheses carried between frames, 1..=[`MAX_HYPOTHESES`] (1 is the single tracker,
    /// bit for bit).
    pub count: u8,
    /// New hypotheses sampled per frame, 0..=[`MAX_SPAWN`]: pairs on either side of the best
    /// along its weakest directions.
    pub spawn_per_frame: u8,
    /// Fingers jumped to their other reading per scored frame, 0..=[`MAX_JUMPS`]: the
    /// fingers of the best whose jump ([`jump`](super::jump)) moves them least in the image.
    /// They take the places of samples: past [`MAX_SPAWN`] samples and jumps together, the
    /// last jumps are left out.
    /// Default 0 (none computed): on three fresh sets of 60 seeds, two jumps at K = 4
    /// shortened the track life and raised the joint error in every group; under
    /// [`HypothesesConfig::motion_weight`] they are neutral (`docs/hypotheses.md`, "Kinematic
    /// jumps").
    pub jumps_per_frame: u8,
    /// A jump turns its pivot joint by at least this much (rad).
    pub jump_min_turn_rad: f32,
    /// A jump is weighed only when it moves the finger's link ends at most this far in the
    /// image, on the mean over the cameras (px): the readings the cameras see alike.
    pub jump_max_moved_px: f32,
    /// Also weigh, every frame, the best with each finger's update undone (the finger where
    /// it was on the last frame), and with every finger's undone: a finger the slices pulled
    /// onto a neighbour's edges scores worse than where it was.
    pub keep_fingers: bool,
    /// Gauss–Newton iterations at most for each sample on the frame it is drawn (0: the
    /// tracker's own). Default 0: at 2 (with [`HypothesesConfig::other_iterations`]) K = 4
    /// costs a third less a frame and, on fresh seeds, gives back part of its gain
    /// (`docs/hypotheses.md`, "Fewer iterations for the hypotheses other than the best").
    pub sample_iterations: u8,
    /// Gauss–Newton iterations at most for each carried hypothesis other than the best (0:
    /// the tracker's own). The best always takes the tracker's own number.
    pub other_iterations: u8,
    /// On the frames between scored ones ([`HypothesesConfig::score_every_frames`]), track
    /// the hypotheses other than the best without region rows and without the silhouette
    /// check ([`Tracker::track_light`](crate::tracker::Tracker::track_light)): their reports
    /// are not read until the next scored frame tracks them in full. Default false.
    pub light_others: bool,
    /// Units of the state kinds.
    pub spread: Spread,
    /// How far a sample lies from the best along a weak direction (in [`Spread`] units).
    pub spawn_step: f32,
    /// Two hypotheses are one when no state differs by more than this (in [`Spread`] units).
    pub merge_distance: f32,
    /// Another hypothesis replaces the best only when it scores this much more (likelihood
    /// units, 0..1): temporal consistency, so the output does not flicker between near ties.
    pub switch_margin: f32,
    /// Taken off the score of a hypothesis whose frame the tracker flagged lost.
    pub lost_penalty: f32,
    /// Temporal consistency: taken off a candidate's score per squared [`Spread`] unit by
    /// which its state departs from its parent's prediction (the state it was carried from,
    /// moved on by that state's velocity), summed over the free states. A carried hypothesis'
    /// parent is itself; a sample, a jump or a finger undone descends from the best. Default
    /// 0.05: at K = 4 against K = 4 without it, on fresh seeds, the mono joint error falls on
    /// every set and the share of frames held rises (`docs/hypotheses.md`, "Temporal
    /// consistency"). The search's confirm phase ranks its leaves without it.
    pub motion_weight: f32,
    /// Temporal consistency in depth: [`DepthAnchor::penalty`] taken off each candidate's
    /// score; `None` by default (the search's confirm phase sets it after a loss:
    /// [`FinderConfig::confirm_held_weight`](crate::acquire::FinderConfig::confirm_held_weight)).
    pub depth_anchor: Option<DepthAnchor>,
    /// How much of a carried hypothesis' past scores its rank keeps, 0..=1: each scored
    /// frame its ranked score becomes `memory × past + (1 − memory) × score` (0: ranked by
    /// this frame's score alone). A frame's score is noisy by about 0.005 between near
    /// readings; a hypothesis better over several frames is the one to keep.
    pub score_memory: f32,
    /// The hypotheses are scored, sampled around and merged on one frame in this many
    /// (0 and 1: every frame), and on every frame after one whose best the tracker flagged
    /// lost; on the frames between, each is only tracked, keeping its rank and last score.
    /// A scored frame costs the edge map of every camera, the samples' tracking and the
    /// scores: most of what K > 1 adds to a frame (docs/hypotheses.md).
    pub score_every_frames: u8,
    /// The image likelihood that scores them (with the reverse chamfer term at
    /// [`HYPOTHESES_REVERSE_WEIGHT`] by default).
    pub likelihood: LikelihoodConfig,
}

/// The weight of the reverse chamfer term (edges near the hand no model line explains) in
/// the hypotheses' likelihood: measured on the robustness sweep, it ranks a frame's
/// hypotheses nearer the truth (docs/hypotheses.md, "The reverse chamfer term").
pub const HYPOTHESES_REVERSE_WEIGHT: f32 = 0.8;

impl HypothesesConfig {
    /// `count` clamped to 1..=[`MAX_HYPOTHESES`].
    pub fn count(&self) -> usize {
        usize::from(self.count).clamp(1, MAX_HYPOTHESES)
    }

    /// `spawn_per_frame` clamped to [`MAX_SPAWN`], and to 0 for a single hypothesis.
    pub fn spawn(&self) -> usize {
        if self.count() == 1 {
            0
        } else {
            usize::from(self.spawn_per_frame).min(MAX_SPAWN)
        }
    }

    /// The cap on the Gauss–Newton iterations of the carried hypothesis of rank `rank` (0 is
    /// the best, never capped): [`HypothesesConfig::other_iterations`] for the others, 0 for
    /// the tracker's own number.
    pub fn carried_iterations(&self, rank: usize) -> u8 {
        if rank == 0 {
            0
        } else {
            self.other_iterations
        }
    }

    /// `jumps_per_frame` clamped to [`MAX_JUMPS`], and to 0 for a single hypothesis.
    pub fn jumps(&self) -> usize {
        if self.count() == 1 {
            0
        } else {
            usize::from(self.jumps_per_frame).min(MAX_JUMPS)
        }
    }
}

impl Default for HypothesesConfig {
    fn default() -> Self {
        HypothesesConfig {
            count: 1,
            spawn_per_frame: 2,
            jumps_per_frame: 0,
            jump_min_turn_rad: 0.3,
            jump_max_moved_px: 4.0,
            keep_fingers: true,
            sample_iterations: 0,
            other_iterations: 0,
            light_others: false,
            spread: Spread::default(),
            spawn_step: 1.0,
            merge_distance: 0.3,
            switch_margin: 0.01,
            lost_penalty: 0.2,
            motion_weight: 0.05,
            depth_anchor: None,
            score_memory: 0.0,
            score_every_frames: 1,
            likelihood: LikelihoodConfig {
                reverse_weight: HYPOTHESES_REVERSE_WEIGHT,
                ..LikelihoodConfig::default()
            },
        }
    }
}
