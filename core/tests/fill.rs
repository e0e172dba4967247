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

/// Which pixels of `camera`'s frame the model covers at `q`, row by row.
fn covered(model: &Model, q: &[f32], camera: &Camera) -> Vec<bool> {
    let view = view_at(model, q, camera);
    let (w, h) = (camera.width as usize, camera.height as usize);
    (0..w * h)
        .map(|i| covers(&view, camera, &Vector2::new((i % w) as f32, (i / w) as f32)))
        .collect()
}

/// The model's silhouette at `q`, 200 grey levels on 40.
fn painted(model: &Model, q: &[f32], camera: &Camera) -> Vec<u8> {
    covered(model, q, camera)
        .into_iter()
        .map(|c| if c { 200 } else { 40 })
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

/// The model's silhouette at `q` with its left half lit (200) and its right half in shade
/// (90, darker than the midpoint between the covered and uncovered means), on 40.
fn painted_with_shade(model: &Model, q: &[f32], camera: &Camera) -> Vec<u8> {
    let w = camera.width as usize;
    let covered = covered(model, q, camera);
    let (sum, count) = covered
        .iter()
        .enumerate()
        .filter(|(_, &c)| c)
        .fold((0usize, 0usize), |(s, n), (i, _)| (s + i % w, n + 1));
    let centre = sum / count.max(1);
    covered
        .iter()
        .enumerate()
        .map(|(i, &c)| match (c, i % w < centre) {
            (false, _) => 40,
            (true, true) => 200,
            (true, false) => 90,
        })
        .collect()
}

#[test]
fn the_hands_own_shade_is_not_background() {
    let model = Model::hand().unwrap();
    let camera = table_camera();
    let truth = bent_pose();
    let pixels = painted_with_shade(&model, &truth, &camera);
    let frame = FrameView::packed(&pixels, camera.width as usize, camera.height as usize).unwrap();
    let mut out = FillPoints::default();
    let dark = |out: &FillPoints| out.points.iter().filter(|p| !p.bright).count();

    let at_truth = view_at(&model, &truth, &camera);
    let midpoint = FillConfig {
        class_margin: 0.0,
        ..FillConfig::default()
    };
    gather(&at_truth, &camera, &frame, &midpoint, &mut out);
    let shade_by_midpoint = dark(&out);
    gather(&at_truth, &camera, &frame, &FillConfig::default(), &mut out);
    let shade_by_margin = dark(&out);

    let mut moved = truth.clone();
    moved[4] += 8.0; // mm across the view
    let off = view_at(&model, &moved, &camera);
    gather(&off, &camera, &frame, &FillConfig::default(), &mut out);
    let off_image = out.points.len();
    println!(
        "dark samples at the truth: {shade_by_midpoint} by the midpoint, {shade_by_margin} with \
         the margin; {off_image} samples moved 8 mm off"
    );
    assert!(
        shade_by_midpoint > 20,
        "{shade_by_midpoint} shaded samples by the midpoint alone"
    );
    assert!(
        shade_by_margin * 10 < shade_by_midpoint,
        "{shade_by_margin} shaded samples classed dark with the margin"
    );
    assert!(off_image > 40, "{off_image} samples moved off the image");
}

#[test]
fn a_foreshortened_links_rows_are_weighed_down_by_length_over_width() {
    let model = Model::hand().unwrap();
    let camera = table_camera();
    let view = view_at(&model, &bent_pose(), &camera);
    let config = FillConfig::default();
    let mut link = view.links[0];
    let width = link.mean_width_px();
    assert!(width > 0.0);
    let (direction, _) = link.axis_frame();
    for (length_widths, expected) in [(3.0f32, 1.0f32), (1.0, 1.0), (0.5, 0.5), (0.0, 0.0)] {
        link.b = link.a + direction * (length_widths * width);
        let weight = config.link_weight(&link);
        assert!(
            (weight - config.weight * expected).abs() < 1e-4,
            "a link {length_widths} widths long weighs {weight}"
        );
    }
    let every_link = FillConfig {
        full_length_widths: 0.0,
        ..config
    };
    assert_eq!(every_link.link_weight(&link), config.weight);
}
