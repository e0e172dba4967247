//! Joint ranges inside the Gauss–Newton step (an active set).
//!
//! A plain step moves every free state at once and then clamps each joint to its range
//! ([`apply_step`](super::apply_step)): a joint that wanted to go past its bound stops there,
//! but the states coupled to it moved as though it had gone on, so they take its share of the
//! fit, and on the next iteration the same happens again: the solve stays pinned at the bound.
//! [`NormalEquations::bounded_step`] instead holds such a joint at its bound and solves the
//! other free states again given that: `(H + S)_FF δ_F = −g_F − H_FB δ_B`, with `B` the held
//! joints, `δ_B` their moves to the bound and `F` the rest. A finger lying straight (every
//! flexion at its lower bound, 0 rad) is the common case: its joints are pushed against 0 by
//! every noisy edge, and the palm and the other joints no longer pay for it.

use nalgebra::SVector;

use super::normal::{position, NormalEquations};
use super::{Conditioning, FreeMask};
use crate::config::MAX_STATES;
use crate::model::Model;

/// Times the step is solved again as more joints reach their bounds, at most (each round holds
/// every joint the last solve carried out of its range; a joint held stays held).
pub const MAX_BOUND_ROUNDS: usize = 3;

impl NormalEquations {
    /// The conditioned Gauss–Newton step ([`step`](Self::step)) at state `q`, with every free
    /// joint the step would carry out of its range held at its bound and the other free states
    /// solved again for it, up to `MAX_BOUND_ROUNDS` times. Bit for bit the plain step when
    /// no bound is crossed. `None` as for [`step`](Self::step), or if `q` is shorter than the
    /// model's states.
    pub fn bounded_step(
        &self,
        model: &Model,
        q: &[f32],
        free: FreeMask,
        conditioning: &Conditioning,
    ) -> Option<SVector<f32, MAX_STATES>> {
        let n = model.n_states().min(MAX_STATES);
        let q = q.get(..n)?;
        let mut step = self.step(n, free, conditioning)?;
        let mut held = FreeMask(0);
        let mut to_bound = SVector::<f32, MAX_STATES>::zeros();
        for _ in 0..MAX_BOUND_ROUNDS {
            let mut crossed = false;
            for (i, &now) in q.iter().enumerate() {
                if !free.contains(i) || held.contains(i) {
                    continue;
                }
                let Some(limit) = model.limit(i) else {
                    continue;
                };
                let next = now + step[i];
                if next > limit.hi || next < limit.lo {
                    held.0 |= 1 << i;
                    to_bound[i] = next.clamp(limit.lo, limit.hi) - now;
                    crossed = true;
                }
            }
            if !crossed {
                break;
            }
            let rest = FreeMask(free.0 & !held.0);
            let coupled = self.times(free, &to_bound);
            let mut rhs = SVector::<f32, MAX_STATES>::zeros();
            for s in 0..n {
                if rest.contains(s) {
                    rhs[s] = self.jtr[position(s)] + coupled[s];
                }
            }
            let x = self.solve(n, rest, conditioning, &rhs)?;
            for s in 0..n {
                step[s] = if held.contains(s) { to_bound[s] } else { -x[s] };
            }
        }
        Some(step)
    }
}
