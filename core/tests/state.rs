//! The state layout's one home (`state`), the free mask's constructors, `Camera::ray` and a
//! projected link's normal and silhouette lines.

use digiteyes_core::estimator::FreeMask;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::Model;
use digiteyes_core::projection::ProjectedModel;
use digiteyes_core::state::{
    clamp_to_limit, renormalise_quaternion, StateKind, QUATERNION, QUATERNION_BITS, TRANSLATION,
};
use nalgebra::Vector2;

mod common;
use common::{bent_pose, table_camera};

#[test]
fn state_kinds_follow_the_layout() {
    let kinds: Vec<StateKind> = (0..9).map(StateKind::of).collect();
    assert_eq!(&kinds[..4], &[StateKind::Quaternion; 4]);
    assert_eq!(&kinds[4..7], &[StateKind::Translation; 3]);
    assert_eq!(&kinds[7..], &[StateKind::Joint; 2]);
    assert_eq!((QUATERNION, TRANSLATION), (0..4, 4..7));
    assert_eq!(QUATERNION_BITS, 0b1111);
}

#[test]
fn renormalising_scales_only_the_quaternion_and_leaves_what_it_cannot() {
    let mut q = [0.0, 0.0, 2.0, 0.0, 5.0, 6.0];
    renormalise_quaternion(&mut q);
    assert_eq!(q, [0.0, 0.0, 1.0, 0.0, 5.0, 6.0]);
    let mut zero = [0.0; 5];
    renormalise_quaternion(&mut zero);
    assert_eq!(zero, [0.0; 5]);
    let mut short = [3.0, 4.0];
    renormalise_quaternion(&mut short);
    assert_eq!(short, [3.0, 4.0]);
}

#[test]
fn clamping_uses_the_models_ranges() {
    let model = Model::hand().unwrap();
    let (state, limit) = (7..model.n_states())
        .find_map(|s| model.limit(s).map(|l| (s, l)))
        .expect("the hand has joint ranges");
    assert_eq!(clamp_to_limit(&model, state, limit.hi + 1.0), limit.hi);
    assert_eq!(clamp_to_limit(&model, state, limit.lo - 1.0), limit.lo);
    assert_eq!(
        clamp_to_limit(&model, 4, 1e6),
        1e6,
        "no range on a translation"
    );
}

#[test]
fn free_masks_from_lists_and_their_checks() {
    assert_eq!(FreeMask::from_states(&[4, 8]), Ok(FreeMask(0b1_0001_0000)));
    assert_eq!(FreeMask::from_states(&[4, 40]), Err(40));
    assert_eq!(FreeMask(1 << 2).with_whole_quaternion(), FreeMask(0b1111));
    assert_eq!(FreeMask(1 << 5).with_whole_quaternion(), FreeMask(1 << 5));
    assert_eq!(FreeMask::all(28).first_beyond(28), None);
    assert_eq!(
        FreeMask((1 << 30) | (1 << 29) | 1).first_beyond(28),
        Some(29)
    );
    assert_eq!(FreeMask(u32::MAX).first_beyond(32), None);
}

#[test]
fn a_pixels_ray_projects_back_to_it() {
    let camera = table_camera();
    for uv in [Vector2::new(10.0, 20.0), Vector2::new(600.5, 400.25)] {
        let ray = camera.ray(&uv);
        assert_eq!(ray.z, 1.0);
        // From camera coordinates at depth 300 mm back to the world, then projected.
        let p_c = ray * 300.0;
        let p_w = camera.r.transpose() * (p_c - camera.t);
        let back = camera.project(&p_w).unwrap();
        assert!((back - uv).norm() < 1e-2, "{uv} -> {back}");
    }
}

#[test]
fn silhouette_lines_lie_at_the_side_radii_along_the_normal() {
    let model = Model::hand().unwrap();
    let poses = Poses::compute(&model, &bent_pose()).unwrap();
    let mut view = ProjectedModel::new();
    view.update(&model, &poses, &table_camera(), 1.0);
    for link in &view.links {
        let normal = link.normal();
        let d = (link.b - link.a).normalize();
        assert!((normal.norm() - 1.0).abs() < 1e-5 && normal.dot(&d).abs() < 1e-5);
        assert!(
            (d.x * normal.y - d.y * normal.x - 1.0).abs() < 1e-5,
            "normal is (−d_y, d_x)"
        );
        for side in [1i8, -1] {
            let (a, b) = link.silhouette(side);
            let s = f32::from(side);
            assert!((s * normal.dot(&(a - link.a)) - link.side_radius_at(0.0, side)).abs() < 1e-4);
            assert!((s * normal.dot(&(b - link.b)) - link.side_radius_at(1.0, side)).abs() < 1e-4);
        }
    }
}
