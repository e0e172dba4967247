//! Helpers shared by the end-to-end tests.
#![allow(dead_code)]

pub mod browser;
pub mod frames;
pub mod search;
pub mod shading;

use std::path::{Path, PathBuf};

use digiteyes_host::sequence::Sequence;
use digiteyes_host::{render_scenario, RenderOptions};

/// A short `mouse` sequence at 320×240 in `dir/mouse` (quick to render, upload and track).
pub fn mouse(dir: &Path, frames: usize) -> PathBuf {
    let seq = dir.join("mouse");
    let options = RenderOptions {
        frames: Some(frames),
        size: Some((320, 240)),
        supersample: 2,
        ..RenderOptions::default()
    };
    render_scenario("mouse", &seq, &options).unwrap();
    seq
}

/// `scenario` rendered with `seed`, `frames` frames at 320×240, in `dir/{scenario}-{seed}`,
/// opened (quick enough for debug builds).
pub fn seeded(dir: &Path, scenario: &str, seed: u64, frames: usize) -> Sequence {
    let seq = dir.join(format!("{scenario}-{seed}"));
    let options = RenderOptions {
        seed,
        frames: Some(frames),
        size: Some((320, 240)),
        ..RenderOptions::default()
    };
    render_scenario(scenario, &seq, &options).unwrap();
    Sequence::open(&seq).unwrap()
}

/// A test that cannot run here (a tool missing). Outside CI it prints `SKIPPED: …` straight to
/// the process's stderr (the harness captures `eprintln!` of a passing test, and a skip must
/// be seen) and the test passes. Under CI (`CI=true`, as `.ci/run` is run) a skip is a
/// failure: CI must never go green on tests that did not run.
pub fn skip(what: &str, reason: &str) {
    let message = format!("SKIPPED: {what}: {reason}");
    if std::env::var("CI").is_ok_and(|v| v == "true" || v == "1") {
        panic!("{message} (CI=true: a skipped test fails the run; install what it needs)");
    }
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "\n{message}\n");
}

/// The seeds a mechanism test's scan runs (`docs/mechanism-seeds.md`), named by
/// `DIGITEYES_SCAN_SEEDS` (`A..=B`, `A..B` or one seed).
pub fn seeds_to_scan() -> Vec<u64> {
    let text = std::env::var("DIGITEYES_SCAN_SEEDS").expect("DIGITEYES_SCAN_SEEDS=A..=B");
    let number = |s: &str| s.trim().parse::<u64>().expect("a seed is a whole number");
    if let Some((a, b)) = text.split_once("..=") {
        (number(a)..=number(b)).collect()
    } else if let Some((a, b)) = text.split_once("..") {
        (number(a)..number(b)).collect()
    } else {
        vec![number(&text)]
    }
}
