//! Tracks a rendered sequence with K hypotheses, for counting instructions per frame under
//! callgrind (`scripts/hypotheses-instructions` collects only `MultiTracker::track`).
//!
//! `cargo run --release -p digiteyes-tests --example hypotheses_cost -- SEQ K FRAMES [EVERY [REVERSE [KEEP [SAMPLE_ITER [OTHER_ITER [LIGHT]]]]]]`
//! (EVERY: `HypothesesConfig::score_every_frames`, default 1; REVERSE: the likelihood's
//! `reverse_weight`, default the hypotheses' own; KEEP: `keep_fingers`, 1 or 0, default the
//! hypotheses' own; SAMPLE_ITER, OTHER_ITER: `sample_iterations` and `other_iterations`,
//! default the hypotheses' own; LIGHT: `light_others`, 1 or 0, default the hypotheses' own).

use anyhow::{Context, Result};
use digiteyes_core::frame::FrameView;
use digiteyes_core::hypotheses::{HypothesesConfig, MultiTracker};
use digiteyes_core::likelihood::{EdgeMap, LikelihoodConfig};
use digiteyes_host::sequence::Sequence;
use digiteyes_host::track::sequence_tracker;
use digiteyes_host::TrackerConfig;

/// A 1 / 0 argument named `name`; left out, `default`.
fn switch(arg: Option<&String>, name: &str, default: bool) -> Result<bool> {
    match arg.map(String::as_str) {
        None => Ok(default),
        Some("1") => Ok(true),
        Some("0") => Ok(false),
        Some(other) => anyhow::bail!("{name} is 1 or 0, not {other:?}"),
    }
}

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let seq = args.first().context("SEQ K FRAMES")?;
    let k: u8 = args.get(1).context("SEQ K FRAMES")?.parse()?;
    let frames: usize = args.get(2).context("SEQ K FRAMES")?.parse()?;
    let every: u8 = args.get(3).map_or(Ok(1), |s| s.parse())?;
    let defaults = HypothesesConfig::default();
    let reverse: f32 = args
        .get(4)
        .map_or(Ok(defaults.likelihood.reverse_weight), |s| s.parse())?;
    let keep_fingers = switch(args.get(5), "KEEP", defaults.keep_fingers)?;
    let sample_iterations: u8 = args
        .get(6)
        .map_or(Ok(defaults.sample_iterations), |s| s.parse())
        .context("SAMPLE_ITER is a whole number of iterations, 0 to 255")?;
    let other_iterations: u8 = args
        .get(7)
        .map_or(Ok(defaults.other_iterations), |s| s.parse())
        .context("OTHER_ITER is a whole number of iterations, 0 to 255")?;
    let light_others = switch(args.get(8), "LIGHT", defaults.light_others)?;
    let sequence = Sequence::open(std::path::Path::new(seq))?;
    let config = HypothesesConfig {
        count: k,
        score_every_frames: every,
        keep_fingers,
        sample_iterations,
        other_iterations,
        light_others,
        likelihood: LikelihoodConfig {
            reverse_weight: reverse,
            ..defaults.likelihood
        },
        ..defaults
    };
    let tracker = sequence_tracker(&sequence, TrackerConfig::default())
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let mut multi = MultiTracker::new(tracker, config);
    let mut buffers: Vec<Vec<u8>> = sequence
        .cameras
        .iter()
        .map(|c| {
            let n = EdgeMap::bytes_needed(
                c.width as usize,
                c.height as usize,
                config.likelihood.stride_px,
            );
            vec![0u8; n]
        })
        .collect();
    let images: Vec<Vec<_>> = (0..frames.min(sequence.frames))
        .map(|f| {
            (0..sequence.cameras.len())
                .map(|c| sequence.read_frame(c, f))
                .collect::<Result<Vec<_>>>()
        })
        .collect::<Result<_>>()?;
    let (mut hypotheses, mut sampled) = (0usize, 0usize);
    for frame in &images {
        let views = frame
            .iter()
            .map(|i| FrameView::packed(i.as_raw(), i.width() as usize, i.height() as usize))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        let mut slices: Vec<&mut [u8]> = buffers.iter_mut().map(|b| b.as_mut_slice()).collect();
        let report = multi
            .track(&views, &mut slices)
            .map_err(|e| anyhow::anyhow!("{e}"))?;
        hypotheses += usize::from(report.count);
        sampled += usize::from(report.sampled);
    }
    println!(
        "K={k}: {} frames, {:.2} hypotheses carried and {:.2} sampled per frame",
        images.len(),
        hypotheses as f64 / images.len().max(1) as f64,
        sampled as f64 / images.len().max(1) as f64
    );
    Ok(())
}
