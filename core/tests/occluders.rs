//! Slices near an occluder (issue 9): `visibility::hidden_within`, the slice search's
//! `FeatureConfig::occluder_margin_px`, and `FeatureConfig::over_hand_any_edge`.

use digiteyes_core::camera::Camera;
use digiteyes_core::features::{find_link_features, FeatureConfig, LinkFeatures};
use digiteyes_core::frame::FrameView;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::Model;
use digiteyes_core::projection::{Bounds, ProjectedModel};
use digiteyes_core::visibility::{candidates, cover_among, hidden_within, Cover};
use nalgebra::Vector2;

mod common;
use common::{bent_pose, table_camera};

/// The bent pose as the table camera sees it, and a pose with every finger curled under the
/// palm (so the palm box hides parts of them).
fn views() -> Vec<(Camera, ProjectedModel)> {
    let model = Model::hand().unwrap();
    let camera = table_camera();
    let mut curled = bent_pose();
    for (i, q) in curled.iter_mut().enumerate().skip(7) {
        *q = if i % 4 == 0 { 0.1 } else { 1.2 };
    }
    [bent_pose(), curled]
        .iter()
        .map(|q| {
            let mut view = ProjectedModel::new();
            view.update(&model, &Poses::compute(&model, q).unwrap(), &camera, 6.0);
            (camera, view)
        })
        .collect()
}

/// Every (link, point, depth) asked about: a 4 px grid over each link's bounds grown by 8 px,
/// at the link's own depth where the point is closest to its axis.
fn queries(view: &ProjectedModel) -> Vec<(usize, Vector2<f32>, f32)> {
    let mut out = Vec::new();
    for (index, link) in view.links.iter().enumerate() {
        let (lo, hi) = (
            link.bounds.min.map(|v| v - 8.0),
            link.bounds.max.map(|v| v + 8.0),
        );
        let mut y = lo.y;
        while y <= hi.y {
            let mut x = lo.x;
            while x <= hi.x {
                let p = Vector2::new(x, y);
                let (s, _) = link.closest(&p);
                out.push((index, p, link.depth_at(s)));
                x += 4.0;
            }
            y += 4.0;
        }
    }
    out
}

/// The parts that can cover any point within `margin` of `p` for `link`.
fn around(view: &ProjectedModel, link: usize, p: &Vector2<f32>, margin: f32) -> (Vec<u8>, bool) {
    let reach = Vector2::new(margin, margin);
    let (among, palm) = candidates(
        view,
        link,
        &Bounds {
            min: p - reach,
            max: p + reach,
        },
    );
    (among.to_vec(), palm)
}

#[test]
fn with_no_margin_a_point_is_hidden_within_it_exactly_when_it_is_hidden() {
    let (mut hidden, mut asked) = (0, 0);
    for (camera, view) in views() {
        for (link, p, depth) in queries(&view) {
            let (among, palm) = around(&view, link, &p, 0.0);
            let is_hidden = cover_among(&view, &camera, &among, palm, &p, depth) == Cover::Hidden;
            let within = hidden_within(&view, &camera, &among, palm, &p, depth, 0.0);
            assert_eq!(within, is_hidden, "link {link} at {p:?}");
            hidden += usize::from(is_hidden);
            asked += 1;
        }
    }
    println!("{hidden} of {asked} hidden");
    assert!(
        hidden > 50 && hidden < asked / 2,
        "{hidden} of {asked} hidden"
    );
}

#[test]
fn a_margin_holds_every_point_at_its_distance_that_is_hidden_and_grows_with_it() {
    let margins = [0.0f32, 0.5, 1.0, 2.0, 4.0];
    let mut grown = [0usize; 5];
    for (camera, view) in views() {
        for (link, p, depth) in queries(&view) {
            let (among, palm) = around(&view, link, &p, 4.0);
            let within: Vec<bool> = margins
                .iter()
                .map(|&m| hidden_within(&view, &camera, &among, palm, &p, depth, m))
                .collect();
            for (k, pair) in within.windows(2).enumerate() {
                assert!(
                    !pair[0] || pair[1],
                    "link {link} at {p:?}: margin {}",
                    k + 1
                );
            }
            for (k, &m) in margins.iter().enumerate() {
                grown[k] += usize::from(within[k]);
                for (dx, dy) in [(m, 0.0), (-m, 0.0), (0.0, m), (0.0, -m)] {
                    let q = p + Vector2::new(dx, dy);
                    // The palm hides a point of the cross, or a link nearer along its whole
                    // axis covers one: either lies within the margin.
                    let by_palm =
                        cover_among(&view, &camera, &[], palm, &q, depth) == Cover::Hidden;
                    let by_link = among.iter().any(|&j| {
                        let other = &view.links[usize::from(j)];
                        let (s, d) = other.closest(&q);
                        let farthest = other.depth_at(0.0).max(other.depth_at(1.0));
                        d < other.radius_at(s) && farthest < depth
                    });
                    assert!(
                        !(by_palm || by_link) || within[k],
                        "link {link} at {p:?}, margin {m}"
                    );
                }
            }
        }
    }
    println!("hidden within 0 / 0.5 / 1 / 2 / 4 px: {grown:?}");
    assert!(
        grown[4] > grown[0] + 20,
        "hidden within 0 / 4 px: {grown:?}"
    );
}

/// A crude frame of `view`: each link painted its own grey (110 to 230 by index, the later
/// over the earlier), 40 elsewhere; where two links meet the grey steps once, with no valley.
fn paint_stepped(view: &ProjectedModel, camera: &Camera) -> Vec<u8> {
    let (w, h) = (camera.width as usize, camera.height as usize);
    let mut pixels = vec![40u8; w * h];
    for y in 0..h {
        for x in 0..w {
            let p = Vector2::new(x as f32, y as f32);
            if let Some(i) = view.links.iter().rposition(|l| {
                let (s, d) = l.closest(&p);
                d <= l.radius_at(s)
            }) {
                pixels[y * w + x] = 110 + (i % 7) as u8 * 20;
            }
        }
    }
    pixels
}

/// Each link's features under `config`, on `pixels`.
fn search(
    camera: &Camera,
    view: &ProjectedModel,
    pixels: &[u8],
    config: &FeatureConfig,
) -> Vec<LinkFeatures> {
    let frame = FrameView::packed(pixels, camera.width as usize, camera.height as usize).unwrap();
    (0..view.links.len())
        .map(|index| {
            let mut out = LinkFeatures::default();
            find_link_features(view, camera, &frame, index, config, &mut out);
            out
        })
        .collect()
}

/// The same features and counts, bit for bit.
fn same(a: &LinkFeatures, b: &LinkFeatures) -> bool {
    a.edges == b.edges
        && a.tip == b.tip
        && (a.expected, a.masked, a.off_frame) == (b.expected, b.masked, b.off_frame)
        && a.reach_px.to_bits() == b.reach_px.to_bits()
}

/// `narrow`'s edges and tip are some of `wide`'s, found where `wide` found them.
fn found_within(narrow: &LinkFeatures, wide: &LinkFeatures) -> bool {
    narrow.edges.iter().all(|e| wide.edges.contains(e))
        && (narrow.tip.is_none() || narrow.tip == wide.tip)
}

#[test]
fn slices_near_a_nearer_part_are_masked_within_the_margin() {
    let mut base = FeatureConfig::default();
    base.occluder_margin_px = 0.0;
    let mut masked_by_margin = [0u32; 4];
    for (camera, view) in views() {
        let pixels = paint_stepped(&view, &camera);
        let at = |m: f32| {
            let mut c = base;
            c.occluder_margin_px = m;
            search(&camera, &view, &pixels, &c)
        };
        let none = at(0.0);
        // A margin that is no distance is none.
        for m in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -3.0] {
            for (index, (a, b)) in at(m).iter().zip(&none).enumerate() {
                assert!(same(a, b), "link {index}, margin {m}");
            }
        }
        let mut narrower = none.clone();
        for (k, m) in [1.0f32, 2.0, 4.0].into_iter().enumerate() {
            let wider = at(m);
            for (index, (w, n)) in wider.iter().zip(&narrower).enumerate() {
                assert!(w.masked >= n.masked, "link {index}, margin {m}");
                assert_eq!(
                    w.masked + w.expected + w.off_frame,
                    n.masked + n.expected + n.off_frame
                );
                assert!(found_within(w, n), "link {index}, margin {m}");
                masked_by_margin[k + 1] += u32::from(w.masked);
            }
            narrower = wider;
        }
        masked_by_margin[0] += none.iter().map(|f| u32::from(f.masked)).sum::<u32>();
    }
    println!("masked at 0 / 1 / 2 / 4 px: {masked_by_margin:?}");
    assert!(
        masked_by_margin[3] > masked_by_margin[0] + 5,
        "windows masked at 0 / 1 / 2 / 4 px: {masked_by_margin:?}"
    );
}

#[test]
fn over_another_part_without_a_valley_an_edge_of_either_sign_is_taken_only_when_asked() {
    let mut taken = FeatureConfig::default();
    taken.occluder_margin_px = 0.0;
    taken.over_hand_any_edge = true;
    let mut left = taken;
    left.over_hand_any_edge = false;
    let (mut with, mut without) = (0usize, 0usize);
    for (camera, view) in views() {
        let pixels = paint_stepped(&view, &camera);
        let a = search(&camera, &view, &pixels, &taken);
        let b = search(&camera, &view, &pixels, &left);
        for (index, (a, b)) in a.iter().zip(&b).enumerate() {
            assert_eq!(
                (a.expected, a.masked),
                (b.expected, b.masked),
                "link {index}"
            );
            assert!(found_within(b, a), "link {index}");
            with += a.edges.len();
            without += b.edges.len();
        }
    }
    println!("edges with the fallback {with}, without {without}");
    assert!(
        with > without + 5,
        "edges with the fallback {with}, without {without}"
    );
}
