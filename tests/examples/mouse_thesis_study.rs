//! The thesis' 3D-mouse trial (`mouse-thesis`) rendered, tracked and judged as a mouse, over
//! several seeds: pole height and base errors, clicks detected, and the tracker's figures.
//!
//! `cargo run --release -p digiteyes-tests --example mouse_thesis_study [FRAMES [WxH [SEEDS]]]`
//! (defaults: 500 frames, 640x480, seeds 1..=5; SEEDS as `A..=B`).

use std::time::Instant;

use anyhow::{bail, Context, Result};
use digiteyes_host::mouse_pole::accuracy::compare;
use digiteyes_host::mouse_pole::MouseConfig;
use digiteyes_host::scenarios::mouse_thesis::NAME;
use digiteyes_host::sequence::Sequence;
use digiteyes_host::{evaluate, render_scenario, track_sequence, RenderOptions, TrackerConfig};

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let frames: usize = args.first().map_or(Ok(500), |s| s.parse())?;
    let size = match args.get(1) {
        Some(s) => {
            let (w, h) = s.split_once('x').context("size as WxH")?;
            (w.parse()?, h.parse()?)
        }
        None => (640, 480),
    };
    let seeds = match args.get(2) {
        Some(s) => {
            let (a, b) = s.split_once("..=").context("seeds as A..=B")?;
            a.parse::<u64>()?..=b.parse::<u64>()?
        }
        None => 1..=5,
    };
    if frames == 0 {
        bail!("at least one frame");
    }
    let dir = tempfile::tempdir()?;
    println!(
        "{NAME}, {frames} frames at {}x{}, default tracker",
        size.0, size.1
    );
    println!("| seed | height RMS mm (max) | fingertip z RMS mm | base RMS mm (max) | thumb clicks once/true, spurious | finger-4 clicks once/true, spurious | fingertip px | joint RMS deg | palm rot deg | track life | s |");
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    for seed in seeds {
        let start = Instant::now();
        let seq = dir.path().join(format!("seed{seed}"));
        let options = RenderOptions {
            seed,
            frames: Some(frames),
            size: Some(size),
            ..RenderOptions::default()
        };
        render_scenario(NAME, &seq, &options)?;
        let states = seq.join("states.csv");
        track_sequence(&seq, &states, TrackerConfig::default(), false)?;
        let eval = evaluate(&seq, &states)?;
        let sequence = Sequence::open(&seq)?;
        let truth = sequence.read_truth()?;
        let estimate = digiteyes_host::sequence::read_states(&states, sequence.n_states())?;
        let rest: Vec<f32> = sequence.initial_state.iter().map(|&v| v as f32).collect();
        let mouse = compare(
            &sequence.model,
            &rest,
            MouseConfig::default(),
            &truth.rows,
            &estimate.rows,
        )?;
        let [finger4, thumb] = mouse.buttons;
        let tip = eval
            .cameras
            .iter()
            .map(|c| c.fingertip_mean_px)
            .fold(0.0, f64::max);
        println!(
            "| {seed} | {:.2} ({:.1}) | {:.2} | {:.2} ({:.1}) | {}/{}, {} | {}/{}, {} | {tip:.2} | {:.2} | {:.2} | {:.0}% | {:.0} |",
            mouse.height_rms_mm,
            mouse.height_max_mm,
            mouse.tip_z_rms_mm,
            mouse.base_rms_mm,
            mouse.base_max_mm,
            thumb.detected_once,
            thumb.truth,
            thumb.spurious,
            finger4.detected_once,
            finger4.truth,
            finger4.spurious,
            eval.joint_rms_deg,
            eval.palm_rotation_deg,
            100.0 * eval.track_life,
            start.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
