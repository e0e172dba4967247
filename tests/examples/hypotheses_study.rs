//! Several hypotheses against one, over the random sweep (`random-mono` for odd seeds,
//! `random-stereo` for even ones): per seed and per K, track life, joint RMS, palm error and
//! tracker time, then the distribution per K.
//!
//! `cargo run --release -p digiteyes-tests --example hypotheses_study [FRAMES [WxH [SEEDS [KS]]]]`
//! (defaults: 120 frames, 640x480, seeds 601..=620, K 1,4; SEEDS as `A..=B`, KS as `1,2,4`;
//! `K/S` scores the hypotheses one frame in S, `HypothesesConfig::score_every_frames`).

use std::time::{Duration, Instant};

use anyhow::{bail, Context, Result};
use digiteyes_core::frame::FrameView;
use digiteyes_core::hypotheses::{HypothesesConfig, MultiTracker};
use digiteyes_host::sequence::states::StatesWriter;
use digiteyes_host::sequence::Sequence;
use digiteyes_host::track::sequence_tracker;
use digiteyes_host::{evaluate, render_scenario, RenderOptions, TrackerConfig};

struct Outcome {
    life: f64,
    joint_deg: f64,
    palm_mm: f64,
    seconds: f64,
    switches: usize,
    /// Frames where the truth scores above the output, among frames with tips > 10 px off.
    truth_better: (usize, usize),
}

fn track(seq: &std::path::Path, (k, every): (u8, u8), out: &std::path::Path) -> Result<Outcome> {
    let sequence = Sequence::open(seq)?;
    let tracker = sequence_tracker(&sequence, TrackerConfig::default())
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let config = HypothesesConfig {
        count: k,
        score_every_frames: every,
        ..HypothesesConfig::default()
    };
    let mut buffers: Vec<Vec<u8>> = sequence
        .cameras
        .iter()
        .map(|c| {
            vec![
                0u8;
                digiteyes_core::likelihood::EdgeMap::bytes_needed(
                    c.width as usize,
                    c.height as usize,
                    config.likelihood.stride_px
                )
            ]
        })
        .collect();
    let mut multi = MultiTracker::new(tracker, config);
    let mut writer = StatesWriter::create(out, sequence.n_states())?;
    let mut time = Duration::ZERO;
    let mut switches = 0;
    let truth = sequence.read_truth()?;
    let mut scorer = digiteyes_core::hypotheses::score::StateScorer::new();
    let mut margins: Vec<f32> = Vec::new();
    for f in 0..sequence.frames {
        let images = (0..sequence.cameras.len())
            .map(|c| sequence.read_frame(c, f))
            .collect::<Result<Vec<_>>>()?;
        let views = images
            .iter()
            .map(|i| FrameView::packed(i.as_raw(), i.width() as usize, i.height() as usize))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        let mut slices: Vec<&mut [u8]> = buffers.iter_mut().map(|b| b.as_mut_slice()).collect();
        let t0 = Instant::now();
        let report = multi
            .track(&views, &mut slices)
            .map_err(|e| anyhow::anyhow!("frame {f}: {e}"))?;
        time += t0.elapsed();
        switches += usize::from(report.switched);
        writer.write(multi.state(), &report.report)?;
        if k > 1 {
            let mut maps = Vec::new();
            for (b, v) in buffers.iter_mut().zip(&views) {
                maps.push(
                    digiteyes_core::likelihood::EdgeMap::build(b, v, &config.likelihood)
                        .map_err(|e| anyhow::anyhow!("{e}"))?,
                );
            }
            let t: Vec<f32> = truth.rows[f].iter().map(|&v| v as f32).collect();
            let model = multi.tracker().model();
            let cams = multi.tracker().cameras();
            let scene = digiteyes_core::likelihood::Scene::new(model, cams, &views, &maps);
            let st = scorer.score(&scene, &t, &config.likelihood);
            let sb = scorer.score(&scene, multi.state(), &config.likelihood);
            margins.push(st - sb);
        }
    }
    writer.finish()?;
    let report = evaluate(seq, out)?;
    let mut truth_better = (0, 0);
    for (m, tip) in margins.iter().zip(&report.fingertip_mean_by_frame) {
        if *tip > 10.0 {
            truth_better.1 += 1;
            truth_better.0 += usize::from(*m > 0.0);
        }
    }
    Ok(Outcome {
        life: report.track_life,
        joint_deg: report.joint_rms_deg,
        palm_mm: report.palm_translation_mm,
        seconds: time.as_secs_f64() / sequence.frames.max(1) as f64,
        switches,
        truth_better,
    })
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        f64::NAN
    } else {
        v[v.len() / 2]
    }
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let frames: usize = args.first().map_or(Ok(120), |s| s.parse())?;
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
        None => 601..=620,
    };
    let ks: Vec<(u8, u8)> = match args.get(3) {
        Some(s) => s
            .split(',')
            .map(|k| match k.split_once('/') {
                Some((k, every)) => Ok((k.parse()?, every.parse()?)),
                None => Ok((k.parse()?, 1)),
            })
            .collect::<Result<_>>()?,
        None => vec![(1, 1), (4, 1)],
    };
    if frames == 0 || ks.is_empty() {
        bail!("at least one frame and one K");
    }
    let dir = tempfile::tempdir()?;
    println!("seed cams | K: life joint° palm_mm ms/frame switches");
    let mut table: Vec<Vec<(bool, Outcome)>> = ks.iter().map(|_| Vec::new()).collect();
    for seed in seeds {
        let stereo = seed % 2 == 0;
        let name = if stereo {
            "random-stereo"
        } else {
            "random-mono"
        };
        let seq = dir.path().join(format!("seed{seed}"));
        render_scenario(
            name,
            &seq,
            &RenderOptions {
                seed,
                frames: Some(frames),
                size: Some(size),
                supersample: 2,
                ..RenderOptions::default()
            },
        )?;
        let mut line = format!("{seed:4} {}", if stereo { 2 } else { 1 });
        for (i, &(k, every)) in ks.iter().enumerate() {
            let o = track(
                &seq,
                (k, every),
                &dir.path().join(format!("s{seed}k{k}-{every}.csv")),
            )?;
            line += &format!(
                " | K{k}/{every}: {:4.0}% {:5.1} {:6.1} {:6.1} {:3} truth>out {}/{}",
                100.0 * o.life,
                o.joint_deg,
                o.palm_mm,
                1e3 * o.seconds,
                o.switches,
                o.truth_better.0,
                o.truth_better.1
            );
            table[i].push((stereo, o));
        }
        println!("{line}");
    }
    for (i, &(k, every)) in ks.iter().enumerate() {
        for (group, want) in [("mono", false), ("stereo", true)] {
            let rows: Vec<&Outcome> = table[i]
                .iter()
                .filter(|(s, _)| *s == want)
                .map(|(_, o)| o)
                .collect();
            if rows.is_empty() {
                continue;
            }
            let held = rows.iter().filter(|o| o.life >= 0.95).count();
            println!(
                "K={k}/{every} {group:6} seeds {:2}: life median {:4.0}%, >=95% {:3.0}%, joint median {:5.1}°, palm median {:6.1} mm, {:6.1} ms/frame",
                rows.len(),
                100.0 * median(&mut rows.iter().map(|o| o.life).collect::<Vec<_>>()),
                100.0 * held as f64 / rows.len() as f64,
                median(&mut rows.iter().map(|o| o.joint_deg).collect::<Vec<_>>()),
                median(&mut rows.iter().map(|o| o.palm_mm).collect::<Vec<_>>()),
                1e3 * median(&mut rows.iter().map(|o| o.seconds).collect::<Vec<_>>()),
            );
        }
    }
    Ok(())
}
