//! One board per camera, as the thesis' stereo system ran: per iteration the host sends the
//! state ([`Measure`]), each board searches its own frame at it and answers with what it
//! found ([`LinkEdges`] per link, [`PalmEdges`] per palm outline edge, then [`Measured`]), and the host fuses every camera's
//! features in one solve. This module is the board's half ([`MeasureWork`]) and the
//! conversions both halves share, so the host rebuilds exactly the features the in-process
//! loop would have found.
//!
//! Why features and not each camera's share of the normal equations: the whole hand's share
//! is 28 × 29 / 2 + 28 floats (≈ 1.75 KB) whatever the image shows, over the largest message;
//! the features are ≈ 13 bytes per edge found, ≈ 1.3 KB for a whole hand in view, less for a
//! sub-model (docs/link.md has the figures).

use crate::camera::Camera;
use crate::features::{EdgePoint, LinkFeatures};
use crate::frame::FrameView;
use crate::kinematics::Poses;
use crate::model::Model;
use crate::nalgebra::Vector2;
use crate::palm_outline::{HullEdge, PalmOutline};
use crate::projection::ProjectedModel;
use crate::protocol::{BoardMessage, LinkEdges, Measure, Measured, PalmEdges, WireEdge};
use crate::search::CameraSearch;
use crate::tracker::TrackerConfig;

/// The wire form of edge points (their strength stays on the board); beyond `N` they are
/// dropped, never a panic (a link's and an outline edge's searches yield at most `N`).
fn wire_edges<const N: usize>(edges: &[EdgePoint]) -> heapless::Vec<WireEdge, N> {
    let mut out = heapless::Vec::new();
    for e in edges {
        let _ = out.push(WireEdge {
            s: e.s,
            side: e.side,
            position: [e.position.x, e.position.y],
        });
    }
    out
}

/// Edge points from their wire form into `out.edges` (strength 0: no estimate uses it).
fn edges_from_wire(edges: &[WireEdge], out: &mut LinkFeatures) {
    out.edges.clear();
    for e in edges {
        // No more than a link's search yields: `out` holds that many.
        let _ = out.edges.push(EdgePoint {
            s: e.s,
            side: e.side,
            position: Vector2::new(e.position[0], e.position[1]),
            strength: 0.0,
        });
    }
}

impl LinkEdges {
    /// The wire form of `features`: link `index` in view (model frame `link`), found in
    /// answer to `measure`.
    pub fn from_features(measure: &Measure, index: u8, link: u8, features: &LinkFeatures) -> Self {
        LinkEdges {
            frame: measure.frame,
            iteration: measure.iteration,
            index,
            link,
            edges: wire_edges(&features.edges),
            tip: features.tip.map(|t| [t.x, t.y]),
            expected: features.expected,
            masked: features.masked,
        }
    }

    /// The features as the tracker uses them (edges, tip and the counts; the strength, the
    /// off-frame count and the reach stay on the board).
    pub fn to_features(&self, out: &mut LinkFeatures) {
        edges_from_wire(&self.edges, out);
        out.tip = self.tip.map(|t| Vector2::new(t[0], t[1]));
        out.expected = self.expected;
        out.masked = self.masked;
        out.off_frame = 0;
        out.reach_px = 0.0;
    }

    /// Whether the board said nothing of this link (nothing expected, found or masked).
    pub fn is_empty(&self) -> bool {
        self.edges.is_empty() && self.tip.is_none() && self.expected == 0 && self.masked == 0
    }
}

impl PalmEdges {
    /// The wire form of `features`, found across the palm outline edge `edge` in answer to
    /// `measure`.
    pub fn from_features(measure: &Measure, edge: &HullEdge, features: &LinkFeatures) -> Self {
        PalmEdges {
            frame: measure.frame,
            iteration: measure.iteration,
            corners: edge.corners,
            edges: wire_edges(&features.edges),
            expected: features.expected,
            masked: features.masked,
        }
    }

    /// The features as the tracker uses them (edges and the counts).
    pub fn to_features(&self, out: &mut LinkFeatures) {
        edges_from_wire(&self.edges, out);
        out.tip = None;
        out.expected = self.expected;
        out.masked = self.masked;
        out.off_frame = 0;
        out.reach_px = 0.0;
    }

    /// Whether the board said nothing of this edge (nothing expected, found or masked).
    pub fn is_empty(&self) -> bool {
        self.edges.is_empty() && self.expected == 0 && self.masked == 0
    }
}

/// A board's working memory for answering [`Measure`]s: the same projection and coarse-to-fine
/// search the in-process tracker runs for one camera.
#[derive(Debug, Clone, Default)]
pub struct MeasureWork {
    poses: Option<Poses>,
    view: ProjectedModel,
    search: CameraSearch,
    outline: PalmOutline,
    features: LinkFeatures,
}

impl MeasureWork {
    /// Working memory that has measured nothing yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Answers `measure` on `frame` (camera `camera`, parameters `config`): hands `send` one
    /// [`BoardMessage::LinkEdges`] per link in view with anything to say, in table order,
    /// then (with `config.features.palm_edges`) one [`BoardMessage::PalmEdges`] per palm
    /// outline edge with anything to say, in outline order, and returns the closing
    /// [`Measured`]. An unusable state measures nothing (`links` = 0).
    #[inline(never)] // a stage of the stereo loop: kept whole so profiles can attribute it
    pub fn measure(
        &mut self,
        model: &Model,
        camera: &Camera,
        frame: &FrameView<'_>,
        config: &TrackerConfig,
        measure: &Measure,
        mut send: impl FnMut(BoardMessage),
    ) -> Measured {
        let mut answer = Measured {
            frame: measure.frame,
            iteration: measure.iteration,
            held: true,
            links: 0,
            silhouette: None,
        };
        let posed = match self.poses.as_mut() {
            Some(p) => p.update(model, &measure.q).is_ok(),
            None => match Poses::compute(model, &measure.q) {
                Ok(p) => {
                    self.poses = Some(p);
                    true
                }
                Err(_) => false,
            },
        };
        let Some(poses) = self.poses.as_ref().filter(|_| posed) else {
            return answer;
        };
        let refine = measure.iteration > 0;
        if !refine {
            self.search.restart();
        }
        self.view
            .update(model, poses, camera, config.features.min_link_px);
        for index in 0..self.view.links.len() {
            self.search.link(
                &self.view,
                camera,
                frame,
                index,
                &config.features,
                refine,
                &mut self.features,
            );
            let link = self.view.links[index].frame;
            let edges = LinkEdges::from_features(measure, index as u8, link, &self.features);
            if !edges.is_empty() {
                send(BoardMessage::LinkEdges(edges));
                answer.links = answer.links.saturating_add(1);
            }
        }
        if config.features.palm_edges {
            self.outline
                .update(self.view.palm.as_ref(), config.features.min_link_px);
            for edge in &self.outline.edges {
                self.search.palm_edge(
                    &self.view,
                    camera,
                    frame,
                    edge,
                    &config.features,
                    refine,
                    &mut self.features,
                );
                let edges = PalmEdges::from_features(measure, edge, &self.features);
                if !edges.is_empty() {
                    send(BoardMessage::PalmEdges(edges));
                    answer.links = answer.links.saturating_add(1);
                }
            }
        }
        if config.silhouette_grid > 0 {
            let grid = usize::from(config.silhouette_grid);
            answer.silhouette =
                crate::silhouette::score(&self.view, camera, frame, grid).map(|s| s.agreement);
        }
        answer
    }
}
