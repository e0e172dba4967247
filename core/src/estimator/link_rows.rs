//! The tracker's rows: each link's residuals gathered as a 6×6 block in the link's image
//! parameters, then applied through the link Jacobian once ([`add_link_rows`]).

use nalgebra::Vector2;

use super::normal::{packed, position};
use super::{EstimatorConfig, FreeMask, LinkJacobian, NormalEquations, ResidualKind};
use crate::config::{MAX_ROW_NONZEROS, MAX_STATES};
use crate::features::{fit_axis_line, EdgePoint, LinkFeatures};
use crate::projection::ProjectedLink;

/// What one link contributed to the normal equations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LinkRows {
    /// Edge or line rows added.
    pub edges: u16,
    /// Tip rows added.
    pub tips: u16,
}

/// The image parameters of a link that every residual depends on: `a.x, a.y, b.x, b.y, r0,
/// r1` (the axis ends and the projected radii at them, px).
const PARAMS: usize = 6;

/// One link's rows, gathered in the link's six image parameters.
///
/// Every residual of a link (edge point, axis point, axis line, tip) is a linear function of
/// the derivatives of its image parameters, `∂r/∂q = cᵀ G` with `G` the 6×n matrix of
/// [`LinkJacobian`] (`∂a`, `∂b`, `∂r0`, `∂r1` by each state) and `c` six coefficients that
/// depend on the row alone. So the link's `JᵀWJ = Gᵀ (Σ w c cᵀ) G` and `JᵀWr = Gᵀ Σ w r c`:
/// each row costs a 6×6 rank-1 update, and `G` is applied once per link.
struct LinkBlock {
    /// `Σ w c cᵀ`.
    cc: [[f32; PARAMS]; PARAMS],
    /// `Σ w r c`.
    cr: [f32; PARAMS],
    sum_squares: f32,
    rows: u16,
}

impl LinkBlock {
    fn new() -> Self {
        LinkBlock {
            cc: [[0.0; PARAMS]; PARAMS],
            cr: [0.0; PARAMS],
            sum_squares: 0.0,
            rows: 0,
        }
    }

    /// Adds the row `cᵀ G` with residual `r` (px) and weight `w`; non-finite rows are
    /// ignored, as [`NormalEquations::add_row`] does.
    fn add(&mut self, c: &[f32; PARAMS], r: f32, w: f32) {
        let finite = c.iter().fold(true, |ok, v| ok & v.is_finite());
        if !(r.is_finite() && w.is_finite() && finite) {
            return;
        }
        self.sum_squares += r * r;
        self.rows = self.rows.saturating_add(1);
        if w == 0.0 {
            return;
        }
        for (row, (rhs, &ci)) in self.cc.iter_mut().zip(self.cr.iter_mut().zip(c)) {
            let wc = w * ci;
            *rhs += wc * r;
            for (a, v) in row.iter_mut().zip(c) {
                *a += wc * v;
            }
        }
    }

    /// Adds `Gᵀ (Σ w c cᵀ) G` and `Gᵀ Σ w r c` to `ne`, over the link's free states. If `G`
    /// is not finite every row would have been, and nothing is added.
    fn scatter(&self, ne: &mut NormalEquations, jac: &LinkJacobian, free: FreeMask) {
        self.scatter_counted(ne, jac, free, true);
    }

    /// [`LinkBlock::scatter`], adding the rows to `ne`'s count and sum of squares (its
    /// [`rms`](NormalEquations::rms)) only when `counted`.
    fn scatter_counted(
        &self,
        ne: &mut NormalEquations,
        jac: &LinkJacobian,
        free: FreeMask,
        counted: bool,
    ) {
        // `G` by rows over the link's free states (zero-padded to a fixed width, so every
        // loop below is a fixed-length vector operation).
        let mut pos = [0usize; MAX_ROW_NONZEROS];
        let mut g = [[0.0f32; BLOCK]; PARAMS];
        let mut n = 0;
        let columns = jac
            .states
            .iter()
            .zip(jac.da.iter().zip(&jac.db))
            .zip(jac.dr0.iter().zip(&jac.dr1));
        for ((&s, (da, db)), (&dr0, &dr1)) in columns {
            let s = usize::from(s);
            if s < MAX_STATES && free.contains(s) && n < MAX_ROW_NONZEROS {
                pos[n] = position(s);
                for (row, v) in g.iter_mut().zip([da.x, da.y, db.x, db.y, dr0, dr1]) {
                    row[n] = v;
                }
                n += 1;
            }
        }
        // `v·0` is 0 for a finite `v` and NaN otherwise: one vectorisable sum tests all.
        let zero: f32 = g.iter().flatten().map(|v| v * 0.0).sum();
        if zero != 0.0 {
            return;
        }
        if counted {
            ne.sum_squares += self.sum_squares;
            ne.rows = ne.rows.saturating_add(self.rows);
        }
        // (Σ w c cᵀ) G and Gᵀ Σ w r c.
        let axpy = |out: &mut [f32; BLOCK], a: f32, x: &[f32; BLOCK]| {
            for (o, v) in out.iter_mut().zip(x) {
                *o += a * v;
            }
        };
        let mut cg = [[0.0f32; BLOCK]; PARAMS];
        for (out, cc) in cg.iter_mut().zip(&self.cc) {
            for (&c, row) in cc.iter().zip(&g) {
                axpy(out, c, row);
            }
        }
        let mut rhs = [0.0f32; BLOCK];
        for (&c, row) in self.cr.iter().zip(&g) {
            axpy(&mut rhs, c, row);
        }
        // Row i of Gᵀ (C G), added into the triangle from the diagonal on.
        for i in 0..n {
            let mut h = [0.0f32; BLOCK];
            for (row, cg_row) in g.iter().zip(&cg) {
                axpy(&mut h, row[i], cg_row);
            }
            let pi = pos[i];
            if let (Some(v), Some(d)) = (ne.jtr.get_mut(pi), ne.diag.get_mut(pi)) {
                *v += rhs[i];
                *d += h[i];
            }
            for (&pj, hj) in pos[i + 1..n].iter().zip(&h[i + 1..n]) {
                let (lo, hi) = if pi < pj { (pi, pj) } else { (pj, pi) };
                if let Some(v) = ne.lower.get_mut(packed(hi.max(1), lo)) {
                    *v += hj;
                }
            }
        }
    }
}

/// Width of the per-link rows of `G`: [`MAX_ROW_NONZEROS`] rounded up to a multiple of 4, so
/// the loops over them have a fixed length the compiler turns into SIMD.
const BLOCK: usize = MAX_ROW_NONZEROS.div_ceil(4) * 4;

/// What every edge row of one link shares, computed once per link (see
/// [`edge_row`](super::reference::edge_row)).
struct EdgeBasis {
    normal: Vector2<f32>,
    axis: Vector2<f32>,
    len2: f32,
    taper: [f32; 2],
}

impl EdgeBasis {
    fn new(link: &ProjectedLink) -> Self {
        let normal = link.normal();
        let axis = link.b - link.a;
        EdgeBasis {
            normal,
            axis,
            len2: axis.norm_squared().max(1e-9),
            taper: [1i8, -1]
                .map(|side| link.side_radius_at(1.0, side) - link.side_radius_at(0.0, side)),
        }
    }

    /// [`edge_row`] as coefficients of the link's image parameters, and [`edge_residual`].
    /// The row is `σ n·((1−s) ∂a + s ∂b) + (1−s) ∂r0 + s ∂r1 + t ∂s` with
    /// `∂s·len² = rel·(∂b − ∂a) − axis·∂a − 2 s_raw axis·(∂b − ∂a)`.
    fn row(&self, link: &ProjectedLink, e: &EdgePoint) -> ([f32; PARAMS], f32) {
        let rel = e.position - link.a;
        let raw_s = rel.dot(&self.axis) / self.len2;
        let s = raw_s.clamp(0.0, 1.0);
        let side = f32::from(e.side);
        let t = if (0.0..=1.0).contains(&raw_s) {
            self.taper[usize::from(e.side < 0)] / self.len2
        } else {
            0.0
        };
        let (n, axis) = (self.normal, self.axis);
        let (u, v) = (side * (1.0 - s), side * s);
        let tb = Vector2::new(
            t * (rel.x - 2.0 * raw_s * axis.x),
            t * (rel.y - 2.0 * raw_s * axis.y),
        );
        let c = [
            u * n.x - tb.x - t * axis.x,
            u * n.y - tb.y - t * axis.y,
            v * n.x + tb.x,
            v * n.y + tb.y,
            1.0 - s,
            s,
        ];
        let r = link.side_radius_at(s, e.side) - side * self.normal.dot(&rel);
        (c, r)
    }
}

/// Adds the rows of one link's features to `ne`.
#[inline(never)] // a stage of Table 4.1: kept whole so profiles can attribute its cost
pub fn add_link_rows(
    ne: &mut NormalEquations,
    link: &ProjectedLink,
    features: &LinkFeatures,
    jac: &LinkJacobian,
    config: &EstimatorConfig,
    free: FreeMask,
) -> LinkRows {
    add_weighted_link_rows(ne, link, features, jac, config, free, 1.0)
}

/// [`add_link_rows`] with every row's weight multiplied by `weight`.
pub(crate) fn add_weighted_link_rows(
    ne: &mut NormalEquations,
    link: &ProjectedLink,
    features: &LinkFeatures,
    jac: &LinkJacobian,
    config: &EstimatorConfig,
    free: FreeMask,
    weight: f32,
) -> LinkRows {
    let mut added = LinkRows::default();
    if jac.states.is_empty() {
        return added;
    }
    let mut block = LinkBlock::new();
    match config.residual {
        ResidualKind::EdgePoints => {
            let basis = EdgeBasis::new(link);
            for e in &features.edges {
                let (c, r) = basis.row(link, e);
                block.add(&c, r, weight * config.robust.weight(r));
                added.edges += 1;
            }
        }
        ResidualKind::AxisPoints => {
            let basis = EdgeBasis::new(link);
            let edges = &features.edges;
            let mut i = 0;
            while i < edges.len() {
                let e = &edges[i];
                let partner = edges
                    .get(i + 1)
                    .filter(|o| o.side == -e.side && (o.s - e.s).abs() < 1e-6);
                let (c, r) = match partner {
                    Some(o) => {
                        let (mut plus, r_plus) = basis.row(link, e);
                        let (minus, r_minus) = basis.row(link, o);
                        if config.width_weight > 0.0 {
                            let mut width = [0.0; PARAMS];
                            for ((m, a), b) in width.iter_mut().zip(&plus).zip(&minus) {
                                *m = 0.5 * (a + b);
                            }
                            let r_width = 0.5 * (r_plus + r_minus);
                            block.add(
                                &width,
                                r_width,
                                weight * config.width_weight * config.robust.weight(r_width),
                            );
                        }
                        let half = 0.5 * f32::from(e.side);
                        for (a, b) in plus.iter_mut().zip(&minus) {
                            *a = (*a - b) * half;
                        }
                        i += 2;
                        (plus, (r_plus - r_minus) * half)
                    }
                    None => {
                        i += 1;
                        basis.row(link, e)
                    }
                };
                block.add(&c, r, weight * config.robust.weight(r));
                added.edges += 1;
            }
        }
        ResidualKind::AxisLines => {
            if let Some((centre, line_normal)) = fit_axis_line(link, features) {
                // Eq. 2.17, as `line_row`: `n·∂a` and `n·∂b`.
                for (end, point) in [link.a, link.b].iter().enumerate() {
                    let mut c = [0.0; PARAMS];
                    c[2 * end] = line_normal.x;
                    c[2 * end + 1] = line_normal.y;
                    block.add(&c, line_normal.dot(&(point - centre)), weight);
                    added.edges += 1;
                }
            }
        }
    }
    if let Some(tip) = features.tip {
        // Eq. 2.19, as `tip_row`: `dir·∂b + ∂r1`.
        let (dir, _) = link.axis_frame();
        let r = dir.dot(&(link.b - tip)) + link.tip_offset;
        let c = [0.0, 0.0, dir.x, dir.y, 0.0, 1.0];
        block.add(&c, r, weight * config.tip_weight * config.robust.weight(r));
        added.tips += 1;
    }
    block.scatter(ne, jac, free);
    added
}

/// The region row of image point `p` for `link`, as coefficients of the link's image
/// parameters `a.x, a.y, b.x, b.y, r0, r1`, and its residual: the capsule's mean radius less
/// the point's distance from the image axis (px; positive inside). Driving it to zero moves
/// the outline, at its nearest place to the point (a side or an end), through the point:
/// `∂r = u·((1−s) ∂a + s ∂b) + (1−s) ∂r0 + s ∂r1 + (r̄1 − r̄0) ∂s`, with `u` the unit
/// direction from the axis to the point and `s` the nearest axis parameter (the last term
/// only between the ends, where `s` moves with the link). `None`
/// for a point on the axis, where `u` is undefined.
pub fn region_row(link: &ProjectedLink, p: &Vector2<f32>) -> Option<([f32; PARAMS], f32)> {
    let (s, dist) = link.closest(p);
    if dist.is_nan() || dist < 1e-3 {
        return None;
    }
    let axis = link.b - link.a;
    let u = (p - (link.a + axis * s)) / dist;
    let mut c = [
        (1.0 - s) * u.x,
        (1.0 - s) * u.y,
        s * u.x,
        s * u.y,
        1.0 - s,
        s,
    ];
    // Between the ends the radius tapers along the axis, so the nearest point's own motion
    // `∂s = (rel·(∂b − ∂a) − axis·∂a − 2 s axis·(∂b − ∂a)) / len²` adds `taper ∂s`.
    let len2 = axis.norm_squared();
    if s > 0.0 && s < 1.0 && len2 > 1e-9 {
        let taper = (link.radius_at(1.0) - link.radius_at(0.0)) / len2;
        let rel = p - link.a;
        let on_b = rel - axis * (2.0 * s);
        let on_a = -on_b - axis;
        c[0] += taper * on_a.x;
        c[1] += taper * on_a.y;
        c[2] += taper * on_b.x;
        c[3] += taper * on_b.y;
    }
    Some((c, link.radius_at(s) - dist))
}

/// Adds one [`region_row`] per region sample in `samples` to `ne`, for `link`, each weighted
/// by `weight` and the robust weight: `(position, bright)`, where a bright sample counts only
/// while it lies outside the link (residual < 0) and a dark one only while inside (> 0).
/// They are left out of `ne`'s row count and residual RMS (the lost test's), as evidence of
/// another kind than the features'. Returns the rows added.
#[inline(never)] // a stage of its own, so profiles can attribute its cost
pub(crate) fn add_region_rows(
    ne: &mut NormalEquations,
    link: &ProjectedLink,
    samples: impl Iterator<Item = (Vector2<f32>, bool)>,
    jac: &LinkJacobian,
    config: &EstimatorConfig,
    free: FreeMask,
    weight: f32,
) -> u16 {
    if jac.states.is_empty() {
        return 0;
    }
    let mut block = LinkBlock::new();
    for (p, bright) in samples {
        let Some((c, r)) = region_row(link, &p) else {
            continue;
        };
        if (bright && r < 0.0) || (!bright && r > 0.0) {
            block.add(&c, r, weight * config.robust.weight(r));
        }
    }
    block.scatter_counted(ne, jac, free, false);
    block.rows
}
