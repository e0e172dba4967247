//! The measurement behind the fingers' MCP range in `models/hand.dh`: scenarios tracked over
//! several seeds, the same frames each time, with the MCP flexions' lower limit at 0 for every
//! finger (the range before the 3D mouse), at -0.5 rad for the index only (q8; the raised
//! finger of the 3D mouse), and at -0.5 rad for all four fingers.
//!
//! `cargo run --release -p digiteyes-tests --example mcp_limits_study [FRAMES [SEEDS [NAMES]]]`
//! (defaults: 60 frames, seeds 1..=5 as `A..=B`, every scenario; NAMES comma-separated).

use anyhow::{anyhow, Context, Result};
use digiteyes_core::frame::FrameView;
use digiteyes_core::model::Limit;
use digiteyes_host::eval::compare;
use digiteyes_host::scenarios::NAMES;
use digiteyes_host::sequence::Sequence;
use digiteyes_host::{render_scenario, sequence_tracker, EvalReport, RenderOptions, TrackerConfig};

/// The fingers' MCP flexion states.
const MCP: [usize; 4] = [8, 12, 16, 20];

/// The lower limits compared: (name, lower limit of q8, q12, q16, q20 in rad).
const VARIANTS: [(&str, [f32; 4]); 3] = [
    ("all 0", [0.0; 4]),
    ("index -0.5", [-0.5, 0.0, 0.0, 0.0]),
    ("all -0.5", [-0.5; 4]),
];

/// Tracks the sequence in `seq` with the MCP flexions' lower limits at `lo` (rad).
fn track(seq: &std::path::Path, lo: [f32; 4]) -> Result<EvalReport> {
    let mut sequence = Sequence::open(seq)?;
    for (s, lo) in MCP.into_iter().zip(lo) {
        let hi = sequence.model.limit(s).context("an MCP limit")?.hi;
        sequence.model.set_limit(s, Some(Limit { lo, hi }));
    }
    let mut tracker =
        sequence_tracker(&sequence, TrackerConfig::default()).map_err(|e| anyhow!("{e}"))?;
    let mut estimate = Vec::with_capacity(sequence.frames);
    for k in 0..sequence.frames {
        let images = (0..sequence.cameras.len())
            .map(|c| sequence.read_frame(c, k))
            .collect::<Result<Vec<_>>>()?;
        let views = images
            .iter()
            .map(|img| {
                FrameView::packed(img.as_raw(), img.width() as usize, img.height() as usize)
                    .map_err(|e| anyhow!("{e}"))
            })
            .collect::<Result<Vec<_>>>()?;
        tracker.track(&views).map_err(|e| anyhow!("{e}"))?;
        estimate.push(tracker.state().iter().map(|&v| f64::from(v)).collect());
    }
    let names: Vec<String> = (0..sequence.cameras.len())
        .map(|c| sequence.camera_name(c))
        .collect();
    compare(
        &sequence.model,
        &sequence.cameras,
        &names,
        &sequence.free_states(),
        &sequence.read_truth()?.rows,
        &estimate,
    )
}

fn tip(r: &EvalReport) -> f64 {
    r.cameras
        .iter()
        .map(|c| c.fingertip_mean_px)
        .fold(0.0, f64::max)
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let frames: usize = args.first().map_or(Ok(60), |s| s.parse())?;
    let seeds = match args.get(1) {
        Some(s) => {
            let (a, b) = s.split_once("..=").context("seeds as A..=B")?;
            a.parse::<u64>()?..=b.parse::<u64>()?
        }
        None => 1..=5,
    };
    let names: Vec<String> = match args.get(2) {
        Some(list) => list.split(',').map(str::to_string).collect(),
        None => NAMES.iter().map(|n| n.to_string()).collect(),
    };
    let dir = tempfile::tempdir()?;
    let variants: Vec<&str> = VARIANTS.iter().map(|(n, _)| *n).collect();
    println!(
        "{frames} frames per run; MCP lower limits: {} (columns in this order)",
        variants.join(" / ")
    );
    println!("| scenario | seed | fingertip px | joint RMS deg | palm rot deg | palm mm | track life % |");
    println!("| --- | --- | --- | --- | --- | --- | --- |");
    for name in &names {
        for seed in seeds.clone() {
            let seq = dir.path().join(format!("{name}-{seed}"));
            let options = RenderOptions {
                seed,
                frames: Some(frames),
                ..RenderOptions::default()
            };
            render_scenario(name, &seq, &options)?;
            let runs = VARIANTS
                .iter()
                .map(|(_, lo)| track(&seq, *lo))
                .collect::<Result<Vec<_>>>()?;
            let column = |f: &dyn Fn(&EvalReport) -> f64| {
                runs.iter()
                    .map(|r| format!("{:.2}", f(r)))
                    .collect::<Vec<_>>()
                    .join(" / ")
            };
            println!(
                "| {name} | {seed} | {} | {} | {} | {} | {} |",
                column(&tip),
                column(&|r| r.joint_rms_deg),
                column(&|r| r.palm_rotation_deg),
                column(&|r| r.palm_translation_mm),
                column(&|r| 100.0 * r.track_life),
            );
        }
    }
    Ok(())
}
