//! The renderer agrees with the independent renderer that made the conformance fixture:
//! same camera convention, pixel centres, quaternion order, palm box placement and capsules.

use std::path::Path;

use digiteyes_host::render::{RenderSettings, Renderer};
use digiteyes_host::sequence::Sequence;

const FIXTURE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../fixtures/sample-mouse");

/// Intersection over union of two masks.
fn iou(a: &[bool], b: &[bool]) -> f64 {
    let inter = a.iter().zip(b).filter(|(x, y)| **x && **y).count();
    let union = a.iter().zip(b).filter(|(x, y)| **x || **y).count();
    inter as f64 / union.max(1) as f64
}

#[test]
fn silhouettes_match_the_fixture() {
    let seq = Sequence::open(Path::new(FIXTURE)).unwrap();
    let truth = seq.read_truth().unwrap();
    let settings = RenderSettings {
        supersample: 4,
        ..RenderSettings::default()
    };
    let renderer = Renderer::new(&seq.model, &seq.cameras[0], settings);
    for frame in [0, 7, 11] {
        let q: Vec<f32> = truth.rows[frame].iter().map(|&v| v as f32).collect();
        let fixture = seq.read_frame(0, frame).unwrap();
        let ours = renderer.render(&q, 0).unwrap();
        let coverage = renderer.coverage(&q).unwrap();
        // The shaded images, both thresholded at grey 60 (backgrounds are ~20–25).
        let fixture_60: Vec<bool> = fixture.as_raw().iter().map(|&v| v > 60).collect();
        let ours_60: Vec<bool> = ours.as_raw().iter().map(|&v| v > 60).collect();
        // Our exact coverage against the fixture at a threshold just above its background.
        let fixture_38: Vec<bool> = fixture.as_raw().iter().map(|&v| v > 38).collect();
        let ours_half: Vec<bool> = coverage.iter().map(|&c| c > 0.5).collect();
        let shaded = iou(&fixture_60, &ours_60);
        let exact = iou(&fixture_38, &ours_half);
        println!(
            "frame {frame}: IoU shaded (grey > 60) {shaded:.4}, coverage vs fixture > 38 {exact:.4}, \
             fixture px {}, ours px {}",
            fixture_60.iter().filter(|&&v| v).count(),
            ours_60.iter().filter(|&&v| v).count()
        );
        assert!(shaded > 0.97, "frame {frame}: IoU {shaded}");
        assert!(exact > 0.97, "frame {frame}: IoU {exact}");
    }
}
