//! The scenarios: motion inside the joint ranges, hand in view, the promised speeds, and the
//! sub-models and cameras they claim.

mod common;

use std::path::Path;
use std::time::Instant;

use common::FIXTURE;
use digiteyes_core::model::Model;
use digiteyes_host::render::Renderer;
use digiteyes_host::scenarios::{generate, measure, RenderOptions, SurfaceChoice, NAMES};
use digiteyes_host::sequence::Sequence;

fn opts(seed: u64) -> RenderOptions {
    RenderOptions {
        seed,
        ..RenderOptions::default()
    }
}

#[test]
fn fast_fingertips_peak_between_15_and_25_px_per_frame() {
    let model = Model::hand().unwrap();
    for seed in 1..=3 {
        let g = generate("fast", &opts(seed)).unwrap();
        let speeds = measure::tip_speeds(&model, &g.cameras, &g.truth).unwrap();
        let peak = speeds.iter().copied().fold(0.0, f64::max);
        let mean = speeds[1..].iter().sum::<f64>() / (speeds.len() - 1) as f64;
        println!("fast, seed {seed}: peak fingertip speed {peak:.2} px/frame (mean {mean:.2})");
        assert!((15.0..=25.0).contains(&peak), "peak {peak} px/frame");
    }
}

#[test]
fn slow_scenarios_move_modestly() {
    let model = Model::hand().unwrap();
    for name in [
        "mouse",
        "clutter",
        "twofinger",
        "rigid",
        "fullhand-mono",
        "fullhand-stereo",
    ] {
        let g = generate(name, &opts(1)).unwrap();
        let peak = measure::peak_tip_speed(&model, &g.cameras, &g.truth).unwrap();
        println!("{name}: peak fingertip speed {peak:.2} px/frame");
        let bar = if name.starts_with("mouse") || name == "clutter" {
            5.0
        } else {
            8.0
        };
        assert!(peak > 1.0 && peak <= bar, "{name}: {peak} px/frame");
    }
}

#[test]
fn every_scenario_stays_in_range_and_in_view() {
    let model = Model::hand().unwrap();
    for name in NAMES {
        for seed in 1..=4 {
            // `generate` itself refuses a trajectory that leaves the view.
            let g = generate(name, &opts(seed)).unwrap();
            assert_eq!(g.truth.len(), 60);
            assert_eq!(g.file.initial_state, g.truth[0]);
            let free: Vec<usize> = g
                .file
                .free
                .as_ref()
                .unwrap()
                .iter()
                .map(|&s| s as usize)
                .collect();
            for (k, q) in g.truth.iter().enumerate() {
                let norm = q[..4].iter().map(|v| v * v).sum::<f64>().sqrt();
                assert!((norm - 1.0).abs() < 1e-9, "{name} frame {k}: |q| = {norm}");
                for (s, &v) in q.iter().enumerate().skip(7) {
                    let l = model.limit(s).unwrap();
                    let v = v as f32;
                    assert!(
                        v >= l.lo - 1e-6 && v <= l.hi + 1e-6,
                        "{name} seed {seed} frame {k}: q{s} = {v} outside {l:?}"
                    );
                }
                for s in (0..28).filter(|s| !free.contains(s)) {
                    assert_eq!(q[s], g.truth[0][s], "{name}: fixed q{s} moved");
                }
            }
            // Every free state moves.
            for &s in &free {
                let moved = g.truth.iter().any(|q| (q[s] - g.truth[0][s]).abs() > 1e-6);
                assert!(moved, "{name}: free q{s} never moves");
            }
        }
    }
}

#[test]
fn scenarios_are_the_sub_models_they_claim() {
    let fixture = Sequence::open(Path::new(FIXTURE)).unwrap();
    let free = |name: &str| generate(name, &opts(1)).unwrap().file.free.unwrap();
    for name in ["mouse", "fast", "clutter"] {
        let g = generate(name, &opts(1)).unwrap();
        assert_eq!(g.file.free, Some(vec![4, 5, 8, 9, 10, 19, 24]), "{name}");
        assert_eq!(g.file.cameras, fixture.file.cameras, "{name}");
        assert_eq!(g.file.initial_state, fixture.initial_state, "{name}");
        assert_eq!(g.file.model, "builtin:hand");
    }
    assert_eq!(free("rigid"), (0..7).collect::<Vec<i64>>());
    assert_eq!(free("twofinger"), vec![4, 5, 6, 8, 9, 10, 12, 13, 14]);
    assert_eq!(free("fullhand-stereo"), (0..28).collect::<Vec<i64>>());
    assert!(generate("clutter", &opts(1)).unwrap().settings.noise_sigma == 8.0);
}

#[test]
fn stereo_cameras_are_30_to_40_degrees_apart_and_mono_moves_the_same() {
    let stereo = generate("fullhand-stereo", &opts(2)).unwrap();
    let mono = generate("fullhand-mono", &opts(2)).unwrap();
    assert_eq!(stereo.truth, mono.truth);
    assert_eq!(stereo.cameras.len(), 2);
    assert_eq!(mono.cameras.len(), 1);
    assert_eq!(stereo.cameras[0], mono.cameras[0]);
    let axis = |c: &digiteyes_core::camera::Camera| c.r.row(2).transpose();
    let angle = axis(&stereo.cameras[0])
        .dot(&axis(&stereo.cameras[1]))
        .acos()
        .to_degrees();
    println!("stereo cameras {angle:.1}° apart");
    assert!((30.0..=40.0).contains(&angle), "{angle}°");
}

#[test]
fn motion_is_seeded_and_short_sequences_are_prefixes() {
    let a = generate("twofinger", &opts(7)).unwrap();
    let b = generate("twofinger", &opts(7)).unwrap();
    let c = generate("twofinger", &opts(8)).unwrap();
    assert_eq!(a.truth, b.truth);
    assert_ne!(a.truth, c.truth);
    let short = generate(
        "twofinger",
        &RenderOptions {
            frames: Some(10),
            ..opts(7)
        },
    )
    .unwrap();
    assert_eq!(short.truth[..], a.truth[..10]);
    assert!(generate("nonsense", &opts(1)).is_err());
    let zero = RenderOptions {
        frames: Some(0),
        ..opts(1)
    };
    assert!(generate("mouse", &zero).is_err());
}

#[test]
fn a_full_size_frame_renders_quickly() {
    let model = Model::hand().unwrap();
    for name in ["mouse", "fullhand-stereo", "clutter"] {
        let g = generate(name, &opts(1)).unwrap();
        let renderer = Renderer::new(&model, &g.cameras[0], g.settings);
        let q: Vec<f32> = g.truth[30].iter().map(|&v| v as f32).collect();
        renderer.render(&q, 0).unwrap();
        let start = Instant::now();
        let frame = renderer.render(&q, 1).unwrap();
        let seconds = start.elapsed().as_secs_f64();
        println!("{name}: one 640x480 frame in {:.1} ms", 1e3 * seconds);
        assert_eq!(frame.dimensions(), (640, 480));
        assert!(seconds < 1.0, "{name}: {seconds} s per frame");
    }
}

#[test]
fn clutter_puts_texture_behind_the_hand() {
    let model = Model::hand().unwrap();
    let g = generate("clutter", &opts(1)).unwrap();
    let q: Vec<f32> = g.truth[0].iter().map(|&v| v as f32).collect();
    let frame = Renderer::new(&model, &g.cameras[0], g.settings)
        .render(&q, 0)
        .unwrap();
    // The top-left corner is background: textured, not a flat grey.
    let corner: Vec<f64> = (0..40)
        .flat_map(|y| (0..40).map(move |x| (x, y)))
        .map(|(x, y)| f64::from(frame.get_pixel(x, y).0[0]))
        .collect();
    let mean = corner.iter().sum::<f64>() / corner.len() as f64;
    let sd = (corner.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / corner.len() as f64).sqrt();
    assert!(sd > 8.0, "background sd {sd}");
}

#[test]
fn a_varied_surface_changes_the_hand_alone() {
    let model = Model::hand().unwrap();
    let seed = 14;
    let matte = generate("random-stereo", &opts(seed)).unwrap();
    let varied = RenderOptions {
        surface: SurfaceChoice::Varied,
        ..opts(seed)
    };
    let varied = generate("random-stereo", &varied).unwrap();
    assert_eq!(matte.truth, varied.truth, "the motion is the matte seed's");
    assert_eq!(matte.cameras, varied.cameras, "the rig is the matte seed's");
    assert_eq!(matte.settings.lighting, varied.settings.lighting);
    assert!(matte.settings.surface.is_matte() && !varied.settings.surface.is_matte());
    let q: Vec<f32> = matte.truth[20].iter().map(|&v| v as f32).collect();
    for camera in &matte.cameras {
        let plain = Renderer::new(&model, camera, matte.settings);
        let rough = Renderer::new(&model, camera, varied.settings);
        let (a, b) = (plain.render(&q, 5).unwrap(), rough.render(&q, 5).unwrap());
        let coverage = plain.coverage(&q).unwrap();
        let (w, h) = (camera.width as usize, camera.height as usize);
        // Past the blur's reach of every hand pixel, the frames are the same, noise and all.
        let near_hand = |x: usize, y: usize| {
            let (x0, y0) = (x.saturating_sub(6), y.saturating_sub(6));
            (y0..(y + 7).min(h)).any(|j| (x0..(x + 7).min(w)).any(|i| coverage[j * w + i] > 0.0))
        };
        let (mut hand, mut changed) = (0, 0);
        for y in 0..h {
            for x in 0..w {
                let (pa, pb) = (
                    a.get_pixel(x as u32, y as u32).0[0],
                    b.get_pixel(x as u32, y as u32).0[0],
                );
                if !near_hand(x, y) {
                    assert_eq!(pa, pb, "background pixel ({x}, {y})");
                } else if coverage[y * w + x] == 1.0 {
                    hand += 1;
                    changed += usize::from(pa.abs_diff(pb) >= 2);
                }
            }
        }
        println!("{changed} of {hand} hand pixels changed by 2 grey levels or more");
        assert!(hand > 1000 && changed * 2 > hand, "{changed} of {hand}");
    }
}

#[test]
fn each_single_effect_is_the_varied_surfaces_own() {
    let seed = 9;
    let varied = SurfaceChoice::Varied.surface(seed);
    assert!(SurfaceChoice::Matte.surface(seed).is_matte());
    let greys = SurfaceChoice::Greys.surface(seed);
    let gloss = SurfaceChoice::Gloss.surface(seed);
    let shadows = SurfaceChoice::Shadows.surface(seed);
    for part in 0..16 {
        assert_eq!(greys.albedo_factor(part), varied.albedo_factor(part));
        assert_eq!(gloss.albedo_factor(part), 1.0);
        assert_eq!(shadows.albedo_factor(part), 1.0);
    }
    assert_eq!(
        (gloss.specular, gloss.shininess),
        (varied.specular, varied.shininess)
    );
    assert_eq!((greys.specular, shadows.specular), (0.0, 0.0));
    assert!(shadows.cast_shadows && !greys.cast_shadows && !gloss.cast_shadows);
}
