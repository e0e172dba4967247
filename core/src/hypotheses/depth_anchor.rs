//! Temporal consistency in depth: a re-acquisition's hypotheses ranked nearer the depth the
//! hand was last claimed at.

/// A depth the hypotheses are drawn to while they are ranked: the palm's distance from the
/// first camera at the last claimed state (`docs/recovery.md`, "The depth the hand was
/// last claimed at").
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DepthAnchor {
    /// The palm's distance from the first camera (mm) the hypotheses are drawn to.
    pub depth_mm: f32,
    /// Score taken off per unit of relative distance from `depth_mm` (likelihood units).
    pub weight: f32,
    /// The relative distance past which the penalty grows no more: one camera reads depth
    /// only within a band of hands that look alike, and beyond it the image decides.
    pub band: f32,
}

impl DepthAnchor {
    /// The score taken off a hypothesis whose palm lies `depth_mm` from the first camera:
    /// `weight × min(|depth − anchor| / anchor, band)`, the most (`weight × band`) for a depth
    /// that is not a number; nothing for an anchor that is not a positive finite depth or a
    /// weight or band that is not positive.
    pub fn penalty(&self, depth_mm: f32) -> f32 {
        let usable = self.depth_mm.is_finite()
            && self.depth_mm > 0.0
            && self.weight > 0.0
            && self.band > 0.0;
        if !usable {
            return 0.0;
        }
        let relative = ((depth_mm - self.depth_mm) / self.depth_mm).abs();
        // `f32::min` takes the band when `relative` is not a number.
        self.weight * relative.min(self.band)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ANCHOR: DepthAnchor = DepthAnchor {
        depth_mm: 1000.0,
        weight: 1.0,
        band: 0.12,
    };

    #[test]
    fn grows_with_the_relative_distance_either_way_up_to_the_band() {
        assert_eq!(ANCHOR.penalty(1000.0), 0.0);
        assert!((ANCHOR.penalty(1050.0) - 0.05).abs() < 1e-6);
        assert!((ANCHOR.penalty(950.0) - 0.05).abs() < 1e-6);
        assert!((ANCHOR.penalty(1120.0) - 0.12).abs() < 1e-5);
        assert_eq!(ANCHOR.penalty(1500.0), ANCHOR.penalty(3000.0));
        assert!((ANCHOR.penalty(1500.0) - 0.12).abs() < 1e-6);
    }

    #[test]
    fn a_depth_not_a_number_takes_the_most() {
        assert!((ANCHOR.penalty(f32::NAN) - 0.12).abs() < 1e-6);
        assert!((ANCHOR.penalty(f32::INFINITY) - 0.12).abs() < 1e-6);
    }

    #[test]
    fn an_unusable_anchor_takes_nothing() {
        for anchor in [
            DepthAnchor {
                depth_mm: 0.0,
                ..ANCHOR
            },
            DepthAnchor {
                depth_mm: -5.0,
                ..ANCHOR
            },
            DepthAnchor {
                depth_mm: f32::NAN,
                ..ANCHOR
            },
            DepthAnchor {
                weight: 0.0,
                ..ANCHOR
            },
            DepthAnchor {
                weight: f32::NAN,
                ..ANCHOR
            },
            DepthAnchor {
                band: 0.0,
                ..ANCHOR
            },
            DepthAnchor {
                band: f32::NAN,
                ..ANCHOR
            },
        ] {
            assert_eq!(anchor.penalty(1200.0), 0.0, "{anchor:?}");
        }
    }
}
