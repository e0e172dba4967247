//! Slices across the palm's own outline (issue 9): for each hull edge of the palm box's
//! image ([`PalmOutline`](crate::palm_outline::PalmOutline)), slices perpendicular to it over
//! `span` of its length, searching for the edge of the expected sign (the palm brighter than
//! what lies outside it).
//!
//! Where the contrast is not palm against background the slice is masked, not searched: when
//! the predicted edge is hidden by a nearer link, and when the point just outside it
//! ([`PROBE_BEYOND_EDGE_PX`]) lies inside any link's image, near or far — where the fingers
//! attach at the knuckle face, or a curled finger lies across the outline, the contrast there
//! is finger against palm.

use super::{
    edge_kept, find_edge, EdgePoint, FeatureConfig, LinkFeatures, RefusedWindows,
    MIN_WINDOW_SAMPLES, PROBE_BEYOND_EDGE_PX,
};
use crate::camera::Camera;
use crate::config::{MAX_SLICES_PER_LINK, MAX_WINDOW};
use crate::frame::FrameView;
use crate::palm_outline::HullEdge;
use crate::projection::{Bounds, ProjectedModel};
use crate::visibility::{candidates, cover_among, Cover};

/// Searches the slices across hull edge `edge` of the palm in `view` on `frame`, into `out`:
/// the edge points found (`side` = the edge's outward side, `s` along it from its first
/// corner), and the counts of slices expected, masked and off the frame, as a link's.
pub fn find_palm_edge_features(
    view: &ProjectedModel,
    camera: &Camera,
    frame: &FrameView<'_>,
    edge: &HullEdge,
    config: &FeatureConfig,
    out: &mut LinkFeatures,
) {
    let mut refused = RefusedWindows::NONE;
    find_palm_edge_features_refusing(view, camera, frame, edge, config, &mut refused, out);
}

/// [`find_palm_edge_features`] across the iterations of one frame, as
/// [`find_link_features_refusing`](super::find_link_features_refusing) is for a link: the
/// windows in `refused` stay refused, and windows refused now are added.
#[inline(never)] // a stage of Table 4.1: kept whole so profiles can attribute its cost
pub fn find_palm_edge_features_refusing(
    view: &ProjectedModel,
    camera: &Camera,
    frame: &FrameView<'_>,
    edge: &HullEdge,
    config: &FeatureConfig,
    refused: &mut RefusedWindows,
    out: &mut LinkFeatures,
) {
    out.edges.clear();
    out.tip = None;
    out.expected = 0;
    out.masked = 0;
    out.off_frame = 0;
    out.reach_px = 0.0;
    let segment = &edge.segment;
    let window = usize::from(config.window_px).clamp(MIN_WINDOW_SAMPLES, MAX_WINDOW);
    let half = (window - 1) as f32 * 0.5;
    let outward = edge.outward_normal();
    let slices = usize::from(config.slices_per_link).clamp(1, MAX_SLICES_PER_LINK);
    // Every point the mask asks about lies within the edge's bounds grown by the probe.
    let (among, _) = if config.mask_occluded {
        let reach = nalgebra::Vector2::new(PROBE_BEYOND_EDGE_PX, PROBE_BEYOND_EDGE_PX);
        let region = Bounds {
            min: segment.bounds.min - reach,
            max: segment.bounds.max + reach,
        };
        // No link is excluded: the palm's outline is no link's neighbour.
        candidates(view, usize::MAX, &region)
    } else {
        (heapless::Vec::new(), false)
    };
    let mut profile = [0.0f32; MAX_WINDOW];
    let tangent_limit = config.edge_tangent_limit();
    for k in 0..slices {
        let s = if slices == 1 {
            0.5 * (config.span[0] + config.span[1])
        } else {
            config.span[0] + (config.span[1] - config.span[0]) * k as f32 / (slices - 1) as f32
        };
        let centre = segment.a + (segment.b - segment.a) * s;
        if config.mask_occluded {
            let depth = segment.depth_at(s);
            let hidden = cover_among(view, camera, &among, false, &centre, depth) == Cover::Hidden;
            let beyond = centre + outward * PROBE_BEYOND_EDGE_PX;
            let over_finger =
                cover_among(view, camera, &among, false, &beyond, depth) != Cover::Clear;
            if hidden || over_finger {
                out.masked += 1;
                continue;
            }
        }
        let start = centre - outward * half;
        if !frame.sample_segment(start, outward, &mut profile[..window]) {
            out.off_frame += 1;
            continue;
        }
        out.expected += 1;
        let Some(found) = find_edge(&profile[..window], config.polarity, config.min_contrast)
            .filter(|e| {
                let at = start + outward * e.position;
                let bit = RefusedWindows::slice(k, edge.outward);
                edge_kept(frame, tangent_limit, refused, bit, at, outward)
            })
        else {
            continue;
        };
        out.reach_px = out.reach_px.max((found.position - half).abs());
        let _ = out.edges.push(EdgePoint {
            s,
            side: edge.outward,
            position: start + outward * found.position,
            strength: found.strength,
        });
    }
}
