//! An acquisition is claimed only once the next frame confirms it
//! (`FinderConfig::probation_max_drop`): the accepting frame still reports searching and the
//! held state; the next frame claims the hand if the tracker keeps it and its worst camera's
//! likelihood holds, and otherwise the search goes on. A hypothesis that Gauss–Newton fitted
//! to clutter rarely survives a second frame; the hand does. Over 1,000 hand-free frames
//! through the whole status machine no frame is claimed.

use digiteyes_core::acquire::{AcquireConfig, FinderConfig};
use digiteyes_core::auto_tracker::{AutoReport, AutoTracker, Status};
use digiteyes_core::fill::FillConfig;
use digiteyes_core::frame::FrameView;
use digiteyes_core::tracker::TrackerConfig;
use digiteyes_host::sequence::Sequence;

mod common;
use common::{frames, search};
use digiteyes_host::render::hand_free;

fn step(auto: &mut AutoTracker, bufs: &mut [Vec<u8>], views: &[FrameView<'_>]) -> AutoReport {
    let mut b: Vec<&mut [u8]> = bufs.iter_mut().map(|b| b.as_mut_slice()).collect();
    auto.step(views, &mut b).unwrap()
}

fn claimed(r: &AutoReport) -> bool {
    r.status != Status::Searching && !r.report.lost
}

fn packed<'a>(sequence: &Sequence, images: &'a [Vec<u8>]) -> Vec<FrameView<'a>> {
    images
        .iter()
        .zip(&sequence.cameras)
        .map(|(p, c)| FrameView::packed(p, c.width as usize, c.height as usize).unwrap())
        .collect()
}

/// `frames` hand-free frames through the status machine of `sequence`'s rig under `finder`
/// and `tracker`: the frames claimed, the leaves accepted, the frames on which a leaf was
/// refined.
fn hand_free_run(
    sequence: &Sequence,
    finder: FinderConfig,
    tracker: TrackerConfig,
    frames: usize,
) -> (usize, usize, usize) {
    let (mut auto, mut bufs) = search::searching_with(sequence, AcquireConfig::default(), tracker);
    auto.set_finder(finder);
    let sizes: Vec<(usize, usize)> = sequence
        .cameras
        .iter()
        .map(|c| (c.width as usize, c.height as usize))
        .collect();
    let (mut claims, mut accepted, mut refined) = (0, 0, 0);
    for k in 0..frames {
        let images = hand_free::hand_free_frame(&sizes, k);
        let r = step(&mut auto, &mut bufs, &packed(sequence, &images));
        claims += usize::from(claimed(&r));
        accepted += usize::from(r.accepted);
        refined += usize::from(r.leaf_score.is_some());
    }
    (claims, accepted, refined)
}

/// The test's lenient arm on one camera: the tracker without its region rows, the search's
/// one-camera bar at 0.91 and no bar on the reverse chamfer term.
fn lenient_arm() -> (TrackerConfig, FinderConfig) {
    let mut plain = TrackerConfig::default();
    plain.fill = FillConfig::OFF;
    // Nor is clutter accepted with one camera's bar on the reverse chamfer term (since): that
    // clutter leaf leaves more of the frame's edges unexplained. Lifted here too.
    let mut lenient = search::without_reverse_bar(FinderConfig::default());
    lenient.accept.one_camera_score = 0.91;
    (plain, lenient)
}

#[test]
fn no_frame_of_1000_hand_free_ones_is_claimed() {
    let dir = tempfile::tempdir().unwrap();
    for (rig, seed) in [("random-mono", 1410), ("random-stereo", 1412)] {
        let sequence = common::seeded(dir.path(), rig, seed, 1);
        let (claims, accepted, refined) = hand_free_run(
            &sequence,
            FinderConfig::default(),
            TrackerConfig::default(),
            1000,
        );
        println!(
            "{rig} {seed}: 1000 hand-free frames, leaves refined on {refined}, {accepted} \
             accepted, {claims} frames claimed"
        );
        assert!(
            refined >= 200,
            "{rig}: the search must have refined leaves on many frames: {refined}"
        );
        assert_eq!(claims, 0, "{rig}: hand-free frames claimed");
        if rig == "random-mono" {
            // With the tracker's region rows (on by default) no clutter leaf is accepted on
            // this rig. Without them, and with the one-camera bar at 0.91 instead of 0.93,
            // the search accepts clutter once in the 1,000 frames, and claimed on the
            // accepting frame it would be 18 frames claimed: the probation is put to the test
            // there. (Until the search's budget of 100 a frame, the default bar accepted
            // clutter twice on rig 1411 without the rows; no mono rig of 1411-1481 does now.
            // Rig 1411's lenient arm accepted clutter until the slice window narrowed to
            // 16 px, stop 72; of the rigs 1401-1414 scanned then, `scan_rigs_for_the_
            // probation` below, 1410 alone accepts it.)
            let (plain, lenient) = lenient_arm();
            let (claims, accepted, _) = hand_free_run(&sequence, lenient, plain, 1000);
            assert_eq!(
                claims, 0,
                "{rig}: hand-free frames claimed without region rows"
            );
            assert!(
                accepted >= 1,
                "the probation must have been put to the test"
            );
            let at_once = FinderConfig {
                probation_max_drop: None,
                ..lenient
            };
            let (claims_at_once, _, _) = hand_free_run(&sequence, at_once, plain, 1000);
            println!("{rig} {seed}: claimed on acceptance, {claims_at_once} frames claimed");
            assert!(
                claims_at_once >= 1,
                "without the probation these acceptances are claimed"
            );
        }
    }
}

/// `random-stereo` 107 from nothing, its frame `replaced` (if any) without the hand: the
/// reports up to frame `last`, and the state reported after each.
fn acquisition(replaced: Option<usize>, last: usize) -> (Vec<AutoReport>, Vec<Vec<f32>>) {
    let dir = tempfile::tempdir().unwrap();
    let sequence = common::seeded(dir.path(), "random-stereo", 107, last + 1);
    let (mut auto, mut bufs) = search::searching(&sequence, AcquireConfig::default());
    let sizes: Vec<(usize, usize)> = sequence
        .cameras
        .iter()
        .map(|c| (c.width as usize, c.height as usize))
        .collect();
    let (mut reports, mut states) = (Vec::new(), Vec::new());
    for k in 0..=last {
        let r = if replaced == Some(k) {
            let images = hand_free::hand_free_frame(&sizes, 0);
            step(&mut auto, &mut bufs, &packed(&sequence, &images))
        } else {
            let images = frames::images(&sequence, k);
            step(&mut auto, &mut bufs, &frames::views(&images))
        };
        reports.push(r);
        states.push(auto.state().to_vec());
    }
    (reports, states)
}

#[test]
fn an_acquisition_is_claimed_once_the_next_frame_confirms_it() {
    // Acquired before frame 10 (acquire.rs): the accepting frame reports searching and the
    // base state; the next frame claims the hand.
    let (reports, states) = acquisition(None, 12);
    let k = reports
        .iter()
        .position(|r| r.accepted)
        .expect("random-stereo 107 is acquired before frame 12");
    assert!(k < 12);
    let base = search::base(states[k].len());
    assert_eq!(reports[k].status, Status::Searching, "the accepting frame");
    assert!(reports[k].report.lost, "the accepting frame claims nothing");
    assert_eq!(states[k], base, "the accepting frame reports the base");
    assert!(claimed(&reports[k + 1]), "the next frame claims the hand");
    assert_eq!(reports[k + 1].status, Status::Tracking);
    assert_ne!(states[k + 1], base);

    // The same, with the frame after the acceptance empty: refuted, the search goes on, and
    // nothing was ever claimed.
    let (refuted, states) = acquisition(Some(k + 1), k + 1);
    assert!(refuted[k].accepted, "the same acceptance on frame {k}");
    assert_eq!(refuted[k + 1].status, Status::Searching);
    assert!(refuted[k + 1].report.lost);
    assert!(!refuted.iter().any(claimed), "no frame claimed");
    assert!(
        states.iter().all(|q| *q == base),
        "the base held throughout"
    );
}

/// A scan for the mono rig of the test above, by its own bars, for when a default changes
/// (`docs/mechanism-seeds.md`): `DIGITEYES_SCAN_SEEDS=1411..=1500 cargo test --release -p
/// digiteyes-tests --test probation scan -- --ignored --nocapture` prints, for each
/// `random-mono` rig, the frames claimed under the defaults and under the lenient arm, the
/// lenient arm's acceptances and its claims without the probation.
#[test]
#[ignore = "a scan of minutes: DIGITEYES_SCAN_SEEDS=A..=B"]
fn scan_rigs_for_the_probation() {
    let (plain, lenient) = lenient_arm();
    let at_once = FinderConfig {
        probation_max_drop: None,
        ..lenient
    };
    let mut passing = Vec::new();
    for seed in common::seeds_to_scan() {
        let dir = tempfile::tempdir().unwrap();
        let sequence = common::seeded(dir.path(), "random-mono", seed, 1);
        let run = |finder, tracker| hand_free_run(&sequence, finder, tracker, 1000);
        let (claims, _, refined) = run(FinderConfig::default(), TrackerConfig::default());
        let (lenient_claims, accepted, _) = run(lenient, plain);
        let shows = refined >= 200 && claims == 0 && lenient_claims == 0 && accepted >= 1;
        let claims_at_once = if shows { run(at_once, plain).0 } else { 0 };
        let shows = shows && claims_at_once >= 1;
        println!(
            "rig {seed}: defaults {claims} claimed ({refined} refined); lenient {accepted} \
             accepted, {lenient_claims} claimed, {claims_at_once} at once; shows {shows}"
        );
        if shows {
            passing.push(seed);
        }
    }
    println!("{} rigs pass: {passing:?}", passing.len());
}
