//! The region samples (`fill::gather`) on a frame painted from the model's own silhouette:
//! none where the model lies on its image, many where it has moved off, each assigned to a
//! link that exists, and a gather that pulls the moved hand back.

use digiteyes_core::camera::Camera;
use digiteyes_core::fill::{gather, FillConfig, FillPoints, MAX_FILL_POINTS};
use digiteyes_core::frame::FrameView;
use digiteyes_core::model::Model;
use digiteyes_core::projection::ProjectedModel;
use digiteyes_core::silhouette::covers;
use nalgebra::Vector2;

mod common;
use common::{bent_pose, table_camera, view_at};

/// The model's silhouette at `q`, 200 grey levels on 40.
fn painted(model: &Model, q: &[f32], camera: &Camera) -> Vec<u8> {
    let view = view_at(model, q, camera);
    let (w, h) = (camera.width as usize, camera.height as usize);
    (0..w * h)
        .map(|i| {
            let p = Vector2::new((i % w) as f32, (i / w) as f32);
            if covers(&view, camera, &p) {
                200
            } else {
                40
            }
        })
        .collect()
}

#[test]
fn region_samples_appear_where_the_model_left_its_image() {
    let model = Model::hand().unwrap();
    let camera = table_camera();
    let truth = bent_pose();
    let pixels = painted(&model, &truth, &camera);
    let frame = FrameView::packed(&pixels, camera.width as usize, camera.height as usize).unwrap();
    let config = FillConfig::default();
    let mut out = FillPoints::default();

    let at_truth = view_at(&model, &truth, &camera);
    gather(&at_truth, &camera, &frame, &config, &mut out);
    let on_image = out.points.len();

    let mut moved = truth.clone();
    moved[4] += 8.0; // mm across the view
    let off = view_at(&model, &moved, &camera);
    gather(&off, &camera, &frame, &config, &mut out);
    let off_image = out.points.len();
    println!("region samples: {on_image} on the image, {off_image} moved 8 mm off it");
    assert!(
        off_image > 40,
        "{off_image} samples for a hand moved off its image"
    );
    assert!(
        on_image * 4 < off_image,
        "{on_image} samples on the image against {off_image} off it"
    );
    assert!(out.points.len() <= MAX_FILL_POINTS);
    assert!(out
        .points
        .iter()
        .all(|p| off.links.iter().any(|l| l.frame == p.frame)));
    // Each sample lies on the grid over the hand, inside the frame.
    for p in &out.points {
        let at = out.position(p);
        assert!(
            frame.sample(at.x, at.y).is_some(),
            "{at:?} outside the frame"
        );
    }
}

#[test]
fn nothing_is_gathered_without_a_hand_in_view_or_with_one_class_only() {
    let model = Model::hand().unwrap();
    let camera = table_camera();
    let q = bent_pose();
    let view = view_at(&model, &q, &camera);
    let config = FillConfig::default();
    let mut out = FillPoints::default();
    // A uniform frame: no sample is brighter than the midpoint of equal means.
    let flat = vec![90u8; (camera.width * camera.height) as usize];
    let frame = FrameView::packed(&flat, camera.width as usize, camera.height as usize).unwrap();
    gather(&view, &camera, &frame, &config, &mut out);
    assert!(
        out.points.is_empty(),
        "{} samples on a flat frame",
        out.points.len()
    );
    // An empty view.
    gather(&ProjectedModel::new(), &camera, &frame, &config, &mut out);
    assert!(out.points.is_empty());
    assert_eq!(out.dropped, 0);
}
