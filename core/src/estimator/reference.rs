//! The reference residual rows: the oracle the tracker's estimator is tested against.
//!
//! Each function here builds one residual row the plain way — its value and its derivative by
//! every state the link depends on, `(state, ∂r/∂q)` — straight from the geometry, for
//! [`NormalEquations::add_row`] to add one at a time. [`add_reference_rows`] adds a link's
//! rows this way, for every residual kind.
//!
//! The tracker does not run this code: it runs [`add_link_rows`](super::add_link_rows), which
//! gathers the same rows as coefficients of a link's six image parameters and applies the link
//! Jacobian once per link (a 6×6 block per link). These rows are kept simple rather than fast
//! so they can be checked against finite differences (`core/tests/estimator.rs`), and the
//! tracker's path is checked against them (`core/tests/normal_equations.rs`): same rows, same
//! RMS, same step to f32 rounding.

use heapless::Vec;
use nalgebra::Vector2;

use super::{EstimatorConfig, FreeMask, LinkJacobian, LinkRows, NormalEquations, ResidualKind};
use crate::config::MAX_ROW_NONZEROS;
use crate::features::{fit_axis_line, EdgePoint, LinkFeatures};
use crate::projection::ProjectedLink;

/// A row of derivative entries `(state, ∂r/∂q_state)`.
pub type Row = Vec<(u8, f32), MAX_ROW_NONZEROS>;

/// The edge-point residual of `edge` (px): the predicted silhouette offset minus the measured
/// one, at the edge's foot on the axis. Positive when the edge lies inside the prediction.
pub fn edge_residual(link: &ProjectedLink, edge: &EdgePoint) -> f32 {
    let normal = link.normal();
    let axis = link.b - link.a;
    let s = ((edge.position - link.a).dot(&axis) / axis.norm_squared().max(1e-9)).clamp(0.0, 1.0);
    link.side_radius_at(s, edge.side) - f32::from(edge.side) * normal.dot(&(edge.position - link.a))
}

/// The edge-point residual (px) and its derivative row (into `row`): the derivative of a fixed
/// point's distance to a moving line, `σ n·((1−s) ∂a + s ∂b)`, plus that of the predicted
/// offset at the edge's foot `s`, `(1−s) ∂r0 + s ∂r1 + (r1 − r0) ∂s` (the foot slides when the
/// link moves along its axis, and the image radius tapers under perspective).
pub fn edge_row(link: &ProjectedLink, jac: &LinkJacobian, edge: &EdgePoint, row: &mut Row) -> f32 {
    let normal = link.normal();
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
    let (dir, _) = link.axis_frame();
    row.clear();
    for k in 0..jac.states.len() {
        let _ = row.push((jac.states[k], dir.dot(&jac.db[k]) + jac.dr1[k]));
    }
    dir.dot(&(link.b - tip)) + link.tip_offset
}

/// Adds the rows of one link's features to `ne` one at a time, from the reference rows above:
/// what [`add_link_rows`](super::add_link_rows) does, written the plain way. Edge rows for
/// [`ResidualKind::EdgePoints`]; for [`ResidualKind::AxisPoints`] the half-difference of the
/// two edge rows of a slice where both edges were found (a lone edge gives its edge row), and
/// with a `width_weight` their half-sum as well, at that weight; for
/// [`ResidualKind::AxisLines`] the two [`line_row`]s against [`fit_axis_line`]'s line
/// (unweighted); then the [`tip_row`] weighted by `tip_weight`. Edge and tip rows are
/// robustly weighted.
pub fn add_reference_rows(
    ne: &mut NormalEquations,
    link: &ProjectedLink,
    features: &LinkFeatures,
    jac: &LinkJacobian,
    config: &EstimatorConfig,
    free: FreeMask,
) -> LinkRows {
    add_weighted_reference_rows(ne, link, features, jac, config, free, 1.0)
}

/// [`add_reference_rows`] with every row's weight multiplied by `weight`.
pub(crate) fn add_weighted_reference_rows(
    ne: &mut NormalEquations,
    link: &ProjectedLink,
    features: &LinkFeatures,
    jac: &LinkJacobian,
    config: &EstimatorConfig,
    free: FreeMask,
    weight: f32,
) -> LinkRows {
    let mut added = LinkRows::default();
    if jac.states.is_empty() {
        return added;
    }
    let mut row = Row::new();
    match config.residual {
        ResidualKind::EdgePoints => {
            for e in &features.edges {
                let r = edge_row(link, jac, e, &mut row);
                ne.add_row(&row, r, weight * config.robust.weight(r), free);
                added.edges += 1;
            }
        }
        ResidualKind::AxisPoints => {
            let edges = &features.edges;
            let mut other = Row::new();
            let mut i = 0;
            while i < edges.len() {
                let e = &edges[i];
                let partner = edges
                    .get(i + 1)
                    .filter(|o| o.side == -e.side && (o.s - e.s).abs() < 1e-6);
                let r = match partner {
                    Some(o) => {
                        let half = 0.5 * f32::from(e.side);
                        let r_plus = edge_row(link, jac, e, &mut row);
                        let r_minus = edge_row(link, jac, o, &mut other);
                        if config.width_weight > 0.0 {
                            let mut width = row.clone();
                            for ((_, a), (_, b)) in width.iter_mut().zip(&other) {
                                *a = 0.5 * (*a + b);
                            }
                            let r_width = 0.5 * (r_plus + r_minus);
                            let w = weight * config.width_weight * config.robust.weight(r_width);
                            ne.add_row(&width, r_width, w, free);
                        }
                        for ((_, a), (_, b)) in row.iter_mut().zip(&other) {
                            *a = (*a - b) * half;
                        }
                        i += 2;
                        (r_plus - r_minus) * half
                    }
                    None => {
                        i += 1;
                        edge_row(link, jac, e, &mut row)
                    }
                };
                ne.add_row(&row, r, weight * config.robust.weight(r), free);
                added.edges += 1;
            }
        }
        ResidualKind::AxisLines => {
            if let Some(line) = fit_axis_line(link, features) {
                for end in [0, 1] {
                    let r = line_row(link, jac, line, end, &mut row);
                    ne.add_row(&row, r, weight, free);
                    added.edges += 1;
                }
            }
        }
    }
    if let Some(tip) = features.tip {
        let r = tip_row(link, jac, &tip, &mut row);
        ne.add_row(
            &row,
            r,
            weight * config.tip_weight * config.robust.weight(r),
            free,
        );
        added.tips += 1;
    }
    added
}
