//! The image's check on the track (`core/src/watch.rs`, issue 9): a track the likelihood no
//! longer supports is flagged lost even while its features and residual look healthy, and a
//! right track is never flagged — also on the independent renderer's fixture, whose right
//! track scores lower than ours (an absolute bar flagged its frames 3–6).

use std::path::Path;

use digiteyes_core::fill::FillConfig;
use digiteyes_core::watch::WatchConfig;
use digiteyes_host::render::Lighting;
use digiteyes_host::sequence::read_states;
use digiteyes_host::track::{track_sequence_opts, TrackOptions};
use digiteyes_host::{evaluate, render_scenario, RenderOptions, TrackerConfig};

mod common;

fn never() -> WatchConfig {
    WatchConfig {
        every_frames: 0,
        ..WatchConfig::default()
    }
}

/// Tracks `seq` with `watch`; returns each frame's `lost` and mean fingertip error (px).
fn track(seq: &Path, out: &Path, watch: WatchConfig) -> (Vec<bool>, Vec<f64>) {
    track_with(seq, out, watch, TrackerConfig::default())
}

/// [`track`] with the tracker's parameters.
fn track_with(
    seq: &Path,
    out: &Path,
    watch: WatchConfig,
    config: TrackerConfig,
) -> (Vec<bool>, Vec<f64>) {
    let options = TrackOptions {
        watch,
        ..TrackOptions::default()
    };
    track_sequence_opts(seq, out, config, false, None, &options).unwrap();
    let report = evaluate(seq, out).unwrap();
    let states = read_states(out, 28).unwrap();
    let lost = states
        .extra("lost")
        .unwrap()
        .iter()
        .map(|&v| v != 0.0)
        .collect();
    (lost, report.fingertip_mean_by_frame)
}

#[test]
fn a_right_track_of_another_renderer_is_never_flagged() {
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fixtures/sample-mouse");
    let dir = tempfile::tempdir().unwrap();
    let (lost, tips) = track(&fixture, &dir.path().join("a.csv"), WatchConfig::default());
    let (plain, _) = track(&fixture, &dir.path().join("b.csv"), never());
    assert!(
        tips.iter().all(|&t| t < 3.0),
        "the fixture is tracked: {tips:?}"
    );
    assert_eq!(lost, plain);
    assert!(lost.iter().all(|&l| !l), "right frames flagged: {lost:?}");
}

/// What the watch did on one seed of [`watch_case`]: frames claimed more than 20 px wrong,
/// and right frames flagged, with the watch and without it.
struct WatchCase {
    claimed_wrong_watched: usize,
    claimed_wrong_plain: usize,
    right_flagged_watched: usize,
    right_flagged_plain: usize,
}

/// `random-stereo` `seed`, 90 frames at 640x480 under the fixed light, tracked with the
/// watch and without it by the tracker that loses it (the set-up the test below explains).
fn watch_case(seed: u64) -> WatchCase {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("seq");
    let options = RenderOptions {
        seed,
        frames: Some(90),
        supersample: 2,
        lighting: Some(Lighting::default()),
        ..RenderOptions::default()
    };
    render_scenario("random-stereo", &seq, &options).unwrap();
    let wrong = 20.0; // px at 640 wide: the sweep's "truly lost"
    let mut config = TrackerConfig::default();
    config.features.palm_edges = false;
    // With the edge-direction test this seed is tracked right: off, to have a wrong track.
    config.features.max_edge_angle_rad = core::f32::consts::FRAC_PI_2;
    // And so with the outermost edge (0 wrong frames claimed with it): off too.
    config.features.outermost_share = 0.0;
    // And so with the knuckle tips (on by default since; 0 wrong frames claimed with them):
    // off too.
    config.features.knuckle_tips = false;
    // And so with the region rows (on by default since; 0 wrong frames claimed with them):
    // off too.
    config.fill = FillConfig::OFF;
    let a = dir.path().join("a.csv");
    let (watched, tips) = track_with(&seq, &a, WatchConfig::default(), config);
    let b = dir.path().join("b.csv");
    let (plain, plain_tips) = track_with(&seq, &b, never(), config);
    let claimed_wrong = |lost: &[bool], tips: &[f64]| {
        lost.iter()
            .zip(tips)
            .filter(|(l, t)| !**l && **t > wrong)
            .count()
    };
    let right_flagged = |lost: &[bool], tips: &[f64]| {
        lost.iter()
            .zip(tips)
            .filter(|(l, t)| **l && **t <= wrong)
            .count()
    };
    WatchCase {
        claimed_wrong_watched: claimed_wrong(&watched, &tips),
        claimed_wrong_plain: claimed_wrong(&plain, &plain_tips),
        right_flagged_watched: right_flagged(&watched, &tips),
        right_flagged_plain: right_flagged(&plain, &plain_tips),
    }
}

#[test]
fn a_track_the_image_no_longer_supports_is_flagged() {
    // Seed 37 (a stereo rig of the robustness sweep, 640x480), tracked without the palm's
    // outline edges and the four mechanisms below: the track settles on wrong fingers while
    // the tracker's own flag stays down. The watch removes a third or more of those frames
    // (measured: 51 -> 33), not all. Found by `scan_seeds_for_the_watch` (below) on seeds
    // 1-120 under stop 77's single-view width rows (`EstimatorConfig::single_view_width_weight`
    // 0.25): 37, 77 and 101 pass of 29 seeds claimed wrong on a frame or more; 115, this
    // test's from stop 72 to 76, no longer does (73 frames claimed wrong, 60 with the watch).
    // Under stop 72's defaults (the slice window at 16 px): 77 and 115 passed (72 -> 31); of the
    // 27 other seeds claimed wrong on a frame or more, the watch cuts two by a third but
    // flags right frames there too (5, 101), and the rest by less. (Seed
    // 76, this test's until the window narrowed, is tracked right to frame 90 since; under
    // the 20 px window it was claimed wrong on 32 frames, 17 with the watch.) (With the palm
    // edges, the default, no sweep seed offered a wrong track the watch catches:
    // docs/robustness.md.) Rendered under the fixed light this case was found under, not
    // the lighting the sweep now draws for the seed.
    let case = watch_case(37);
    let (with, without) = (case.claimed_wrong_watched, case.claimed_wrong_plain);
    assert!(
        without >= 10,
        "the plain track is claimed while wrong: {without} frames"
    );
    assert!(
        with * 3 <= without * 2,
        "frames claimed while wrong: {with} with the watch, {without} without"
    );
    assert_eq!(
        case.right_flagged_watched, case.right_flagged_plain,
        "the watch flagged right frames"
    );
}

/// A scan for the seed of the test above, by its own bars, for when a default changes
/// (`docs/mechanism-seeds.md`): `DIGITEYES_SCAN_SEEDS=1..=100 cargo test --release -p
/// digiteyes-tests --test watch scan -- --ignored --nocapture` prints each seed's frames
/// claimed wrong and right frames flagged, with the watch and without.
#[test]
#[ignore = "a scan of minutes: DIGITEYES_SCAN_SEEDS=A..=B"]
fn scan_seeds_for_the_watch() {
    let mut passing = Vec::new();
    for seed in common::seeds_to_scan() {
        let c = watch_case(seed);
        let shows = c.claimed_wrong_plain >= 10
            && c.claimed_wrong_watched * 3 <= c.claimed_wrong_plain * 2
            && c.right_flagged_watched == c.right_flagged_plain;
        println!(
            "seed {seed}: claimed wrong {} watched, {} plain; right flagged {} watched, {} \
             plain; shows {shows}",
            c.claimed_wrong_watched,
            c.claimed_wrong_plain,
            c.right_flagged_watched,
            c.right_flagged_plain
        );
        if shows {
            passing.push(seed);
        }
    }
    println!("{} seeds pass: {passing:?}", passing.len());
}
