//! The image's word on a track (issue 9): every few tracking frames the tracked state is
//! scored by the [likelihood](crate::likelihood) in every camera, and a state that some camera
//! does not support is a lost frame, however well the slices fit.
//!
//! The tracker's own `lost` flag comes from feature counts, the residual and the silhouette;
//! a track that settled on the wrong fingers' edges keeps all three healthy. The likelihood
//! scores the whole projected model — oriented chamfer along every silhouette line and the
//! region's agreement — so such a track scores low.
//!
//! The bar is relative: the first frame checked (the given initial state's, or the first
//! acquisition's) sets the *reference*, and a later check fails when the worst camera scores
//! more than [`WatchConfig::max_drop`] under it. The reference is kept through losses and
//! re-acquisitions: the scene's scale does not change, and a wrong re-acquisition must not
//! set its own bar. The score's scale depends on the images (contrast,
//! edges, renderer): a right track of the independent renderer's `sample-mouse` fixture scores
//! 0.80–0.88, of our own random rigs 0.89–0.97, so no fixed bar fits both. Measured on the
//! robustness sweep's rigs (seeds 61–80, 640×480, 200 frames, `host/examples/watch_study.rs`):
//! a drop of 0.10 flagged 260 of the 825 frames the tracker claimed while truly wrong, and 1 of
//! the 2,411 right ones; 0.08 flagged 326 and 8.
//!
//! While a check fails the track is *in doubt*: every frame is checked until one passes.
//!
//! A check can also ask how much of the image's edges near the hand the state leaves
//! unexplained (the reverse chamfer term, [`WatchConfig::max_reverse_px`]); off by default:
//! it flagged right tracks too (docs/robustness.md, "The reverse term as a bar of the watch").

/// When and how strictly the track is checked.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WatchConfig {
    /// A tracking frame is checked once every this many (0: never checked), whatever the
    /// frame's size. A check builds each camera's edge map over the cells around the tracked
    /// hand only, so its cost follows the hand's size in the image, not the frame's: a quarter
    /// to a third of a whole-hand tracking frame at 640×480 (docs/performance.md, "Edge maps
    /// for a score"). (Before stop 61 a check built the whole frame's maps, and larger frames
    /// were checked proportionally less often: every 32 frames at 640×480.)
    pub every_frames: u8,
    /// How far (likelihood units, 0..=1) the worst camera's score may fall under the
    /// track's reference.
    pub max_drop: f32,
    /// The checks weigh the [reverse chamfer term](crate::likelihood) (the edges near the
    /// hand that no model line explains) by this, whatever the search's own weight
    /// ([`LikelihoodConfig::reverse_weight`](crate::likelihood::LikelihoodConfig)); 0, the
    /// default, leaves it out. The search's likelihood is otherwise the watch's.
    pub reverse_weight: f32,
    /// A check also fails when the tracked state leaves more than this of the [reverse
    /// chamfer term](crate::likelihood) in its worst camera (px: the mean distance from the
    /// edges near the hand to the nearest line of it that could explain them);
    /// `f32::INFINITY`, the default, asks nothing of it and computes nothing.
    pub max_reverse_px: f32,
    /// The reverse term's bar applies only to a check whose worst camera scores at least this
    /// much (likelihood units) under the track's reference: a weaker drop than
    /// [`Self::max_drop`], confirmed by the edges left unexplained. 0: whatever the score.
    pub reverse_min_drop: f32,
}

impl Default for WatchConfig {
    fn default() -> Self {
        WatchConfig {
            every_frames: 8,
            max_drop: 0.10,
            reverse_weight: 0.0,
            max_reverse_px: f32::INFINITY,
            reverse_min_drop: 0.0,
        }
    }
}

/// What the watch keeps between frames.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Watch {
    config: WatchConfig,
    /// A check every this many tracking frames (0: never).
    period_frames: u16,
    /// Tracking frames since the last check.
    since_check: u16,
    /// The last check failed.
    doubted: bool,
    /// The worst camera's score on the track's first checked frame.
    reference: Option<f32>,
}

impl Watch {
    /// A watch that checks as `config` says.
    pub fn new(config: WatchConfig) -> Self {
        Watch {
            config,
            period_frames: u16::from(config.every_frames),
            since_check: 0,
            doubted: false,
            reference: None,
        }
    }

    /// The parameters.
    pub fn config(&self) -> &WatchConfig {
        &self.config
    }

    /// A check falls due every this many tracking frames (0: never).
    pub fn period_frames(&self) -> u16 {
        self.period_frames
    }

    /// Whether this tracking frame is to be checked (and counts it).
    pub fn due(&mut self) -> bool {
        if self.period_frames == 0 {
            return false;
        }
        self.since_check = self.since_check.saturating_add(1);
        self.doubted || self.reference.is_none() || self.since_check >= self.period_frames
    }

    /// The track's reference score, once its first frame has been checked.
    pub fn reference(&self) -> Option<f32> {
        self.reference
    }

    /// Whether a check reads the reverse chamfer term (a finite
    /// [`WatchConfig::max_reverse_px`]): only then need a caller compute it.
    pub fn weighs_reverse(&self) -> bool {
        self.config.max_reverse_px.is_finite()
    }

    /// Takes a check's worst camera score and reverse term (px; `None` when not computed or
    /// no edge lay near the hand); returns whether the state passed. The track's first finite
    /// score becomes its reference and passes, unless its reverse term is over the bar.
    pub fn judge(&mut self, worst_camera_score: f32, reverse_px: Option<f32>) -> bool {
        self.since_check = 0;
        let min_drop = self.config.reverse_min_drop;
        let dropped = min_drop <= 0.0
            || self
                .reference
                .is_some_and(|reference| worst_camera_score < reference - min_drop);
        let explains_its_edges =
            !dropped || reverse_px.is_none_or(|px| px <= self.config.max_reverse_px);
        let scored = worst_camera_score.is_finite()
            && match self.reference {
                None => {
                    self.reference = Some(worst_camera_score);
                    true
                }
                Some(reference) => worst_camera_score >= reference - self.config.max_drop,
            };
        let passed = scored && explains_its_edges;
        self.doubted = !passed;
        passed
    }

    /// Forgets the doubt (the hand was acquired again); the reference is kept.
    pub fn clear(&mut self) {
        self.since_check = 0;
        self.doubted = false;
    }

    /// The last check failed and no check has passed since.
    pub fn doubted(&self) -> bool {
        self.doubted
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn every(n: u8) -> Watch {
        Watch::new(WatchConfig {
            every_frames: n,
            max_drop: 0.1,
            ..WatchConfig::default()
        })
    }

    #[test]
    fn the_period_is_the_configured_one() {
        assert_eq!(Watch::new(WatchConfig::default()).period_frames(), 8);
        assert_eq!(every(0).period_frames(), 0);
        assert_eq!(every(u8::MAX).period_frames(), 255);
    }

    #[test]
    fn the_first_frame_sets_the_reference_then_a_check_falls_due_every_n_frames() {
        let mut w = every(3);
        assert!(w.due());
        assert!(w.judge(0.9, None));
        assert_eq!(w.reference(), Some(0.9));
        let due: [bool; 6] = core::array::from_fn(|_| {
            let d = w.due();
            if d {
                assert!(w.judge(0.85, None));
            }
            d
        });
        assert_eq!(due, [false, false, true, false, false, true]);
    }

    #[test]
    fn a_drop_beyond_the_margin_fails_and_is_checked_every_frame_until_a_pass() {
        let mut w = every(4);
        assert!(w.due() && w.judge(0.95, None));
        assert!(!w.due() && !w.due() && !w.due() && w.due());
        assert!(!w.judge(0.84, None));
        assert!(w.doubted());
        assert!(w.due() && !w.judge(f32::NAN, None));
        assert!(w.due() && w.judge(0.86, None));
        assert!(!w.doubted() && !w.due());
    }

    #[test]
    fn clearing_forgets_the_doubt_and_keeps_the_reference() {
        let mut w = every(4);
        assert!(w.due() && w.judge(0.95, None));
        w.due();
        assert!(!w.judge(0.5, None));
        w.clear();
        assert!(!w.doubted() && !w.due());
        assert_eq!(w.reference(), Some(0.95));
        assert!(!w.due() && !w.due() && w.due());
        assert!(!w.judge(0.6, None));
    }

    #[test]
    fn a_nan_first_score_sets_no_reference() {
        let mut w = every(4);
        assert!(w.due() && !w.judge(f32::NAN, None));
        assert!(w.reference().is_none() && w.due());
    }

    #[test]
    fn a_watch_every_zero_frames_never_checks() {
        let mut w = every(0);
        assert!((0..100).all(|_| !w.due()));
    }

    /// A watch checking every frame with a bar on the reverse term.
    fn reverse_barred(max_reverse_px: f32, reverse_min_drop: f32) -> Watch {
        Watch::new(WatchConfig {
            every_frames: 1,
            max_reverse_px,
            reverse_min_drop,
            ..WatchConfig::default()
        })
    }

    #[test]
    fn edges_left_unexplained_fail_a_check_only_under_a_finite_bar() {
        let mut plain = every(1);
        assert!(!plain.weighs_reverse());
        assert!(plain.due() && plain.judge(0.95, Some(9.0)));
        let mut barred = reverse_barred(4.0, 0.0);
        assert!(barred.weighs_reverse());
        assert!(barred.due() && barred.judge(0.95, Some(3.0)));
        assert!(
            barred.due() && !barred.judge(0.95, Some(4.5)),
            "over the bar"
        );
        assert!(
            barred.doubted() && barred.due(),
            "in doubt: checked every frame"
        );
        assert!(
            barred.judge(0.95, None),
            "no edge near the hand: nothing against it"
        );
        assert!(barred.due() && !barred.judge(0.95, Some(f32::NAN)));
        assert!(
            barred.due() && !barred.judge(0.80, Some(3.0)),
            "the score still counts"
        );
        assert_eq!(barred.reference(), Some(0.95));
    }

    #[test]
    fn with_a_minimum_drop_the_reverse_bar_only_confirms_a_falling_score() {
        let mut w = reverse_barred(4.0, 0.03);
        for (score, reverse_px, passes, why) in [
            (0.95, 9.0, true, "no reference yet: no drop"),
            (0.94, 9.0, true, "0.01 under: the edges not asked"),
            (0.90, 4.5, false, "0.05 under and over the bar"),
            (0.90, 3.5, true, "0.05 under, within the bar"),
            (0.80, 1.0, false, "the score's own bar still counts"),
        ] {
            assert!(w.due());
            assert_eq!(w.judge(score, Some(reverse_px)), passes, "{why}");
        }
    }
}
