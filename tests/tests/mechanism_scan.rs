//! A scan for the seeds of the one-camera mechanism tests (`pursue.rs`, `settle.rs`,
//! `confirm_depth.rs`), by those tests' own bars, for when a default of the tracker or the
//! search changes and a test's seed no longer shows its mechanism (`docs/mechanism-seeds.md`).
//! Ignored: it runs five acquisitions a seed. Run it with the seeds to scan,
//!
//! ```text
//! DIGITEYES_SCAN_SEEDS=30001..=30600 cargo test --release -p digiteyes-tests \
//!     --test mechanism_scan -- --ignored --nocapture
//! ```
//!
//! and it prints, for each seed, the tests whose bars it passes; the summary lists every
//! passing seed per test. `DIGITEYES_SCAN_TESTS=settle,pursue` scans for those tests only
//! (of `pursue`, `settle`, `confirm_depth`, `rival`). Confirm a candidate in the test itself
//! before moving its seed. The bars are the tests' own, written again here as predicates:
//! a test that changes its bars changes them here too.

use digiteyes_core::acquire::FinderConfig;

mod common;
use common::search::{acquire_mono, MonoRun};
use common::seeds_to_scan;

/// The last frame's tip error, if that frame is claimed.
fn last_error(run: &MonoRun) -> Option<f32> {
    run.errors.last().copied().flatten()
}

/// `with` ends claimed nearer the hand by half than `without` (claimed too).
fn ends_nearer_by_half(with: &MonoRun, without: &MonoRun) -> bool {
    matches!((last_error(with), last_error(without)), (Some(a), Some(b)) if a < 0.5 * b)
}

/// `pursue.rs`: acquired with the pursuit, never claimed without it.
fn shows_pursuit(with: &MonoRun, without: &MonoRun) -> bool {
    with.held.is_some() && without.errors.iter().all(Option::is_none)
}

/// `settle.rs`: acquired settling freely, not with the prior, ending nearer by half.
fn shows_settling(settled: &MonoRun, with_prior: &MonoRun) -> bool {
    settled.held.is_some() && with_prior.held.is_none() && ends_nearer_by_half(settled, with_prior)
}

/// `confirm_depth.rs`'s first test: two more hypotheses carried, acquired only with the
/// variants, the same acceptance on the same frame, ending nearer by half.
fn shows_depth_variants(with: &MonoRun, without: &MonoRun) -> bool {
    with.most_hypotheses == without.most_hypotheses + 2
        && with.held.is_some()
        && without.held.is_none()
        && with.accepted.is_some()
        && with.accepted == without.accepted
        && ends_nearer_by_half(with, without)
}

/// `confirm_depth.rs`'s second test's first filter: the same acceptance and hypotheses, and
/// at least five frames claimed unruled that the rule withholds (the oracle frame by frame
/// is the test's own).
fn shows_rival_rule(ruled: &MonoRun, unruled: &MonoRun) -> bool {
    let withheld = ruled
        .errors
        .iter()
        .zip(&unruled.errors)
        .filter(|(r, u)| r.is_none() && u.is_some())
        .count();
    ruled.accepted.is_some()
        && ruled.accepted == unruled.accepted
        && ruled.carried == unruled.carried
        && withheld >= 5
}

/// Whether a seed's run under the defaults and its run without the mechanism pass a test's
/// bars.
type Shows = fn(&MonoRun, &MonoRun) -> bool;

#[test]
#[ignore = "a scan of minutes to hours: DIGITEYES_SCAN_SEEDS=A..=B, see the module doc"]
fn scan_seeds_for_the_one_camera_mechanism_tests() {
    let defaults = FinderConfig::default();
    let arms: [(&str, FinderConfig, Shows); 4] = [
        (
            "pursue",
            FinderConfig {
                pursue_frames: [0, 0],
                ..defaults
            },
            shows_pursuit,
        ),
        (
            "settle",
            FinderConfig {
                settle_frames: 0,
                ..defaults
            },
            shows_settling,
        ),
        (
            "confirm_depth",
            FinderConfig {
                confirm_depth_share: [0.0, 0.0],
                ..defaults
            },
            shows_depth_variants,
        ),
        (
            "rival",
            FinderConfig {
                confirm_rival_margin: -1.0,
                ..defaults
            },
            shows_rival_rule,
        ),
    ];
    let wanted = std::env::var("DIGITEYES_SCAN_TESTS").ok();
    let wanted = |name: &str| {
        wanted
            .as_ref()
            .is_none_or(|w| w.split(',').any(|t| t == name))
    };
    let mut passing: Vec<Vec<u64>> = vec![Vec::new(); arms.len()];
    for seed in seeds_to_scan() {
        let with = acquire_mono(seed, defaults);
        let mut shown = Vec::new();
        for ((name, finder, shows), found) in arms.iter().zip(&mut passing) {
            if !wanted(name) || (*name != "rival" && with.held.is_none()) {
                continue; // every bar but the rival rule's needs the default arm acquired
            }
            if shows(&with, &acquire_mono(seed, *finder)) {
                shown.push(*name);
                found.push(seed);
            }
        }
        println!("seed {seed}: held {:?}, shows {shown:?}", with.held);
    }
    for ((name, _, _), found) in arms.iter().zip(&passing) {
        println!("{name}: {} seeds {found:?}", found.len());
    }
}
