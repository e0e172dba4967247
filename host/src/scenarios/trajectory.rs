//! Smooth seeded motion: every moving state follows a sum of sinusoids around its base value.
//!
//! A channel's signal is `s(τ) = Σ_k w_k sin(2π f_k τ) / Σ_k |w_k|`, so `|s| ≤ 1` and `s(0) = 0`:
//! frame 0 is exactly the scenario's base pose. A joint state moves as `base + amplitude · s`;
//! the palm rotation as `base ⊗ exp(ω)` with `ω_i = amplitude_i · s_i` about the palm's own
//! axes. Time `τ = frame · time_scale`; the time scale sets how fast the hand moves.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Sinusoids summed per channel.
const COMPONENTS: usize = 3;

/// One channel's signal: a sum of sinusoids through zero at τ = 0.
#[derive(Debug, Clone, PartialEq)]
pub struct Signal {
    /// `(weight, frequency in cycles per unit τ)`.
    terms: [(f64, f64); COMPONENTS],
}

impl Signal {
    /// A random signal: frequencies in 0.3–1 cycles per unit τ, weights of either sign.
    pub fn random(rng: &mut impl Rng) -> Signal {
        let mut terms = [(0.0, 0.0); COMPONENTS];
        for t in terms.iter_mut() {
            let sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            *t = (
                sign * rng.random_range(0.4..1.0),
                rng.random_range(0.3..1.0),
            );
        }
        Signal { terms }
    }

    /// The signal at time `tau`, in [−1, 1].
    pub fn at(&self, tau: f64) -> f64 {
        let norm: f64 = self.terms.iter().map(|(w, _)| w.abs()).sum();
        self.terms
            .iter()
            .map(|(w, f)| w * (std::f64::consts::TAU * f * tau).sin())
            .sum::<f64>()
            / norm
    }
}

/// How the states of a scenario move.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    /// The pose at frame 0 (quaternion, mm, rad).
    pub base: Vec<f64>,
    /// `(state, amplitude, signal)`: state `base + amplitude · s(τ)` (mm or rad).
    pub states: Vec<(usize, f64, Signal)>,
    /// Palm rotation about its own x, y, z axes: `(amplitude in rad, signal)` each.
    pub rotation: Option<[(f64, Signal); 3]>,
}

impl Motion {
    /// A motion with fresh signals from `seed`: `amplitudes` lists `(state, amplitude)` for the
    /// moving states, `rotation` the palm's rotation amplitudes (rad) when it turns.
    pub fn random(
        base: Vec<f64>,
        amplitudes: &[(usize, f64)],
        rotation: Option<[f64; 3]>,
        seed: u64,
    ) -> Motion {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let states = amplitudes
            .iter()
            .map(|&(s, a)| (s, a, Signal::random(&mut rng)))
            .collect();
        let rotation = rotation.map(|amp| amp.map(|a| (a, Signal::random(&mut rng))));
        Motion {
            base,
            states,
            rotation,
        }
    }

    /// The same motion with every amplitude multiplied by `factor`.
    pub fn scaled(mut self, factor: f64) -> Motion {
        for (_, amplitude, _) in &mut self.states {
            *amplitude *= factor;
        }
        if let Some(rotation) = &mut self.rotation {
            for (amplitude, _) in rotation.iter_mut() {
                *amplitude *= factor;
            }
        }
        self
    }

    /// The state at time `tau` (quaternion unit length, mm, rad).
    pub fn at(&self, tau: f64) -> Vec<f64> {
        let mut q = self.base.clone();
        for (s, amplitude, signal) in &self.states {
            q[*s] += amplitude * signal.at(tau);
        }
        if let Some(rotation) = &self.rotation {
            let omega = Vector3::from_fn(|i, _| rotation[i].0 * rotation[i].1.at(tau));
            let turned = base_rotation(&self.base) * UnitQuaternion::from_scaled_axis(omega);
            q[0] = turned.w;
            q[1] = turned.i;
            q[2] = turned.j;
            q[3] = turned.k;
        }
        q
    }

    /// States at frames `0..frames` with `τ = frame · time_scale`.
    pub fn sample(&self, frames: usize, time_scale: f64) -> Vec<Vec<f64>> {
        (0..frames)
            .map(|k| self.at(k as f64 * time_scale))
            .collect()
    }
}

/// The palm rotation of a state vector (its quaternion `w, x, y, z`, normalised).
fn base_rotation(q: &[f64]) -> UnitQuaternion<f64> {
    UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use digiteyes_core::quaternion;

    #[test]
    fn signals_are_bounded_and_start_at_zero() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let s = Signal::random(&mut rng);
        assert_eq!(s.at(0.0), 0.0);
        assert!((0..1000).all(|k| s.at(k as f64 * 0.01).abs() <= 1.0));
    }

    #[test]
    fn rotation_composes_in_the_palm_frame_with_the_core_convention() {
        // Base: 90° about world z; a turn about the palm's own x axis is then about world y.
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let mut base = vec![h, 0.0, 0.0, h];
        base.extend([0.0; 3]);
        let mut motion = Motion::random(base, &[], Some([0.3, 0.0, 0.0]), 1);
        motion.rotation.as_mut().unwrap()[0].1 = Signal {
            terms: [(1.0, 0.25), (0.0, 0.0), (0.0, 0.0)],
        };
        let q = motion.at(1.0); // s = sin(π/2) = 1: 0.3 rad about palm x
        let r = quaternion::rotation(q[0] as f32, q[1] as f32, q[2] as f32, q[3] as f32);
        // The palm's x axis (first column) stays world y.
        assert!(
            (r.column(0) - digiteyes_core::nalgebra::Vector3::new(0.0, 1.0, 0.0)).norm() < 1e-6
        );
        // The palm's z axis turned by 0.3 rad about world y.
        let z = r.column(2);
        assert!((z.x - 0.3f32.sin()).abs() < 1e-6 && (z.z - 0.3f32.cos()).abs() < 1e-6);
    }
}
