//! A/B of tracker configurations on rendered scenarios: track life, joint RMS, fingertip
//! error, and how well `lost` matches the truth, per variant.
//!
//! ```text
//! cargo run --release -p digiteyes-host --example motion_ab -- fullhand-mono,clutter --seeds 1..=4
//! ```

use anyhow::Result;
use clap::Parser;
use digiteyes_core::motion::{MotionConfig, PriorWeights};
use digiteyes_host::eval::evaluate;
use digiteyes_host::scenarios::{render_scenario, RenderOptions};
use digiteyes_host::sequence::read_states;
use digiteyes_host::{track_sequence, TrackerConfig};

#[derive(Parser)]
struct Args {
    /// Comma-separated scenarios.
    scenarios: String,
    #[arg(long, default_value_t = 1)]
    first_seed: u64,
    #[arg(long, default_value_t = 4)]
    seeds: u64,
    #[arg(long, default_value_t = 60)]
    frames: usize,
    /// Comma-separated variants (default: all).
    #[arg(long)]
    variants: Option<String>,
    /// Image size WxH.
    #[arg(long, default_value = "320x240")]
    size: String,
}

fn variant(name: &str) -> Option<TrackerConfig> {
    let mut c = TrackerConfig::default();
    let mut m = MotionConfig::PLAIN;
    for part in name.split('+') {
        match part {
            "plain" => {}
            "hold" => m.hold_when_lost = true,
            "decay" => m.full_velocity_found = 0.7,
            "nopredict" => c.predict = false,
            p if p.starts_with("pj") => m.prior.joint = p[2..].parse().ok()?,
            p if p.starts_with("pt") => m.prior.translation = p[2..].parse().ok()?,
            p if p.starts_with("pq") => m.prior.quaternion = p[2..].parse().ok()?,
            p if p.starts_with("prior") => {
                let w: f32 = p[5..].parse().ok()?;
                m.prior = PriorWeights {
                    quaternion: w * 10.0,
                    translation: w / 100.0,
                    joint: w,
                };
            }
            p if p.starts_with("sil") => {
                let d: f32 = p[3..].parse().ok()?;
                c.silhouette_grid = 24;
                c.lost_silhouette_drop = d;
            }
            _ => return None,
        }
    }
    c.motion = m;
    Some(c)
}

fn main() -> Result<()> {
    let args = Args::parse();
    let (w, h) = args.size.split_once('x').unwrap();
    let size = (w.parse()?, h.parse()?);
    let variants: Vec<String> = args
        .variants
        .as_deref()
        .unwrap_or("plain,hold+decay,hold+decay+prior2000,hold+decay+prior2000+sil0.04")
        .split(',')
        .map(String::from)
        .collect();
    let dir = tempfile::tempdir()?;
    println!(
        "scenario seed variant life joint_deg tip_px palm_mm lost wrong_unflagged flagged_right"
    );
    for scenario in args.scenarios.split(',') {
        for seed in args.first_seed..args.first_seed + args.seeds {
            let seq = dir.path().join(format!("{scenario}-{seed}"));
            let opts = RenderOptions {
                seed,
                frames: Some(args.frames),
                size: Some(size),
                supersample: 2,
                ..RenderOptions::default()
            };
            render_scenario(scenario, &seq, &opts)?;
            for v in &variants {
                let config = variant(v).unwrap_or_else(|| panic!("bad variant {v}"));
                let out = dir.path().join("states.csv");
                track_sequence(&seq, &out, config, false)?;
                let r = evaluate(&seq, &out)?;
                let table = read_states(&out, r_states(&seq)?)?;
                let lost = table.extra("lost").unwrap_or_default();
                let (mut wrong_unflagged, mut flagged_right) = (0, 0);
                for (k, e) in r.fingertip_mean_by_frame.iter().enumerate() {
                    let flagged = lost.get(k).is_some_and(|&v| v != 0.0);
                    if *e > 20.0 && !flagged {
                        wrong_unflagged += 1;
                    }
                    if *e < 5.0 && flagged {
                        flagged_right += 1;
                    }
                }
                let tip = r.cameras.iter().map(|c| c.fingertip_mean_px).sum::<f64>()
                    / r.cameras.len() as f64;
                println!(
                    "{scenario} {seed} {v} {:.3} {:.2} {:.2} {:.2} {} {} {}",
                    r.track_life,
                    r.joint_rms_deg,
                    tip,
                    r.palm_translation_mm,
                    r.lost_frames.unwrap_or(0),
                    wrong_unflagged,
                    flagged_right
                );
            }
        }
    }
    Ok(())
}

fn r_states(seq: &std::path::Path) -> Result<usize> {
    Ok(digiteyes_host::sequence::Sequence::open(seq)?.n_states())
}
