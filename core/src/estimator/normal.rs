//! The normal equations `JᵀWJ`, `JᵀWr` and the conditioned Gauss–Newton step, solved by a
//! sparse `LDLᵀ` factorisation over the free states (Eq. 2.22).

use nalgebra::SVector;

use super::{Conditioning, FreeMask};
use crate::config::{MAX_ROW_NONZEROS, MAX_STATES};
use crate::model::BASE_STATES;

/// Where state `s` is stored in [`NormalEquations`]: the joints (`q7`...) first, the palm
/// states last. Every row involves the palm and one joint chain, so in this order `JᵀWJ` is
/// block-arrowhead and its factor has no fill outside the rows' envelope.
#[inline]
pub(super) fn position(s: usize) -> usize {
    (s + MAX_STATES - BASE_STATES) % MAX_STATES
}

/// The state stored at position `p` (the inverse of [`position`]).
#[inline]
fn state_at(p: usize) -> usize {
    (p + BASE_STATES) % MAX_STATES
}

/// Entries strictly below the diagonal of a `MAX_STATES` square, packed by rows.
const LOWER: usize = MAX_STATES * (MAX_STATES - 1) / 2;

/// Index in a packed strict lower triangle of element (`hi`, `lo`), `hi > lo`.
#[inline]
pub(super) fn packed(hi: usize, lo: usize) -> usize {
    hi * (hi - 1) / 2 + lo
}

/// The normal equations `JᵀWJ`, `JᵀWr` accumulated row by row, with residual statistics.
///
/// Kept as a packed triangle (under 2 KiB, so clearing it each iteration is a few vector
/// stores rather than a long `rep stos`).
#[derive(Debug, Clone)]
pub struct NormalEquations {
    /// Strict lower triangle of `JᵀWJ`, rows and columns in [`position`] order, packed.
    pub(super) lower: [f32; LOWER],
    /// Diagonal of `JᵀWJ` in [`position`] order.
    pub(super) diag: [f32; MAX_STATES],
    /// `JᵀWr` in [`position`] order.
    pub(super) jtr: [f32; MAX_STATES],
    pub(super) sum_squares: f32,
    pub(super) rows: u16,
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
            crate::float::sqrt(self.sum_squares / f32::from(self.rows))
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

    /// Element (`si`, `sj`) of `JᵀWJ` by states (either order; 0 beyond [`MAX_STATES`]).
    pub fn element(&self, si: usize, sj: usize) -> f32 {
        if si >= MAX_STATES || sj >= MAX_STATES {
            return 0.0;
        }
        let (pi, pj) = (position(si), position(sj));
        match pi.cmp(&pj) {
            core::cmp::Ordering::Equal => self.diag[pi],
            core::cmp::Ordering::Greater => self.below(pi, pj),
            core::cmp::Ordering::Less => self.below(pj, pi),
        }
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
