//! The one-euro filter (Casiez, Roussel, Vogel, "1 € Filter: A Simple Speed-based Low-pass
//! Filter for Noisy Input in Interactive Systems", CHI 2012) for forwarded states.
//!
//! A first-order low-pass whose cutoff rises with speed: `cutoff = min_cutoff + beta·|dx/dt|`,
//! the speed itself low-passed at `d_cutoff`. At rest the cutoff is low and jitter goes; in
//! fast motion it is high and lag goes. Tuning, as the paper advises: with `beta = 0`, lower
//! `min_cutoff` until the jitter at rest is acceptable; then raise `beta` until fast motion
//! does not lag.
//!
//! `beta` multiplies a speed, so its unit is the inverse of the state's: the palm's
//! translation (mm) and the angles (rad) have one each ([`Smoothing`]).

use anyhow::{bail, Result};
use digiteyes_core::state::TRANSLATION;

/// Default lowest cutoff, at rest (Hz).
pub const DEFAULT_MIN_CUTOFF_HZ: f32 = 1.0;
/// Default speed coefficient of the palm's translation q4..q6 (per mm: Hz of cutoff per mm/s).
pub const DEFAULT_BETA_MM: f32 = 0.02;
/// Default speed coefficient of the quaternion and the joints (per rad: Hz per rad/s): 50 ×
/// the translation's, as a joint turning 1 rad moves a fingertip about 50 mm.
pub const DEFAULT_BETA_RAD: f32 = 1.0;
/// Default cutoff of the speed estimate (Hz), the paper's.
pub const DEFAULT_D_CUTOFF_HZ: f32 = 1.0;

/// The interval assumed for a sample whose time does not advance before any that did (s).
const FALLBACK_DT_S: f64 = 1.0 / 30.0;

/// The parameters of one filter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OneEuroConfig {
    /// Lowest cutoff, at rest (Hz, > 0).
    pub min_cutoff_hz: f32,
    /// Cutoff added per unit of speed (Hz per unit/s, >= 0); 0 = a fixed low-pass.
    pub beta: f32,
    /// Cutoff of the speed estimate (Hz, > 0).
    pub d_cutoff_hz: f32,
}

impl OneEuroConfig {
    /// Checks the parameters: cutoffs finite and > 0 Hz, `beta` finite and >= 0.
    pub fn new(min_cutoff_hz: f32, beta: f32, d_cutoff_hz: f32) -> Result<OneEuroConfig> {
        let config = OneEuroConfig {
            min_cutoff_hz,
            beta,
            d_cutoff_hz,
        };
        config.check()?;
        Ok(config)
    }

    fn check(&self) -> Result<()> {
        let cutoff = |v: f32| v.is_finite() && v > 0.0;
        if !cutoff(self.min_cutoff_hz) {
            bail!(
                "one-euro filter: min cutoff {} Hz is not > 0",
                self.min_cutoff_hz
            );
        }
        if !cutoff(self.d_cutoff_hz) {
            bail!(
                "one-euro filter: d cutoff {} Hz is not > 0",
                self.d_cutoff_hz
            );
        }
        if !(self.beta.is_finite() && self.beta >= 0.0) {
            bail!("one-euro filter: beta {} is not >= 0", self.beta);
        }
        Ok(())
    }
}

/// The one-euro filter of one value.
#[derive(Debug, Clone)]
pub struct OneEuro {
    config: OneEuroConfig,
    /// Time (s), filtered value and filtered speed (unit/s) of the last sample.
    last: Option<(f64, f64, f64)>,
    /// The last positive interval between samples (s).
    last_dt: f64,
}

impl OneEuro {
    /// A filter that has seen nothing yet.
    pub fn new(config: OneEuroConfig) -> OneEuro {
        OneEuro {
            config,
            last: None,
            last_dt: FALLBACK_DT_S,
        }
    }

    /// Forgets the past: the next sample passes through.
    pub fn reset(&mut self) {
        self.last = None;
        self.last_dt = FALLBACK_DT_S;
    }

    /// Filters `x` taken at time `t_s` (s, any origin). The first sample passes through. A
    /// sample whose time does not advance (`dt <= 0` or not finite) is filtered as if it came
    /// one last positive interval (1/30 s before any) after the previous one, and the clock
    /// stays where it was; a value that is not finite is returned as it is and forgotten.
    pub fn filter(&mut self, t_s: f64, x: f32) -> f32 {
        if !x.is_finite() {
            return x;
        }
        let x = f64::from(x);
        let Some((t0, x0, dx0)) = self.last else {
            self.last = Some((t_s, x, 0.0));
            return x as f32;
        };
        let dt = t_s - t0;
        let (t, dt) = if dt.is_finite() && dt > 0.0 {
            self.last_dt = dt;
            (t_s, dt)
        } else {
            (t0, self.last_dt)
        };
        let dx = smooth(
            dx0,
            (x - x0) / dt,
            alpha(self.config.d_cutoff_hz.into(), dt),
        );
        let cutoff = f64::from(self.config.min_cutoff_hz) + f64::from(self.config.beta) * dx.abs();
        let y = smooth(x0, x, alpha(cutoff, dt));
        self.last = Some((t, y, dx));
        y as f32
    }
}

/// The smoothing factor of a first-order low-pass at `cutoff_hz` for a step of `dt_s`.
fn alpha(cutoff_hz: f64, dt_s: f64) -> f64 {
    let tau = 1.0 / (2.0 * std::f64::consts::PI * cutoff_hz);
    1.0 / (1.0 + tau / dt_s)
}

/// One low-pass step; exact when `x == last`, so a constant input comes out unchanged.
fn smooth(last: f64, x: f64, alpha: f64) -> f64 {
    last + alpha * (x - last)
}

/// The one-euro parameters of a hand state vector: one speed coefficient for lengths, one for
/// angles.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Smoothing {
    /// Lowest cutoff, at rest (Hz).
    pub min_cutoff_hz: f32,
    /// Speed coefficient of the palm's translation q4..q6 (per mm).
    pub beta_mm: f32,
    /// Speed coefficient of the quaternion q0..q3 and the joints q7.. (per rad).
    pub beta_rad: f32,
    /// Cutoff of the speed estimate (Hz).
    pub d_cutoff_hz: f32,
}

impl Default for Smoothing {
    fn default() -> Self {
        Smoothing {
            min_cutoff_hz: DEFAULT_MIN_CUTOFF_HZ,
            beta_mm: DEFAULT_BETA_MM,
            beta_rad: DEFAULT_BETA_RAD,
            d_cutoff_hz: DEFAULT_D_CUTOFF_HZ,
        }
    }
}

impl Smoothing {
    /// Checks the parameters (see [`OneEuroConfig::new`]).
    pub fn new(
        min_cutoff_hz: f32,
        beta_mm: f32,
        beta_rad: f32,
        d_cutoff_hz: f32,
    ) -> Result<Smoothing> {
        OneEuroConfig::new(min_cutoff_hz, beta_mm, d_cutoff_hz)?;
        OneEuroConfig::new(min_cutoff_hz, beta_rad, d_cutoff_hz)?;
        Ok(Smoothing {
            min_cutoff_hz,
            beta_mm,
            beta_rad,
            d_cutoff_hz,
        })
    }

    /// The filter parameters of state `i` (q4..q6 in mm, the rest in rad or quaternion units).
    pub fn for_state(&self, i: usize) -> OneEuroConfig {
        let beta = if TRANSLATION.contains(&i) {
            self.beta_mm
        } else {
            self.beta_rad
        };
        OneEuroConfig {
            min_cutoff_hz: self.min_cutoff_hz,
            beta,
            d_cutoff_hz: self.d_cutoff_hz,
        }
    }
}

/// One-euro filters over a whole state vector: the palm's quaternion (q0..q3) filtered
/// component-wise, kept in the hemisphere of the last output (q and −q are one rotation) and
/// renormalised; every other state filtered on its own.
#[derive(Debug, Clone)]
pub struct StateSmoother {
    smoothing: Smoothing,
    filters: Vec<OneEuro>,
    /// The last output's quaternion, for the sign.
    last_quaternion: Option<[f32; 4]>,
}

impl StateSmoother {
    /// A smoother that has seen nothing yet.
    pub fn new(smoothing: Smoothing) -> StateSmoother {
        StateSmoother {
            smoothing,
            filters: Vec::new(),
            last_quaternion: None,
        }
    }

    /// Forgets the past (a board restarted, its clock too): the next state passes through.
    pub fn reset(&mut self) {
        self.filters.clear();
        self.last_quaternion = None;
    }

    /// The smoothed copy of `q` taken at `t_s` (s). A state vector of another length than the
    /// last one starts afresh.
    pub fn filter(&mut self, t_s: f64, q: &[f32]) -> Vec<f32> {
        if self.filters.len() != q.len() {
            self.filters = (0..q.len())
                .map(|i| OneEuro::new(self.smoothing.for_state(i)))
                .collect();
            self.last_quaternion = None;
        }
        let mut input = q.to_vec();
        if let (Some(last), Some(quat)) = (self.last_quaternion, input.get_mut(..4)) {
            let dot: f32 = last.iter().zip(quat.iter()).map(|(a, b)| a * b).sum();
            if dot < 0.0 {
                quat.iter_mut().for_each(|v| *v = -*v);
            }
        }
        let mut out: Vec<f32> = self
            .filters
            .iter_mut()
            .zip(&input)
            .map(|(f, &x)| f.filter(t_s, x))
            .collect();
        if let Some(quat) = out.get_mut(..4) {
            let norm = quat.iter().map(|v| v * v).sum::<f32>().sqrt();
            if norm.is_finite() && norm > 0.0 {
                quat.iter_mut().for_each(|v| *v /= norm);
                self.last_quaternion = Some([quat[0], quat[1], quat[2], quat[3]]);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    fn mm_config() -> OneEuroConfig {
        Smoothing::default().for_state(4)
    }

    fn rms(errors: impl Iterator<Item = f64>) -> f64 {
        let (sum, n) = errors.fold((0.0, 0), |(s, n), e| (s + e * e, n + 1));
        (sum / f64::from(n)).sqrt()
    }

    #[test]
    fn a_constant_comes_out_unchanged() {
        let mut f = OneEuro::new(mm_config());
        for i in 0..200 {
            assert_eq!(f.filter(f64::from(i) / 30.0, 42.125), 42.125, "sample {i}");
        }
    }

    #[test]
    fn the_first_sample_passes_through() {
        let mut f = OneEuro::new(OneEuroConfig::new(0.01, 0.0, 1.0).unwrap());
        assert_eq!(f.filter(5.0, -17.5), -17.5);
        // A very low cutoff barely moves after it.
        assert!((f.filter(5.1, 100.0) + 17.5).abs() < 1.0);
        f.reset();
        assert_eq!(f.filter(6.0, 3.0), 3.0);
    }

    #[test]
    fn noise_on_a_slow_sine_is_cut_down() {
        // 30 Hz samples of a 0.1 Hz, 5 mm sine with 1 mm of Gaussian noise, for 20 s.
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let noise = Normal::new(0.0, 1.0).unwrap();
        let mut f = OneEuro::new(mm_config());
        let (mut input_err, mut output_err) = (Vec::new(), Vec::new());
        for i in 0..600 {
            let t = f64::from(i) / 30.0;
            let clean = 5.0 * (2.0 * std::f64::consts::PI * 0.1 * t).sin();
            let noisy = clean + noise.sample(&mut rng);
            let y = f.filter(t, noisy as f32);
            if i >= 30 {
                // After the first second, once the filter has settled.
                input_err.push(noisy - clean);
                output_err.push(f64::from(y) - clean);
            }
        }
        let (input, output) = (rms(input_err.into_iter()), rms(output_err.into_iter()));
        assert!(
            output < 0.6 * input,
            "rms error {output:.3} mm after the filter, {input:.3} mm before"
        );
    }

    /// The distance (mm) the output trails a 200 mm/s ramp after 1 s at 60 Hz.
    fn ramp_lag(beta: f32) -> f64 {
        let mut f = OneEuro::new(OneEuroConfig::new(1.0, beta, 1.0).unwrap());
        let mut lag = 0.0;
        for i in 0..=60 {
            let t = f64::from(i) / 60.0;
            let x = 200.0 * t;
            lag = x - f64::from(f.filter(t, x as f32));
        }
        lag
    }

    #[test]
    fn speed_shortens_the_lag_on_a_fast_ramp() {
        let (fixed, adaptive) = (ramp_lag(0.0), ramp_lag(0.05));
        assert!(fixed > 0.0 && adaptive > 0.0, "{fixed} {adaptive}");
        assert!(
            adaptive < 0.5 * fixed,
            "lag {adaptive:.2} mm with beta 0.05, {fixed:.2} mm with beta 0"
        );
    }

    #[test]
    fn times_that_do_not_advance_and_nan_do_not_break_it() {
        let mut f = OneEuro::new(mm_config());
        assert_eq!(f.filter(1.0, 10.0), 10.0);
        for (t, x) in [
            (1.0, 11.0),
            (0.5, 12.0),
            (f64::NAN, 13.0),
            (f64::INFINITY, 14.0),
            (f64::NEG_INFINITY, 14.0),
        ] {
            let y = f.filter(t, x);
            assert!(y.is_finite() && (10.0..=x).contains(&y), "t {t}: {y}");
        }
        assert!(f.filter(1.1, f32::NAN).is_nan());
        // The NaN was not kept: later samples are still finite and near the input.
        let y = f.filter(1.2, 14.0);
        assert!(y.is_finite() && (10.0..=14.0).contains(&y), "{y}");
        assert!(OneEuroConfig::new(0.0, 0.0, 1.0).is_err());
        assert!(OneEuroConfig::new(1.0, -1.0, 1.0).is_err());
        assert!(OneEuroConfig::new(1.0, 0.0, f32::NAN).is_err());
        assert!(Smoothing::new(1.0, 0.01, f32::INFINITY, 1.0).is_err());
    }

    #[test]
    fn quaternions_stay_unit_and_keep_their_hemisphere() {
        let mut s = StateSmoother::new(Smoothing::default());
        let half = 0.2f32;
        let mut q = vec![half.cos(), 0.0, 0.0, half.sin(), 1.0, 2.0, 3.0, 0.5];
        assert_eq!(s.filter(0.0, &q), q);
        // The same rotation written as −q, then turning on: no swing through zero.
        for i in 1..30 {
            let half = 0.2 + 0.01 * i as f32;
            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
            q[0] = sign * half.cos();
            q[3] = sign * half.sin();
            let out = s.filter(f64::from(i) / 30.0, &q);
            let norm: f32 = out[..4].iter().map(|v| v * v).sum::<f32>().sqrt();
            assert!((norm - 1.0).abs() < 1e-5, "{out:?}");
            assert!(out[0] > 0.8 && out[3] > 0.19, "{out:?}");
            assert_eq!(&out[4..7], &[1.0, 2.0, 3.0]);
        }
        // Another model's length starts afresh.
        assert_eq!(
            s.filter(2.0, &[1.0, 0.0, 0.0, 0.0, 9.0]),
            [1.0, 0.0, 0.0, 0.0, 9.0]
        );
    }
}
