//! Where a finger's outline ends at a knuckle (`ProjectedLink::knuckle_ends`): a straight
//! finger's outline runs on to its tip; a finger whose middle link points along the camera's
//! ray, or turns back over its proximal link, ends at the knuckle; and the slice search then
//! looks beyond that knuckle for the outline's end, as for a fingertip.

use digiteyes_core::camera::Camera;
use digiteyes_core::features::FeatureConfig;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::Model;
use digiteyes_core::projection::{ProjectedLink, ProjectedModel};
use nalgebra::Vector3;

mod common;
use common::looking_along;

/// Finger 2's joint states: abduction, MCP, PIP, DIP.
const FINGER_2: [usize; 4] = [11, 12, 13, 14];

fn straight_hand() -> Vec<f32> {
    let mut q = vec![0.0f32; 28];
    q[0] = 1.0;
    q
}

/// Finger 2's PIP and DIP points at `q`.
fn pip_and_dip(model: &Model, q: &[f32]) -> (Vector3<f32>, Vector3<f32>) {
    let poses = Poses::compute(model, q).unwrap();
    let pip = poses
        .origin(model.joint_frame(FINGER_2[2]).unwrap())
        .unwrap();
    let dip = poses
        .origin(model.joint_frame(FINGER_2[3]).unwrap())
        .unwrap();
    (pip, dip)
}

/// A camera 500 mm behind finger 2's PIP, looking along its middle link at `q`; and at an
/// angle `off` (rad) from that line, in the plane of the finger's bend.
fn along_middle_link(model: &Model, q: &[f32], off: f32) -> Camera {
    let (pip, dip) = pip_and_dip(model, q);
    let middle = (dip - pip).normalize();
    let poses = Poses::compute(model, q).unwrap();
    let mcp = poses
        .origin(model.joint_frame(FINGER_2[1]).unwrap())
        .unwrap();
    let proximal = (pip - mcp).normalize();
    let forward = (middle * off.cos() + proximal * off.sin()).normalize();
    looking_along(pip - forward * 500.0, forward)
}

fn view_of(model: &Model, q: &[f32], camera: &Camera) -> ProjectedModel {
    let poses = Poses::compute(model, q).unwrap();
    let mut view = ProjectedModel::new();
    view.update(model, &poses, camera, FeatureConfig::default().min_link_px);
    view
}

/// The link of `view` whose axis ends at finger 2's PIP.
fn proximal_of_finger_2<'a>(model: &Model, view: &'a ProjectedModel) -> &'a ProjectedLink {
    let pip_frame = model.joint_frame(FINGER_2[2]).unwrap();
    view.links
        .iter()
        .find(|l| usize::from(l.child) == pip_frame)
        .expect("finger 2's proximal link is in view")
}

#[test]
fn a_straight_hand_seen_from_above_ends_only_at_its_tips() {
    let model = Model::hand().unwrap();
    let q = straight_hand();
    let poses = Poses::compute(&model, &q).unwrap();
    let (pip, _) = pip_and_dip(&model, &q);
    for (eye, label) in [
        (pip + Vector3::new(0.0, -100.0, 600.0), "from above"),
        (pip + Vector3::new(300.0, -200.0, 300.0), "from the side"),
    ] {
        let camera = looking_along(eye, (pip - eye).normalize());
        let mut view = ProjectedModel::new();
        view.update(&model, &poses, &camera, 6.0);
        assert!(view.links.len() >= 15, "{label}: the hand is in view");
        for link in &view.links {
            assert!(
                !link.knuckle_ends,
                "{label}: link {} of a straight hand ends at its knuckle",
                link.frame
            );
        }
        assert_eq!(view.links.iter().filter(|l| l.distal).count(), 5, "{label}");
    }
}

#[test]
fn a_middle_link_along_the_ray_ends_the_outline_at_the_knuckle() {
    let model = Model::hand().unwrap();
    let mut q = straight_hand();
    q[FINGER_2[1]] = 0.3;
    q[FINGER_2[2]] = 1.5;
    let camera = along_middle_link(&model, &q, 0.0);
    let view = view_of(&model, &q, &camera);
    let proximal = proximal_of_finger_2(&model, &view);
    assert!(proximal.knuckle_ends);
    // The middle link itself is shorter than `min_link_px` here: skipped as end-on.
    let middle_frame = model.joint_frame(FINGER_2[2]).unwrap();
    assert!(view
        .links
        .iter()
        .all(|l| usize::from(l.frame) != middle_frame));
    assert!(view.skipped.end_on >= 1);
    // The search looks beyond the knuckle only when asked to.
    let mut config = FeatureConfig::default();
    config.knuckle_tips = true;
    assert!(config.searches_tip(proximal));
    config.knuckle_tips = false;
    assert!(!config.searches_tip(proximal));
}

#[test]
fn a_middle_link_turned_back_ends_the_outline_at_the_knuckle_and_one_turned_on_does_not() {
    let model = Model::hand().unwrap();
    let mut q = straight_hand();
    q[FINGER_2[1]] = 0.3;
    q[FINGER_2[2]] = 1.5;
    // Seen 0.5 rad off the middle link's line, toward the proximal link: the middle link
    // turns back over the proximal one in the image.
    let back = along_middle_link(&model, &q, 0.5);
    let view = view_of(&model, &q, &back);
    assert!(proximal_of_finger_2(&model, &view).knuckle_ends);
    // Seen 0.5 rad off the other way, the middle link runs on beyond the knuckle.
    let on = along_middle_link(&model, &q, -0.5);
    let view = view_of(&model, &q, &on);
    assert!(!proximal_of_finger_2(&model, &view).knuckle_ends);
}

#[test]
fn a_fingertips_link_is_never_a_knuckle_end() {
    let model = Model::hand().unwrap();
    let mut q = straight_hand();
    q[FINGER_2[1]] = 0.3;
    q[FINGER_2[2]] = 1.5;
    q[FINGER_2[3]] = 1.2;
    for off in [-0.5, 0.0, 0.5] {
        let view = view_of(&model, &q, &along_middle_link(&model, &q, off));
        assert!(view.links.iter().all(|l| !(l.distal && l.knuckle_ends)));
    }
}
