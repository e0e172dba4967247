//! The Gauss–Newton step with joint ranges (`NormalEquations::bounded_step`) against its
//! oracles: the plain step when no bound is crossed, the step solved without a joint when
//! that joint sits at its bound and is pushed out, and the reduced normal equations when a
//! joint crosses its bound mid-step.

use digiteyes_core::estimator::{Conditioning, EstimatorConfig, FreeMask, NormalEquations};
use digiteyes_core::model::Model;
use nalgebra::SVector;

mod common;
use common::Rng;

/// Finger 1's PIP flexion (range 0..1.6 rad in the built-in hand).
const PIP: usize = 9;

/// Random rows over every state of the hand, so every state is coupled to the others,
/// plus two heavy rows that pull the PIP down by `pull` rad (and its DIP with it).
fn equations(model: &Model, pull: f32, seed: u64) -> NormalEquations {
    let n = model.n_states();
    let free = FreeMask::all(n);
    let mut rng = Rng::new(seed);
    let mut normal = NormalEquations::new();
    for _ in 0..200 {
        let entries: Vec<(u8, f32)> = (0..4)
            .map(|_| ((rng.next_u64() % n as u64) as u8, rng.range(-30.0, 30.0)))
            .collect();
        normal.add_row(&entries, rng.range(-1.0, 1.0), 1.0, free);
    }
    // A residual r with derivative 1 moves the state by about −r: these push the PIP to
    // −pull, out of its range when it starts near 0.
    normal.add_row(&[(PIP as u8, 100.0)], 100.0 * pull, 100.0, free);
    normal.add_row(
        &[(PIP as u8, 60.0), (PIP as u8 + 1, 60.0)],
        60.0 * pull,
        100.0,
        free,
    );
    normal
}

fn state(model: &Model, pip: f32) -> Vec<f32> {
    let mut q = vec![0.0f32; model.n_states()];
    q[0] = 1.0;
    q[6] = 500.0;
    for (i, v) in q.iter_mut().enumerate().skip(7) {
        if let Some(l) = model.limit(i) {
            *v = 0.5 * (l.lo + l.hi);
        }
    }
    q[PIP] = pip;
    q
}

fn conditioning() -> Conditioning {
    EstimatorConfig::default().conditioning
}

#[test]
fn the_step_is_the_plain_one_when_no_bound_is_crossed() {
    let model = Model::hand().unwrap();
    let n = model.n_states();
    let free = FreeMask::all(n);
    let normal = equations(&model, 0.05, 1);
    let q = state(&model, 0.8);
    let plain = normal.step(n, free, &conditioning()).unwrap();
    let bounded = normal
        .bounded_step(&model, &q, free, &conditioning())
        .unwrap();
    assert!(plain.iter().all(|d| d.is_finite()));
    assert!(
        q.iter()
            .zip(plain.iter())
            .enumerate()
            .all(|(i, (&v, &d))| model
                .limit(i)
                .is_none_or(|l| v + d >= l.lo && v + d <= l.hi)),
        "the case must stay inside every range"
    );
    assert_eq!(
        plain, bounded,
        "no joint leaves its range: the same step, bit for bit"
    );
}

#[test]
fn a_joint_at_its_bound_pushed_out_is_held_and_the_rest_solved_without_it() {
    let model = Model::hand().unwrap();
    let n = model.n_states();
    let free = FreeMask::all(n);
    let normal = equations(&model, 0.5, 2);
    let q = state(&model, 0.0);
    let plain = normal.step(n, free, &conditioning()).unwrap();
    assert!(
        plain[PIP] < -0.1,
        "the plain step pushes the PIP out: {}",
        plain[PIP]
    );
    let bounded = normal
        .bounded_step(&model, &q, free, &conditioning())
        .unwrap();
    assert_eq!(bounded[PIP], 0.0, "held at its bound");
    // The oracle: the same equations solved with the PIP not free at all.
    let without = FreeMask(free.0 & !(1 << PIP));
    let reduced = normal.step(n, without, &conditioning()).unwrap();
    for s in (0..n).filter(|&s| s != PIP) {
        assert!(
            (bounded[s] - reduced[s]).abs() <= 1e-6 * reduced.amax().max(1e-3),
            "state {s}: {} against {}",
            bounded[s],
            reduced[s]
        );
    }
    // And the coupled DIP moves otherwise than under the plain step: the test can fail.
    assert!(
        (bounded[PIP + 1] - plain[PIP + 1]).abs() > 1e-3,
        "DIP {} against the plain step's {}",
        bounded[PIP + 1],
        plain[PIP + 1]
    );
}

#[test]
fn a_joint_crossing_its_bound_mid_step_ends_on_it_and_the_rest_fit_that() {
    let model = Model::hand().unwrap();
    let n = model.n_states();
    let free = FreeMask::all(n);
    let c = conditioning();
    let normal = equations(&model, 0.5, 3);
    let q = state(&model, 0.1);
    let bounded = normal.bounded_step(&model, &q, free, &c).unwrap();
    assert!(
        (bounded[PIP] + 0.1).abs() < 1e-6,
        "moved to 0: {}",
        bounded[PIP]
    );
    // The reduced normal equations (H + S)_FF δ_F = −g_F − H_FB δ_B, checked through
    // `times` (H δ) and the plain step (−(H + S)⁻¹ g): with g = −(H + S) · plain,
    // (H + S) δ − (H + S) plain must vanish on every free state but the PIP.
    let plain = normal.step(n, free, &c).unwrap();
    let h_delta = normal.times(free, &bounded);
    let h_plain = normal.times(free, &plain);
    let scale = h_plain.amax();
    for s in (0..n).filter(|&s| s != PIP) {
        let with_s = |x: &SVector<f32, { digiteyes_core::config::MAX_STATES }>, h: f32| {
            h + c.for_state(s) * x[s]
        };
        let lhs = with_s(&bounded, h_delta[s]);
        let rhs = with_s(&plain, h_plain[s]);
        assert!(
            (lhs - rhs).abs() <= 1e-4 * scale,
            "state {s}: {lhs} against {rhs} (scale {scale})"
        );
    }
    // Every state stays in its range after the step.
    for (i, (&v, d)) in q.iter().zip(bounded.iter()).enumerate() {
        if let Some(l) = model.limit(i) {
            assert!(v + d >= l.lo - 1e-6 && v + d <= l.hi + 1e-6, "state {i}");
        }
    }
}
