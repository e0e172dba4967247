//! Whether a refined leaf is the hand: its likelihood (and, with one camera, how much of
//! the image's edges near it it leaves unexplained) against thresholds set from measured
//! distributions (docs/recovery.md): the refined leaf's score on frames with the hand where
//! it is right, where it is wrong, and on frames with no hand (plain, noisy, cluttered).

/// The thresholds.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AcceptConfig {
    /// With two or more cameras, the mean likelihood score over the cameras a leaf needs
    /// (0..=1).
    pub min_score: f32,
    /// With two or more cameras, the score every camera must reach on its own (0..=1): a
    /// leaf that fits one view and not the other is not the hand.
    pub min_camera_score: f32,
    /// With one camera, the score a leaf needs (0..=1). A single view is fooled by clutter
    /// more easily: refined leaves on hand-free frames reach 0.93–0.95 in one camera, under
    /// 0.88 in the worse of two (docs/recovery.md).
    pub one_camera_score: f32,
    /// With two or more cameras, the largest [reverse chamfer term](crate::likelihood) a
    /// leaf may leave in its worst camera (px; `f32::INFINITY`: not asked, not computed):
    /// edges near the hand that no line of it explains, as a wrong reading leaves them.
    pub max_reverse_px: f32,
    /// The same with one camera (px; `f32::INFINITY`: not asked). A single view's wrong
    /// leaves pass its score bar far more often than two views' do; right leaves leave a
    /// median 2.8 px, wrong ones 3.8 px, and 3.5 px keeps nine right leaves in ten
    /// (docs/recovery.md, "A bar on the reverse term itself").
    pub one_camera_max_reverse_px: f32,
}

impl Default for AcceptConfig {
    fn default() -> Self {
        AcceptConfig {
            min_score: 0.91,
            min_camera_score: 0.91,
            one_camera_score: 0.93,
            max_reverse_px: f32::INFINITY,
            one_camera_max_reverse_px: 3.5,
        }
    }
}

/// The judgement of one refined leaf.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Verdict {
    /// Mean likelihood score over the cameras.
    pub score: f32,
    /// The worst camera's score.
    pub worst_camera: f32,
    /// The worst camera's reverse chamfer term (px), when the thresholds ask for it and an
    /// edge lay near the hand.
    pub reverse_px: Option<f32>,
    /// Gauss–Newton lost it (too few features, or the residual exploded).
    pub lost: bool,
    /// Taken for the hand.
    pub accepted: bool,
}

/// What the acceptance reads of a refined leaf: its likelihood scores, and its reverse term
/// when the thresholds ask for it ([`AcceptConfig::weighs_reverse`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LeafScore {
    /// Mean likelihood score over the cameras (0..=1).
    pub score: f32,
    /// The worst camera's score (0..=1).
    pub worst_camera: f32,
    /// The worst camera's reverse chamfer term (px): `None` when not computed, or no edge
    /// lay near the hand.
    pub reverse_px: Option<f32>,
}

impl AcceptConfig {
    /// Whether the judgement of `cameras` cameras reads the reverse chamfer term (a finite
    /// bar on it): only then need a caller compute it.
    pub fn weighs_reverse(&self, cameras: usize) -> bool {
        self.max_reverse_px_for(cameras).is_finite()
    }

    fn max_reverse_px_for(&self, cameras: usize) -> f32 {
        if cameras >= 2 {
            self.max_reverse_px
        } else {
            self.one_camera_max_reverse_px
        }
    }

    /// Judges a refined leaf seen by `cameras` cameras from its scores and whether the
    /// tracker lost it. A reverse term over its bar refuses the leaf; none (no edge near it,
    /// or not computed) does not.
    pub fn judge(&self, cameras: usize, leaf: LeafScore, lost: bool) -> Verdict {
        let LeafScore {
            score,
            worst_camera,
            reverse_px,
        } = leaf;
        let (min_score, min_camera_score) = if cameras >= 2 {
            (self.min_score, self.min_camera_score)
        } else {
            (self.one_camera_score, self.one_camera_score)
        };
        let max_reverse_px = self.max_reverse_px_for(cameras);
        let explains_its_edges = reverse_px.is_none_or(|px| px <= max_reverse_px);
        let accepted = !lost
            && score.is_finite()
            && worst_camera.is_finite()
            && score >= min_score
            && worst_camera >= min_camera_score
            && explains_its_edges;
        Verdict {
            score,
            worst_camera,
            reverse_px,
            lost,
            accepted,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn leaf(score: f32, worst_camera: f32) -> LeafScore {
        LeafScore {
            score,
            worst_camera,
            reverse_px: None,
        }
    }

    #[test]
    fn a_lost_a_poor_or_a_lopsided_leaf_is_refused() {
        let c = AcceptConfig::default();
        assert!(c.judge(2, leaf(0.95, 0.94), false).accepted);
        assert!(!c.judge(2, leaf(0.95, 0.94), true).accepted);
        assert!(!c.judge(2, leaf(0.80, 0.80), false).accepted);
        assert!(!c.judge(2, leaf(0.95, 0.70), false).accepted);
        assert!(!c.judge(2, leaf(f32::NAN, 0.95), false).accepted);
    }

    #[test]
    fn one_camera_needs_its_own_higher_bar() {
        let c = AcceptConfig::default();
        assert!(c.judge(2, leaf(0.92, 0.92), false).accepted);
        assert!(!c.judge(1, leaf(0.92, 0.92), false).accepted);
        assert!(c.judge(1, leaf(0.94, 0.94), false).accepted);
        assert!(c.judge(3, leaf(0.92, 0.915), false).accepted);
        assert!(
            !c.judge(0, leaf(0.92, 0.92), false).accepted,
            "no camera: the stricter bar"
        );
    }

    #[test]
    fn a_leaf_leaving_edges_unexplained_is_refused_only_under_a_finite_bar() {
        let unexplained = LeafScore {
            reverse_px: Some(5.0),
            ..leaf(0.95, 0.95)
        };
        let explained = LeafScore {
            reverse_px: Some(3.0),
            ..unexplained
        };
        let defaults = AcceptConfig::default();
        assert!(defaults.weighs_reverse(1) && !defaults.weighs_reverse(2));
        let plain = AcceptConfig {
            max_reverse_px: f32::INFINITY,
            one_camera_max_reverse_px: f32::INFINITY,
            ..defaults
        };
        assert!(!plain.weighs_reverse(1) && !plain.weighs_reverse(2));
        assert!(plain.judge(2, unexplained, false).accepted);
        let barred = AcceptConfig {
            max_reverse_px: 4.0,
            one_camera_max_reverse_px: 3.5,
            ..plain
        };
        assert!(barred.weighs_reverse(2) && barred.weighs_reverse(1));
        assert!(!barred.judge(2, unexplained, false).accepted);
        assert!(barred.judge(2, explained, false).accepted);
        assert!(barred.judge(1, explained, false).accepted);
        let between = LeafScore {
            reverse_px: Some(3.8),
            ..explained
        };
        assert!(barred.judge(2, between, false).accepted);
        assert!(
            !barred.judge(1, between, false).accepted,
            "one camera: its own bar"
        );
        assert!(
            barred.judge(2, leaf(0.95, 0.95), false).accepted,
            "no edge near the hand: nothing against it"
        );
        let nan = LeafScore {
            reverse_px: Some(f32::NAN),
            ..explained
        };
        assert!(!barred.judge(2, nan, false).accepted, "NaN passes no bar");
        assert_eq!(barred.judge(2, unexplained, false).reverse_px, Some(5.0));
    }
}
