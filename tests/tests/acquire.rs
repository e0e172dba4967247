//! The search that finds the hand without help (issue 10, in progress): it keeps within its
//! per-frame budget and picks up where it left off, and a tracker searching hand-free frames
//! — plain, noisy, cluttered — never claims a hand, even when its search runs to the end on
//! every frame.

use digiteyes_core::acquire::{AcquireConfig, Acquirer, Progress, WorkingVolume};
use digiteyes_core::frame::FrameView;
use digiteyes_core::likelihood::EdgeMap;
use digiteyes_host::acquire::{AutoTracker, Status};
use digiteyes_host::sequence::Sequence;
use digiteyes_host::{render_scenario, RenderOptions, TrackerConfig};

/// A hand-free frame: the background's grey, optional noise, optional clutter (bright and
/// dark bars at every angle), from a small deterministic generator.
fn hand_free(
    width: usize,
    height: usize,
    grey: u8,
    noise: u8,
    clutter: bool,
    seed: u64,
) -> Vec<u8> {
    let mut state = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
    let mut next = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 33) as u32
    };
    let mut pixels = vec![grey; width * height];
    if clutter {
        for _ in 0..25 {
            let (cx, cy) = (next() as usize % width, next() as usize % height);
            let angle = (next() % 360) as f32 * std::f32::consts::PI / 180.0;
            let (len, half) = (20 + next() as usize % 80, 2 + next() as usize % 5);
            let level = if next() % 2 == 0 { 230 } else { 20 };
            for t in 0..len {
                for w in 0..2 * half {
                    let x =
                        cx as f32 + angle.cos() * t as f32 - angle.sin() * (w as f32 - half as f32);
                    let y =
                        cy as f32 + angle.sin() * t as f32 + angle.cos() * (w as f32 - half as f32);
                    if x >= 0.0 && y >= 0.0 && (x as usize) < width && (y as usize) < height {
                        pixels[y as usize * width + x as usize] = level;
                    }
                }
            }
        }
    }
    if noise > 0 {
        for p in &mut pixels {
            let n = (next() % (2 * u32::from(noise) + 1)) as i32 - i32::from(noise);
            *p = (i32::from(*p) + n).clamp(0, 255) as u8;
        }
    }
    pixels
}

fn rig(dir: &std::path::Path) -> Sequence {
    let seq = dir.join("rig");
    let options = RenderOptions {
        frames: Some(1),
        size: Some((320, 240)),
        ..RenderOptions::default()
    };
    render_scenario("fullhand-mono", &seq, &options).unwrap();
    Sequence::open(&seq).unwrap()
}

#[test]
fn hand_free_frames_are_never_claimed() {
    let dir = tempfile::tempdir().unwrap();
    let sequence = rig(dir.path());
    let camera = sequence.cameras[0];
    let (w, h) = (camera.width as usize, camera.height as usize);
    // The whole search, to the end, on every frame: every leaf is refined and judged.
    let acquire = AcquireConfig {
        evaluations_per_frame: u16::MAX,
        ..AcquireConfig::default()
    };
    let mut base = vec![0.0f32; sequence.n_states()];
    base[0] = 1.0;
    let mut auto = AutoTracker::new(
        sequence.model.clone(),
        &sequence.cameras,
        &base,
        digiteyes_core::estimator::FreeMask::all(sequence.n_states()),
        TrackerConfig::default(),
        acquire,
    )
    .unwrap();
    let mut leaves = 0;
    let mut frames = 0;
    for (k, (noise, clutter)) in [(0, false), (8, false), (8, true), (0, true)]
        .into_iter()
        .cycle()
        .take(40)
        .enumerate()
    {
        let pixels = hand_free(w, h, 60, noise, clutter, k as u64);
        let view = FrameView::packed(&pixels, w, h).unwrap();
        let report = auto.step(&[view]).unwrap();
        frames += 1;
        leaves += usize::from(report.leaf_score.is_some());
        assert_ne!(report.status, Status::Tracking, "frame {k} claimed a hand");
        assert!(report.report.lost, "frame {k}");
    }
    println!("{frames} hand-free frames, {leaves} leaves refined and refused");
    assert!(
        leaves >= 8,
        "the search must have reached its leaves: {leaves}"
    );
}

#[test]
fn the_search_keeps_its_budget_and_goes_on_where_it_left_off() {
    let dir = tempfile::tempdir().unwrap();
    let sequence = rig(dir.path());
    let image = sequence.read_frame(0, 0).unwrap();
    let frame = FrameView::packed(
        image.as_raw(),
        image.width() as usize,
        image.height() as usize,
    )
    .unwrap();
    let config = AcquireConfig {
        evaluations_per_frame: 1000,
        ..AcquireConfig::default()
    };
    let mut buffer =
        vec![
            0u8;
            EdgeMap::bytes_needed(frame.width(), frame.height(), config.likelihood.stride_px)
        ];
    let edges = EdgeMap::build(&mut buffer, &frame, &config.likelihood).unwrap();
    let base: Vec<f32> = sequence.initial_state.iter().map(|&v| v as f32).collect();
    let free = digiteyes_core::estimator::FreeMask::all(sequence.n_states());
    let volume = WorkingVolume::from_cameras(&sequence.cameras, 600.0);
    let mut acquirer = Acquirer::new(&sequence.model, &base, free, volume, config);
    let mut steps = 0;
    let mut last = 0;
    let found = loop {
        match acquirer.step(
            &sequence.model,
            &sequence.cameras,
            std::slice::from_ref(&frame),
            std::slice::from_ref(&edges),
        ) {
            Progress::Searching { evaluated } => {
                // The item under way is finished: a step overruns by less than one item.
                assert!(
                    evaluated < 1000 + acquirer.largest_item_cost,
                    "step {steps}: {evaluated}, largest item {}",
                    acquirer.largest_item_cost
                );
                assert!(
                    acquirer.largest_item_cost < 1000,
                    "{}",
                    acquirer.largest_item_cost
                );
                assert!(acquirer.evaluations > last, "step {steps} did nothing");
                last = acquirer.evaluations;
            }
            Progress::Found(leaf) => break leaf,
        }
        steps += 1;
        assert!(steps < 10_000, "the search never ends");
    };
    println!(
        "found after {steps} steps, {} hypotheses, score {:.2}",
        acquirer.evaluations, found.score
    );
    assert!(
        steps > 5,
        "a 1000-evaluation budget spreads the search over frames"
    );
    assert!(found.score > 0.0 && acquirer.best().len() > 1);
}
