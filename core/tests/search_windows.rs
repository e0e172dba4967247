//! `find_link_features_watched`: the same features as the tracker's `find_link_features`,
//! bit for bit, and one reported window per slice and tip search, accounted as the counters;
//! `find_link_features_refusing`: windows the edge-direction test refused earlier in a frame
//! stay refused.

use digiteyes_core::camera::Camera;
use digiteyes_core::features::{
    find_link_features, find_link_features_refusing, find_link_features_watched, FeatureConfig,
    LinkFeatures, RefusedWindows, SearchWindow, WindowOutcome,
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
        let tips = usize::from(config.searches_tip(link));
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

/// Edges and tips found.
fn found(f: &LinkFeatures) -> usize {
    f.edges.len() + usize::from(f.tip.is_some())
}

/// A crude frame of the bent pose, and the projection of a prediction off by `offset_rad` in
/// every joint (so many predicted edges cross the painted ones at an angle).
fn off_prediction(offset_rad: f32) -> (Camera, Vec<u8>, ProjectedModel) {
    let model = Model::hand().unwrap();
    let camera = camera();
    let truth = pose();
    let mut view = ProjectedModel::new();
    view.update(
        &model,
        &Poses::compute(&model, &truth).unwrap(),
        &camera,
        6.0,
    );
    let pixels = paint(&view, &camera);
    let predicted: Vec<f32> = truth
        .iter()
        .enumerate()
        .map(|(i, q)| if i >= 7 { q + offset_rad } else { *q })
        .collect();
    view.update(
        &model,
        &Poses::compute(&model, &predicted).unwrap(),
        &camera,
        6.0,
    );
    (camera, pixels, view)
}

/// The slice search with the edge-direction test at 30° and off.
fn on_and_off() -> (FeatureConfig, FeatureConfig) {
    let mut on = FeatureConfig::default();
    on.max_edge_angle_rad = 30f32.to_radians();
    let mut off = on;
    off.max_edge_angle_rad = core::f32::consts::FRAC_PI_2;
    (on, off)
}

#[test]
fn windows_refused_earlier_in_the_frame_stay_refused() {
    // Every joint 0.25 rad off: 7 windows refused under the 16 px slice window (9 under a
    // 20 px one). At 0.3 rad, this test's offset until the window narrowed, the 16 px window
    // reaches fewer crossed edges (5 refused).
    let (camera, pixels, view) = off_prediction(0.25);
    let frame = FrameView::packed(&pixels, 640, 480).unwrap();
    let (on, off) = on_and_off();
    let mut everything = RefusedWindows::NONE;
    for bit in 0..=RefusedWindows::TIP {
        everything.insert(bit);
    }
    let mut refused_anywhere = 0;
    for index in 0..view.links.len() {
        let search = |config: &FeatureConfig, refused: &mut RefusedWindows| {
            let mut out = LinkFeatures::default();
            find_link_features_refusing(&view, &camera, &frame, index, config, refused, &mut out);
            out
        };
        let plain = |config: &FeatureConfig| {
            let mut out = LinkFeatures::default();
            find_link_features(&view, &camera, &frame, index, config, &mut out);
            out
        };
        // A fresh frame judges every edge as the one-off search does, and records exactly
        // the windows whose edge it refused.
        let mut refused = RefusedWindows::NONE;
        let first = search(&on, &mut refused);
        assert_eq!(first.edges, plain(&on).edges, "link {index}");
        assert_eq!(first.tip, plain(&on).tip, "link {index}");
        let without_test = plain(&off);
        assert_eq!(
            refused.count() as usize,
            found(&without_test) - found(&first),
            "link {index}"
        );
        refused_anywhere += refused.count();
        // Searched again in the same frame, the same windows stay refused.
        let mut again = refused;
        assert_eq!(search(&on, &mut again).edges, first.edges);
        assert_eq!(again, refused);
        // Windows refused earlier are not looked at again, but still count as expected.
        let none = search(&on, &mut everything.clone());
        assert_eq!(found(&none), 0, "link {index}");
        assert_eq!(none.expected, without_test.expected);
        // With the test off, nothing is refused.
        let mut unrefused = RefusedWindows::NONE;
        search(&off, &mut unrefused);
        assert_eq!(unrefused, RefusedWindows::NONE, "link {index}");
    }
    println!("{refused_anywhere} windows refused");
    assert!(refused_anywhere > 5, "{refused_anywhere} windows refused");
}
