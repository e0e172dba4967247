//! The reverse chamfer term: edges near the hand that no model line explains.
//!
//! The chamfer term asks, of each projected silhouette line, how far the nearest like-oriented
//! image edge lies (model → image). A finger read onto the palm or onto a neighbour finds
//! edges under its lines there, and that term is content; the true finger's own edges, which
//! no model line now explains, cost nothing. This term counts them: over the edge cells of the
//! frame's [`EdgeMap`] within the projected hand's bounds (widened by
//! [`LikelihoodConfig::reverse_margin_px`]), the mean distance (px) to the nearest projected
//! silhouette line of a like orientation bin — every link's two sides and the palm's outline —
//! truncated at [`LikelihoodConfig::reverse_cap_px`]. Lines hidden by a nearer part count as
//! explaining too: the term is a cheap bound, not a render.
//!
//! At most [`MAX_REVERSE_CELLS`] cells are visited: a larger region is visited on a coarser
//! lattice of cells, so the cost per view is bounded whatever the hand's size in the image.

use heapless::Vec;

use crate::config::MAX_LINKS;
use crate::float::Length;
use crate::nalgebra::Vector2;
use crate::palm_outline::{PalmOutline, MAX_HULL_EDGES};
use crate::projection::ProjectedModel;
use crate::silhouette::hand_bounds;

use super::edges::{bin_of, EdgeMap};
use super::{LikelihoodConfig, EDGE_BINS};

/// Most edge-map cells one view's term visits.
pub const MAX_REVERSE_CELLS: usize = 1024;

/// Most silhouette lines of one view: two per link and the palm's outline.
const MAX_LINES: usize = MAX_LINKS * 2 + MAX_HULL_EDGES;

/// One projected silhouette line: its ends (px), the bins (one bit each) its normal falls in,
/// and its bounds widened by the cap, to skip it cheaply.
#[derive(Debug, Clone, Copy)]
struct Line {
    a: Vector2<f32>,
    b: Vector2<f32>,
    bins: u8,
    min: Vector2<f32>,
    max: Vector2<f32>,
}

impl Line {
    fn new(a: Vector2<f32>, b: Vector2<f32>, cap_px: f32) -> Option<Self> {
        let d = b - a;
        let long_enough = d.norm_squared() > 1e-6;
        if !long_enough {
            return None;
        }
        let (nearest, second) = bin_of(libm::atan2f(d.x, -d.y));
        let reach = Vector2::new(cap_px, cap_px);
        Some(Line {
            a,
            b,
            bins: (1 << nearest) | (1 << second),
            min: a.inf(&b) - reach,
            max: a.sup(&b) + reach,
        })
    }

    /// Distance (px) from `p` to the segment.
    fn distance_px(&self, p: &Vector2<f32>) -> f32 {
        let d = self.b - self.a;
        let t = ((p - self.a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
        (self.a + d * t - p).length()
    }
}

/// The reverse chamfer term of `view` against `edges` (px, 0..=cap): `None` when nothing of
/// the hand is projected or no edge cell lies within its widened bounds.
pub(crate) fn reverse_px(
    view: &ProjectedModel,
    edges: &EdgeMap<'_>,
    config: &LikelihoodConfig,
) -> Option<f32> {
    let cap = config.reverse_cap_px.max(1e-3);
    let bounds = hand_bounds(view)?;
    let mut lines: Vec<Line, MAX_LINES> = Vec::new();
    for link in &view.links {
        for side in [1i8, -1] {
            let (a, b) = link.silhouette(side);
            if let Some(line) = Line::new(a, b, cap) {
                // At most two per link: cannot overflow.
                let _ = lines.push(line);
            }
        }
    }
    let mut outline = PalmOutline::new();
    outline.update(view.palm.as_ref(), 1.0);
    for edge in &outline.edges {
        if let Some(line) = Line::new(edge.segment.a, edge.segment.b, cap) {
            let _ = lines.push(line);
        }
    }
    let stride = edges.stride_px() as f32;
    let (cols, rows) = edges.cells();
    let margin = config.reverse_margin_px.max(0.0);
    let cell = |v: f32, n: usize| -> usize {
        if v > 0.0 {
            ((v / stride) as usize).min(n)
        } else {
            0
        }
    };
    let (x0, x1) = (
        cell(bounds.min.x - margin, cols),
        cell(bounds.max.x + margin + stride, cols),
    );
    let (y0, y1) = (
        cell(bounds.min.y - margin, rows),
        cell(bounds.max.y + margin + stride, rows),
    );
    let area = (x1 - x0) * (y1 - y0);
    // The lattice step (cells) that keeps the visits within MAX_REVERSE_CELLS.
    let mut step = 1usize;
    while area.div_ceil(step * step) > MAX_REVERSE_CELLS {
        step += 1;
    }
    let (mut sum, mut count) = (0.0f32, 0u32);
    for cy in (y0..y1).step_by(step) {
        for cx in (x0..x1).step_by(step) {
            let centre = Vector2::new((cx as f32 + 0.5) * stride, (cy as f32 + 0.5) * stride);
            let mut bins = 0u8;
            for bin in 0..EDGE_BINS {
                if edges.distance_units(bin, &centre) == Some(0) {
                    bins |= 1 << bin;
                }
            }
            if bins == 0 {
                continue;
            }
            let mut nearest = cap;
            for line in &lines {
                let inside = centre.x >= line.min.x
                    && centre.x <= line.max.x
                    && centre.y >= line.min.y
                    && centre.y <= line.max.y;
                if inside && line.bins & bins != 0 {
                    nearest = nearest.min(line.distance_px(&centre));
                }
            }
            sum += nearest;
            count += 1;
        }
    }
    (count > 0).then(|| sum / count as f32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::FrameView;
    use crate::nalgebra::Vector3;
    use crate::projection::{Bounds, ProjectedLink};

    const W: usize = 160;
    const H: usize = 120;

    /// A dark frame with a bright horizontal bar over rows `y0..y0 + 12` of columns 20..100
    /// for each of `bars`.
    fn frame_with(bars: &[usize]) -> [u8; W * H] {
        let mut pixels = [40u8; W * H];
        for &y0 in bars {
            for y in y0..y0 + 12 {
                pixels[y * W + 20..y * W + 100].fill(200);
            }
        }
        pixels
    }

    /// A link lying along the bar of rows `y0..y0 + 12`.
    fn link_on(y0: usize) -> ProjectedLink {
        let y = y0 as f32 + 6.0;
        ProjectedLink {
            frame: 0,
            child: 1,
            distal: false,
            knuckle_ends: false,
            radius_mm: 6.0,
            p0: Vector3::zeros(),
            p1: Vector3::zeros(),
            a: Vector2::new(20.0, y),
            b: Vector2::new(100.0, y),
            z0: 500.0,
            z1: 500.0,
            r0: [6.0, 6.0],
            r1: [6.0, 6.0],
            tip_offset: 6.0,
            bounds: Bounds {
                min: Vector2::new(14.0, y - 6.0),
                max: Vector2::new(106.0, y + 6.0),
            },
        }
    }

    fn view_of(bars: &[usize]) -> ProjectedModel {
        let mut view = ProjectedModel::new();
        for &y0 in bars {
            view.links.push(link_on(y0)).unwrap();
        }
        view
    }

    fn term(pixels: &[u8], view: &ProjectedModel, config: &LikelihoodConfig) -> Option<f32> {
        let frame = FrameView::packed(pixels, W, H).unwrap();
        let mut buffer = [0u8; (W / 4) * (H / 4) * EDGE_BINS];
        let edges = EdgeMap::build(&mut buffer, &frame, config).unwrap();
        reverse_px(view, &edges, config)
    }

    fn config() -> LikelihoodConfig {
        LikelihoodConfig {
            reverse_weight: 1.0,
            reverse_margin_px: 40.0,
            ..LikelihoodConfig::default()
        }
    }

    #[test]
    fn edges_no_line_explains_raise_the_term_and_a_line_on_them_lowers_it() {
        let config = config();
        let explained = term(&frame_with(&[30]), &view_of(&[30]), &config).unwrap();
        let unexplained = term(&frame_with(&[30, 70]), &view_of(&[30]), &config).unwrap();
        let both = term(&frame_with(&[30, 70]), &view_of(&[30, 70]), &config).unwrap();
        assert!(explained < 4.0, "{explained}");
        assert!(unexplained > explained + 2.0, "{explained} {unexplained}");
        assert!(both < unexplained - 2.0, "{both} {unexplained}");
        // Every distance is truncated at the cap.
        assert!(unexplained <= config.reverse_cap_px);
    }

    #[test]
    fn a_flat_frame_an_empty_view_or_a_nan_view_give_none_or_a_bounded_term() {
        let config = config();
        assert_eq!(term(&[40u8; W * H], &view_of(&[30]), &config), None);
        assert_eq!(
            term(&frame_with(&[30]), &ProjectedModel::new(), &config),
            None
        );
        let mut view = view_of(&[30]);
        view.links[0].a = Vector2::new(f32::NAN, f32::NAN);
        view.links[0].bounds.min = Vector2::new(f32::NAN, f32::NAN);
        if let Some(px) = term(&frame_with(&[30]), &view, &config) {
            assert!((0.0..=config.reverse_cap_px).contains(&px), "{px}");
        }
    }

    #[test]
    fn the_score_loses_the_weighted_term_and_nothing_without_a_weight() {
        let pixels = frame_with(&[30, 70]);
        let frame = FrameView::packed(&pixels, W, H).unwrap();
        let view = view_of(&[30]);
        let camera = crate::camera::Camera::looking_along(
            Vector3::new(0.0, 0.0, -500.0),
            Vector3::z(),
            Vector3::y(),
            (W as u32, H as u32),
            400.0,
        )
        .unwrap();
        let off = LikelihoodConfig {
            reverse_weight: 0.0,
            ..config()
        };
        let on = config();
        let mut buffer = [0u8; (W / 4) * (H / 4) * EDGE_BINS];
        let edges = EdgeMap::build(&mut buffer, &frame, &off).unwrap();
        let without = super::super::evaluate(&view, &camera, &frame, &edges, &off);
        let with = super::super::evaluate(&view, &camera, &frame, &edges, &on);
        assert_eq!(without.reverse_px, None);
        let px = with.reverse_px.unwrap();
        let expected = (without.score - px / on.reverse_cap_px).max(0.0);
        assert!(
            (with.score - expected).abs() < 1e-6,
            "{} {expected}",
            with.score
        );
        assert!(with.score < without.score);
    }
}
