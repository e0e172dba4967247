//! The axis line of a link fitted through its edge points (the measurement of Eq. 2.17).

use heapless::Vec;
use nalgebra::Vector2;

use super::{LinkFeatures, MAX_LINK_EDGES};
use crate::projection::ProjectedLink;

/// Fits the axis line of a link through its edge points, each moved toward the axis by the
/// projected radius (so one silhouette alone still gives the axis), rejecting points more than
/// 2 px (or 3 median deviations) off a first fit. Returns a point on the line and its normal.
pub fn fit_axis_line(
    link: &ProjectedLink,
    features: &LinkFeatures,
) -> Option<(Vector2<f32>, Vector2<f32>)> {
    let normal = link.normal();
    let axis = link.b - link.a;
    let len2 = axis.norm_squared().max(1e-9);
    let mut points: Vec<Vector2<f32>, MAX_LINK_EDGES> = Vec::new();
    for e in &features.edges {
        let s = ((e.position - link.a).dot(&axis) / len2).clamp(0.0, 1.0);
        let _ =
            points.push(e.position - normal * (f32::from(e.side) * link.side_radius_at(s, e.side)));
    }
    let first = total_least_squares(&points, None)?;
    let mut deviations: Vec<f32, MAX_LINK_EDGES> = Vec::new();
    for p in &points {
        let _ = deviations.push(first.1.dot(&(p - first.0)).abs());
    }
    let mut sorted = deviations.clone();
    sorted.sort_unstable_by(|a, b| a.total_cmp(b));
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
    let limit = (3.0 * median).max(2.0);
    total_least_squares(&points, Some((&deviations, limit))).or(Some(first))
}

fn total_least_squares(
    points: &[Vector2<f32>],
    keep: Option<(&[f32], f32)>,
) -> Option<(Vector2<f32>, Vector2<f32>)> {
    let kept = |i: usize| keep.is_none_or(|(d, limit)| d.get(i).is_some_and(|v| *v <= limit));
    let mut n = 0.0f32;
    let mut centre = Vector2::zeros();
    for (i, p) in points.iter().enumerate() {
        if kept(i) {
            centre += p;
            n += 1.0;
        }
    }
    if n < 2.0 {
        return None;
    }
    centre /= n;
    let (mut sxx, mut sxy, mut syy) = (0.0f32, 0.0f32, 0.0f32);
    for (i, p) in points.iter().enumerate() {
        if kept(i) {
            let d = p - centre;
            sxx += d.x * d.x;
            sxy += d.x * d.y;
            syy += d.y * d.y;
        }
    }
    // Direction of largest spread: angle of the principal axis of the 2×2 scatter matrix.
    let angle = 0.5 * libm::atan2f(2.0 * sxy, sxx - syy);
    let (s, c) = crate::float::sin_cos(angle);
    if sxx + syy < 1e-6 {
        return None;
    }
    Some((centre, Vector2::new(-s, c)))
}
