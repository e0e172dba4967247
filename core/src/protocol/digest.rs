//! A model's fingerprint, so a host can tell that a board tracks the model it expects.
//!
//! The digest is CRC-32/ISO-HDLC over the model's *canonical form*, a byte string fully
//! specified in `docs/protocol.md` §7 so that a client in any language computes it from a
//! `hand.dh` file alone. Names, comments, spacing and how a number was written (`pi/2`,
//! `1.5707964`) do not enter it; the geometry, the joints, the tree and the joint ranges do.
//!
//! ```text
//! canonical = n_frames:u8 ‖ frame_0 ‖ … ‖ frame_{n−1} ‖ n_limits:u8 ‖ limit … (state order)
//! frame     = theta ‖ d:f32 ‖ a:f32 ‖ alpha:f32 ‖ shape ‖ n_next:u8 ‖ next:u8 …
//! theta     = 0 (base) | 1 ‖ state:u8 | 2 ‖ angle:f32
//! shape     = 0 (none) | 1 ‖ radius:f32 (cyl) | 2 ‖ radius:f32 (tip)
//!           | 3 ‖ size:3×f32 ‖ centre:3×f32 (box)
//! limit     = state:u8 ‖ lo:f32 ‖ hi:f32
//! ```
//!
//! Every `f32` is IEEE 754 single precision, little-endian.

use super::CRC;
use crate::model::{Model, Shape, Theta};

/// CRC-32/ISO-HDLC of `model`'s canonical form (see the module's documentation).
pub fn model_digest(model: &Model) -> u32 {
    let mut digest = CRC.digest();
    canonical_form(model, |bytes| digest.update(bytes));
    digest.finalize()
}

/// Hands the canonical form of `model` to `out`, piece by piece, in order.
pub fn canonical_form(model: &Model, mut out: impl FnMut(&[u8])) {
    let links = model.links();
    out(&[links.len() as u8]);
    for link in links {
        match link.theta {
            Theta::Base => out(&[0]),
            Theta::State(s) => out(&[1, s]),
            Theta::Const(angle) => {
                out(&[2]);
                out(&angle.to_le_bytes());
            }
        }
        for v in [link.d, link.a, link.alpha] {
            out(&v.to_le_bytes());
        }
        match link.shape {
            Shape::None => out(&[0]),
            Shape::Cylinder { radius } => {
                out(&[1]);
                out(&radius.to_le_bytes());
            }
            Shape::Tip { radius } => {
                out(&[2]);
                out(&radius.to_le_bytes());
            }
            Shape::Box { size, centre } => {
                out(&[3]);
                for v in size.iter().chain(&centre) {
                    out(&v.to_le_bytes());
                }
            }
        }
        out(&[link.children.len() as u8]);
        out(&link.children);
    }
    let limited = (0..model.n_states()).filter(|&s| model.limit(s).is_some());
    out(&[limited.clone().count() as u8]);
    for s in limited {
        if let Some(limit) = model.limit(s) {
            out(&[s as u8]);
            out(&limit.lo.to_le_bytes());
            out(&limit.hi.to_le_bytes());
        }
    }
}
