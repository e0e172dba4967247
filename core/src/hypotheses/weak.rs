//! The directions of the state the images constrain least, from a frame's normal equations:
//! where a single Gauss–Newton track may settle on the wrong reading of an ambiguous image
//! (how a finger seen end-on splits its bend among its joints, Sec. 2.5.4; the depth of a
//! palm seen by one camera), and so where other hypotheses are worth sampling.

use heapless::Vec;
use nalgebra::{SMatrix, SVector};

use super::config::Spread;
use super::fingers::Fingers;
use crate::config::{MAX_CHAIN, MAX_SPAWN, MAX_STATES};
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

/// The finger whose bend the images split least surely, and how: for each finger, the
/// eigen-directions of its own block of `JᵀWJ` (its joints only, in [`Spread`] units); the
/// finger whose weakest direction is weakest *relative to its strongest* — seen, but not how
/// the bend is shared (a finger wholly hidden has them all alike, and is left to the prior) —
/// with that direction. `None` when no finger has rows.
#[inline(never)] // a stage of the hypotheses' loop: kept whole so profiles can attribute it
pub fn most_ambiguous_finger(
    normal: &NormalEquations,
    n_states: usize,
    free: FreeMask,
    fingers: &Fingers,
    spread: &Spread,
) -> Option<(usize, WeakDirection)> {
    let mut best: Option<(f32, usize, WeakDirection)> = None;
    for f in 0..fingers.count() {
        let mut states = [0usize; MAX_CHAIN];
        let mut m = 0;
        for s in 0..n_states.min(MAX_STATES) {
            if m < MAX_CHAIN && free.contains(s) && fingers.contains(f, s) {
                states[m] = s;
                m += 1;
            }
        }
        if m < 2 {
            continue;
        }
        let mut block = SMatrix::<f32, MAX_CHAIN, MAX_CHAIN>::zeros();
        let mut largest = 0.0f32;
        for a in 0..m {
            for b in 0..m {
                let (sa, sb) = (states[a], states[b]);
                block[(a, b)] =
                    normal.element(sa, sb) * spread.for_state(sa) * spread.for_state(sb);
            }
            largest = largest.max(block[(a, a)]);
        }
        if !block.iter().all(|v| v.is_finite()) || largest <= 0.0 {
            continue;
        }
        // Padding sits far above every real eigenvalue (at most m × the largest diagonal).
        let padding = 100.0 * largest;
        for a in m..MAX_CHAIN {
            block[(a, a)] = padding;
        }
        let Some(eigen) = block.try_symmetric_eigen(1e-6, MAX_EIGEN_ITERATIONS) else {
            continue;
        };
        let real = |k: &usize| eigen.eigenvalues[*k] < 0.5 * padding;
        let by_value =
            |a: &usize, b: &usize| eigen.eigenvalues[*a].total_cmp(&eigen.eigenvalues[*b]);
        let (Some(lo), Some(hi)) = (
            (0..MAX_CHAIN).filter(real).min_by(by_value),
            (0..MAX_CHAIN).filter(real).max_by(by_value),
        ) else {
            continue;
        };
        let (weak, strong) = (eigen.eigenvalues[lo], eigen.eigenvalues[hi]);
        if !(strong > 0.0 && weak.is_finite()) {
            continue;
        }
        let ratio = weak.max(0.0) / strong;
        if best.as_ref().is_some_and(|(r, _, _)| *r <= ratio) {
            continue;
        }
        let mut direction = SVector::<f32, MAX_STATES>::zeros();
        for a in 0..m {
            direction[states[a]] = eigen.eigenvectors[(a, lo)] * spread.for_state(states[a]);
        }
        best = Some((
            ratio,
            f,
            WeakDirection {
                direction,
                strength: weak,
            },
        ));
    }
    best.map(|(_, f, d)| (f, d))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Equations that observe joints 7..=10 one by one, except that 8 and 9 are seen only
    /// through their sum (a finger seen end-on: the bend, not its split).
    fn split_blind() -> NormalEquations {
        let mut normal = NormalEquations::new();
        let free = FreeMask::from_states(&[7, 8, 9, 10]).unwrap();
        for _ in 0..3 {
            normal.add_row(&[(7, 40.0)], 0.0, 1.0, free);
            normal.add_row(&[(10, 30.0)], 0.0, 1.0, free);
            normal.add_row(&[(8, 25.0), (9, 25.0)], 0.0, 1.0, free);
        }
        for s in [7, 8, 9, 10] {
            normal.add_prior(s, 1.0, 0.0, free); // what keeps the blind split finite
        }
        normal
    }

    #[test]
    fn the_weakest_direction_is_the_split_the_images_cannot_see() {
        let free = FreeMask::from_states(&[7, 8, 9, 10]).unwrap();
        let spread = Spread::default();
        let weak = weakest(&split_blind(), 28, free, &spread, 2);
        assert_eq!(weak.len(), 2);
        let d = weak[0].direction;
        // Along q8 − q9, in spread units of length 1; nothing on the seen states.
        let unit = spread.joint_rad / crate::float::sqrt(2.0);
        assert!((libm::fabsf(d[8]) - unit).abs() < 1e-4, "{d:?}");
        assert!((d[8] + d[9]).abs() < 1e-4, "{d:?}");
        assert!(d[7].abs() < 1e-4 && d[10].abs() < 1e-4, "{d:?}");
        // Only the prior holds it: strength prior × spread².
        let prior = spread.joint_rad * spread.joint_rad;
        assert!(
            (weak[0].strength - prior).abs() < 1e-3 * prior.max(1.0),
            "{}",
            weak[0].strength
        );
        assert!(weak[1].strength > 100.0 * weak[0].strength);
        // States that are not free never appear.
        assert!((0..32)
            .filter(|s| ![7, 8, 9, 10].contains(s))
            .all(|s| d[s] == 0.0));
    }

    #[test]
    fn nothing_free_or_not_finite_gives_no_direction() {
        let spread = Spread::default();
        assert!(weakest(&split_blind(), 28, FreeMask(0), &spread, 2).is_empty());
        let mut normal = split_blind();
        normal.add_prior(7, f32::INFINITY, 0.0, FreeMask::all(28)); // ignored: not finite
        assert_eq!(weakest(&normal, 28, FreeMask::all(28), &spread, 1).len(), 1);
    }
}
