//! The hand's shading against a frame: how well a state's surface normals, lit by the best
//! single distant light, explain the grey levels inside and around its silhouette.
//!
//! On a `grid × grid` lattice over the projected hand (its bounds widened by a quarter on each
//! side), each point's ray is cast against every link's capsule and the palm box; the nearest
//! surface gives the point's outward unit normal `n` (camera coordinates). The frame's grey
//! level there is fitted, by least squares over the lattice, as
//! `g = b · (1 − c) + m · c + l · n · c`, with `c` 1 on the hand and 0 off it: a background
//! `b`, a mean hand grey `m` and a linear shading `l` (a Lambertian surface under one light
//! and an ambient term, to first order). No light is given: it is fitted per state and
//! camera. The fit's root-mean-square residual (grey levels) is the score: a state whose
//! fingers lie where the image's shading says they are leaves less.
//!
//! Measured (`host/examples/shading_check.rs`, `docs/robustness.md`, "What a frame reads,
//! three more ways"): the same fit on full-resolution renders told a wrong finger from the
//! same finger put right 79–82 % of the time where the tracker's likelihood did 65–66 %.

use nalgebra::{SMatrix, SVector, Vector2, Vector3};

use crate::camera::Camera;
use crate::config::MAX_LINKS;
use crate::frame::FrameView;
use crate::projection::{Bounds, ProjectedLink, ProjectedModel};
use crate::silhouette::hand_bounds;

/// The largest lattice side [`fit`] takes.
pub const MAX_SHADING_GRID: usize = 64;

/// Fewest lattice points on the hand, and off it, for a fit.
pub const MIN_SHADING_POINTS: u16 = 8;

/// The terms of the fit: background, hand, and the light's three components.
pub(super) const TERMS: usize = 5;

/// A state's shading fitted to one camera's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ShadingFit {
    /// Root-mean-square residual of the fit (grey levels).
    pub rms: f32,
    /// Lattice points in the frame (on and off the hand).
    pub points: u16,
    /// Of those, the points on the hand.
    pub on_hand: u16,
    /// The fitted background grey, mean hand grey, and light (grey levels per unit of each
    /// normal component, camera x, y, z).
    pub terms: [f32; TERMS],
}

/// The nearest surface of `view` on the ray through pixel `p`: its outward unit normal in
/// camera coordinates; `None` off the hand. `capsules` holds each link's capsule in camera
/// coordinates, as [`capsules`] computes them.
fn normal_at(
    view: &ProjectedModel,
    camera: &Camera,
    capsules: &[Capsule],
    p: &Vector2<f32>,
) -> Option<Vector3<f32>> {
    nearest_surface(view, camera, capsules, p, |_| false).map(|(_, n)| n)
}

/// The nearest surface of `view` on the ray through pixel `p`, leaving out the links `skip`
/// picks: its camera depth (mm) and outward unit normal (camera coordinates); the links in
/// order, then the palm, a later one taken only when strictly nearer.
#[inline]
pub(super) fn nearest_surface(
    view: &ProjectedModel,
    camera: &Camera,
    capsules: &[Capsule],
    p: &Vector2<f32>,
    skip: impl Fn(&ProjectedLink) -> bool,
) -> Option<(f32, Vector3<f32>)> {
    let d = unit_ray(camera, p);
    let mut best: Option<(f32, Vector3<f32>)> = None;
    for (link, capsule) in view.links.iter().zip(capsules) {
        if skip(link) {
            continue;
        }
        if let Some((depth, n)) = link_hit(link, capsule, &d, p) {
            if best.is_none_or(|(z, _)| depth < z) {
                best = Some((depth, n));
            }
        }
    }
    if let Some((depth, n)) = view.palm.as_ref().and_then(|palm| palm.hit_at(camera, p)) {
        if best.is_none_or(|(z, _)| depth < z) {
            best = Some((depth, n));
        }
    }
    best
}

/// The unit direction of the ray through pixel `p` (camera coordinates).
#[inline]
pub(super) fn unit_ray(camera: &Camera, p: &Vector2<f32>) -> Vector3<f32> {
    let ray = camera.ray(p);
    ray / ray.norm()
}

/// Where the ray `d` (unit, [`unit_ray`]) through pixel `p` meets `link`, whose capsule in
/// camera coordinates is `capsule`: the camera depth (mm) and the outward unit normal. `None`
/// when `p` lies outside the link's image bounds or the ray misses it.
#[inline]
pub(super) fn link_hit(
    link: &ProjectedLink,
    capsule: &Capsule,
    d: &Vector3<f32>,
    p: &Vector2<f32>,
) -> Option<(f32, Vector3<f32>)> {
    if !link.bounds.contains(p) {
        return None;
    }
    let (t, n) = capsule.hit(d)?;
    Some((t * d.z, n))
}

/// A lattice point's row of the fit: background where no surface is hit, else the hand's grey
/// and the light's three components times the normal.
pub(super) fn row_of(normal: Option<Vector3<f32>>) -> SVector<f32, TERMS> {
    match normal {
        Some(n) => SVector::<f32, TERMS>::new(0.0, 1.0, n.x, n.y, n.z),
        None => SVector::<f32, TERMS>::new(1.0, 0.0, 0.0, 0.0, 0.0),
    }
}

/// Each link of `view` as a [`Capsule`] in camera coordinates, as [`normal_at`] takes them.
pub(super) fn capsules(view: &ProjectedModel, camera: &Camera) -> [Capsule; MAX_LINKS] {
    let mut capsules = [Capsule::default(); MAX_LINKS];
    for (capsule, link) in capsules.iter_mut().zip(&view.links) {
        *capsule = Capsule::new(
            camera.to_camera(&link.p0),
            camera.to_camera(&link.p1),
            link.radius_mm,
        );
    }
    capsules
}

/// A link's capsule in camera coordinates (mm), with what every ray's test of it shares.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct Capsule {
    /// Axis start and end.
    a: Vector3<f32>,
    b: Vector3<f32>,
    /// Radius (mm).
    r: f32,
    /// `b − a`, and its products with itself and with `−a`; `a · a`.
    ba: Vector3<f32>,
    baba: f32,
    baoa: f32,
    oaoa: f32,
}

impl Capsule {
    /// The capsule `a`–`b` of radius `r` (mm, camera coordinates).
    pub(super) fn new(a: Vector3<f32>, b: Vector3<f32>, r: f32) -> Self {
        let ba = b - a;
        let oa = -a;
        Capsule {
            a,
            b,
            r,
            ba,
            baba: ba.dot(&ba),
            baoa: ba.dot(&oa),
            oaoa: oa.dot(&oa),
        }
    }

    /// The nearest intersection of the ray `t · d` (t > 0, `d` unit, from the camera centre)
    /// with the capsule: `t` and the outward unit normal. `None` when the ray misses it or the
    /// radius is not positive.
    #[inline]
    pub(super) fn hit(&self, d: &Vector3<f32>) -> Option<(f32, Vector3<f32>)> {
        let Capsule {
            a,
            b,
            r,
            ba,
            baba,
            baoa,
            oaoa,
        } = *self;
        if r.is_nan() || r <= 0.0 {
            return None;
        }
        let oa = -a;
        let bard = ba.dot(d);
        let rdoa = d.dot(&oa);
        // The infinite cylinder, kept only where the hit lies between the end caps.
        let qa = baba - bard * bard;
        if qa > 1e-6 * baba.max(1.0) {
            let qb = baba * rdoa - baoa * bard;
            let qc = baba * oaoa - baoa * baoa - r * r * baba;
            let h = qb * qb - qa * qc;
            if h < 0.0 {
                return None;
            }
            let t = (-qb - libm::sqrtf(h)) / qa;
            let y = baoa + t * bard;
            if t > 0.0 && y > 0.0 && y < baba {
                let axis_point = a + ba * (y / baba);
                return Some((t, (d * t - axis_point) / r));
            }
        }
        // Otherwise the nearer of the two end spheres.
        let sphere = |c: &Vector3<f32>| {
            let bq = d.dot(c);
            let h = bq * bq - (c.dot(c) - r * r);
            if h < 0.0 {
                return None;
            }
            let t = bq - libm::sqrtf(h);
            (t > 0.0).then(|| (t, (d * t - c) / r))
        };
        match (sphere(&a), sphere(&b)) {
            (Some(x), Some(y)) => Some(if x.0 <= y.0 { x } else { y }),
            (x, y) => x.or(y),
        }
    }
}

/// Fits the shading of `view` (one camera's projection of a state) to `frame` on a
/// `grid × grid` lattice (clamped to 2..=[`MAX_SHADING_GRID`]). `None` when the hand projects
/// nowhere, fewer than [`MIN_SHADING_POINTS`] lattice points fall on it or off it within the
/// frame, or the fit is singular or not finite.
pub fn fit(
    view: &ProjectedModel,
    camera: &Camera,
    frame: &FrameView<'_>,
    grid: usize,
) -> Option<ShadingFit> {
    let lattice = FitLattice::over(view, grid)?;
    let capsules = capsules(view, camera);
    let capsules = &capsules[..view.links.len().min(MAX_LINKS)];
    let (terms, points, on_hand) = solve(view, camera, frame, &lattice, capsules)?;
    // The residual, in a second pass: exact in f32, where `gᵀg − tᵀAᵀg` would cancel.
    let mut sum = 0.0f32;
    for j in 0..lattice.grid {
        for i in 0..lattice.grid {
            if let Some((row, g)) = lattice.row_at(view, camera, capsules, frame, i, j) {
                let e = row.dot(&terms) - g;
                sum += e * e;
            }
        }
    }
    let rms = libm::sqrtf(sum / f32::from(points));
    (rms.is_finite() && terms.iter().all(|t| t.is_finite())).then_some(ShadingFit {
        rms,
        points,
        on_hand,
        terms: [terms[0], terms[1], terms[2], terms[3], terms[4]],
    })
}

/// [`fit`]'s terms alone, the same bits, without the residual's second pass over the lattice
/// (half the rays). `None` as for [`fit`], but for a residual that overflows.
pub fn fit_terms(
    view: &ProjectedModel,
    camera: &Camera,
    frame: &FrameView<'_>,
    grid: usize,
) -> Option<[f32; TERMS]> {
    let lattice = FitLattice::over(view, grid)?;
    let capsules = capsules(view, camera);
    let capsules = &capsules[..view.links.len().min(MAX_LINKS)];
    let (terms, _, _) = solve(view, camera, frame, &lattice, capsules)?;
    terms
        .iter()
        .all(|t| t.is_finite())
        .then_some([terms[0], terms[1], terms[2], terms[3], terms[4]])
}

/// The lattice [`fit`] samples: `grid × grid` points over the hand's bounds widened by a
/// quarter on each side.
struct FitLattice {
    /// The first point (px).
    min: Vector2<f32>,
    /// Between neighbouring points (px).
    step: Vector2<f32>,
    /// Points a side (2..=[`MAX_SHADING_GRID`]).
    grid: usize,
}

impl FitLattice {
    /// The lattice over `view`'s hand, `grid` (clamped) a side; `None` when the hand
    /// projects nowhere or the steps are not finite.
    fn over(view: &ProjectedModel, grid: usize) -> Option<Self> {
        let grid = grid.clamp(2, MAX_SHADING_GRID);
        let bounds = hand_bounds(view)?;
        let size = bounds.max - bounds.min;
        let min = bounds.min - size * 0.25;
        let step = size * (1.5 / (grid - 1) as f32);
        (step.x.is_finite() && step.y.is_finite()).then_some(FitLattice { min, step, grid })
    }

    /// Point `(i, j)`'s row of the fit and the frame's grey level there; `None` outside the
    /// frame.
    fn row_at(
        &self,
        view: &ProjectedModel,
        camera: &Camera,
        capsules: &[Capsule],
        frame: &FrameView<'_>,
        i: usize,
        j: usize,
    ) -> Option<(SVector<f32, TERMS>, f32)> {
        let p = Vector2::new(
            self.min.x + self.step.x * i as f32,
            self.min.y + self.step.y * j as f32,
        );
        let g = frame.sample(p.x, p.y)?;
        Some((row_of(normal_at(view, camera, capsules, &p)), g))
    }
}

/// The least-squares terms over `lattice`, the points in the frame and those on the hand;
/// `None` with too few of either or a singular system.
fn solve(
    view: &ProjectedModel,
    camera: &Camera,
    frame: &FrameView<'_>,
    lattice: &FitLattice,
    capsules: &[Capsule],
) -> Option<(SVector<f32, TERMS>, u16, u16)> {
    let mut normal = SMatrix::<f32, TERMS, TERMS>::zeros();
    let mut rhs = SVector::<f32, TERMS>::zeros();
    let (mut points, mut on_hand) = (0u16, 0u16);
    for j in 0..lattice.grid {
        for i in 0..lattice.grid {
            let Some((row, g)) = lattice.row_at(view, camera, capsules, frame, i, j) else {
                continue;
            };
            normal += row * row.transpose();
            rhs += row * g;
            points += 1;
            on_hand += u16::from(row[1] > 0.0);
        }
    }
    if on_hand < MIN_SHADING_POINTS || points - on_hand < MIN_SHADING_POINTS {
        return None;
    }
    // A light term the lattice cannot separate (all normals alike) is held near 0.
    for k in 2..TERMS {
        normal[(k, k)] += 1e-3 * f32::from(on_hand);
    }
    Some((normal.cholesky()?.solve(&rhs), points, on_hand))
}

/// How one pixel's residual counts toward a region's sum ([`residual_in`],
/// [`super::shading_cache`]): its square, capped at `cap_grey²` when a cap is set — a
/// truncated quadratic, so a highlight, a shadow or a part of another grey than the fit's
/// (which the fit's one matte grey cannot model) costs no more than a pixel wholly wrong.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PixelCost {
    /// The cap's square (grey levels²); 0 for none.
    cap_sq: f32,
}

impl PixelCost {
    /// Squares, uncapped.
    pub const SQUARE: PixelCost = PixelCost { cap_sq: 0.0 };

    /// Squares capped at `cap_grey²` (grey levels); squares alone when `cap_grey` is not a
    /// positive finite number.
    pub fn capped_at(cap_grey: f32) -> Self {
        let cap_sq = cap_grey * cap_grey;
        if cap_grey > 0.0 && cap_sq.is_finite() {
            PixelCost { cap_sq }
        } else {
            PixelCost::SQUARE
        }
    }

    /// The cost of residual `e` (grey levels): NaN stays NaN.
    #[inline]
    pub fn of(&self, e: f32) -> f32 {
        let square = e * e;
        if self.cap_sq > 0.0 && square > self.cap_sq {
            self.cap_sq
        } else {
            square
        }
    }
}

/// The squared residual of a shading already fitted ([`ShadingFit::terms`]) over a region of
/// the image: what a change confined there (one finger moved) does to the fit, without
/// fitting again.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RegionResidual {
    /// Sum of the pixels' costs ([`PixelCost`]; squared residuals, grey levels²).
    pub sum_sq: f32,
    /// Pixels sampled (inside the frame).
    pub points: u32,
}

/// How a region's shading residual is taken ([`residual_in`], [`super::shading_cache`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RegionScoring {
    /// The fitted terms ([`ShadingFit::terms`]), for the camera and frame scored.
    pub terms: [f32; TERMS],
    /// The region (px; clipped to the frame).
    pub region: Bounds,
    /// Between the pixels sampled, along rows and columns (px; at least 1, 1 when not
    /// finite).
    pub step_px: f32,
    /// How each pixel's residual counts.
    pub cost: PixelCost,
    /// Predict a surface facing away from the light at the hand grey alone (`m`, the light's
    /// term clamped at 0, as a Lambertian surface is lit) instead of the linear fit's
    /// `m + l · n` below it.
    pub clamp_light: bool,
}

impl RegionScoring {
    /// The grey level predicted where the nearest surface has unit normal `normal` (camera
    /// coordinates; `None` off the hand), `terms` being [`RegionScoring::terms`] as a vector.
    #[inline]
    pub(super) fn predicted(
        &self,
        terms: &SVector<f32, TERMS>,
        normal: Option<Vector3<f32>>,
    ) -> f32 {
        match normal {
            Some(n) if self.clamp_light => {
                terms[1] + (n.x * terms[2] + n.y * terms[3] + n.z * terms[4]).max(0.0)
            }
            normal => row_of(normal).dot(terms),
        }
    }
}

/// The residual of `scoring`'s terms against the normals of `view` at its region's pixels.
/// `None` when no pixel of the region lies in the frame, or the sum is not finite.
pub fn residual_in(
    view: &ProjectedModel,
    camera: &Camera,
    frame: &FrameView<'_>,
    scoring: &RegionScoring,
) -> Option<RegionResidual> {
    let lattice = RegionLattice::new(frame, &scoring.region, scoring.step_px)?;
    let capsules = capsules(view, camera);
    let capsules = &capsules[..view.links.len().min(MAX_LINKS)];
    let terms = SVector::<f32, TERMS>::from_column_slice(&scoring.terms);
    let (mut sum_sq, mut points) = (0.0f32, 0u32);
    for p in lattice.points() {
        let Some(g) = frame.sample(p.x, p.y) else {
            continue;
        };
        let e = scoring.predicted(&terms, normal_at(view, camera, capsules, &p)) - g;
        sum_sq += scoring.cost.of(e);
        points += 1;
    }
    (points > 0 && sum_sq.is_finite()).then_some(RegionResidual { sum_sq, points })
}

/// Every `step`-th pixel of an image region clipped to a frame, row by row: the points
/// [`residual_in`] and [`super::shading_cache`] sum over, in the order they sum them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct RegionLattice {
    /// The first point (px).
    min: Vector2<f32>,
    /// Between neighbouring points (px, at least 1).
    step: f32,
    columns: u32,
    rows: u32,
}

impl RegionLattice {
    /// The lattice over `region` (px) clipped to `frame`, every `step_px` (at least 1 px; 1
    /// when not finite). `None` when no pixel of the region lies in the frame.
    pub(super) fn new(frame: &FrameView<'_>, region: &Bounds, step_px: f32) -> Option<Self> {
        let step = if step_px.is_finite() {
            step_px.max(1.0)
        } else {
            1.0
        };
        let last = Vector2::new(frame.width() as f32 - 1.0, frame.height() as f32 - 1.0);
        let min = Vector2::new(region.min.x.max(0.0), region.min.y.max(0.0));
        let max = Vector2::new(region.max.x.min(last.x), region.max.y.min(last.y));
        if !(min.x <= max.x && min.y <= max.y) {
            return None;
        }
        Some(RegionLattice {
            min,
            step,
            columns: libm::floorf((max.x - min.x) / step) as u32 + 1,
            rows: libm::floorf((max.y - min.y) / step) as u32 + 1,
        })
    }

    /// How many points.
    pub(super) fn len(&self) -> usize {
        self.columns as usize * self.rows as usize
    }

    /// The points, row by row (px).
    pub(super) fn points(&self) -> impl Iterator<Item = Vector2<f32>> + '_ {
        (0..self.rows).flat_map(move |j| {
            (0..self.columns).map(move |i| {
                Vector2::new(
                    self.min.x + self.step * i as f32,
                    self.min.y + self.step * j as f32,
                )
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::PixelCost;

    #[test]
    fn a_capped_cost_is_the_square_up_to_the_cap() {
        let cost = PixelCost::capped_at(10.0);
        assert_eq!(cost.of(3.0), 9.0);
        assert_eq!(cost.of(-10.0), 100.0);
        assert_eq!(cost.of(40.0), 100.0);
        assert!(cost.of(f32::NAN).is_nan());
        for no_cap in [0.0, -1.0, f32::NAN, f32::INFINITY, 1e30] {
            assert_eq!(PixelCost::capped_at(no_cap), PixelCost::SQUARE);
        }
        assert_eq!(PixelCost::SQUARE.of(40.0), 1600.0);
        assert_eq!(PixelCost::default(), PixelCost::SQUARE);
    }
}
