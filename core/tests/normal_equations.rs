//! The tracker's normal equations against the oracle's: for every residual kind a host can
//! select over the wire, the per-link blocks of `add_link_rows` (what the tracker runs) and the
//! reference rows of `estimator::reference` added one at a time with `add_row` must give the
//! same rows, the same RMS, the same `JᵀWJ` and the same step — mono and stereo, the whole
//! hand and the 3D mouse's sub-model, at a few poses.

use digiteyes_core::camera::Camera;
use digiteyes_core::estimator::reference::add_reference_rows;
use digiteyes_core::estimator::{
    add_link_rows, EstimatorConfig, FreeMask, LinkJacobian, LinkRows, NormalEquations, ResidualKind,
};
use digiteyes_core::features::{axis_frame, EdgePoint, LinkFeatures};
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::Model;
use digiteyes_core::projection::{ProjectedLink, ProjectedModel};
use digiteyes_core::protocol::{TrackerParams, WireResidual};
use digiteyes_core::tracker::TrackerConfig;
use nalgebra::{Matrix3, SVector};

mod common;
use common::{bent_pose, table_camera, Rng};

// How close the two paths must agree, and why. Measured over the 36 cases below (worst
// case): rows and per-link counts identical; RMS 1.8e-7 relative; `JᵀWJ` 5.5e-7 of its largest
// entry; the step 3.6e-3 of its largest entry, while the tracker's step solves the oracle's
// equations to 3.6e-6 of their right-hand side. The two paths compute the same sums in a
// different order (a row's derivative `cᵀ G` state by state, against `Gᵀ (Σ w c cᵀ) G` per
// link), so they agree to f32 rounding of sums over a few hundred rows; the step then
// differs by that rounding times the condition number of `JᵀWJ + S` (a whole hand in one
// camera has directions it barely sees), which is why its forward error is the loosest
// figure and its backward error (how well it solves the other path's equations) the tighter
// one. Each bound leaves a margin of about 10 over the worst measured; a wrong coefficient,
// sign or weight in either path moves these figures by 1e-2 or more (see
// `a_wrong_coefficient_would_be_caught`).
const RMS_TOLERANCE: f32 = 2e-6;
const NORMAL_TOLERANCE: f32 = 5e-6;
const STEP_TOLERANCE: f32 = 3e-2;
const STEP_BACKWARD_TOLERANCE: f32 = 4e-5;

/// The estimator configurations the wire can select: the default parameters with each
/// `WireResidual`, decoded the way a board decodes them.
fn wire_configs() -> Vec<EstimatorConfig> {
    let configs: Vec<EstimatorConfig> = [
        WireResidual::EdgePoints,
        WireResidual::AxisLines,
        WireResidual::AxisPoints,
    ]
    .into_iter()
    .map(|residual| {
        let mut params = TrackerParams::from_config(&TrackerConfig::default());
        params.residual = residual;
        params.to_config().expect("default parameters").estimator
    })
    .collect();
    for kind in [
        ResidualKind::EdgePoints,
        ResidualKind::AxisLines,
        ResidualKind::AxisPoints,
    ] {
        assert!(
            configs.iter().any(|c| c.residual == kind),
            "{kind:?} is selectable"
        );
    }
    configs
}

/// The table camera and one beside it, turned 35° about the vertical through the hand.
fn cameras() -> [Camera; 2] {
    let first = table_camera();
    let mut second = first;
    let (s, c) = 35f32.to_radians().sin_cos();
    let turn = Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0);
    second.r = first.r * turn.transpose();
    [first, second]
}

fn view(model: &Model, poses: &Poses, camera: &Camera) -> ProjectedModel {
    let mut view = ProjectedModel::new();
    view.update(model, poses, camera, 6.0);
    view
}

/// What a slice search would find for `link` if the hand were at the truth view: each slice's
/// edges on the truth's silhouette, with noise; some slices lose an edge (a lone edge), one
/// edge is an outlier (so robust weights are not all 1), and a distal link finds its tip.
fn features(link: &ProjectedLink, truth: &ProjectedLink, rng: &mut Rng) -> LinkFeatures {
    let mut out = LinkFeatures::default();
    let (dir, normal) = axis_frame(&truth.a, &truth.b);
    for k in 0..5 {
        let s = 0.15 + 0.175 * k as f32;
        let axis = truth.a + (truth.b - truth.a) * s;
        for side in [1i8, -1] {
            if rng.unit() < 0.15 {
                continue;
            }
            let outlier = if rng.unit() < 0.05 { 6.0 } else { 0.0 };
            let offset = truth.side_radius_at(s, side) + rng.range(-0.4, 0.4) + outlier;
            let _ = out.edges.push(EdgePoint {
                s,
                side,
                position: axis + normal * (f32::from(side) * offset),
                strength: 30.0,
            });
        }
    }
    if link.distal {
        out.tip = Some(truth.b + dir * (truth.tip_offset + rng.range(-1.0, 1.0)));
    }
    out
}

/// The normal equations built both ways over every camera and link, and each link's counts.
fn both_ways(
    model: &Model,
    cameras: &[Camera],
    q: &[f32],
    truth: &[f32],
    config: &EstimatorConfig,
    free: FreeMask,
) -> (NormalEquations, NormalEquations) {
    let poses = Poses::compute(model, q).unwrap();
    let truth_poses = Poses::compute(model, truth).unwrap();
    let (mut tracker, mut oracle) = (NormalEquations::new(), NormalEquations::new());
    let mut jac = LinkJacobian::default();
    let mut rng = Rng::new(7);
    for camera in cameras {
        let seen = view(model, &poses, camera);
        let truth_view = view(model, &truth_poses, camera);
        for link in &seen.links {
            let Some(truth_link) = truth_view.links.iter().find(|l| l.frame == link.frame) else {
                continue;
            };
            let found = features(link, truth_link, &mut rng);
            jac.compute(model, &poses, camera, link);
            let a = add_link_rows(&mut tracker, link, &found, &jac, config, free);
            let b = add_reference_rows(&mut oracle, link, &found, &jac, config, free);
            assert_eq!(a, b, "link {}: rows added", link.frame);
        }
    }
    (tracker, oracle)
}

/// `JᵀWJ` by state, column by column.
fn normal_matrix(ne: &NormalEquations, free: FreeMask, n: usize) -> Vec<Vec<f32>> {
    (0..n)
        .map(|j| {
            let mut e = SVector::<f32, 32>::zeros();
            e[j] = 1.0;
            ne.times(free, &e).as_slice()[..n].to_vec()
        })
        .collect()
}

/// The largest difference between two matrices, relative to the second's largest entry.
fn relative_difference(h: &[Vec<f32>], h_ref: &[Vec<f32>]) -> f32 {
    let scale = max_abs(h_ref.iter().flatten().copied());
    max_abs(
        h.iter()
            .flatten()
            .zip(h_ref.iter().flatten())
            .map(|(a, b)| a - b),
    ) / scale
}

fn max_abs(v: impl Iterator<Item = f32>) -> f32 {
    v.fold(0.0, |m, x| m.max(x.abs()))
}

/// A pose near the bent pose: palm moved and turned a little, joints changed.
fn pose(rng: &mut Rng, base: &[f32]) -> Vec<f32> {
    let mut q = base.to_vec();
    for v in &mut q[..4] {
        *v += rng.range(-0.03, 0.03);
    }
    let n = q[..4].iter().map(|v| v * v).sum::<f32>().sqrt();
    for v in &mut q[..4] {
        *v /= n;
    }
    for v in &mut q[4..7] {
        *v += rng.range(-4.0, 4.0);
    }
    for v in &mut q[7..] {
        *v += rng.range(-0.1, 0.1);
    }
    q
}

fn mouse_free() -> FreeMask {
    let mut m = 0b1111;
    for s in [4, 5, 8, 9, 10, 19, 24] {
        m |= 1 << s;
    }
    FreeMask(m)
}

#[test]
fn the_tracker_and_the_oracle_build_the_same_normal_equations_for_every_wire_residual() {
    let model = Model::hand().unwrap();
    let n = model.n_states();
    let cams = cameras();
    let mut rng = Rng::new(11);
    let mut worst = [0.0f32; 4];
    let mut cases = 0;
    let mut width = TrackerConfig::default().estimator;
    width.residual = ResidualKind::AxisPoints;
    width.width_weight = 0.5;
    for config in wire_configs().into_iter().chain([width]) {
        let kind = config.residual;
        for rig in [&cams[..1], &cams[..]] {
            for free in [FreeMask::all(n), mouse_free()] {
                for _ in 0..3 {
                    let q = pose(&mut rng, &bent_pose());
                    let truth = pose(&mut rng, &q);
                    let (tracker, oracle) = both_ways(&model, rig, &q, &truth, &config, free);
                    let what = format!(
                        "{kind:?}, width rows {}, {} camera(s), free {:#x}",
                        config.width_weight,
                        rig.len(),
                        free.0
                    );
                    assert!(tracker.rows() > 20, "{what}: {} rows", tracker.rows());
                    assert_eq!(tracker.rows(), oracle.rows(), "{what}: rows");
                    let rms = (tracker.rms() - oracle.rms()).abs() / oracle.rms();
                    assert!(rms <= RMS_TOLERANCE, "{what}: RMS {rms}");
                    let (h, h_ref) = (
                        normal_matrix(&tracker, free, n),
                        normal_matrix(&oracle, free, n),
                    );
                    let diff = relative_difference(&h, &h_ref);
                    assert!(diff <= NORMAL_TOLERANCE, "{what}: JᵀWJ differs by {diff}");
                    let conditioning = config.conditioning;
                    let step = tracker
                        .step(n, free, &conditioning)
                        .expect("tracker's step");
                    let step_ref = oracle.step(n, free, &conditioning).expect("oracle's step");
                    let scale = max_abs(step_ref.iter().copied());
                    assert!(scale > 0.0, "{what}: the step moves");
                    let step_diff = max_abs(step.iter().zip(&step_ref).map(|(a, b)| a - b)) / scale;
                    assert!(
                        step_diff <= STEP_TOLERANCE,
                        "{what}: step differs by {step_diff}"
                    );
                    // (H_ref + S)(Δ − Δ_ref) against (H_ref + S) Δ_ref = −JᵀWr_ref.
                    let system = |x: &SVector<f32, 32>| {
                        let mut y = oracle.times(free, x);
                        for i in 0..n {
                            if free.contains(i) {
                                y[i] += conditioning.for_state(i) * x[i];
                            }
                        }
                        y
                    };
                    let rhs = system(&step_ref);
                    let backward = max_abs(system(&(step - step_ref)).iter().copied())
                        / max_abs(rhs.iter().copied());
                    assert!(
                        backward <= STEP_BACKWARD_TOLERANCE,
                        "{what}: the tracker's step solves the oracle's equations to {backward}"
                    );
                    for (i, v) in step.iter().enumerate() {
                        if !free.contains(i) {
                            assert_eq!(*v, 0.0, "{what}: fixed q{i} moved");
                        }
                    }
                    worst[0] = worst[0].max(rms);
                    worst[1] = worst[1].max(diff);
                    worst[2] = worst[2].max(step_diff);
                    worst[3] = worst[3].max(backward);
                    cases += 1;
                }
            }
        }
    }
    assert_eq!(cases, 4 * 2 * 2 * 3);
    println!(
        "worst relative differences: RMS {:e}, JᵀWJ {:e}, step {:e} (backward {:e})",
        worst[0], worst[1], worst[2], worst[3]
    );
}

#[test]
fn a_wrong_coefficient_would_be_caught() {
    // The comparison can fail: the oracle with a tip weight 10% off is far outside the bounds.
    let model = Model::hand().unwrap();
    let n = model.n_states();
    let q = bent_pose();
    let truth = pose(&mut Rng::new(3), &q);
    let config = EstimatorConfig::default();
    let mut off = config;
    off.tip_weight *= 1.1;
    let free = FreeMask::all(n);
    let poses = Poses::compute(&model, &q).unwrap();
    let truth_poses = Poses::compute(&model, &truth).unwrap();
    let camera = table_camera();
    let (seen, truth_view) = (
        view(&model, &poses, &camera),
        view(&model, &truth_poses, &camera),
    );
    let (mut a, mut b) = (NormalEquations::new(), NormalEquations::new());
    let mut jac = LinkJacobian::default();
    let mut rng = Rng::new(5);
    let mut tips = LinkRows::default();
    for link in &seen.links {
        let truth_link = truth_view.links.iter().find(|l| l.frame == link.frame);
        let found = features(link, truth_link.unwrap(), &mut rng);
        jac.compute(&model, &poses, &camera, link);
        tips.tips += add_link_rows(&mut a, link, &found, &jac, &config, free).tips;
        add_reference_rows(&mut b, link, &found, &jac, &off, free);
    }
    assert_eq!(tips.tips, 5, "five fingertips found");
    let h = normal_matrix(&a, free, n);
    let h_ref = normal_matrix(&b, free, n);
    let diff = relative_difference(&h, &h_ref);
    assert!(diff > 100.0 * NORMAL_TOLERANCE, "{diff}");
}
