//! Residuals and the conditioned Gauss–Newton step (Sec. 2.5, Eq. 2.22).
//!
//! Residual rows are added one at a time to the normal equations `JᵀWJ` and `JᵀWr` (a full
//! `J` is never stored); the step is `Δ = −(JᵀWJ + S)⁻¹ JᵀWr` with the constant diagonal
//! conditioning matrix `S`, solved by Cholesky; only the free states change.
//!
//! Three residual kinds, each "predicted minus measured", in pixels:
//! - **edge point**: the distance of a detected silhouette point from the predicted silhouette
//!   line (the axis offset by the projected radius) — robustly weighted;
//! - **axis line** (Eq. 2.17, the thesis' form): the distance of the projected model axis'
//!   end points from the axis line fitted through a link's edge points;
//! - **tip** (Eq. 2.19): the distance along the axis between the predicted and found tip.

use heapless::Vec;
use nalgebra::{SVector, Vector2};

use crate::camera::Camera;
use crate::config::{MAX_ROW_NONZEROS, MAX_STATES};
use crate::features::{axis_frame, EdgePoint, LinkFeatures};
use crate::kinematics::Poses;
use crate::model::{Model, BASE_STATES};
use crate::projection::ProjectedLink;

/// Which residuals a link's edge points give.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ResidualKind {
    /// One row per edge point: its distance from the predicted silhouette line.
    EdgePoints,
    /// Two rows per link: the model axis' end points against the fitted axis line (Eq. 2.17).
    AxisLines,
    /// One row per slice: where both edges were found, the distance of their midpoint from the
    /// model axis (blind to a width bias, such as shading pulling both edges inward); a lone
    /// edge gives its edge-point row.
    AxisPoints,
}

/// Robust weighting of residuals (px).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Robust {
    /// Plain least squares.
    None,
    /// Huber: weight 1 up to `k` px, then `k / |r|`.
    Huber(f32),
    /// Tukey's biweight: `(1 − (r/c)²)²` up to `c` px, 0 beyond.
    Tukey(f32),
}

impl Robust {
    /// The weight of a residual `r` (px).
    pub fn weight(&self, r: f32) -> f32 {
        let a = r.abs();
        match *self {
            Robust::None => 1.0,
            Robust::Huber(k) if a > k => k / a,
            Robust::Huber(_) => 1.0,
            Robust::Tukey(c) if a < c => {
                let u = 1.0 - (r / c) * (r / c);
                u * u
            }
            Robust::Tukey(_) => 0.0,
        }
    }
}

/// The diagonal of the conditioning matrix `S` per kind of state (Table 4.2).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Conditioning {
    /// For each quaternion state.
    pub quaternion: f32,
    /// For each translation state (per mm²).
    pub translation: f32,
    /// For each joint angle (per rad²).
    pub joint: f32,
}

impl Conditioning {
    /// The thesis' weights (Table 4.2): quaternion 1, translation 10, joint 1000.
    pub const THESIS: Conditioning = Conditioning {
        quaternion: 1.0,
        translation: 10.0,
        joint: 1000.0,
    };

    /// `S` for state `i`.
    pub fn for_state(&self, i: usize) -> f32 {
        match i {
            0..=3 => self.quaternion,
            4..=6 => self.translation,
            _ => self.joint,
        }
    }
}

/// Parameters of the estimator.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub struct EstimatorConfig {
    /// Which residuals edges give.
    pub residual: ResidualKind,
    /// Robust weighting of edge and tip residuals.
    pub robust: Robust,
    /// The conditioning matrix `S`.
    pub conditioning: Conditioning,
    /// Weight of a tip row relative to an edge row.
    pub tip_weight: f32,
}

impl Default for EstimatorConfig {
    fn default() -> Self {
        EstimatorConfig {
            residual: ResidualKind::AxisPoints,
            robust: Robust::Huber(2.0),
            conditioning: Conditioning {
                quaternion: 1.0,
                translation: 1.0,
                joint: 1000.0,
            },
            tip_weight: 1.0,
        }
    }
}

/// Which states the estimator may change: bit `i` for state `qi`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FreeMask(pub u32);

impl FreeMask {
    /// Every state of a model with `n` states.
    pub fn all(n: usize) -> Self {
        FreeMask(if n >= 32 { u32::MAX } else { (1u32 << n) - 1 })
    }

    /// Whether state `i` is free.
    pub fn contains(&self, i: usize) -> bool {
        i < 32 && self.0 & (1 << i) != 0
    }

    /// Number of free states.
    pub fn count(&self) -> u32 {
        self.0.count_ones()
    }
}

/// How the image measurements of one link move with each state it depends on.
#[derive(Debug, Clone, Default)]
pub struct LinkJacobian {
    /// The states, palm first then the link's joint chain.
    pub states: Vec<u8, MAX_ROW_NONZEROS>,
    /// `∂a/∂q` for the axis start in the image (px per unit state).
    pub da: Vec<Vector2<f32>, MAX_ROW_NONZEROS>,
    /// `∂b/∂q` for the axis end in the image.
    pub db: Vec<Vector2<f32>, MAX_ROW_NONZEROS>,
    /// `∂r0/∂q` for the projected radius at the start (px).
    pub dr0: Vec<f32, MAX_ROW_NONZEROS>,
    /// `∂r1/∂q` for the projected radius at the end (px).
    pub dr1: Vec<f32, MAX_ROW_NONZEROS>,
}

impl LinkJacobian {
    /// Computes the derivatives of link `link`'s image axis and radii (Eq. 2.16 through the
    /// camera). Left empty if an end does not project.
    #[inline(never)] // a stage of Table 4.1: kept whole so profiles can attribute its cost
    pub fn compute(&mut self, model: &Model, poses: &Poses, camera: &Camera, link: &ProjectedLink) {
        self.states.clear();
        self.da.clear();
        self.db.clear();
        self.dr0.clear();
        self.dr1.clear();
        let frame = usize::from(link.frame);
        let (Some((_, z0, j0)), Some((_, z1, j1))) = (
            camera.project_with_jacobian(&link.p0),
            camera.project_with_jacobian(&link.p1),
        ) else {
            return;
        };
        let depth_row = camera.r.row(2).into_owned();
        let d0 = poses.point_derivatives(model, frame, &link.p0);
        let d1 = poses.point_derivatives(model, frame, &link.p1);
        for ((s, v0), (_, v1)) in d0.iter().zip(d1.iter()) {
            let _ = self.states.push(*s);
            let _ = self.da.push(j0 * v0);
            let _ = self.db.push(j1 * v1);
            let _ = self
                .dr0
                .push(-link.radius_at(0.0) / z0 * (depth_row * v0)[0]);
            let _ = self
                .dr1
                .push(-link.radius_at(1.0) / z1 * (depth_row * v1)[0]);
        }
    }
}

/// Where state `s` is stored in [`NormalEquations`]: the joints (`q7`...) first, the palm
/// states last. Every row involves the palm and one joint chain, so in this order `JᵀWJ` is
/// block-arrowhead and its factor has no fill outside the rows' envelope.
fn position(s: usize) -> usize {
    (s + MAX_STATES - BASE_STATES) % MAX_STATES
}

/// The state stored at position `p` (the inverse of [`position`]).
fn state_at(p: usize) -> usize {
    (p + BASE_STATES) % MAX_STATES
}

/// Entries strictly below the diagonal of a `MAX_STATES` square, packed by rows.
const LOWER: usize = MAX_STATES * (MAX_STATES - 1) / 2;

/// Index in a packed strict lower triangle of element (`hi`, `lo`), `hi > lo`.
fn packed(hi: usize, lo: usize) -> usize {
    hi * (hi - 1) / 2 + lo
}

/// The normal equations `JᵀWJ`, `JᵀWr` accumulated row by row, with residual statistics.
///
/// Kept as a packed triangle (under 2 KiB, so clearing it each iteration is a few vector
/// stores rather than a long `rep stos`).
#[derive(Debug, Clone)]
pub struct NormalEquations {
    /// Strict lower triangle of `JᵀWJ`, rows and columns in [`position`] order, packed.
    lower: [f32; LOWER],
    /// Diagonal of `JᵀWJ` in [`position`] order.
    diag: [f32; MAX_STATES],
    /// `JᵀWr` in [`position`] order.
    jtr: [f32; MAX_STATES],
    sum_squares: f32,
    rows: u16,
}

impl Default for NormalEquations {
    fn default() -> Self {
        Self::new()
    }
}

impl NormalEquations {
    /// Empty equations.
    pub fn new() -> Self {
        NormalEquations {
            lower: [0.0; LOWER],
            diag: [0.0; MAX_STATES],
            jtr: [0.0; MAX_STATES],
            sum_squares: 0.0,
            rows: 0,
        }
    }

    /// Clears for the next iteration.
    pub fn clear(&mut self) {
        self.lower = [0.0; LOWER];
        self.diag = [0.0; MAX_STATES];
        self.jtr = [0.0; MAX_STATES];
        self.sum_squares = 0.0;
        self.rows = 0;
    }

    /// Adds `v` to element (`si`, `sj`) of `JᵀWJ` (states; either order).
    fn add_at(&mut self, si: usize, sj: usize, v: f32) {
        let (pi, pj) = (position(si), position(sj));
        let cell = match pi.cmp(&pj) {
            core::cmp::Ordering::Equal => self.diag.get_mut(pi),
            core::cmp::Ordering::Greater => self.lower.get_mut(packed(pi, pj)),
            core::cmp::Ordering::Less => self.lower.get_mut(packed(pj, pi)),
        };
        if let Some(cell) = cell {
            *cell += v;
        }
    }

    /// Element (`pi`, `pj`) of `JᵀWJ` by positions, `pi > pj`.
    fn below(&self, pi: usize, pj: usize) -> f32 {
        self.lower.get(packed(pi, pj)).copied().unwrap_or(0.0)
    }

    /// Adds one residual `r` (px) with derivative entries `(state, ∂r/∂q_state)` and weight
    /// `w`; entries of states that are not free are dropped. Non-finite rows are ignored.
    pub fn add_row(&mut self, entries: &[(u8, f32)], r: f32, w: f32, free: FreeMask) {
        if !(r.is_finite() && w.is_finite()) || entries.iter().any(|(_, v)| !v.is_finite()) {
            return;
        }
        self.sum_squares += r * r;
        self.rows = self.rows.saturating_add(1);
        if w == 0.0 {
            return;
        }
        // Keep the free entries once, then a plain rank-1 update of the triangle.
        let mut index = [0usize; MAX_ROW_NONZEROS];
        let mut value = [0.0f32; MAX_ROW_NONZEROS];
        let mut n = 0;
        for &(s, v) in entries.iter().take(MAX_ROW_NONZEROS) {
            let s = usize::from(s);
            if s < MAX_STATES && free.contains(s) {
                index[n] = s;
                value[n] = v;
                n += 1;
            }
        }
        for a in 0..n {
            let (ia, wv) = (index[a], w * value[a]);
            self.jtr[position(ia)] += wv * r;
            for b in a..n {
                self.add_at(ia, index[b], wv * value[b]);
            }
        }
    }

    /// Adds a prior on one state: `weight · (q − centre)²` with `offset = q − centre` (the
    /// state's units), i.e. `weight` on the diagonal and `weight · offset` on `JᵀWr`. Not a
    /// residual: it changes neither [`rows`](Self::rows) nor [`rms`](Self::rms). Ignored for a
    /// state that is not free, or for a non-finite or non-positive weight.
    pub fn add_prior(&mut self, state: usize, weight: f32, offset: f32, free: FreeMask) {
        if state >= MAX_STATES
            || !free.contains(state)
            || !(weight > 0.0 && weight.is_finite() && offset.is_finite())
        {
            return;
        }
        let p = position(state);
        self.diag[p] += weight;
        self.jtr[p] += weight * offset;
    }

    /// Rows added since the last clear.
    pub fn rows(&self) -> u16 {
        self.rows
    }

    /// Root-mean-square of the (unweighted) residuals added (px).
    pub fn rms(&self) -> f32 {
        if self.rows == 0 {
            0.0
        } else {
            libm::sqrtf(self.sum_squares / f32::from(self.rows))
        }
    }

    /// The conditioned Gauss–Newton step `−(JᵀWJ + S)⁻¹ JᵀWr` for the free states (zero for
    /// the others), or `None` if the system is not positive definite or not finite
    /// ([`solve`](Self::solve)).
    #[inline(never)] // a stage of Table 4.1: kept whole so profiles can attribute its cost
    pub fn step(
        &self,
        n_states: usize,
        free: FreeMask,
        conditioning: &Conditioning,
    ) -> Option<SVector<f32, MAX_STATES>> {
        let mut rhs = SVector::<f32, MAX_STATES>::zeros();
        for p in 0..MAX_STATES {
            rhs[state_at(p)] = self.jtr[p];
        }
        self.solve(n_states, free, conditioning, &rhs).map(|x| -x)
    }

    /// `JᵀWJ · x` over the free states (zero for the others); `x` and the result by state.
    pub fn times(&self, free: FreeMask, x: &SVector<f32, MAX_STATES>) -> SVector<f32, MAX_STATES> {
        let mut y = SVector::<f32, MAX_STATES>::zeros();
        for pi in 0..MAX_STATES {
            let si = state_at(pi);
            if !free.contains(si) {
                continue;
            }
            y[si] += self.diag[pi] * x[si];
            for pj in 0..pi {
                let sj = state_at(pj);
                if !free.contains(sj) {
                    continue;
                }
                let h = self.below(pi, pj);
                y[si] += h * x[sj];
                y[sj] += h * x[si];
            }
        }
        y
    }

    /// Solves `(JᵀWJ + S) x = rhs` over the free states (zero for the others); `rhs` and `x`
    /// by state. `None` if the system is not positive definite or the answer not finite.
    ///
    /// Solved over the free states only, by an `LDLᵀ` factorisation (no square roots) that
    /// works within each row's envelope: in the joints-then-palm order a joint's row is zero
    /// left of its chain's first joint, and the factor keeps that profile.
    pub fn solve(
        &self,
        n_states: usize,
        free: FreeMask,
        conditioning: &Conditioning,
        rhs: &SVector<f32, MAX_STATES>,
    ) -> Option<SVector<f32, MAX_STATES>> {
        // The free states, in storage order: `at[i]` is the position of the i-th.
        let mut at = [0usize; MAX_STATES];
        let mut m = 0;
        for p in 0..MAX_STATES {
            let s = state_at(p);
            if s < n_states && free.contains(s) {
                at[m] = p;
                m += 1;
            }
        }
        let at = &at[..m];
        // The compact system, packed by rows like `lower`: each row's envelope (from its first
        // non-zero) in `l`, the diagonal in `d`.
        let mut l = [0.0f32; LOWER];
        let mut first = [0usize; MAX_STATES];
        let mut d = [0.0f32; MAX_STATES];
        let mut b = [0.0f32; MAX_STATES];
        for (i, &pi) in at.iter().enumerate() {
            let f = at[..i]
                .iter()
                .position(|&pj| self.below(pi, pj) != 0.0)
                .unwrap_or(i);
            first[i] = f;
            let row = packed(i.max(1), 0);
            for (j, &pj) in at.iter().enumerate().take(i).skip(f) {
                l[row + j] = self.below(pi, pj);
            }
            d[i] = self.diag[pi] + conditioning.for_state(state_at(pi));
            b[i] = rhs[state_at(pi)];
        }
        // LDLᵀ, row by row: `l` becomes the unit lower factor, `d` the pivots.
        let mut w = [0.0f32; MAX_STATES]; // L[i][k]·D[k] of the row being factored
        let mut inv_d = [0.0f32; MAX_STATES];
        for i in 0..m {
            let fi = first[i];
            let row = packed(i.max(1), 0);
            for j in fi..i {
                let from = first[j].max(fi);
                let row_j = packed(j.max(1), 0);
                let mut t = l[row + j];
                // Mostly 0–4 terms (a joint's chain) or a whole row (palm by palm): a plain
                // indexed loop, without an iterator's set-up.
                let mut k = from;
                while k < j {
                    t -= w[k] * l[row_j + k];
                    k += 1;
                }
                w[j] = t;
                l[row + j] = t * inv_d[j];
            }
            let mut pivot = d[i];
            for (wk, lik) in w[fi..i].iter().zip(&l[row + fi..row + i]) {
                pivot -= wk * lik;
            }
            if !(pivot > 0.0 && pivot.is_finite()) {
                return None;
            }
            inv_d[i] = 1.0 / pivot;
        }
        // L y = b, then Lᵀ x = D⁻¹ y.
        for i in 0..m {
            let (fi, row) = (first[i], packed(i.max(1), 0));
            let mut t = b[i];
            for (lik, yk) in l[row + fi..row + i].iter().zip(&b[fi..i]) {
                t -= lik * yk;
            }
            b[i] = t;
        }
        for (y, inv) in b.iter_mut().zip(&inv_d).take(m) {
            *y *= inv;
        }
        for i in (0..m).rev() {
            let (fi, row, xi) = (first[i], packed(i.max(1), 0), b[i]);
            for (xk, lik) in b[fi..i].iter_mut().zip(&l[row + fi..row + i]) {
                *xk -= lik * xi;
            }
        }
        let mut x = SVector::<f32, MAX_STATES>::zeros();
        for (&p, v) in at.iter().zip(&b) {
            x[state_at(p)] = *v;
        }
        x.iter().all(|v| v.is_finite()).then_some(x)
    }
}

/// A row of derivative entries `(state, ∂r/∂q_state)`.
pub type Row = Vec<(u8, f32), MAX_ROW_NONZEROS>;

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
        ne.sum_squares += self.sum_squares;
        ne.rows = ne.rows.saturating_add(self.rows);
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

/// What every edge row of one link shares, computed once per link (see [`edge_row`]).
struct EdgeBasis {
    normal: Vector2<f32>,
    axis: Vector2<f32>,
    len2: f32,
    taper: [f32; 2],
}

impl EdgeBasis {
    fn new(link: &ProjectedLink) -> Self {
        let (_, normal) = axis_frame(&link.a, &link.b);
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
                block.add(&c, r, config.robust.weight(r));
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
                block.add(&c, r, config.robust.weight(r));
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
                    block.add(&c, line_normal.dot(&(point - centre)), 1.0);
                    added.edges += 1;
                }
            }
        }
    }
    if let Some(tip) = features.tip {
        // Eq. 2.19, as `tip_row`: `dir·∂b + ∂r1`.
        let (dir, _) = axis_frame(&link.a, &link.b);
        let r = dir.dot(&(link.b - tip)) + link.tip_offset;
        let c = [0.0, 0.0, dir.x, dir.y, 0.0, 1.0];
        block.add(&c, r, config.tip_weight * config.robust.weight(r));
        added.tips += 1;
    }
    block.scatter(ne, jac, free);
    added
}

/// The edge-point residual of `edge` (px): the predicted silhouette offset minus the measured
/// one, at the edge's foot on the axis. Positive when the edge lies inside the prediction.
pub fn edge_residual(link: &ProjectedLink, edge: &EdgePoint) -> f32 {
    let (_, normal) = axis_frame(&link.a, &link.b);
    let axis = link.b - link.a;
    let s = ((edge.position - link.a).dot(&axis) / axis.norm_squared().max(1e-9)).clamp(0.0, 1.0);
    link.side_radius_at(s, edge.side) - f32::from(edge.side) * normal.dot(&(edge.position - link.a))
}

/// The edge-point residual (px) and its derivative row (into `row`): the derivative of a fixed
/// point's distance to a moving line, `σ n·((1−s) ∂a + s ∂b)`, plus that of the predicted
/// offset at the edge's foot `s`, `(1−s) ∂r0 + s ∂r1 + (r1 − r0) ∂s` (the foot slides when the
/// link moves along its axis, and the image radius tapers under perspective).
pub fn edge_row(link: &ProjectedLink, jac: &LinkJacobian, edge: &EdgePoint, row: &mut Row) -> f32 {
    let (_, normal) = axis_frame(&link.a, &link.b);
    let axis = link.b - link.a;
    let len2 = axis.norm_squared().max(1e-9);
    let rel = edge.position - link.a;
    let raw_s = rel.dot(&axis) / len2;
    let s = raw_s.clamp(0.0, 1.0);
    let inside = (0.0..=1.0).contains(&raw_s);
    let taper = link.side_radius_at(1.0, edge.side) - link.side_radius_at(0.0, edge.side);
    let side = f32::from(edge.side);
    row.clear();
    for k in 0..jac.states.len() {
        let moved = jac.da[k] * (1.0 - s) + jac.db[k] * s;
        let dr = jac.dr0[k] * (1.0 - s) + jac.dr1[k] * s;
        let d_axis = jac.db[k] - jac.da[k];
        let ds = if inside {
            (rel.dot(&d_axis) - jac.da[k].dot(&axis) - 2.0 * raw_s * axis.dot(&d_axis)) / len2
        } else {
            0.0
        };
        let _ = row.push((jac.states[k], side * normal.dot(&moved) + dr + taper * ds));
    }
    edge_residual(link, edge)
}

/// The axis-line residual (Eq. 2.17) of the model axis' start (`end` 0) or end (`end` 1)
/// against the measured line `(point, normal)` (px), and its derivative row.
pub fn line_row(
    link: &ProjectedLink,
    jac: &LinkJacobian,
    line: (Vector2<f32>, Vector2<f32>),
    end: usize,
    row: &mut Row,
) -> f32 {
    let (centre, line_normal) = line;
    let point = if end == 0 { link.a } else { link.b };
    row.clear();
    for k in 0..jac.states.len() {
        let moved = if end == 0 { jac.da[k] } else { jac.db[k] };
        let _ = row.push((jac.states[k], line_normal.dot(&moved)));
    }
    line_normal.dot(&(point - centre))
}

/// The tip residual (Eq. 2.19, along the image axis) of a fingertip found at `tip` (px):
/// predicted minus measured distance beyond `b`, and its derivative row.
pub fn tip_row(link: &ProjectedLink, jac: &LinkJacobian, tip: &Vector2<f32>, row: &mut Row) -> f32 {
    let (dir, _) = axis_frame(&link.a, &link.b);
    row.clear();
    for k in 0..jac.states.len() {
        let _ = row.push((jac.states[k], dir.dot(&jac.db[k]) + jac.dr1[k]));
    }
    dir.dot(&(link.b - tip)) + link.tip_offset
}

/// Fits the axis line of a link through its edge points, each moved toward the axis by the
/// projected radius (so one silhouette alone still gives the axis), rejecting points more than
/// 2 px (or 3 median deviations) off a first fit. Returns a point on the line and its normal.
pub fn fit_axis_line(
    link: &ProjectedLink,
    features: &LinkFeatures,
) -> Option<(Vector2<f32>, Vector2<f32>)> {
    let (_, normal) = axis_frame(&link.a, &link.b);
    let axis = link.b - link.a;
    let len2 = axis.norm_squared().max(1e-9);
    let mut points: Vec<Vector2<f32>, { crate::features::MAX_LINK_EDGES }> = Vec::new();
    for e in &features.edges {
        let s = ((e.position - link.a).dot(&axis) / len2).clamp(0.0, 1.0);
        let _ =
            points.push(e.position - normal * (f32::from(e.side) * link.side_radius_at(s, e.side)));
    }
    let first = total_least_squares(&points, None)?;
    let mut deviations: Vec<f32, { crate::features::MAX_LINK_EDGES }> = Vec::new();
    for p in &points {
        let _ = deviations.push(first.1.dot(&(p - first.0)).abs());
    }
    let mut sorted = deviations.clone();
    sorted.sort_unstable_by(|a, b| a.total_cmp(b));
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
    let limit = (3.0 * median).max(2.0);
    total_least_squares(&points, Some((&deviations, limit))).or(Some(first))
}

fn total_least_squares(
    points: &[Vector2<f32>],
    keep: Option<(&[f32], f32)>,
) -> Option<(Vector2<f32>, Vector2<f32>)> {
    let kept = |i: usize| keep.is_none_or(|(d, limit)| d.get(i).is_some_and(|v| *v <= limit));
    let mut n = 0.0f32;
    let mut centre = Vector2::zeros();
    for (i, p) in points.iter().enumerate() {
        if kept(i) {
            centre += p;
            n += 1.0;
        }
    }
    if n < 2.0 {
        return None;
    }
    centre /= n;
    let (mut sxx, mut sxy, mut syy) = (0.0f32, 0.0f32, 0.0f32);
    for (i, p) in points.iter().enumerate() {
        if kept(i) {
            let d = p - centre;
            sxx += d.x * d.x;
            sxy += d.x * d.y;
            syy += d.y * d.y;
        }
    }
    // Direction of largest spread: angle of the principal axis of the 2×2 scatter matrix.
    let angle = 0.5 * libm::atan2f(2.0 * sxy, sxx - syy);
    let (s, c) = libm::sincosf(angle);
    if sxx + syy < 1e-6 {
        return None;
    }
    Some((centre, Vector2::new(-s, c)))
}

/// Applies a step to the free states of `q`, renormalises the quaternion and clamps joints to
/// the model's ranges. Returns the largest joint-angle change (rad) and translation (mm).
pub fn apply_step(
    model: &Model,
    q: &mut [f32],
    delta: &SVector<f32, MAX_STATES>,
    free: FreeMask,
) -> (f32, f32) {
    let (mut max_angle, mut max_move) = (0.0f32, 0.0f32);
    for (i, v) in q.iter_mut().enumerate().take(MAX_STATES) {
        if !free.contains(i) {
            continue;
        }
        *v += delta[i];
        if i >= BASE_STATES {
            if let Some(limit) = model.limit(i) {
                *v = v.clamp(limit.lo, limit.hi);
            }
            max_angle = max_angle.max(delta[i].abs());
        } else if i >= 4 {
            max_move = max_move.max(delta[i].abs());
        } else {
            max_angle = max_angle.max(delta[i].abs());
        }
    }
    if q.len() >= 4 {
        if let Some(u) = crate::quaternion::normalised([q[0], q[1], q[2], q[3]]) {
            q[..4].copy_from_slice(&u);
        }
    }
    (max_angle, max_move)
}
