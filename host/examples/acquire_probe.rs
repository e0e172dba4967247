//! How well the search finds the hand from nothing: renders seeds of the random rigs, tracks
//! each with no initial state (`AutoTracker`), and prints per seed the frame where the hand
//! was acquired (fingertips within 10 px at 640 px wide, held 5 frames), the leaf scores it
//! tried, and the truth's own score.
//!
//! ```text
//! cargo run --release -p digiteyes-host --example acquire_probe -- --seeds 301..=310
//! ```

use std::ops::RangeInclusive;

use anyhow::Result;
use clap::Parser;
use digiteyes_core::acquire::AcquireConfig;
use digiteyes_core::frame::FrameView;
use digiteyes_host::acquire::{AutoTracker, Status};
use digiteyes_host::eval::compare;
use digiteyes_host::scenarios::{render_scenario, RenderOptions};
use digiteyes_host::sequence::Sequence;
use digiteyes_host::TrackerConfig;

#[derive(Parser)]
struct Args {
    #[arg(long, value_parser = parse_range, default_value = "301..=306")]
    seeds: RangeInclusive<u64>,
    #[arg(long, default_value_t = 60)]
    frames: usize,
    #[arg(long, default_value_t = 320)]
    width: u32,
    #[arg(long, default_value_t = 1000)]
    budget: u16,
    #[arg(long, default_value_t = 20)]
    normals: u8,
    #[arg(long, default_value_t = 6)]
    spins: u8,
    #[arg(long, default_value_t = 3)]
    depths: u8,
    #[arg(long, default_value_t = 4)]
    rounds: u8,
    #[arg(long, default_value_t = 0.80)]
    accept: f32,
}

fn parse_range(s: &str) -> Result<RangeInclusive<u64>, String> {
    let (a, b) = s.split_once("..=").ok_or("A..=B")?;
    Ok(a.parse().map_err(|_| "A")?..=b.parse().map_err(|_| "B")?)
}

fn main() -> Result<()> {
    let args = Args::parse();
    let dir = tempfile::tempdir()?;
    let (w, h) = (args.width, args.width * 3 / 4);
    println!(
        "| seed | rig | acquired at | tries (leaf scores) | evaluations | frame-0 truth score |"
    );
    println!("|---|---|---|---|---|---|");
    for seed in args.seeds.clone() {
        let stereo = seed % 2 == 0;
        let name = if stereo {
            "random-stereo"
        } else {
            "random-mono"
        };
        let seq = dir.path().join(format!("s{seed}"));
        let options = RenderOptions {
            seed,
            frames: Some(args.frames),
            size: Some((w, h)),
            supersample: 2,
            ..RenderOptions::default()
        };
        render_scenario(name, &seq, &options)?;
        let sequence = Sequence::open(&seq)?;
        let truth = sequence.read_truth()?;
        let mut base: Vec<f32> = vec![0.0; sequence.n_states()];
        base[0] = 1.0;
        let acquire = AcquireConfig {
            evaluations_per_frame: args.budget,
            normals: args.normals,
            spins: args.spins,
            depths: args.depths,
            refine_rounds: args.rounds,
            ..AcquireConfig::default()
        };
        let mut auto = AutoTracker::new(
            sequence.model.clone(),
            &sequence.cameras,
            &base,
            sequence.free_mask(),
            TrackerConfig::default(),
            acquire,
        )?;
        auto.set_accept_score(args.accept);
        let mut estimated = Vec::new();
        let mut statuses = Vec::new();
        let mut leaves = Vec::new();
        let mut evaluations = 0u32;
        for k in 0..sequence.frames {
            let images: Vec<_> = (0..sequence.cameras.len())
                .map(|c| sequence.read_frame(c, k))
                .collect::<Result<_>>()?;
            let views: Vec<_> = images
                .iter()
                .map(|i| FrameView::packed(i.as_raw(), i.width() as usize, i.height() as usize))
                .collect::<Result<_, _>>()?;
            let r = auto.step(&views)?;
            evaluations += u32::from(r.evaluated);
            if let Some(s) = r.leaf_score {
                leaves.push(format!("{s:.2}@{k}"));
            }
            statuses.push(r.status);
            estimated.push(
                auto.state()
                    .iter()
                    .map(|&v| f64::from(v))
                    .collect::<Vec<_>>(),
            );
        }
        let names: Vec<String> = (0..sequence.cameras.len())
            .map(|c| format!("cam{c}"))
            .collect();
        let free: Vec<usize> = (0..sequence.n_states()).collect();
        let report = compare(
            &sequence.model,
            &sequence.cameras,
            &names,
            &free,
            &truth.rows,
            &estimated,
        )?;
        let limit = 10.0 * f64::from(w) / 640.0;
        let tips = &report.fingertip_mean_by_frame;
        let acquired = (0..tips.len().saturating_sub(4))
            .find(|&k| (k..k + 5).all(|j| statuses[j] == Status::Tracking && tips[j] <= limit));
        // The truth's score on frame 0, for the acceptance threshold.
        let truth_score = {
            let images: Vec<_> = (0..sequence.cameras.len())
                .map(|c| sequence.read_frame(c, 0))
                .collect::<Result<_>>()?;
            let views: Vec<_> = images
                .iter()
                .map(|i| FrameView::packed(i.as_raw(), i.width() as usize, i.height() as usize))
                .collect::<Result<_, _>>()?;
            let mut buffers: Vec<Vec<u8>> = views
                .iter()
                .map(|v| {
                    vec![
                        0;
                        digiteyes_core::likelihood::EdgeMap::bytes_needed(
                            v.width(),
                            v.height(),
                            acquire.likelihood.stride_px
                        )
                    ]
                })
                .collect();
            let maps: Vec<_> = buffers
                .iter_mut()
                .zip(&views)
                .map(|(b, v)| digiteyes_core::likelihood::EdgeMap::build(b, v, &acquire.likelihood))
                .collect::<Result<_, _>>()
                .map_err(|e| anyhow::anyhow!("{e}"))?;
            let mut q = [0.0f32; digiteyes_core::config::MAX_STATES];
            for (d, s) in q.iter_mut().zip(&truth.rows[0]) {
                *d = *s as f32;
            }
            let mut probe = digiteyes_core::acquire::Acquirer::new(
                &sequence.model,
                &base,
                auto.tracker().free(),
                digiteyes_core::acquire::WorkingVolume::from_cameras(&sequence.cameras, 600.0),
                acquire,
            );
            if let Some(placed) =
                probe.place(&sequence.model, &sequence.cameras[0], &maps[0], q, None)
            {
                let d = (4..7)
                    .map(|i| (placed.q[i] - q[i]).powi(2))
                    .sum::<f32>()
                    .sqrt();
                let full =
                    probe.score(&sequence.model, &sequence.cameras, &views, &maps, &placed.q);
                eprintln!("seed {seed}: the truth slid: {d:.1} mm away, chamfer score {:.2}, full {full:.2}", placed.score);
            }
            probe.score(&sequence.model, &sequence.cameras, &views, &maps, &q)
        };
        if let Some(k) = statuses.iter().position(|s| *s == Status::Tracking) {
            let e = &estimated[k];
            let t = &truth.rows[k];
            let palm = (4..7).map(|i| (e[i] - t[i]).powi(2)).sum::<f64>().sqrt();
            let dot = (0..4).map(|i| e[i] * t[i]).sum::<f64>().abs().min(1.0);
            let joints =
                (7..e.len()).map(|i| (e[i] - t[i]).powi(2)).sum::<f64>() / (e.len() - 7) as f64;
            eprintln!(
                "seed {seed}: claimed at {k}: tips {:.1} px, palm {palm:.0} mm, {:.0} deg, joints {:.0} deg RMS",
                tips[k],
                (2.0 * dot.acos()).to_degrees(),
                joints.sqrt().to_degrees()
            );
        }
        println!(
            "| {seed} | {} | {} | {} | {evaluations} | {truth_score:.2} |",
            if stereo { "stereo" } else { "mono" },
            acquired.map_or("never".to_string(), |k| k.to_string()),
            leaves.join(" "),
        );
    }
    Ok(())
}
