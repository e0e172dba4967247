//! Slice features (Sec. 4.3.1): edges found along slices perpendicular to each projected link
//! axis, and fingertips found by a search along the axis beyond the tip.
//!
//! Along a slice the 1-D intensity derivative is taken; a peak of the expected sign is a
//! silhouette edge, located to sub-pixel precision by a parabola through the peak and its
//! neighbours. The hand is expected brighter than what surrounds it (the derivative going
//! outward is negative), except where the outside of an edge lies over a farther part of the
//! hand, where either sign is accepted. Slices whose predicted edge lies inside a nearer link
//! or the palm are masked ([`crate::visibility`]).

use heapless::Vec;
use nalgebra::Vector2;

use crate::camera::Camera;
use crate::config::{MAX_SLICES_PER_LINK, MAX_WINDOW};
use crate::frame::FrameView;
use crate::projection::Bounds;
use crate::projection::ProjectedLink;
use crate::projection::ProjectedModel;
use crate::visibility::{candidates, cover_among, Cover};

mod axis_line;
mod palm;
mod refusals;
pub use axis_line::fit_axis_line;
pub use palm::{find_palm_edge_features, find_palm_edge_features_refusing};
pub use refusals::RefusedWindows;

/// Which sign of intensity change, going outward across an edge, counts as an edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Polarity {
    /// Bright inside, dark outside (a hand over a darker background).
    DarkOutside,
    /// Either sign.
    Any,
}

/// Parameters of the slice search.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub struct FeatureConfig {
    /// Slices per link (at most [`MAX_SLICES_PER_LINK`]).
    pub slices_per_link: u8,
    /// Search window along each slice and beyond each tip (px, at most [`MAX_WINDOW`]), in
    /// a frame's first iteration.
    pub window_px: u8,
    /// Coarse to fine: in a frame's later iterations the tracker narrows each link's window
    /// to what its last search needed, [`LinkFeatures::reach_px`] plus this margin on each
    /// side (px); infinite keeps `window_px` throughout.
    pub refine_margin_px: f32,
    /// Smallest derivative peak accepted as an edge (grey levels per px).
    pub min_contrast: f32,
    /// Slices are spread over this part of the axis (fractions of its length).
    pub span: [f32; 2],
    /// Links shorter than this in the image are skipped as seen end-on (px).
    pub min_link_px: f32,
    /// Sign of the edges sought.
    pub polarity: Polarity,
    /// Mask slices whose predicted edge is hidden by a nearer link or the palm.
    pub mask_occluded: bool,
    /// Search for fingertips.
    pub tips: bool,
    /// Also search beyond a knuckle where the outline ends there, as beyond a fingertip
    /// (needs `tips`): where the next link, from this camera, turns back over the link or is
    /// seen end-on pointing away ([`ProjectedLink::knuckle_ends`]), as a finger curled away
    /// from the camera is. On by default: track life +9.8 points mono and +5.4 stereo on 360
    /// fresh seeds (+22.4 mono from overhead), cost within ±4 % a frame
    /// (`docs/robustness.md`, "Knuckle tips").
    pub knuckle_tips: bool,
    /// Also slice across the palm box's own image outline ([`find_palm_edge_features`]),
    /// so the palm's pose is seen by its edges and not only through the fingers'.
    pub palm_edges: bool,
    /// An edge found on a slice is kept only if the image's own edge there runs within this
    /// angle of the predicted one (rad): the gradient's component along the predicted edge is
    /// at most `tan(angle)` of its component across it ([`edge_runs_along`]). A slice that
    /// crosses another finger's or the palm's outline at an angle then finds nothing rather
    /// than that outline, and a window refused once stays refused for the rest of the frame
    /// ([`RefusedWindows`]). `π/2` or more keeps every edge. Default 30°: track life +5.6
    /// points on 240 fresh seeds for 11 % more instructions per frame (`docs/robustness.md`,
    /// `docs/performance.md`).
    pub max_edge_angle_rad: f32,
    /// Where the model says a slice's edge lies against the background (no part of the hand
    /// just outside it), the outermost edge of the window at least this share of its
    /// strongest is taken rather than the strongest ([`find_outermost_edge`]; 0: the
    /// strongest). The hand's outline against the background is the last drop going
    /// outward; a stronger one inside it is the hand's own shading or another finger lying
    /// inside the outline. Default 0.3: the rule came in at 0.5 (+4.9 points of stereo track
    /// life) and 0.3 gained stereo +2.4 more on the 480 fresh seeds it was first judged on,
    /// and on seven of the eight blocks judged in all, mono level (`docs/robustness.md`, "The
    /// outermost edge", "Stop 72" and "Stop 73").
    pub outermost_share: f32,
}

impl Default for FeatureConfig {
    fn default() -> Self {
        FeatureConfig {
            slices_per_link: 5,
            window_px: 16,
            refine_margin_px: 1.5,
            min_contrast: 4.0,
            span: [0.15, 0.85],
            min_link_px: 6.0,
            polarity: Polarity::DarkOutside,
            mask_occluded: true,
            tips: true,
            knuckle_tips: true,
            palm_edges: true,
            max_edge_angle_rad: core::f32::consts::FRAC_PI_6,
            outermost_share: 0.3,
        }
    }
}

impl FeatureConfig {
    /// Whether a tip search runs beyond `link`'s end `b`: a fingertip's, or (with
    /// `knuckle_tips`) a knuckle where the outline ends.
    pub fn searches_tip(&self, link: &ProjectedLink) -> bool {
        self.tips && (link.distal || (self.knuckle_tips && link.knuckle_ends))
    }

    /// `tan(max_edge_angle_rad)`, or `None` when every edge is kept.
    pub fn edge_tangent_limit(&self) -> Option<f32> {
        (self.max_edge_angle_rad < core::f32::consts::FRAC_PI_2 - 1e-3)
            .then(|| crate::float::tan(self.max_edge_angle_rad.max(0.0)))
    }
}

/// Whether an edge found at `p` on search window `window` (a [`RefusedWindows`] bit), stepping
/// `outward`, is kept: not refused earlier in the frame, and running along the predicted edge
/// under `limit` ([`FeatureConfig::edge_tangent_limit`]; `None` keeps every edge). A window
/// refused now is added to `refused`, and stays refused without a look.
pub(crate) fn edge_kept(
    frame: &FrameView<'_>,
    limit: Option<f32>,
    refused: &mut RefusedWindows,
    window: u32,
    p: Vector2<f32>,
    outward: Vector2<f32>,
) -> bool {
    if refused.contains(window) {
        return false;
    }
    let kept = limit.is_none_or(|limit| edge_runs_along(frame, p, outward, limit));
    if !kept {
        refused.insert(window);
    }
    kept
}

/// Whether the image's edge at `p` runs along the predicted edge, whose outward normal is
/// `outward` (a unit vector): the intensity gradient at the nearest pixel, by a 3×3 Sobel
/// ([`FrameView::sobel`]), has a component along the edge at most `limit` times its
/// component across it. True where the stencil leaves the frame (nothing to judge).
pub fn edge_runs_along(
    frame: &FrameView<'_>,
    p: Vector2<f32>,
    outward: Vector2<f32>,
    limit: f32,
) -> bool {
    let (x, y) = (libm::roundf(p.x), libm::roundf(p.y));
    if !(x >= 0.0 && y >= 0.0 && x < frame.width() as f32 && y < frame.height() as f32) {
        return true;
    }
    let Some([dx, dy]) = frame.sobel(x as usize, y as usize) else {
        return true;
    };
    let (dx, dy) = (dx as f32, dy as f32);
    let across = dx * outward.x + dy * outward.y;
    let tangent = dy * outward.x - dx * outward.y;
    libm::fabsf(tangent) <= limit * libm::fabsf(across)
}

/// Fewest samples a search window has: the smoothed derivative needs 2 samples each side of a
/// point, and the peak test one more derivative each side (so [`find_edge`] finds nothing in
/// fewer). Windows asked for smaller are widened to this.
pub const MIN_WINDOW_SAMPLES: usize = 7;

/// How far beyond a predicted edge (outward) or tip the occlusion mask is probed to tell an
/// edge over the background from one over a farther part of the hand (px). The region of
/// links tested for cover is grown by the same distance, so every probe lies inside it.
pub const PROBE_BEYOND_EDGE_PX: f32 = 2.0;

/// An edge found along a 1-D profile.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Edge {
    /// Sub-pixel position, in samples from the profile's start.
    pub position: f32,
    /// Derivative magnitude at the peak (grey levels per sample).
    pub strength: f32,
}

/// Finds the strongest edge of the wanted sign in `profile` (samples one pixel apart, going
/// outward). The derivative is the smoothed difference `(2(I[k+1] − I[k−1]) + I[k+2] − I[k−2]) / 8`
/// and the peak is refined by a parabola. `None` when no peak reaches `min_contrast`.
pub fn find_edge(profile: &[f32], polarity: Polarity, min_contrast: f32) -> Option<Edge> {
    let (d, n) = oriented_derivative(profile, polarity)?;
    let mut best: Option<usize> = None;
    for k in 3..n - 3 {
        if is_peak(&d, k, min_contrast) && best.is_none_or(|b| d[k] > d[b]) {
            best = Some(k);
        }
    }
    best.map(|k| edge_at(&d, k))
}

/// As [`find_edge`], but the outermost peak (the last going outward) whose strength is at
/// least `share` of the strongest peak's; `None` when no peak reaches `min_contrast`.
pub fn find_outermost_edge(
    profile: &[f32],
    polarity: Polarity,
    min_contrast: f32,
    share: f32,
) -> Option<Edge> {
    let (d, n) = oriented_derivative(profile, polarity)?;
    let peaks = || (3..n - 3).filter(|&k| is_peak(&d, k, min_contrast));
    let strongest = peaks().map(|k| d[k]).fold(0.0f32, f32::max);
    // A share above 1 (or NaN) would refuse even the strongest peak: it is taken as 1.
    let bar = share.min(1.0) * strongest;
    let k = peaks().rev().find(|&k| d[k] >= bar)?;
    Some(edge_at(&d, k))
}

/// The smoothed derivative of `profile` (its first [`MAX_WINDOW`] samples), signed so that
/// the edges `polarity` wants are positive, and how many samples it covers; `None` for a
/// profile shorter than [`MIN_WINDOW_SAMPLES`].
fn oriented_derivative(profile: &[f32], polarity: Polarity) -> Option<([f32; MAX_WINDOW], usize)> {
    if profile.len() < MIN_WINDOW_SAMPLES {
        return None;
    }
    let n = profile.len().min(MAX_WINDOW);
    let mut d = [0.0f32; MAX_WINDOW];
    for k in 2..n - 2 {
        let v = (2.0 * (profile[k + 1] - profile[k - 1]) + profile[k + 2] - profile[k - 2]) / 8.0;
        d[k] = match polarity {
            Polarity::DarkOutside => -v,
            Polarity::Any => v.abs(),
        };
    }
    Some((d, n))
}

/// Whether sample `k` of an oriented derivative is a peak reaching `min_contrast`.
fn is_peak(d: &[f32], k: usize, min_contrast: f32) -> bool {
    d[k] >= min_contrast && d[k] >= d[k - 1] && d[k] > d[k + 1]
}

/// The edge at peak `k` of an oriented derivative, refined by a parabola.
fn edge_at(d: &[f32], k: usize) -> Edge {
    Edge {
        position: k as f32 + vertex_offset(d[k - 1], d[k], d[k + 1]),
        strength: d[k],
    }
}

/// Sub-sample offset (−0.5..0.5) of the vertex of the parabola through three samples one
/// apart, `l`, `c`, `r`, with `c` the extremum; 0 when they are collinear.
fn vertex_offset(l: f32, c: f32, r: f32) -> f32 {
    let curvature = l - 2.0 * c + r;
    if curvature.abs() > 1e-6 {
        (0.5 * (l - r) / curvature).clamp(-0.5, 0.5)
    } else {
        0.0
    }
}

/// Finds the boundary between two touching bright surfaces in `profile`: the deepest intensity
/// valley (smoothed `[1 2 1] / 4`) at least `min_depth` below the brightest sample on each side,
/// refined by a parabola. Under shading, where one part of the hand lies over another, the
/// silhouette is this valley, while the steepest descent lies on the shading ramp inside it.
pub fn find_valley(profile: &[f32], min_depth: f32) -> Option<Edge> {
    let n = profile.len().min(MAX_WINDOW);
    if n < 5 {
        return None;
    }
    let mut smooth = [0.0f32; MAX_WINDOW];
    for k in 1..n - 1 {
        smooth[k] = 0.25 * (profile[k - 1] + 2.0 * profile[k] + profile[k + 1]);
    }
    let mut best: Option<(usize, f32)> = None;
    for k in 2..n - 2 {
        let v = smooth[k];
        if v > smooth[k - 1] || v > smooth[k + 1] {
            continue;
        }
        let left = smooth[1..k].iter().fold(f32::MIN, |m, x| m.max(*x));
        let right = smooth[k + 1..n - 1].iter().fold(f32::MIN, |m, x| m.max(*x));
        let depth = (left - v).min(right - v);
        if depth >= min_depth && best.is_none_or(|(_, d)| depth > d) {
            best = Some((k, depth));
        }
    }
    let (k, strength) = best?;
    let offset = vertex_offset(smooth[k - 1], smooth[k], smooth[k + 1]);
    Some(Edge {
        position: k as f32 + offset,
        strength,
    })
}

/// One silhouette edge point found on a slice.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgePoint {
    /// Where the slice crosses the axis, as a fraction of the axis from `a` to `b`.
    pub s: f32,
    /// Which side of the axis: +1 along the normal `(−d_y, d_x)` of the axis direction, or −1.
    pub side: i8,
    /// The edge in the image (px).
    pub position: Vector2<f32>,
    /// Derivative magnitude at the edge.
    pub strength: f32,
}

// By hand: nalgebra's vectors do not implement `defmt::Format`.
#[cfg(feature = "defmt")]
impl defmt::Format for EdgePoint {
    fn format(&self, f: defmt::Formatter<'_>) {
        defmt::write!(
            f,
            "EdgePoint {{ s: {}, side: {}, position: ({}, {}), strength: {} }}",
            self.s,
            self.side,
            self.position.x,
            self.position.y,
            self.strength
        )
    }
}

/// Most edge points one link yields.
pub const MAX_LINK_EDGES: usize = 2 * MAX_SLICES_PER_LINK;

/// What the slice search found for one link.
#[derive(Debug, Clone, Default)]
pub struct LinkFeatures {
    /// Silhouette edge points.
    pub edges: Vec<EdgePoint, MAX_LINK_EDGES>,
    /// The fingertip in the image (px), for a distal link.
    pub tip: Option<Vector2<f32>>,
    /// Edges and tips the model predicted visible and in the frame.
    pub expected: u16,
    /// Predicted edges and tips hidden by a nearer part of the hand.
    pub masked: u16,
    /// Slices and tip windows that left the frame.
    pub off_frame: u16,
    /// Farthest any edge or tip found lies from its prediction (px); 0 when none was found.
    pub reach_px: f32,
}

pub use crate::projection::axis_frame;

/// What became of one search window of [`find_link_features`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WindowOutcome {
    /// Not searched: the predicted edge or tip is hidden by a nearer link or the palm.
    Masked,
    /// Not searched: the window leaves the frame.
    OffFrame,
    /// Searched; no edge reached the contrast threshold.
    NoEdge,
    /// Searched; an edge (or tip) was found and added to the link's features.
    Found,
}

/// One search window of [`find_link_features`], where it lies in the image and what became
/// of it: samples `start + step · k` for `k = 0..samples` (px), `step` a unit vector pointing
/// outward (away from the axis for a slice, along the axis beyond `b` for a tip).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SearchWindow {
    /// The first sample (px).
    pub start: Vector2<f32>,
    /// From one sample to the next: a unit vector (px).
    pub step: Vector2<f32>,
    /// Samples in the window.
    pub samples: u8,
    /// Whether this is the window beyond a fingertip (else a slice across the axis).
    pub tip: bool,
    /// What the search came to.
    pub outcome: WindowOutcome,
}

/// Runs the slice and tip searches for link `index` of `view` on `frame`, into `out`.
pub fn find_link_features(
    view: &ProjectedModel,
    camera: &Camera,
    frame: &FrameView<'_>,
    index: usize,
    config: &FeatureConfig,
    out: &mut LinkFeatures,
) {
    let mut refused = RefusedWindows::NONE;
    find_link_features_refusing(view, camera, frame, index, config, &mut refused, out);
}

/// [`find_link_features`] across the iterations of one frame: windows in `refused` (refused
/// by the direction test earlier in the frame) stay refused, and windows refused now are
/// added ([`RefusedWindows`]).
#[inline(never)] // a stage of Table 4.1: kept whole so profiles can attribute its cost
#[allow(clippy::too_many_arguments)]
pub fn find_link_features_refusing(
    view: &ProjectedModel,
    camera: &Camera,
    frame: &FrameView<'_>,
    index: usize,
    config: &FeatureConfig,
    refused: &mut RefusedWindows,
    out: &mut LinkFeatures,
) {
    search_link(
        view,
        camera,
        frame,
        index,
        config,
        refused,
        out,
        &mut |_| {},
    );
}

/// [`find_link_features`], also handing `watch` every search window it considered, in
/// search order (slices from `s = span[0]`, side +1 then −1, then the tip window), masked and
/// off-frame ones included. The same code as the tracker's search, so a debug view drawn from
/// it shows exactly what the tracker searched; `out` ends up the same as without `watch`.
pub fn find_link_features_watched(
    view: &ProjectedModel,
    camera: &Camera,
    frame: &FrameView<'_>,
    index: usize,
    config: &FeatureConfig,
    out: &mut LinkFeatures,
    mut watch: impl FnMut(&SearchWindow),
) {
    let mut refused = RefusedWindows::NONE;
    search_link(
        view,
        camera,
        frame,
        index,
        config,
        &mut refused,
        out,
        &mut watch,
    );
}

/// The one body of both searches; with a no-op `watch` it compiles to the plain search.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn search_link<W: FnMut(&SearchWindow)>(
    view: &ProjectedModel,
    camera: &Camera,
    frame: &FrameView<'_>,
    index: usize,
    config: &FeatureConfig,
    refused: &mut RefusedWindows,
    out: &mut LinkFeatures,
    watch: &mut W,
) {
    out.edges.clear();
    out.tip = None;
    out.expected = 0;
    out.masked = 0;
    out.off_frame = 0;
    out.reach_px = 0.0;
    let Some(link) = view.links.get(index) else {
        return;
    };
    let window = usize::from(config.window_px).clamp(MIN_WINDOW_SAMPLES, MAX_WINDOW);
    let half = (window - 1) as f32 * 0.5;
    let (dir, normal) = link.axis_frame();
    let slices = usize::from(config.slices_per_link).clamp(1, MAX_SLICES_PER_LINK);
    let mut profile = [0.0f32; MAX_WINDOW];
    let tangent_limit = config.edge_tangent_limit();
    let slice_s = |k: usize| {
        if slices == 1 {
            0.5 * (config.span[0] + config.span[1])
        } else {
            config.span[0] + (config.span[1] - config.span[0]) * k as f32 / (slices - 1) as f32
        }
    };
    // Every point `cover` is asked about (the predicted edges and tip, and
    // `PROBE_BEYOND_EDGE_PX` beyond each) lies within the link's own bounds grown by that
    // distance, so only the links and palm whose bounds meet that box are tested.
    let (among, palm) = if config.mask_occluded {
        let reach = Vector2::new(PROBE_BEYOND_EDGE_PX, PROBE_BEYOND_EDGE_PX);
        let tip = if config.searches_tip(link) {
            link.b + dir * (link.tip_offset + PROBE_BEYOND_EDGE_PX)
        } else {
            link.b
        };
        let region = Bounds {
            min: (link.bounds.min - reach).inf(&tip),
            max: (link.bounds.max + reach).sup(&tip),
        };
        candidates(view, index, &region)
    } else {
        (heapless::Vec::new(), false)
    };
    let mut search = |centre: Vector2<f32>,
                      outward: Vector2<f32>,
                      depth: f32,
                      window_bit: u32,
                      out: &mut LinkFeatures| {
        let tip = window_bit == RefusedWindows::TIP;
        let mut watched = |outcome| {
            watch(&SearchWindow {
                start: centre - outward * half,
                step: outward,
                samples: window as u8,
                tip,
                outcome,
            })
        };
        let mut over_hand = false;
        if config.mask_occluded {
            match cover_among(view, camera, &among, palm, &centre, depth) {
                Cover::Hidden => {
                    out.masked += 1;
                    watched(WindowOutcome::Masked);
                    return None;
                }
                Cover::Behind => over_hand = true,
                Cover::Clear => {
                    over_hand = cover_among(
                        view,
                        camera,
                        &among,
                        palm,
                        &(centre + outward * PROBE_BEYOND_EDGE_PX),
                        depth,
                    ) != Cover::Clear;
                }
            }
        }
        let start = centre - outward * half;
        if !frame.sample_segment(start, outward, &mut profile[..window]) {
            out.off_frame += 1;
            watched(WindowOutcome::OffFrame);
            return None;
        }
        out.expected += 1;
        let edge = if over_hand {
            find_valley(&profile[..window], config.min_contrast)
                .or_else(|| find_edge(&profile[..window], Polarity::Any, config.min_contrast))
        } else if config.outermost_share > 0.0 && !tip {
            find_outermost_edge(
                &profile[..window],
                config.polarity,
                config.min_contrast,
                config.outermost_share,
            )
        } else {
            find_edge(&profile[..window], config.polarity, config.min_contrast)
        };
        let edge = edge.filter(|e| {
            let at = start + outward * e.position;
            edge_kept(frame, tangent_limit, refused, window_bit, at, outward)
        });
        let Some(edge) = edge else {
            watched(WindowOutcome::NoEdge);
            return None;
        };
        watched(WindowOutcome::Found);
        out.reach_px = out.reach_px.max((edge.position - half).abs());
        Some((start + outward * edge.position, edge.strength))
    };
    for k in 0..slices {
        let s = slice_s(k);
        let axis_point = link.a + (link.b - link.a) * s;
        let depth = link.depth_at(s);
        for side in [1i8, -1] {
            let outward = normal * f32::from(side);
            let predicted = axis_point + outward * link.side_radius_at(s, side);
            if let Some((position, strength)) = search(
                predicted,
                outward,
                depth,
                RefusedWindows::slice(k, side),
                out,
            ) {
                let _ = out.edges.push(EdgePoint {
                    s,
                    side,
                    position,
                    strength,
                });
            }
        }
    }
    if config.searches_tip(link) {
        let predicted = link.b + dir * link.tip_offset;
        if let Some((position, _)) = search(predicted, dir, link.z1, RefusedWindows::TIP, out) {
            out.tip = Some(position);
        }
    }
}
