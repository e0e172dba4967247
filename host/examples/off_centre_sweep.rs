//! The sweep's rigs with motions that do not swing around mid-range. `random_scenario` draws
//! every joint's centre at 35–65 % of its range, so a setting that prefers mid-range (as the
//! prior toward it did, measured and removed: `docs/robustness.md`) agrees with the
//! generator's own centre; this writes the same
//! seeds' rigs, noise, blur and light with each joint's centre moved to 10–30 % or 70–90 % of
//! its range (either end, drawn per joint), the swing 70–100 % of the room left, so a setting
//! can be judged on motions whose centre it cannot know. The folder is laid out as `bench
//! robustness --keep` lays it out (without `states.csv`), for `kept_ab`. With `--straight S`
//! the centres stay the sweep's and every finger flexion is instead shifted down by S of its
//! range and clipped at 0, so the fingers lie straight, at their lower bounds, part of the
//! time: what a flat hand does and the sweep's motions never do (`docs/robustness.md`,
//! "Joints at their bounds").
//!
//! ```text
//! cargo run --release -p digiteyes-host --example off_centre_sweep -- /tmp/off --first-seed 5421
//! cargo run --release -p digiteyes-host --example kept_ab -- /tmp/off default knuckle=0
//! cargo run --release -p digiteyes-host --example off_centre_sweep -- /tmp/straight \
//!     --first-seed 7001 --seeds 40 --straight 0.3
//! ```

use std::path::PathBuf;

use anyhow::Result;
use clap::Parser;
use digiteyes_host::scenarios::RenderOptions;

#[path = "common/motions.rs"]
mod motions;

use motions::{render_seed, Motion};

#[derive(Parser)]
struct Args {
    /// Where the seeds' folders (`seedNNNN/`) are written.
    out: PathBuf,
    /// The first seed (odd seeds one camera, even seeds two, as in the sweep).
    #[arg(long, default_value_t = 5421)]
    first_seed: u64,
    /// How many seeds.
    #[arg(long, default_value_t = 60)]
    seeds: u64,
    /// Frames per seed.
    #[arg(long, default_value_t = 200)]
    frames: usize,
    /// Instead of moving the centres: keep the sweep's own motion and shift every finger
    /// flexion (MCP, PIP, DIP of fingers 1-4) down by this share of its range, clipped at 0,
    /// so the fingers lie straight (at their lower bound) part of the time, as a flat hand's do.
    #[arg(long, default_value_t = 0.0)]
    straight: f64,
}

fn main() -> Result<()> {
    let args = Args::parse();
    let motion = if args.straight > 0.0 {
        Motion::Straight(args.straight)
    } else {
        Motion::OffCentre
    };
    for seed in args.first_seed..args.first_seed + args.seeds {
        let options = RenderOptions {
            seed,
            frames: Some(args.frames),
            size: Some((640, 480)),
            supersample: 2,
            ..RenderOptions::default()
        };
        let out = args.out.join(format!("seed{seed:04}"));
        render_seed(seed, seed.is_multiple_of(2), motion, &options, &out)?;
        eprintln!("seed {seed} written");
    }
    Ok(())
}
