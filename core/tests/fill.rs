//! The region samples (`fill::gather`) on a frame painted from the model's own silhouette:
//! none where the model lies on its image, many where it has moved off, each assigned to a
//! link that exists, and a gather that pulls the moved hand back; the hand's own shade, on its
//! shaded side or in a link's core, is not classed as background; and a link the model hides
//! is preferred for the hand it leaves uncovered.

use digiteyes_core::camera::Camera;
use digiteyes_core::fill::{gather, hidden_link, FillConfig, FillPoints, MAX_FILL_POINTS};
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

/// The grey level of the painted hand ...
const LIT: u8 = 200;
/// ... and of the background around it.
const BARE: u8 = 40;

/// The model's silhouette at `q`, [`LIT`] on [`BARE`].
fn painted(model: &Model, q: &[f32], camera: &Camera) -> Vec<u8> {
    covered(model, q, camera)
        .into_iter()
        .map(|c| if c { LIT } else { BARE })
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
        core_share: 0.0,
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

/// Whether pixel `i` of a frame `w` wide lies in the core of a link of `view`: within half
/// its radius of the axis.
fn in_a_core(view: &ProjectedModel, i: usize, w: usize) -> bool {
    let p = Vector2::new((i % w) as f32, (i / w) as f32);
    view.links.iter().any(|link| {
        let (s, dist) = link.closest(&p);
        dist < 0.5 * link.radius_at(s)
    })
}

/// The model's silhouette at `q`, [`LIT`] on [`BARE`], with the core of every link
/// ([`in_a_core`]) painted `core_grey`.
fn painted_with_cores(model: &Model, q: &[f32], camera: &Camera, core_grey: u8) -> Vec<u8> {
    let view = view_at(model, q, camera);
    let w = camera.width as usize;
    painted(model, q, camera)
        .into_iter()
        .enumerate()
        .map(|(i, grey)| {
            if grey == LIT && in_a_core(&view, i, w) {
                core_grey
            } else {
                grey
            }
        })
        .collect()
}

/// The grey level of the cores ([`painted_with_cores`]) that lies 0.15 of the contrast above
/// the mean the model leaves uncovered: dark by the class margin (below 0.2 of it), not by
/// the core's (below 0.1). The pixels' means stand for the gather's grid's.
fn shade_between_the_bars(model: &Model, q: &[f32], camera: &Camera) -> u8 {
    let (lit, bare) = (f32::from(LIT), f32::from(BARE));
    // The cores' share of the covered pixels moves the covered mean: solve for the grey g
    // that sits 0.15 of the contrast above the uncovered mean, with the cores painted g.
    let view = view_at(model, q, camera);
    let w = camera.width as usize;
    let covered: Vec<usize> = covered(model, q, camera)
        .iter()
        .enumerate()
        .filter_map(|(i, &c)| c.then_some(i))
        .collect();
    let core = covered.iter().filter(|&&i| in_a_core(&view, i, w)).count();
    let f = core as f32 / covered.len().max(1) as f32;
    // g = bare + 0.15 (covered − bare), covered = f g + (1 − f) lit.
    let g = (bare + 0.15 * (1.0 - f) * (lit - bare)) / (1.0 - 0.15 * f);
    g.round() as u8
}

#[test]
fn a_shade_in_a_links_core_is_the_hands_and_background_there_is_not() {
    let model = Model::hand().unwrap();
    let camera = table_camera();
    let truth = bent_pose();
    let view = view_at(&model, &truth, &camera);
    let (w, h) = (camera.width as usize, camera.height as usize);
    let dark = |pixels: &[u8], config: &FillConfig| {
        let frame = FrameView::packed(pixels, w, h).unwrap();
        let mut out = FillPoints::default();
        gather(&view, &camera, &frame, config, &mut out);
        out.points.iter().filter(|p| !p.bright).count()
    };
    let by_class_margin = FillConfig {
        core_share: 0.0,
        ..FillConfig::default()
    };
    let shade = shade_between_the_bars(&model, &truth, &camera);
    let shaded = painted_with_cores(&model, &truth, &camera, shade);
    let bare = painted_with_cores(&model, &truth, &camera, BARE);
    let (shade_before, shade_now, bare_now) = (
        dark(&shaded, &by_class_margin),
        dark(&shaded, &FillConfig::default()),
        dark(&bare, &FillConfig::default()),
    );
    println!(
        "cores painted {shade}: {shade_before} dark samples by the class margin, {shade_now} \
         with the core's; painted as the background: {bare_now}"
    );
    assert!(
        shade_before > 10,
        "{shade_before} shaded core samples classed dark"
    );
    assert_eq!(shade_now, 0, "shaded core samples classed dark");
    assert!(
        bare_now > 10,
        "{bare_now} background core samples classed dark"
    );
}

/// The model frames of the links of `view` the model hides wholly from `camera`.
fn hidden_frames(view: &ProjectedModel, camera: &Camera) -> Vec<u8> {
    (0..view.links.len())
        .filter(|&i| hidden_link(view, camera, i))
        .map(|i| view.links[i].frame)
        .collect()
}

#[test]
fn a_link_the_model_hides_is_preferred_for_the_hand_it_leaves_uncovered() {
    let model = Model::hand().unwrap();
    let camera = table_camera();
    let truth = bent_pose();
    let pixels = painted(&model, &truth, &camera);
    let frame = FrameView::packed(&pixels, camera.width as usize, camera.height as usize).unwrap();
    let (mut as_any_sum, mut preferred_sum) = (0, 0);
    for finger in 0..4 {
        // The finger held curled under the palm while the image shows it as it was.
        let mut held = truth.clone();
        for (j, c) in [1.2f32, 1.4, 1.0].iter().enumerate() {
            held[8 + 4 * finger + j] = *c;
        }
        let view = view_at(&model, &held, &camera);
        let hidden = hidden_frames(&view, &camera);
        assert!(!hidden.is_empty(), "finger {finger}: nothing hidden");
        let to_hidden = |share: f32| {
            let config = FillConfig {
                hidden_gap_share: share,
                ..FillConfig::default()
            };
            let mut out = FillPoints::default();
            gather(&view, &camera, &frame, &config, &mut out);
            out.points
                .iter()
                .filter(|p| p.bright && hidden.contains(&p.frame))
                .count()
        };
        let (never, nan, as_any, preferred) = (
            to_hidden(f32::INFINITY),
            to_hidden(f32::NAN),
            to_hidden(1.0),
            to_hidden(0.5),
        );
        println!(
            "finger {finger} curled under the palm: {} links hidden; bright samples to them: \
             {never} never, {as_any} as any link, {preferred} preferred",
            hidden.len()
        );
        assert_eq!(
            (never, nan),
            (0, 0),
            "finger {finger}: hidden links passed over"
        );
        assert!(
            preferred >= as_any,
            "finger {finger}: {preferred} samples preferred, {as_any} as any link"
        );
        as_any_sum += as_any;
        preferred_sum += preferred;
    }
    assert!(
        preferred_sum > as_any_sum,
        "{preferred_sum} samples to hidden links preferred, {as_any_sum} as any link"
    );
}
