//! The palm outline's rows: each hull edge of the palm box's image is a radius-0 segment of
//! the palm's frame ([`HullEdge`]), so its found edge points give the links' edge-point rows
//! — the distance of each from the predicted hull edge line — through the same link Jacobian
//! (the two box corners' derivatives by the 7 palm states).

use super::link_rows::add_weighted_link_rows;
use super::reference::add_weighted_reference_rows;
use super::ResidualKind;
use super::{EstimatorConfig, FreeMask, LinkJacobian, LinkRows, NormalEquations};
use crate::features::LinkFeatures;
use crate::palm_outline::HullEdge;

/// The estimator parameters for a palm edge: edge-point rows whatever the links' residual
/// form (a hull edge has one side, so there is no axis to pair edges about or fit).
fn palm_config(config: &EstimatorConfig) -> EstimatorConfig {
    EstimatorConfig {
        residual: ResidualKind::EdgePoints,
        ..*config
    }
}

/// Adds the edge-point rows of one palm hull edge's features to `ne`, as
/// [`add_link_rows`](super::add_link_rows) does for a link's, each weighted by
/// `config.palm_edge_weight` besides the robust weight; `jac` is the [`LinkJacobian`] of
/// `edge.segment`.
pub fn add_palm_edge_rows(
    ne: &mut NormalEquations,
    edge: &HullEdge,
    features: &LinkFeatures,
    jac: &LinkJacobian,
    config: &EstimatorConfig,
    free: FreeMask,
) -> LinkRows {
    add_weighted_link_rows(
        ne,
        &edge.segment,
        features,
        jac,
        &palm_config(config),
        free,
        config.palm_edge_weight,
    )
}

/// [`add_palm_edge_rows`] the plain way, one reference row at a time: the oracle.
pub fn add_reference_palm_edge_rows(
    ne: &mut NormalEquations,
    edge: &HullEdge,
    features: &LinkFeatures,
    jac: &LinkJacobian,
    config: &EstimatorConfig,
    free: FreeMask,
) -> LinkRows {
    add_weighted_reference_rows(
        ne,
        &edge.segment,
        features,
        jac,
        &palm_config(config),
        free,
        config.palm_edge_weight,
    )
}
