//! `find_link_features_watched`: the same features as the tracker's `find_link_features`,
//! bit for bit, and one reported window per slice and tip search, accounted as the counters.

use digiteyes_core::camera::Camera;
use digiteyes_core::features::{
    find_link_features, find_link_features_watched, FeatureConfig, LinkFeatures, SearchWindow,
    WindowOutcome,
};
use digiteyes_core::frame::FrameView;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::Model;
use digiteyes_core::projection::ProjectedModel;
use nalgebra::Vector2;

mod common;
use common::{bent_pose as pose, table_camera as camera};

/// A crude frame of `view`: 200 inside any link's projected outline, 40 elsewhere.
fn paint(view: &ProjectedModel, camera: &Camera) -> Vec<u8> {
    let (w, h) = (camera.width as usize, camera.height as usize);
    let mut pixels = vec![40u8; w * h];
    for y in 0..h {
        for x in 0..w {
            let p = Vector2::new(x as f32, y as f32);
            if view.links.iter().any(|l| {
                let (s, d) = l.closest(&p);
                d <= l.radius_at(s)
            }) {
                pixels[y * w + x] = 200;
            }
        }
    }
    pixels
}

#[test]
fn watched_search_finds_the_same_features_and_reports_every_window() {
    let model = Model::hand().unwrap();
    let camera = camera();
    let poses = Poses::compute(&model, &pose()).unwrap();
    let mut view = ProjectedModel::new();
    view.update(&model, &poses, &camera, 6.0);
    assert!(view.links.len() >= 10, "{} links in view", view.links.len());
    let pixels = paint(&view, &camera);
    let frame = FrameView::packed(&pixels, 640, 480).unwrap();
    let config = FeatureConfig::default();
    let (mut masked, mut found_any) = (0, 0);
    for index in 0..view.links.len() {
        let mut plain = LinkFeatures::default();
        find_link_features(&view, &camera, &frame, index, &config, &mut plain);
        let mut watched = LinkFeatures::default();
        let mut windows: Vec<SearchWindow> = Vec::new();
        find_link_features_watched(&view, &camera, &frame, index, &config, &mut watched, |w| {
            windows.push(*w)
        });
        assert_eq!(plain.edges, watched.edges, "link {index}");
        assert_eq!(plain.tip, watched.tip, "link {index}");
        assert_eq!(
            (plain.expected, plain.masked, plain.off_frame),
            (watched.expected, watched.masked, watched.off_frame)
        );
        assert_eq!(plain.reach_px.to_bits(), watched.reach_px.to_bits());

        let count = |o: WindowOutcome| windows.iter().filter(|w| w.outcome == o).count();
        let link = &view.links[index];
        let tips = usize::from(config.tips && link.distal);
        assert_eq!(
            windows.len(),
            2 * usize::from(config.slices_per_link) + tips
        );
        assert_eq!(count(WindowOutcome::Masked), usize::from(plain.masked));
        assert_eq!(count(WindowOutcome::OffFrame), usize::from(plain.off_frame));
        assert_eq!(
            count(WindowOutcome::NoEdge) + count(WindowOutcome::Found),
            usize::from(plain.expected)
        );
        assert_eq!(
            count(WindowOutcome::Found),
            plain.edges.len() + usize::from(plain.tip.is_some())
        );
        for (w, e) in windows
            .iter()
            .filter(|w| !w.tip && w.outcome == WindowOutcome::Found)
            .zip(&plain.edges)
        {
            // The edge lies on its window, inside it.
            assert!((w.step.norm() - 1.0).abs() < 1e-5);
            let along = (e.position - w.start).dot(&w.step);
            let across = (e.position - w.start).perp(&w.step);
            assert!(across.abs() < 1e-3, "edge {across} px off its window");
            assert!(
                (0.0..=f32::from(w.samples - 1)).contains(&along),
                "edge {along} px along a {}-sample window",
                w.samples
            );
        }
        masked += plain.masked;
        found_any += plain.edges.len();
    }
    assert!(masked > 0, "the pose hides some slices");
    assert!(found_any > 20, "{found_any} edges found");
}
