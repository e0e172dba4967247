//! Does the image likelihood of the tracked state tell a right track from a wrong one? For
//! each seed of the robustness sweep (random rigs, never tuned on): render, track with the
//! defaults, then score every frame's output state by the likelihood of issue 10 and write
//! one row per frame: seed, stereo, frame, claims (the tracker claims the hand), truly lost
//! (the sweep's definition), fingertip px, palm mm, the mean and worst camera score.
//!
//! `cargo run --release -p digiteyes-host --example watch_study -- 61..=80 640x480 200 > w.csv`

use std::path::Path;

use anyhow::{anyhow, Result};
use digiteyes_core::acquire::AcquireConfig;
use digiteyes_core::frame::FrameView;
use digiteyes_core::hypotheses::score::StateScorer;
use digiteyes_core::likelihood::{EdgeMap, Scene};
use digiteyes_host::bench::robustness::{judge_frame, TRULY_LOST_TIP_PX_AT_640};
use digiteyes_host::scenarios::{render_scenario, RenderOptions};
use digiteyes_host::sequence::states::read_states_with_gaps;
use digiteyes_host::sequence::Sequence;
use digiteyes_host::{evaluate, track_sequence_with, TrackerConfig};

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let (Some("--seq"), Some(seq)) = (args.first().map(String::as_str), args.get(1)) {
        println!("seed,stereo,frame,claims,truly,tip_px,palm_mm,score,worst");
        return score_run(0, Path::new(seq), (640, 480));
    }
    let (a, b) = args
        .first()
        .and_then(|s| s.split_once("..="))
        .ok_or_else(|| anyhow!("usage: watch_study A..=B WxH FRAMES"))?;
    let (first, last): (u64, u64) = (a.parse()?, b.parse()?);
    let (w, h) = args
        .get(1)
        .and_then(|s| s.split_once('x'))
        .ok_or_else(|| anyhow!("size WxH"))?;
    let size: (u32, u32) = (w.parse()?, h.parse()?);
    let frames: usize = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(200);
    let dir = tempfile::tempdir()?;
    println!("seed,stereo,frame,claims,truly,tip_px,palm_mm,score,worst");
    for seed in first..=last {
        study_seed(seed, size, frames, dir.path())?;
    }
    Ok(())
}

fn study_seed(seed: u64, size: (u32, u32), frames: usize, dir: &Path) -> Result<()> {
    let name = if seed.is_multiple_of(2) {
        "random-stereo"
    } else {
        "random-mono"
    };
    let seq = dir.join(format!("seed{seed}"));
    let options = RenderOptions {
        seed,
        frames: Some(frames),
        size: Some(size),
        supersample: 2,
        ..RenderOptions::default()
    };
    render_scenario(name, &seq, &options)?;
    score_run(seed, &seq, size)
}

/// Tracks the sequence in `seq` and scores every frame's output (one row per frame).
fn score_run(seed: u64, seq: &Path, size: (u32, u32)) -> Result<()> {
    let states = std::env::temp_dir().join(format!("watch_study_{}.csv", std::process::id()));
    track_sequence_with(seq, &states, TrackerConfig::default(), false, None)?;
    let report = evaluate(seq, &states)?;
    let sequence = Sequence::open(seq)?;
    let stereo = sequence.cameras.len() > 1;
    let truth = sequence.read_truth()?;
    let table = read_states_with_gaps(&states, sequence.n_states())?;
    let claims = table.table.claimed();
    let likelihood = AcquireConfig::default().likelihood;
    let mut buffers: Vec<Vec<u8>> = sequence
        .cameras
        .iter()
        .map(|c| {
            vec![
                0u8;
                EdgeMap::bytes_needed(c.width as usize, c.height as usize, likelihood.stride_px)
            ]
        })
        .collect();
    let mut scorer = StateScorer::new();
    let tip_limit = TRULY_LOST_TIP_PX_AT_640 * f64::from(size.0) / 640.0;
    for (k, (estimate, true_state)) in table.table.rows.iter().zip(&truth.rows).enumerate() {
        let images = (0..sequence.cameras.len())
            .map(|c| sequence.read_frame(c, k))
            .collect::<Result<Vec<_>>>()?;
        let views: Vec<FrameView<'_>> = images
            .iter()
            .map(|i| FrameView::packed(i.as_raw(), i.width() as usize, i.height() as usize))
            .collect::<Result<_, _>>()
            .map_err(|e| anyhow!("{e}"))?;
        let maps = buffers
            .iter_mut()
            .zip(&views)
            .map(|(b, v)| EdgeMap::build(b, v, &likelihood).map_err(|e| anyhow!("{e}")))
            .collect::<Result<Vec<_>>>()?;
        let q: Vec<f32> = estimate.iter().map(|&v| v as f32).collect();
        let mut each = Vec::new();
        for (c, camera) in sequence.cameras.iter().enumerate() {
            let scene = Scene::new(
                &sequence.model,
                core::slice::from_ref(camera),
                &views[c..=c],
                &maps[c..=c],
            );
            each.push(scorer.score(&scene, &q, &likelihood));
        }
        let mean = each.iter().sum::<f32>() / each.len() as f32;
        let worst = each.iter().copied().fold(f32::INFINITY, f32::min);
        let (palm_mm, truly) = judge_frame(estimate, true_state, &report, k, tip_limit);
        let tip = report
            .fingertip_mean_by_frame
            .get(k)
            .copied()
            .unwrap_or(f64::NAN);
        println!(
            "{seed},{},{k},{},{},{tip:.1},{palm_mm:.1},{mean:.4},{worst:.4}",
            u8::from(stereo),
            u8::from(claims.get(k).copied().unwrap_or(false)),
            u8::from(truly),
        );
    }
    Ok(())
}
