//! A region's shading residual with one finger free: the rest of the hand is found once.
//!
//! While a finger's joints are searched ([`super::shading_refine`]) nothing else moves, so at
//! each pixel of the finger's region the nearest surface that stays put (the palm, the other
//! fingers) and the fitted shading's residual there are the same for every trial. They are
//! found once ([`ShadingCache::fill`]); a trial then casts each pixel's ray against the
//! finger's own links only ([`ShadingCache::residual`]). The sum is
//! [`super::shading::residual_in`]'s: the same pixels in the same order, each with the same
//! nearest surface (a surface of the finger taken when strictly nearer than the fixed one).

use nalgebra::{SVector, Vector3};

use super::shading::{
    capsules, link_hit, nearest_surface, unit_ray, RegionLattice, RegionResidual, RegionScoring,
    TERMS,
};
use crate::camera::Camera;
use crate::config::MAX_LINKS;
use crate::frame::FrameView;
use crate::model::Model;
use crate::projection::{Bounds, ProjectedModel};

/// Region pixels the cache holds, over all cameras (8 bytes each): 8,192 with the
/// `shading-cache` feature (the host's; enough for a finger's region in two 640 × 480
/// cameras), none without it (a board's, 64 KB spared: every region is then scored the slow
/// way, to the same sums).
#[cfg(feature = "shading-cache")]
pub const MAX_CACHED_PIXELS: usize = 8192;
/// Region pixels the cache holds: none without the `shading-cache` feature (see its
/// definition with it).
#[cfg(not(feature = "shading-cache"))]
pub const MAX_CACHED_PIXELS: usize = 0;

/// Which model frames move: indexed by frame.
pub type MovingFrames = [bool; MAX_LINKS];

/// One region pixel as the fixed part of the hand leaves it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct FixedPixel {
    /// The cost ([`super::shading::PixelCost`]) of the fit's prediction minus the frame's
    /// grey level there (grey levels²).
    cost: f32,
    /// Camera depth of the nearest fixed surface (mm; infinite where none is hit, NaN where
    /// the pixel is not sampled).
    depth_mm: f32,
}

const UNSAMPLED: FixedPixel = FixedPixel {
    cost: 0.0,
    depth_mm: f32::NAN,
};

/// Working memory for [`super::shading_refine`]: the fixed surfaces of each camera's region.
#[derive(Debug, Clone)]
pub struct ShadingCache {
    pixels: [FixedPixel; MAX_CACHED_PIXELS],
    /// Pixels in use.
    used: usize,
    /// Pixels it may use (at most [`MAX_CACHED_PIXELS`]).
    room: usize,
    /// Times cleared: a region kept before the last clear is no longer here.
    generation: u32,
}

impl Default for ShadingCache {
    fn default() -> Self {
        ShadingCache::with_room(MAX_CACHED_PIXELS)
    }
}

/// One camera's region as [`ShadingCache::fill`] kept it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CachedRegion {
    lattice: RegionLattice,
    /// How it is scored.
    scoring: RegionScoring,
    /// Its first pixel in the cache.
    start: usize,
    /// The cache's generation when it was kept.
    generation: u32,
}

/// The model frames that any of `joints` (states) moves: every frame whose chain holds one
/// (and, to be safe, any whose chain cannot be read: a moving frame taken as fixed would
/// corrupt the cache's sums; a fixed one taken as moving only costs rays).
pub fn moving_frames(model: &Model, joints: &[usize]) -> MovingFrames {
    let mut moving = [false; MAX_LINKS];
    for (f, slot) in moving.iter_mut().enumerate().take(model.links().len()) {
        *slot = model
            .chain(f)
            .is_none_or(|chain| chain.iter().any(|&s| joints.contains(&usize::from(s))));
    }
    moving
}

/// Whether a link of a projection moves with `moving` frames: its own frame or its child.
fn link_moves(moving: &MovingFrames, frame: u8, child: u8) -> bool {
    let at = |f: u8| moving.get(usize::from(f)).copied().unwrap_or(false);
    at(frame) || at(child)
}

impl ShadingCache {
    /// A cache that keeps at most `room` pixels (clamped to [`MAX_CACHED_PIXELS`]; 0 keeps
    /// none, so every region is scored the slow way).
    // Without the `shading-cache` feature the capacity is 0, and clippy calls the clamp idle.
    #[allow(clippy::unnecessary_min_or_max)]
    pub fn with_room(room: usize) -> Self {
        ShadingCache {
            pixels: [UNSAMPLED; MAX_CACHED_PIXELS],
            used: 0,
            room: room.min(MAX_CACHED_PIXELS),
            generation: 0,
        }
    }

    /// Forgets every region kept.
    pub fn clear(&mut self) {
        self.used = 0;
        self.generation = self.generation.wrapping_add(1);
    }

    /// Keeps, for every pixel of `scoring`'s region (as [`super::shading::residual_in`]
    /// samples it), the cost of the residual of its terms against the nearest surface of
    /// `view` whose link does not move with `moving` (or the palm), and that surface's depth.
    /// `None`, keeping nothing, when no pixel of the region lies in the frame or its pixels do
    /// not fit in what is left of [`MAX_CACHED_PIXELS`].
    pub fn fill(
        &mut self,
        view: &ProjectedModel,
        camera: &Camera,
        frame: &FrameView<'_>,
        scoring: &RegionScoring,
        moving: &MovingFrames,
    ) -> Option<CachedRegion> {
        let lattice = RegionLattice::new(frame, &scoring.region, scoring.step_px)?;
        let start = self.used;
        let end = start.checked_add(lattice.len())?;
        if end > self.room {
            return None;
        }
        let pixels = self.pixels.get_mut(start..end)?;
        let capsules = capsules(view, camera);
        let terms = SVector::<f32, TERMS>::from_column_slice(&scoring.terms);
        for (pixel, p) in pixels.iter_mut().zip(lattice.points()) {
            let Some(g) = frame.sample(p.x, p.y) else {
                *pixel = UNSAMPLED;
                continue;
            };
            let best = nearest_surface(view, camera, &capsules, &p, |link| {
                link_moves(moving, link.frame, link.child)
            });
            let e = scoring.predicted(&terms, best.map(|(_, n)| n)) - g;
            *pixel = FixedPixel {
                cost: scoring.cost.of(e),
                depth_mm: best.map_or(f32::INFINITY, |(z, _)| z),
            };
        }
        self.used = end;
        Some(CachedRegion {
            lattice,
            scoring: *scoring,
            start,
            generation: self.generation,
        })
    }

    /// The residual over `cached` (kept by [`ShadingCache::fill`] for this camera and frame,
    /// scored as it was kept) with `view`'s links that move with `moving` where they are now:
    /// what [`super::shading::residual_in`] gives for `view` when nothing else has moved
    /// since. `None` when the region was not kept here, no pixel was sampled, or the sum is
    /// not finite.
    pub fn residual(
        &self,
        cached: &CachedRegion,
        view: &ProjectedModel,
        camera: &Camera,
        frame: &FrameView<'_>,
        moving: &MovingFrames,
    ) -> Option<RegionResidual> {
        let end = cached.start.checked_add(cached.lattice.len())?;
        if cached.generation != self.generation || end > self.used {
            return None;
        }
        let pixels = self.pixels.get(cached.start..end)?;
        let capsules = capsules(view, camera);
        let mut free: heapless::Vec<usize, MAX_LINKS> = heapless::Vec::new();
        let mut reach: Option<Bounds> = None;
        for (k, link) in view.links.iter().enumerate() {
            if link_moves(moving, link.frame, link.child) {
                let _ = free.push(k);
                reach = Some(reach.map_or(link.bounds, |r| Bounds {
                    min: r.min.inf(&link.bounds.min),
                    max: r.max.sup(&link.bounds.max),
                }));
            }
        }
        let terms = SVector::<f32, TERMS>::from_column_slice(&cached.scoring.terms);
        let (mut sum_sq, mut points) = (0.0f32, 0u32);
        for (pixel, p) in pixels.iter().zip(cached.lattice.points()) {
            if pixel.depth_mm.is_nan() {
                continue;
            }
            points += 1;
            if !reach.is_some_and(|r| r.contains(&p)) {
                sum_sq += pixel.cost;
                continue;
            }
            let mut ray = None;
            let mut best: Option<(f32, Vector3<f32>)> = None;
            for &k in &free {
                let (Some(link), Some(capsule)) = (view.links.get(k), capsules.get(k)) else {
                    continue;
                };
                if !link.bounds.contains(&p) {
                    continue;
                }
                let d = *ray.get_or_insert_with(|| unit_ray(camera, &p));
                if let Some((depth, n)) = link_hit(link, capsule, &d, &p) {
                    if depth < pixel.depth_mm && best.is_none_or(|(z, _)| depth < z) {
                        best = Some((depth, n));
                    }
                }
            }
            let e_sq = match best.and_then(|(_, n)| Some((n, frame.sample(p.x, p.y)?))) {
                Some((n, g)) => {
                    let scoring = &cached.scoring;
                    scoring.cost.of(scoring.predicted(&terms, Some(n)) - g)
                }
                None => pixel.cost,
            };
            sum_sq += e_sq;
        }
        (points > 0 && sum_sq.is_finite()).then_some(RegionResidual { sum_sq, points })
    }
}
