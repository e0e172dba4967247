//! The directions of the state the images constrain least, from a frame's normal equations:
//! where a single Gauss–Newton track may settle on the wrong reading of an ambiguous image
//! (how a finger seen end-on splits its bend among its joints, Sec. 2.5.4; the depth of a
//! palm seen by one camera), and so where other hypotheses are worth sampling.

use heapless::Vec;
use nalgebra::{SMatrix, SVector};

use super::config::Spread;
use crate::config::{MAX_SPAWN, MAX_STATES};
use crate::estimator::{FreeMask, NormalEquations};

/// A direction in state space (by state, in the states' own units: a step of 1 along it
/// changes each state by its entry) and how strongly the images observed it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WeakDirection {
    /// The direction, by state (zero on states that are not free).
    pub direction: SVector<f32, MAX_STATES>,
    /// The eigenvalue of `JᵀWJ` along it, in [`Spread`] units (px² per unit²).
    pub strength: f32,
}

/// Iterations the eigen-solver may take.
const MAX_EIGEN_ITERATIONS: usize = 64;

/// The `count` weakest directions of `normal` over the free states of a model with
/// `n_states` states, weakest first, each of unit length in `spread` units. Empty when the
/// equations have no free state or are not finite.
#[inline(never)] // a stage of the hypotheses' loop: kept whole so profiles can attribute it
pub fn weakest(
    normal: &NormalEquations,
    n_states: usize,
    free: FreeMask,
    spread: &Spread,
    count: usize,
) -> Vec<WeakDirection, MAX_SPAWN> {
    let mut out = Vec::new();
    let n = n_states.min(MAX_STATES);
    let scale = |i: usize| spread.for_state(i);
    let mut scaled = SMatrix::<f32, MAX_STATES, MAX_STATES>::zeros();
    let mut largest = 0.0f32;
    let mut any_free = false;
    for i in 0..MAX_STATES {
        if i >= n || !free.contains(i) {
            continue;
        }
        any_free = true;
        for j in 0..=i {
            if j >= n || !free.contains(j) {
                continue;
            }
            let v = normal.element(i, j) * scale(i) * scale(j);
            scaled[(i, j)] = v;
            scaled[(j, i)] = v;
        }
        largest = largest.max(scaled[(i, i)]);
    }
    if !any_free || !scaled.iter().all(|v| v.is_finite()) {
        return out;
    }
    // States that are not estimated sit far above every real eigenvalue, out of the way.
    let out_of_the_way = 10.0 * largest.max(1.0);
    for i in 0..MAX_STATES {
        if i >= n || !free.contains(i) {
            scaled[(i, i)] = out_of_the_way;
        }
    }
    let Some(eigen) = scaled.try_symmetric_eigen(1e-6, MAX_EIGEN_ITERATIONS) else {
        return out;
    };
    let mut order = [0usize; MAX_STATES];
    for (k, o) in order.iter_mut().enumerate() {
        *o = k;
    }
    order.sort_unstable_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]));
    for &k in order.iter().take(count.min(MAX_SPAWN)) {
        let strength = eigen.eigenvalues[k];
        if !strength.is_finite() || strength >= out_of_the_way * 0.5 {
            break;
        }
        let mut direction = SVector::<f32, MAX_STATES>::zeros();
        for i in 0..n {
            if free.contains(i) {
                direction[i] = eigen.eigenvectors[(i, k)] * scale(i);
            }
        }
        let _ = out.push(WeakDirection {
            direction,
            strength,
        });
    }
    out
}
