//! What a frame shows of each link at a given state: measured axis lines and fingertips.
//!
//! The features a board sends in `protocol::Features` — one slice search over every link at
//! the tracked state, with no estimation — so that a host with several boards (one per
//! camera, as the IC40 set-up used) can fuse them.

use heapless::Vec;

use crate::camera::Camera;
use crate::config::MAX_LINKS;
use crate::features::fit_axis_line;
use crate::features::{find_link_features, FeatureConfig, LinkFeatures};
use crate::frame::FrameView;
use crate::kinematics::Poses;
use crate::model::Model;
use crate::nalgebra::Vector2;
use crate::projection::ProjectedModel;
use crate::protocol::{AxisLine, LinkMeasurement};

/// Measures every link of `model` in view of `camera` at state `q` on `frame`: the axis line
/// fitted through its edges (when two or more were found) and its fingertip (when found).
/// Links with neither are left out; an unusable state measures nothing.
pub fn measure_links(
    model: &Model,
    camera: &Camera,
    q: &[f32],
    frame: &FrameView<'_>,
    config: &FeatureConfig,
) -> Vec<LinkMeasurement, MAX_LINKS> {
    let mut out = Vec::new();
    let Ok(poses) = Poses::compute(model, q) else {
        return out;
    };
    let mut view = ProjectedModel::new();
    view.update(model, &poses, camera, config.min_link_px);
    let mut features = LinkFeatures::default();
    for (index, link) in view.links.iter().enumerate() {
        find_link_features(&view, camera, frame, index, config, &mut features);
        let axis = (features.edges.len() >= 2)
            .then(|| fit_axis_line(link, &features))
            .flatten()
            .map(|(point, normal)| {
                let along = Vector2::new(normal.y, -normal.x);
                let direction = if along.dot(&(link.b - link.a)) < 0.0 {
                    -along
                } else {
                    along
                };
                AxisLine {
                    point: [point.x, point.y],
                    direction: [direction.x, direction.y],
                }
            });
        let tip = features.tip.map(|t| [t.x, t.y]);
        if axis.is_some() || tip.is_some() {
            // At most one entry per model frame: the Vec cannot overflow.
            let _ = out.push(LinkMeasurement {
                link: link.frame,
                axis,
                tip,
            });
        }
    }
    out
}
