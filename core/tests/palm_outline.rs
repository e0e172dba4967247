//! The palm box's image outline (issue 9): its hull from several directions, the palm edge
//! rows against finite differences for all 7 palm states and against the oracle's path, the
//! slice search on a drawn palm, and the mask (a finger in front of a palm edge, a finger
//! beyond the knuckle face).

use digiteyes_core::camera::Camera;
use digiteyes_core::estimator::reference::{edge_residual, edge_row, Row};
use digiteyes_core::estimator::{
    add_palm_edge_rows, add_reference_palm_edge_rows, EstimatorConfig, FreeMask, LinkJacobian,
    NormalEquations,
};
use digiteyes_core::features::{find_palm_edge_features, EdgePoint, FeatureConfig, LinkFeatures};
use digiteyes_core::frame::FrameView;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::Model;
use digiteyes_core::palm_outline::{convex_hull, HullEdge, PalmOutline};
use digiteyes_core::projection::{ProjectedLink, ProjectedModel};
use nalgebra::{Rotation3, Vector2, Vector3};

mod common;
use common::{bent_pose, table_camera, view_at};

fn outline_of(view: &ProjectedModel) -> PalmOutline {
    let mut outline = PalmOutline::new();
    outline.update(view.palm.as_ref(), 1.0);
    outline
}

/// A camera at `eye` (mm) looking at `target`, 640×480, f = 800 px.
fn looking_at(eye: Vector3<f32>, target: Vector3<f32>) -> Camera {
    common::looking_along(eye, target - eye)
}

/// The palm alone at the origin, rotated by `rotation`, every joint 0.
fn palm_pose(rotation: Rotation3<f32>) -> Vec<f32> {
    let q = nalgebra::UnitQuaternion::from_rotation_matrix(&rotation);
    let mut state = vec![0.0f32; 28];
    state[..4].copy_from_slice(&[q.w, q.i, q.j, q.k]);
    state
}

fn cross(u: Vector2<f32>, v: Vector2<f32>) -> f32 {
    u.x * v.y - u.y * v.x
}

/// The outline's invariants: edges chain corner to corner in one turning direction, each
/// edge's outward side has no corner beyond it, and every corner lies on or inside the hull.
fn check_outline(view: &ProjectedModel, outline: &PalmOutline, what: &str) {
    let palm = view.palm.as_ref().expect("palm in view");
    let n = outline.edges.len();
    for (i, e) in outline.edges.iter().enumerate() {
        let next = &outline.edges[(i + 1) % n];
        assert_eq!(e.corners[1], next.corners[0], "{what}: edges chain");
        let turn = cross(e.segment.b - e.segment.a, next.segment.b - next.segment.a);
        assert!(turn > 0.0, "{what}: edge {i} turns the wrong way ({turn})");
        let out = e.outward_normal();
        for (k, c) in palm.corners_px.iter().enumerate() {
            let beyond = out.dot(&(c - e.segment.a));
            assert!(
                beyond < 1e-2,
                "{what}: corner {k} lies {beyond} px outside edge {:?}",
                e.corners
            );
        }
        assert_eq!(e.segment.r0, [0.0; 2]);
        assert_eq!(e.segment.radius_mm, 0.0);
    }
}

#[test]
fn a_box_seen_face_on_has_4_outline_edges_and_seen_obliquely_6() {
    let model = Model::hand().unwrap();
    // Straight down the palm's normal (its z axis, the 15 mm side): the near face hides the far.
    let above = looking_at(Vector3::new(0.0, 0.0, 400.0), Vector3::zeros());
    let view = view_at(&model, &palm_pose(Rotation3::identity()), &above);
    let outline = outline_of(&view);
    assert_eq!(outline.edges.len(), 4, "face-on: {:?}", outline.edges);
    check_outline(&view, &outline, "face-on");
    // From a corner's direction: three faces in view, six outline edges.
    for (eye, what) in [
        (Vector3::new(300.0, 250.0, 350.0), "oblique 1"),
        (Vector3::new(-260.0, 310.0, -300.0), "oblique 2"),
        (Vector3::new(220.0, -340.0, 280.0), "oblique 3"),
    ] {
        let camera = looking_at(eye, Vector3::zeros());
        let view = view_at(&model, &palm_pose(Rotation3::identity()), &camera);
        let outline = outline_of(&view);
        assert_eq!(outline.edges.len(), 6, "{what}: {:?}", outline.edges);
        check_outline(&view, &outline, what);
    }
    // Along one face's plane (side-on to two faces): 4 edges again.
    let side = looking_at(Vector3::new(0.0, -400.0, 0.0), Vector3::zeros());
    let view = view_at(&model, &palm_pose(Rotation3::identity()), &side);
    let outline = outline_of(&view);
    assert_eq!(outline.edges.len(), 4, "side-on: {:?}", outline.edges);
    check_outline(&view, &outline, "side-on");
}

#[test]
fn a_palm_with_a_corner_behind_the_camera_has_no_outline() {
    let model = Model::hand().unwrap();
    // The camera's centre lies inside the box's slab, a corner behind it.
    let inside = looking_at(Vector3::new(0.0, 0.0, 1.0), Vector3::new(0.0, 100.0, 1.0));
    let view = view_at(&model, &palm_pose(Rotation3::identity()), &inside);
    assert!(view.palm.is_none());
    let outline = outline_of(&view);
    assert!(outline.edges.is_empty());
}

#[test]
fn the_hull_leaves_out_inner_collinear_and_repeated_points() {
    let p = |x: f32, y: f32| Vector2::new(x, y);
    let points = [
        p(0.0, 0.0),
        p(10.0, 0.0),
        p(10.0, 10.0),
        p(0.0, 10.0),
        p(5.0, 5.0),   // inside
        p(5.0, 0.0),   // on an edge
        p(10.0, 10.0), // a repeat
        p(f32::NAN, 3.0),
    ];
    let mut hull = [0u8; 8];
    let n = convex_hull(&points, &mut hull);
    assert_eq!(n, 4, "{:?}", &hull[..n]);
    let mut seen: Vec<u8> = hull[..n].to_vec();
    seen.sort();
    assert!(seen == [0, 1, 2, 3] || seen == [0, 1, 3, 6], "{seen:?}");
    // All collinear: no hull.
    let line = [0.0f32, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0].map(|t| p(t, 2.0 * t));
    assert_eq!(convex_hull(&line, &mut hull), 0);
}

/// Central differences of `residual(view)` for state `j`.
fn numeric(
    model: &Model,
    q: &[f32],
    camera: &Camera,
    j: usize,
    residual: &dyn Fn(&ProjectedModel) -> f32,
) -> f32 {
    let h = if (4..7).contains(&j) { 1e-2 } else { 1e-3 };
    let (mut plus, mut minus) = (q.to_vec(), q.to_vec());
    plus[j] += h;
    minus[j] -= h;
    (residual(&view_at(model, &plus, camera)) - residual(&view_at(model, &minus, camera)))
        / (2.0 * h)
}

#[test]
fn palm_edge_rows_match_finite_differences_for_all_7_palm_states() {
    let model = Model::hand().unwrap();
    let mut cases = 0;
    for (camera, q) in [
        (table_camera(), bent_pose()),
        (
            looking_at(Vector3::new(300.0, 250.0, 350.0), Vector3::zeros()),
            palm_pose(Rotation3::from_euler_angles(0.2, -0.3, 0.4)),
        ),
    ] {
        let poses = Poses::compute(&model, &q).unwrap();
        let view = view_at(&model, &q, &camera);
        let outline = outline_of(&view);
        assert!(outline.edges.len() >= 4);
        let mut jac = LinkJacobian::default();
        let mut row = Row::new();
        for edge in &outline.edges {
            jac.compute(&model, &poses, &camera, &edge.segment);
            let states: Vec<u8> = jac.states.iter().copied().collect();
            assert_eq!(states, (0..7).collect::<Vec<u8>>(), "the palm's 7 states");
            for (s, shift) in [(0.3f32, 1.5f32), (0.7, -2.0)] {
                let seg = &edge.segment;
                let found = EdgePoint {
                    s,
                    side: edge.outward,
                    position: seg.a + (seg.b - seg.a) * s + edge.outward_normal() * shift,
                    strength: 50.0,
                };
                let r = edge_row(seg, &jac, &found, &mut row);
                assert!((r + shift).abs() < 1e-3, "predicted − measured: {r}");
                let corners = edge.corners;
                let residual = |v: &ProjectedModel| {
                    let o = outline_of(v);
                    edge_residual(&o.find(corners).expect("same edge").segment, &found)
                };
                let scale = row.iter().fold(0.0f32, |m, (_, v)| m.max(v.abs()));
                for j in 0..28 {
                    let analytic = row
                        .iter()
                        .find(|(k, _)| usize::from(*k) == j)
                        .map_or(0.0, |(_, v)| *v);
                    let fd = numeric(&model, &q, &camera, j, &residual);
                    let tol = 0.005 * scale + 0.02;
                    assert!(
                        (analytic - fd).abs() <= tol,
                        "edge {corners:?} s {s}: q{j} analytic {analytic} vs finite \
                         difference {fd} (tol {tol})"
                    );
                }
                cases += 1;
            }
        }
    }
    assert!(cases >= 20, "{cases} rows checked");
}

#[test]
fn the_trackers_palm_rows_equal_the_oracles() {
    let model = Model::hand().unwrap();
    let camera = table_camera();
    let q = bent_pose();
    let poses = Poses::compute(&model, &q).unwrap();
    let view = view_at(&model, &q, &camera);
    let outline = outline_of(&view);
    let config = EstimatorConfig::default();
    let free = FreeMask::all(28);
    let (mut fast, mut plain) = (NormalEquations::new(), NormalEquations::new());
    let mut jac = LinkJacobian::default();
    for (i, edge) in outline.edges.iter().enumerate() {
        jac.compute(&model, &poses, &camera, &edge.segment);
        let mut features = LinkFeatures::default();
        for (k, s) in [0.15f32, 0.5, 0.85].into_iter().enumerate() {
            let seg = &edge.segment;
            let shift = 0.7 * (i as f32 - 2.0) + 0.9 * k as f32;
            let _ = features.edges.push(EdgePoint {
                s,
                side: edge.outward,
                position: seg.a + (seg.b - seg.a) * s + edge.outward_normal() * shift,
                strength: 30.0,
            });
        }
        let a = add_palm_edge_rows(&mut fast, edge, &features, &jac, &config, free);
        let b = add_reference_palm_edge_rows(&mut plain, edge, &features, &jac, &config, free);
        assert_eq!(a, b);
        assert_eq!(a.edges, 3);
    }
    assert_eq!(fast.rows(), plain.rows());
    assert!((fast.rms() - plain.rms()).abs() <= 1e-5 * plain.rms());
    let mut largest = 0.0f32;
    for i in 0..7 {
        for j in 0..7 {
            largest = largest.max(plain.element(i, j).abs());
        }
    }
    for i in 0..7 {
        for j in 0..7 {
            let (x, y) = (fast.element(i, j), plain.element(i, j));
            assert!(
                (x - y).abs() <= 1e-5 * largest,
                "JᵀWJ[{i}][{j}]: {x} vs {y}"
            );
        }
    }
    assert!(largest > 0.0);
}

/// A frame with the palm's outline filled at 200 on 30, nothing else drawn.
fn drawn_palm(view: &ProjectedModel, outline: &PalmOutline, camera: &Camera) -> Vec<u8> {
    let (w, h) = (camera.width as usize, camera.height as usize);
    let mut image = vec![30u8; w * h];
    for y in 0..h {
        for x in 0..w {
            let p = Vector2::new(x as f32, y as f32);
            let inside = outline
                .edges
                .iter()
                .all(|e| e.outward_normal().dot(&(p - e.segment.a)) <= 0.0);
            if inside {
                image[y * w + x] = 200;
            }
        }
    }
    assert!(view.palm.is_some());
    image
}

#[test]
fn slices_find_a_drawn_palm_outline_where_predicted() {
    let model = Model::hand().unwrap();
    let camera = looking_at(Vector3::new(300.0, 250.0, 350.0), Vector3::zeros());
    let q = palm_pose(Rotation3::from_euler_angles(0.2, -0.3, 0.4));
    let view = view_at(&model, &q, &camera);
    let outline = outline_of(&view);
    let image = drawn_palm(&view, &outline, &camera);
    let frame = FrameView::new(&image, 640, 480, 640).unwrap();
    // Only the palm: no link may mask it.
    let mut palm_only = view.clone();
    palm_only.links.clear();
    let config = FeatureConfig::default();
    let mut out = LinkFeatures::default();
    let mut found = 0;
    for edge in &outline.edges {
        find_palm_edge_features(&palm_only, &camera, &frame, edge, &config, &mut out);
        assert_eq!(out.masked, 0);
        assert_eq!(usize::from(out.expected), 5);
        assert_eq!(out.edges.len(), 5, "edge {:?}", edge.corners);
        for e in &out.edges {
            assert_eq!(e.side, edge.outward);
            let r = edge_residual(&edge.segment, e);
            assert!(r.abs() < 1.0, "found {r} px from the predicted edge");
            found += 1;
        }
    }
    assert_eq!(found, 5 * outline.edges.len());
}

/// A capsule link in the image from `a` to `b`, radius `r` px, at camera depth `z` (mm).
fn fake_link(frame: u8, a: Vector2<f32>, b: Vector2<f32>, r: f32, z: f32) -> ProjectedLink {
    ProjectedLink {
        frame,
        child: frame + 1,
        distal: false,
        knuckle_ends: false,
        radius_mm: 10.0,
        p0: Vector3::zeros(),
        p1: Vector3::zeros(),
        a,
        b,
        z0: z,
        z1: z,
        r0: [r; 2],
        r1: [r; 2],
        tip_offset: r,
        bounds: digiteyes_core::projection::Bounds {
            min: a.inf(&b) - Vector2::new(r, r),
            max: a.sup(&b) + Vector2::new(r, r),
        },
    }
}

fn masked_on(view: &ProjectedModel, camera: &Camera, frame: &FrameView<'_>, e: &HullEdge) -> u16 {
    let mut out = LinkFeatures::default();
    find_palm_edge_features(view, camera, frame, e, &FeatureConfig::default(), &mut out);
    assert_eq!(out.masked + out.expected, 5);
    out.masked
}

#[test]
fn palm_slices_are_masked_under_a_nearer_finger_and_beside_any_finger() {
    let model = Model::hand().unwrap();
    let camera = looking_at(Vector3::new(0.0, 0.0, 400.0), Vector3::zeros());
    let q = palm_pose(Rotation3::identity());
    let view = view_at(&model, &q, &camera);
    let outline = outline_of(&view);
    let image = drawn_palm(&view, &outline, &camera);
    let frame = FrameView::new(&image, 640, 480, 640).unwrap();
    let mut base = view.clone();
    base.links.clear();
    let edge = outline
        .edges
        .iter()
        .max_by(|a, b| a.segment.length().total_cmp(&b.segment.length()))
        .unwrap();
    assert_eq!(masked_on(&base, &camera, &frame, edge), 0, "nothing near");
    let seg = &edge.segment;
    let out = edge.outward_normal();
    let along = (seg.b - seg.a).normalize();
    let at = |s: f32| seg.a + (seg.b - seg.a) * s;
    let palm_z = seg.z0.min(seg.z1);
    // A finger lying across the edge at its middle slice, nearer than the palm: hidden.
    let mut across = base.clone();
    let _ = across.links.push(fake_link(
        4,
        at(0.5) - out * 20.0,
        at(0.5) + out * 20.0,
        6.0,
        palm_z - 30.0,
    ));
    assert_eq!(
        masked_on(&across, &camera, &frame, edge),
        1,
        "one slice hidden"
    );
    // The same finger farther than the palm: the edge is seen, but its outside is finger.
    let mut under = base.clone();
    let _ = under.links.push(fake_link(
        4,
        at(0.5) - out * 20.0,
        at(0.5) + out * 20.0,
        6.0,
        palm_z + 30.0,
    ));
    assert_eq!(
        masked_on(&under, &camera, &frame, edge),
        1,
        "finger far beyond"
    );
    // Fingers beyond the edge along its whole length, just outside (the knuckle face): every
    // slice's outside is finger.
    let mut knuckles = base.clone();
    let _ = knuckles.links.push(fake_link(
        4,
        seg.a + out * 8.0 - along * 10.0,
        seg.b + out * 8.0 + along * 10.0,
        7.0,
        palm_z,
    ));
    assert_eq!(
        masked_on(&knuckles, &camera, &frame, edge),
        5,
        "knuckle face"
    );
    // Fingers well clear of the edge: nothing masked.
    let mut clear = base.clone();
    let _ = clear.links.push(fake_link(
        4,
        seg.a + out * 25.0,
        seg.b + out * 25.0,
        7.0,
        palm_z,
    ));
    assert_eq!(masked_on(&clear, &camera, &frame, edge), 0, "fingers clear");
}

#[test]
fn the_real_hands_knuckle_face_is_masked() {
    // Palm down under the table camera, fingers straight: the palm's edge at the knuckles
    // has fingers just outside it along most of its length.
    let model = Model::hand().unwrap();
    let camera = table_camera();
    let mut q = bent_pose();
    for v in q.iter_mut().skip(7) {
        *v = 0.0;
    }
    let view = view_at(&model, &q, &camera);
    let outline = outline_of(&view);
    let image = vec![30u8; 640 * 480];
    let frame = FrameView::new(&image, 640, 480, 640).unwrap();
    let masked: Vec<u16> = outline
        .edges
        .iter()
        .map(|e| masked_on(&view, &camera, &frame, e))
        .collect();
    assert!(
        masked.iter().any(|&m| m >= 3),
        "some edge (the knuckle face) mostly masked: {masked:?}"
    );
    assert!(
        masked.iter().filter(|&&m| m == 0).count() >= 2,
        "the palm's free sides searched: {masked:?}"
    );
}
