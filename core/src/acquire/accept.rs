//! Whether a refined leaf is the hand: its likelihood against thresholds set from measured
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
}

impl Default for AcceptConfig {
    fn default() -> Self {
        AcceptConfig {
            min_score: 0.91,
            min_camera_score: 0.91,
            one_camera_score: 0.93,
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
    /// Gauss–Newton lost it (too few features, or the residual exploded).
    pub lost: bool,
    /// Taken for the hand.
    pub accepted: bool,
}

impl AcceptConfig {
    /// Judges a refined leaf seen by `cameras` cameras from its mean and worst camera score
    /// and whether the tracker lost it.
    pub fn judge(&self, cameras: usize, score: f32, worst_camera: f32, lost: bool) -> Verdict {
        let (min_score, min_camera_score) = if cameras >= 2 {
            (self.min_score, self.min_camera_score)
        } else {
            (self.one_camera_score, self.one_camera_score)
        };
        let accepted = !lost
            && score.is_finite()
            && worst_camera.is_finite()
            && score >= min_score
            && worst_camera >= min_camera_score;
        Verdict {
            score,
            worst_camera,
            lost,
            accepted,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lost_a_poor_or_a_lopsided_leaf_is_refused() {
        let c = AcceptConfig::default();
        assert!(c.judge(2, 0.95, 0.94, false).accepted);
        assert!(!c.judge(2, 0.95, 0.94, true).accepted);
        assert!(!c.judge(2, 0.80, 0.80, false).accepted);
        assert!(!c.judge(2, 0.95, 0.70, false).accepted);
        assert!(!c.judge(2, f32::NAN, 0.95, false).accepted);
    }

    #[test]
    fn one_camera_needs_its_own_higher_bar() {
        let c = AcceptConfig::default();
        assert!(c.judge(2, 0.92, 0.92, false).accepted);
        assert!(!c.judge(1, 0.92, 0.92, false).accepted);
        assert!(c.judge(1, 0.94, 0.94, false).accepted);
        assert!(c.judge(3, 0.92, 0.915, false).accepted);
        assert!(
            !c.judge(0, 0.92, 0.92, false).accepted,
            "no camera: the stricter bar"
        );
    }
}
