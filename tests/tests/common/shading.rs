//! How the shading tests score a region.

use digiteyes_core::likelihood::shading::{PixelCost, RegionScoring};
use digiteyes_core::projection::Bounds;

/// `terms` over `region` every `step_px`, each pixel counted by `cost`.
pub fn scored(terms: &[f32; 5], region: &Bounds, step_px: f32, cost: PixelCost) -> RegionScoring {
    RegionScoring {
        terms: *terms,
        region: *region,
        step_px,
        cost,
        clamp_light: false,
    }
}
