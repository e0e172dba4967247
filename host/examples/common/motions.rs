//! The sweep's rigs under motions other than its own, for the study examples.
//!
//! `random_scenario` draws every joint's centre at 35–65 % of its range, so a setting that
//! prefers mid-range agrees with the generator's own centre. These keep each seed's rig,
//! noise, blur and light and change only the fingers' motion:
//! - **off-centre**: each joint's centre moved to 10–30 % or 70–90 % of its range (either
//!   end, drawn per joint), the swing 70–100 % of the room left;
//! - **straight S**: the sweep's own motion with every finger flexion shifted down by S of its
//!   range and clipped at 0, so the fingers lie straight part of the time, as a flat hand's do.
#![allow(dead_code)] // each example uses part of it

use std::path::Path;

use anyhow::{anyhow, bail, Result};
use digiteyes_core::model::{Model, BASE_STATES};
use digiteyes_host::scenarios::random::{random_scenario, zoomed};
use digiteyes_host::scenarios::{
    generate_from, render_scenario, write_generated, RenderOptions, MAX_ZOOM_OUTS, ZOOM_OUT,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Which fingers' motion a seed is rendered with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// The sweep's own (`random-mono`, `random-stereo`).
    Sweep,
    /// Centres near either end of each joint's range.
    OffCentre,
    /// The sweep's, every finger flexion shifted down by this share of its range.
    Straight(f64),
}

impl std::str::FromStr for Motion {
    type Err = anyhow::Error;

    /// `sweep`, `off-centre` or `straight=S` (S a share of the range, in (0, 1]).
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "sweep" => Ok(Motion::Sweep),
            "off-centre" => Ok(Motion::OffCentre),
            _ => match s.strip_prefix("straight=").map(str::parse::<f64>) {
                Some(Ok(share)) if share > 0.0 && share <= 1.0 => Ok(Motion::Straight(share)),
                _ => bail!("motion {s:?}: give sweep, off-centre or straight=S with S in (0, 1]"),
            },
        }
    }
}

/// Renders `seed`'s rig (two cameras when `stereo`) under `motion` into `out`, as `render`
/// lays a sequence out (`render random-mono|random-stereo` for [`Motion::Sweep`]).
pub fn render_seed(
    seed: u64,
    stereo: bool,
    motion: Motion,
    options: &RenderOptions,
    out: &Path,
) -> Result<()> {
    if motion == Motion::Sweep {
        let name = if stereo {
            "random-stereo"
        } else {
            "random-mono"
        };
        return render_scenario(name, out, options);
    }
    let model = Model::hand().map_err(|e| anyhow!("built-in hand model: {e}"))?;
    let mut scenario = random_scenario(seed, stereo);
    if motion == Motion::OffCentre {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x0ff_c3e7);
        scenario.amplitudes.retain(|&(s, _)| s < BASE_STATES);
        for s in BASE_STATES..model.n_states() {
            let Some(limit) = model.limit(s) else {
                continue;
            };
            let (lo, hi) = (f64::from(limit.lo), f64::from(limit.hi));
            let share = if rng.random_bool(0.5) {
                rng.random_range(0.1..0.3)
            } else {
                rng.random_range(0.7..0.9)
            };
            let centre = lo + (hi - lo) * share;
            scenario.base[s] = centre;
            let room = (centre - lo).min(hi - centre);
            scenario
                .amplitudes
                .push((s, room * rng.random_range(0.7..1.0)));
        }
    }
    // As `render` does: zoomed out step by step until the whole motion stays in view.
    let mut generated = Err(anyhow!("seed {seed}: no view fits"));
    for k in 0..=MAX_ZOOM_OUTS {
        generated = generate_from(zoomed(&scenario, ZOOM_OUT.powi(k as i32)), options);
        if generated.is_ok() {
            break;
        }
    }
    let mut generated = generated?;
    if let Motion::Straight(share) = motion {
        straighten(&model, &mut generated.truth, share);
        generated.file.initial_state = generated.truth[0].clone();
    }
    write_generated(&generated, out, options)
}

/// Every finger flexion (the three joints after each finger's abduction, states 8-10, 12-14,
/// 16-18, 20-22) moved down by `share` of its range and clipped at its lower bound.
fn straighten(model: &Model, truth: &mut [Vec<f64>], share: f64) {
    let flexions = (0..4).flat_map(|finger| {
        let abduction = BASE_STATES + 4 * finger;
        abduction + 1..abduction + 4
    });
    let ranges: Vec<(usize, f64, f64)> = flexions
        .filter_map(|s| {
            let limit = model.limit(s)?;
            Some((s, f64::from(limit.lo), f64::from(limit.hi)))
        })
        .collect();
    for q in truth {
        for &(s, lo, hi) in &ranges {
            q[s] = (q[s] - share * (hi - lo)).max(lo);
        }
    }
}
