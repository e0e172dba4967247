//! The estimator's analytic residual rows against finite differences, the normal equations
//! against a dense computation, robust weights and the axis-line fit.

use digiteyes_core::estimator::reference::*;
use digiteyes_core::estimator::*;
use digiteyes_core::features::{axis_frame, fit_axis_line, EdgePoint, LinkFeatures};
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::Model;
use digiteyes_core::projection::{ProjectedLink, ProjectedModel};
use nalgebra::Vector2;

mod common;
use common::{bent_pose as pose, table_camera as camera, view_at};

fn find(view: &ProjectedModel, frame: u8) -> &ProjectedLink {
    view.links
        .iter()
        .find(|l| l.frame == frame)
        .expect("link in view")
}

/// Central differences of `residual(view)` for state `j`, steps in radians or mm.
fn numeric(model: &Model, q: &[f32], j: usize, residual: &dyn Fn(&ProjectedModel) -> f32) -> f32 {
    let h = if (4..7).contains(&j) { 1e-2 } else { 1e-3 };
    let (mut plus, mut minus) = (q.to_vec(), q.to_vec());
    plus[j] += h;
    minus[j] -= h;
    (residual(&view_at(model, &plus, &camera())) - residual(&view_at(model, &minus, &camera())))
        / (2.0 * h)
}

fn check_row(
    model: &Model,
    q: &[f32],
    row: &Row,
    residual: &dyn Fn(&ProjectedModel) -> f32,
    what: &str,
) {
    let scale = row.iter().fold(0.0f32, |m, (_, v)| m.max(v.abs()));
    for j in 0..28 {
        let analytic = row
            .iter()
            .find(|(s, _)| usize::from(*s) == j)
            .map_or(0.0, |(_, v)| *v);
        let fd = numeric(model, q, j, residual);
        // The radius derivative uses the f·R/z form of the exact perspective offset (0.5% seen
        // here): allow 1% of the row's largest entry plus f32 differencing noise.
        let tol = 0.01 * scale + 0.02;
        assert!(
            (analytic - fd).abs() <= tol,
            "{what}: q{j} analytic {analytic} vs finite difference {fd} (tol {tol})"
        );
    }
}

#[test]
fn edge_point_rows_match_finite_differences_on_every_link() {
    let model = Model::hand().unwrap();
    let cam = camera();
    let q = pose();
    let poses = Poses::compute(&model, &q).unwrap();
    let view = view_at(&model, &q, &cam);
    assert_eq!(view.links.len(), 15, "all 15 capsule links in view");
    let mut jac = LinkJacobian::default();
    let mut row = Row::new();
    for link in &view.links {
        jac.compute(&model, &poses, &cam, link);
        let (_, normal) = axis_frame(&link.a, &link.b);
        for (s, side, shift) in [(0.3f32, 1i8, 1.5f32), (0.7, -1, -2.0)] {
            let predicted = link.a
                + (link.b - link.a) * s
                + normal * (f32::from(side) * link.side_radius_at(s, side));
            let edge = EdgePoint {
                s,
                side,
                position: predicted + normal * shift,
                strength: 50.0,
            };
            let r = edge_row(link, &jac, &edge, &mut row);
            assert!(
                (r + f32::from(side) * shift).abs() < 1e-3,
                "residual is predicted − measured"
            );
            let frame = link.frame;
            check_row(
                &model,
                &q,
                &row,
                &|v| edge_residual(find(v, frame), &edge),
                "edge",
            );
        }
    }
}

#[test]
fn region_rows_match_finite_differences_on_every_link() {
    let model = Model::hand().unwrap();
    let cam = camera();
    let q = pose();
    let poses = Poses::compute(&model, &q).unwrap();
    let view = view_at(&model, &q, &cam);
    let mut jac = LinkJacobian::default();
    for link in &view.links {
        jac.compute(&model, &poses, &cam, link);
        let (dir, normal) = axis_frame(&link.a, &link.b);
        let r = link.radius_at(0.4);
        // Beside the axis outside and inside the outline, and beyond each end.
        let points = [
            link.a + (link.b - link.a) * 0.4 + normal * (r + 3.0),
            link.a + (link.b - link.a) * 0.6 - normal * (0.5 * r),
            link.b + dir * (link.radius_at(1.0) + 2.0),
            link.a - dir * 1.5 + normal * 0.5,
        ];
        for p in points {
            let (c, residual) = region_row(link, &p).expect("off the axis");
            let expected = link.radius_at(link.closest(&p).0) - link.closest(&p).1;
            assert!((residual - expected).abs() < 1e-4);
            let mut row = Row::new();
            for (k, &s) in jac.states.iter().enumerate() {
                let g = [
                    jac.da[k].x,
                    jac.da[k].y,
                    jac.db[k].x,
                    jac.db[k].y,
                    jac.dr0[k],
                    jac.dr1[k],
                ];
                let v: f32 = c.iter().zip(&g).map(|(a, b)| a * b).sum();
                row.push((s, v)).unwrap();
            }
            let frame = link.frame;
            check_row(
                &model,
                &q,
                &row,
                &|v| {
                    let l = find(v, frame);
                    let (s, dist) = l.closest(&p);
                    l.radius_at(s) - dist
                },
                "region",
            );
        }
        assert!(
            region_row(link, &link.a.lerp(&link.b, 0.5)).is_none(),
            "on the axis"
        );
    }
}

#[test]
fn tip_and_line_rows_match_finite_differences() {
    let model = Model::hand().unwrap();
    let cam = camera();
    let q = pose();
    let poses = Poses::compute(&model, &q).unwrap();
    let view = view_at(&model, &q, &cam);
    let mut jac = LinkJacobian::default();
    let mut row = Row::new();
    let mut distal = 0;
    for link in view.links.iter().filter(|l| l.distal) {
        distal += 1;
        jac.compute(&model, &poses, &cam, link);
        let (dir, normal) = axis_frame(&link.a, &link.b);
        let tip = link.b + dir * (link.tip_offset + 1.0);
        let r = tip_row(link, &jac, &tip, &mut row);
        assert!((r + 1.0).abs() < 1e-3);
        let frame = link.frame;
        let tip_residual = |v: &ProjectedModel| {
            let l = find(v, frame);
            let (d, _) = axis_frame(&l.a, &l.b);
            d.dot(&(l.b - tip)) + l.tip_offset
        };
        check_row(&model, &q, &row, &tip_residual, "tip");
        // A measured axis line 1 px beside the model axis.
        let line = (link.a + normal, normal);
        for end in [0, 1] {
            let r = line_row(link, &jac, line, end, &mut row);
            assert!((r + 1.0).abs() < 1e-3);
            let line_residual = |v: &ProjectedModel| {
                let l = find(v, frame);
                let p = if end == 0 { l.a } else { l.b };
                line.1.dot(&(p - line.0))
            };
            check_row(&model, &q, &row, &line_residual, "line");
        }
    }
    assert_eq!(distal, 5, "five fingertips");
}

#[test]
fn normal_equations_match_a_dense_computation_and_the_step_solves_them() {
    let mut ne = NormalEquations::new();
    let free = FreeMask((1 << 4) | (1 << 5) | (1 << 8) | (1 << 9) | (1 << 20));
    let mut dense = [[0.0f64; 28]; 28];
    let mut rhs = [0.0f64; 28];
    let mut seed = 3u32;
    let mut next = || {
        seed = seed.wrapping_mul(1664525).wrapping_add(1013904223);
        (seed >> 8) as f32 / (1u32 << 24) as f32 - 0.5
    };
    for _ in 0..40 {
        let states = [4u8, 5, 8, 9, 20, 12];
        let row: Vec<(u8, f32)> = states.iter().map(|&s| (s, next() * 10.0)).collect();
        let r = next() * 4.0;
        let w = 0.5 + next().abs();
        ne.add_row(&row, r, w, free);
        for &(i, vi) in &row {
            if !free.contains(usize::from(i)) {
                continue;
            }
            rhs[usize::from(i)] += f64::from(w * vi * r);
            for &(j, vj) in &row {
                if free.contains(usize::from(j)) {
                    dense[usize::from(i)][usize::from(j)] += f64::from(w * vi * vj);
                }
            }
        }
    }
    assert_eq!(ne.rows(), 40);
    let s = Conditioning {
        quaternion: 1.0,
        translation: 2.0,
        joint: 30.0,
    };
    let delta = ne.step(28, free, &s).expect("positive definite");
    for i in 0..28 {
        if !free.contains(i) {
            assert_eq!(delta[i], 0.0, "fixed state q{i} must not move");
            continue;
        }
        let mut lhs = f64::from(s.for_state(i)) * f64::from(delta[i]);
        for j in 0..28 {
            lhs += dense[i][j] * f64::from(delta[j]);
        }
        assert!(
            (lhs + rhs[i]).abs() < 1e-3 * (1.0 + rhs[i].abs()),
            "row {i}: {lhs} vs {}",
            -rhs[i]
        );
    }
}

#[test]
fn non_finite_rows_are_ignored() {
    let mut ne = NormalEquations::new();
    ne.add_row(&[(8, f32::NAN)], 1.0, 1.0, FreeMask::all(28));
    ne.add_row(&[(8, 1.0)], f32::INFINITY, 1.0, FreeMask::all(28));
    assert_eq!(ne.rows(), 0);
    assert_eq!(ne.rms(), 0.0);
}

#[test]
fn robust_weights() {
    assert_eq!(Robust::None.weight(100.0), 1.0);
    assert_eq!(Robust::Huber(2.0).weight(1.5), 1.0);
    assert!((Robust::Huber(2.0).weight(-8.0) - 0.25).abs() < 1e-6);
    assert!((Robust::Tukey(4.0).weight(2.0) - 0.5625).abs() < 1e-6);
    assert_eq!(Robust::Tukey(4.0).weight(5.0), 0.0);
}

#[test]
fn the_axis_line_fit_rejects_an_outlier_and_uses_single_silhouettes() {
    let model = Model::hand().unwrap();
    let view = view_at(&model, &pose(), &camera());
    let link = view.links[0];
    let (_, normal) = axis_frame(&link.a, &link.b);
    let mut features = LinkFeatures::default();
    // One silhouette only, 1 px outside the prediction, plus one wild point.
    for k in 0..5 {
        let s = 0.15 + 0.175 * k as f32;
        let shift = if k == 2 { 9.0 } else { 1.0 };
        let position =
            link.a + (link.b - link.a) * s + normal * (link.side_radius_at(s, 1) + shift);
        features
            .edges
            .push(EdgePoint {
                s,
                side: 1,
                position,
                strength: 40.0,
            })
            .unwrap();
    }
    let (point, line_normal) = fit_axis_line(&link, &features).expect("line");
    let offset_a = line_normal.dot(&(link.a - point)).abs();
    let offset_b = line_normal.dot(&(link.b - point)).abs();
    assert!(
        (offset_a - 1.0).abs() < 0.1 && (offset_b - 1.0).abs() < 0.1,
        "{offset_a} {offset_b}"
    );
    let _ = Vector2::<f32>::zeros();
}
