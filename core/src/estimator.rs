//! Residuals and the conditioned Gauss–Newton step (Sec. 2.5, Eq. 2.22).
//!
//! Each link's residual rows are gathered as a 6×6 block in the link's six image parameters
//! (axis ends and projected radii) and applied through the link's Jacobian once, into the
//! normal equations `JᵀWJ` and `JᵀWr` ([`add_link_rows`]; a full `J` is never stored). The
//! step is `Δ = −(JᵀWJ + S)⁻¹ JᵀWr` with the constant diagonal conditioning matrix `S`, solved
//! by a sparse `LDLᵀ` factorisation over the free states ([`NormalEquations::step`]); only the
//! free states change. [`reference`](mod@reference) builds the same rows one at a time, the plain way: it is
//! the oracle the tests hold the tracker's path to.
//!
//! Residual kinds, each "predicted minus measured", in pixels ([`ResidualKind`]):
//! - **edge point**: the distance of a detected silhouette point from the predicted silhouette
//!   line (the axis offset by the projected radius) — robustly weighted;
//! - **axis point** (the default): where both edges of a slice were found, the distance of
//!   their midpoint from the model axis; a lone edge gives its edge-point row;
//! - **axis line** (Eq. 2.17, the thesis' form): the distance of the projected model axis'
//!   end points from the axis line fitted through a link's edge points
//!   ([`fit_axis_line`](crate::features::fit_axis_line));
//! - **tip** (Eq. 2.19): the distance along the axis between the predicted and found tip;
//! - **palm edge point**: the distance of a point found across the palm box's image outline
//!   from the predicted hull edge, an edge-point row of a radius-0 segment between two box
//!   corners ([`add_palm_edge_rows`]).
//!
//! Modules: `config` (the parameters), `jacobian` ([`LinkJacobian`]), `normal`
//! ([`NormalEquations`] and the solve), `link_rows` (the tracker's per-link blocks),
//! `palm_rows` (the palm outline's, through the same blocks) and [`reference`](mod@reference) (the oracle
//! rows).

use nalgebra::SVector;

use crate::config::MAX_STATES;
use crate::model::Model;
use crate::state::{clamp_to_limit, renormalise_quaternion, StateKind};

mod bounds;
mod config;
mod jacobian;
mod link_rows;
mod normal;
mod palm_rows;
pub mod reference;

pub use config::{Conditioning, EstimatorConfig, FreeMask, ResidualKind, Robust};
pub use jacobian::LinkJacobian;
pub(crate) use link_rows::add_region_rows;
pub use link_rows::{add_link_rows, region_row, LinkRows};
pub use normal::NormalEquations;
pub use palm_rows::{add_palm_edge_rows, add_reference_palm_edge_rows};

/// Applies a step to the free states of `q`, renormalises the quaternion and clamps joints to
/// the model's ranges. Returns the largest joint-angle change (rad) and translation (mm).
pub fn apply_step(
    model: &Model,
    q: &mut [f32],
    delta: &SVector<f32, MAX_STATES>,
    free: FreeMask,
) -> (f32, f32) {
    let (mut max_angle, mut max_move) = (0.0f32, 0.0f32);
    for (i, v) in q.iter_mut().enumerate().take(MAX_STATES) {
        if !free.contains(i) {
            continue;
        }
        *v += delta[i];
        match StateKind::of(i) {
            StateKind::Joint => {
                *v = clamp_to_limit(model, i, *v);
                max_angle = max_angle.max(delta[i].abs());
            }
            StateKind::Translation => max_move = max_move.max(delta[i].abs()),
            StateKind::Quaternion => max_angle = max_angle.max(delta[i].abs()),
        }
    }
    renormalise_quaternion(q);
    (max_angle, max_move)
}
