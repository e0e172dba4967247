//! Losing the hand and finding it again: a blackout (frames rendered as the empty background
//! while the hand moves on) must turn the status to `lost`, then `searching`, and the local
//! re-acquisition must find the hand again soon after it returns; frames without the hand are
//! never claimed; and while the hand is not lost, the status machine tracks exactly as the
//! plain tracker does. Sequences are short and small (320×240): quick in debug builds too.

use std::path::{Path, PathBuf};

use digiteyes_core::acquire::{AcquireConfig, FinderConfig, LOCAL_TURN_RAD};
use digiteyes_core::auto_tracker::AutoTracker as CoreAutoTracker;
use digiteyes_core::estimator::FreeMask;
use digiteyes_core::fill::FillConfig;
use digiteyes_core::frame::FrameView;
use digiteyes_host::acquire::{AutoTracker, Recovery, Status, LOST_FRAMES_BEFORE_SEARCH};
use digiteyes_host::sequence::{read_states, Sequence};
use digiteyes_host::track::{sequence_auto_tracker, track_sequence_opts, TrackOptions};
use digiteyes_host::{render_scenario, sequence_tracker, RenderOptions, TrackerConfig};

mod common;

/// `fullhand-stereo` at 320×240, `frames` frames, frames `dark` without the hand.
fn render(dir: &Path, frames: usize, dark: std::ops::Range<usize>) -> PathBuf {
    let seq = dir.join("stereo");
    let options = RenderOptions {
        frames: Some(frames),
        size: Some((320, 240)),
        supersample: 2,
        blackout: Some(dark),
        ..RenderOptions::default()
    };
    render_scenario("fullhand-stereo", &seq, &options).unwrap();
    seq
}

fn views(images: &[image::GrayImage]) -> Vec<FrameView<'_>> {
    images
        .iter()
        .map(|i| FrameView::packed(i.as_raw(), i.width() as usize, i.height() as usize).unwrap())
        .collect()
}

fn frames(sequence: &Sequence, k: usize) -> Vec<image::GrayImage> {
    (0..sequence.cameras.len())
        .map(|c| sequence.read_frame(c, k).unwrap())
        .collect()
}

fn palm_error_mm(truth: &[f64], q: &[f64]) -> f64 {
    (4..7)
        .map(|i| (truth[i] - q[i]).powi(2))
        .sum::<f64>()
        .sqrt()
}

#[test]
fn after_a_blackout_the_hand_is_lost_searched_and_found_again_within_30_frames() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b, n) = (20, 50, 80);
    let seq = render(dir.path(), n, a..b);
    let out = dir.path().join("states.csv");
    let summary = track_sequence_opts(
        &seq,
        &out,
        TrackerConfig::default(),
        false,
        None,
        &TrackOptions::default(),
    )
    .unwrap();
    println!("{summary}");
    let sequence = Sequence::open(&seq).unwrap();
    let table = read_states(&out, sequence.n_states()).unwrap();
    let truth = sequence.read_truth().unwrap();
    let status: Vec<Status> = table
        .status
        .unwrap()
        .into_iter()
        .map(Option::unwrap)
        .collect();
    let word = |s: &[Status]| s.iter().map(|s| &s.as_str()[..1]).collect::<String>();
    println!("{}", word(&status));
    // Tracked up to the blackout, then lost, then searching, never claimed in the dark.
    assert!(
        status[..a].iter().all(|&s| s == Status::Tracking),
        "{}",
        word(&status)
    );
    assert_eq!(status[a], Status::Lost, "the first dark frame is lost");
    let searching = a + LOST_FRAMES_BEFORE_SEARCH as usize - 1;
    assert!(status[a..searching].iter().all(|&s| s == Status::Lost));
    assert!(status[searching..b].iter().all(|&s| s == Status::Searching));
    // Found again within 30 frames of the hand's return, and held to the end near the truth.
    let back = (b..n)
        .find(|&k| status[k] == Status::Tracking)
        .expect("never re-acquired");
    assert!(
        back < b + 30,
        "re-acquired at frame {back}, {} after its return",
        back - b
    );
    assert_eq!(summary.status.reacquired, vec![back]);
    assert_eq!(summary.status.lost_at, vec![a]);
    let after = status.iter().zip(&truth.rows).zip(&table.rows).enumerate();
    for (k, ((s, t), q)) in after.skip(back + 5) {
        assert_eq!(*s, Status::Tracking, "frame {k}");
        let e = palm_error_mm(t, q);
        assert!(e < 10.0, "frame {k}: palm {e:.1} mm from the truth");
    }
    // While searching, the states hold the last tracked one.
    for (k, row) in table.rows.iter().enumerate().take(back).skip(searching) {
        assert_eq!(row, &table.rows[a - 1], "frame {k}");
    }
    // eval sees the acquisition at frame 0 and the re-acquisition; the report draws the band.
    let report = digiteyes_host::evaluate(&seq, &out).unwrap();
    println!("{report}");
    assert_eq!(report.frames_to_acquire, Some(0));
    assert_eq!(report.reacquired_at.len(), 1, "{:?}", report.reacquired_at);
    assert!(report.reacquired_at[0] >= back && report.reacquired_at[0] < b + 30);
    assert_eq!(report.status.unwrap().reacquired, vec![back]);
    let mut options = digiteyes_host::report::ReportOptions::default();
    options.thumb_every = 0;
    let (html, _) = digiteyes_host::report::build_report(&seq, &out, &options).unwrap();
    for class in ["status-searching", "status-tracking", "status-lost"] {
        assert!(
            html.contains(&format!(r#"<rect class="{class}""#)),
            "no {class} band"
        );
    }
}

#[test]
fn frames_without_the_hand_are_never_claimed() {
    // A blackout longer than the local re-acquisition: the local and then the global search
    // both run on hand-free frames (plain background, noise σ 2 as rendered).
    let dir = tempfile::tempdir().unwrap();
    let (a, n) = (3, 3 + 10 + 70);
    let seq = render(dir.path(), n, a..n);
    let sequence = Sequence::open(&seq).unwrap();
    let mut auto = sequence_auto_tracker(
        &sequence,
        TrackerConfig::default(),
        &TrackOptions::default(),
    )
    .unwrap();
    let (mut local, mut global, mut refused) = (0, 0, 0);
    for k in 0..n {
        let images = frames(&sequence, k);
        let r = auto.step(&views(&images)).unwrap();
        if k >= a {
            assert_ne!(
                r.status,
                Status::Tracking,
                "hand-free frame {k} claimed a hand"
            );
            assert!(r.report.lost, "frame {k}");
        }
        local += usize::from(r.local);
        global += usize::from(r.status == Status::Searching && !r.local);
        refused += usize::from(r.leaf_score.is_some());
    }
    println!("{local} local frames, {global} global, {refused} hypotheses refused");
    assert!(
        local >= 50,
        "the local re-acquisition must have run: {local}"
    );
    assert!(global >= 5, "the global search must have run: {global}");
}

#[test]
fn the_status_machine_tracks_bit_for_bit_as_the_tracker_while_not_lost() {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("mouse");
    let options = RenderOptions {
        frames: Some(12),
        size: Some((320, 240)),
        supersample: 1,
        ..RenderOptions::default()
    };
    render_scenario("mouse", &seq, &options).unwrap();
    let sequence = Sequence::open(&seq).unwrap();
    let config = TrackerConfig::default();
    let mut plain = sequence_tracker(&sequence, config).unwrap();
    let initial: Vec<f32> = sequence.initial_state.iter().map(|&v| v as f32).collect();
    let mut auto = AutoTracker::tracking(
        sequence.model.clone(),
        &sequence.cameras,
        &initial,
        sequence.free_mask(),
        config,
        Default::default(),
    )
    .unwrap();
    for k in 0..sequence.frames {
        let images = frames(&sequence, k);
        let expected = plain.track(&views(&images)).unwrap();
        let got = auto.step(&views(&images)).unwrap();
        assert!(
            !expected.lost,
            "frame {k}: the test needs a sequence never lost"
        );
        assert_eq!(got.report, expected, "frame {k}");
        assert_eq!(got.status, Status::Tracking);
        let bits = |q: &[f32]| q.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(auto.state()), bits(plain.state()), "frame {k}");
    }
}

#[test]
fn recover_never_writes_the_plain_trackers_states_through_a_blackout() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b, n) = (4, 20, 26);
    let seq = render(dir.path(), n, a..b);
    let sequence = Sequence::open(&seq).unwrap();
    let mut plain = sequence_tracker(&sequence, TrackerConfig::default()).unwrap();
    let options = TrackOptions {
        recovery: Recovery::Never,
        ..TrackOptions::default()
    };
    let mut auto = sequence_auto_tracker(&sequence, TrackerConfig::default(), &options).unwrap();
    let (mut lost_run, mut longest) = (0, 0);
    for k in 0..n {
        let images = frames(&sequence, k);
        let expected = plain.track(&views(&images)).unwrap();
        let got = auto.step(&views(&images)).unwrap();
        assert_eq!(got.report, expected, "frame {k}");
        assert_eq!(auto.state(), plain.state(), "frame {k}");
        assert_ne!(
            got.status,
            Status::Searching,
            "frame {k}: --recover never searched"
        );
        lost_run = if expected.lost { lost_run + 1 } else { 0 };
        longest = longest.max(lost_run);
        assert_eq!(got.status == Status::Lost, expected.lost, "frame {k}");
    }
    assert!(
        longest >= LOST_FRAMES_BEFORE_SEARCH as usize,
        "the blackout must lose the hand long enough to search: {longest} frames"
    );
}

/// `rig` (`random-stereo` or `random-mono`) at `seed` (320×240, `frames` frames, frames
/// `dark` without the hand) tracked from its initial state by the status machine under
/// `finder` and `tracker`: the first frame after the hand's return from which 5 frames in a
/// row claim it within `ON_HAND_PX` (10 px) of the truth, within 30 frames of the return; and
/// the status line (`y` right, `n` wrong; none claimed: `L` a local re-acquisition frame that
/// refined a start Gauss–Newton kept, `l` one that did not, `.` any other).
fn reacquired_after(
    dir: &Path,
    rig: &str,
    seed: u64,
    frames_n: usize,
    dark: std::ops::Range<usize>,
    finder: FinderConfig,
    tracker: TrackerConfig,
) -> (Option<usize>, String) {
    let seq = dir.join(format!("{rig}-{seed}"));
    let options = RenderOptions {
        seed,
        frames: Some(frames_n),
        size: Some((320, 240)),
        blackout: Some(dark.clone()),
        ..RenderOptions::default()
    };
    render_scenario(rig, &seq, &options).unwrap();
    let sequence = Sequence::open(&seq).unwrap();
    let truth = sequence.read_truth().unwrap();
    let to_f32 = |q: &[f64]| q.iter().map(|&v| v as f32).collect::<Vec<f32>>();
    let acquire = AcquireConfig::default();
    let mut auto = CoreAutoTracker::tracking(
        sequence.model.clone(),
        &sequence.cameras,
        &to_f32(&sequence.initial_state),
        FreeMask::all(sequence.n_states()),
        tracker,
        acquire,
    )
    .unwrap();
    auto.set_finder(finder);
    let mut bufs = common::search::buffers(&sequence.cameras, acquire.likelihood.stride_px);
    let (mut good, mut line) = (Vec::new(), String::new());
    for k in 0..sequence.frames {
        let images = frames(&sequence, k);
        let mut b: Vec<&mut [u8]> = bufs.iter_mut().map(|b| b.as_mut_slice()).collect();
        let r = auto.step(&views(&images), &mut b).unwrap();
        let claimed = r.status == Status::Tracking && !r.report.lost;
        let e = common::search::tip_error_px(
            &sequence.model,
            &sequence.cameras,
            auto.state(),
            &to_f32(&truth.rows[k]),
        );
        let ok = claimed && e <= common::search::ON_HAND_PX;
        line.push(if ok {
            'y'
        } else if claimed {
            'n'
        } else if r.local && r.leaf_score.is_some_and(|s| s > 0.0) {
            'L'
        } else if r.local {
            'l'
        } else {
            '.'
        });
        good.push(ok);
    }
    let back = (dark.end..dark.end + 30)
        .filter(|&k| k + 5 <= good.len())
        .find(|&k| good[k..k + 5].iter().all(|&g| g))
        .map(|k| k - dark.end);
    (back, line)
}

/// The tracker the local re-acquisition's mechanisms are shown under: they were shown on
/// seeds the tracker once lost; with its region rows (on by default since) the hand is taken
/// back on them without those mechanisms, so the rows are off.
fn without_rows() -> TrackerConfig {
    let mut tracker = TrackerConfig::default();
    tracker.fill = FillConfig::OFF;
    tracker
}

/// `random-stereo` `seed` (140 frames, blackout 80..110) tracked under `tracker` is
/// re-acquired within 10 px under `with` and not under `without`: a mechanism shown on one
/// seed, both ways.
fn reacquired_only_with(
    seed: u64,
    with: FinderConfig,
    without: FinderConfig,
    tracker: TrackerConfig,
    what: &str,
) {
    let dir = tempfile::tempdir().unwrap();
    let run = |finder| {
        reacquired_after(
            dir.path(),
            "random-stereo",
            seed,
            140,
            80..110,
            finder,
            tracker,
        )
    };
    let (back, line) = run(with);
    println!("with {what}:    {line}");
    assert!(back.is_some(), "{seed} not re-acquired with {what}: {line}");
    let (back, line) = run(without);
    println!("without {what}: {line}");
    assert!(back.is_none(), "{seed} re-acquired without {what}: {line}");
}

#[test]
fn the_local_reacquisition_tries_the_librarys_finger_poses_under_the_last_good_palm() {
    // While the hand is hidden its fingers move on: started from the last good fingers,
    // Gauss-Newton settles on a wrong finger pose, or on none the acceptance takes. The local
    // re-acquisition also starts from the last good palm under the library's finger pose the
    // likelihood scores best (`FinderConfig::local_library_pose`). `random-stereo` 1048 is
    // re-acquired only with it: under stop 77's single-view width rows (0.25) the probe named
    // below, on 1011-1060, finds 1037 and 1048 re-acquired only with it, and 1048 passes this test's
    // bars (1037 is not re-acquired within its 140 frames; 1022 and 1033 are no longer
    // re-acquired with it). Under stop 73's defaults (the outermost share 0.3) four seeds
    // of 1011-1060 are re-acquired only with it by `acquire_probe --frames 200 --blackout
    // 80..110 --limit-px 20 --fill-weight 0 --settle-frames 0` with and without
    // `--local-library false`, and of those 1022 and 1033 pass this test's bars (1020 and 1044
    // are not re-acquired within its 140 frames). (1048 until stop 73 as well, whose run the
    // share 0.3 moved, and 1022 from stop 73 to 76; 1014 until single-precision sines and
    // cosines, stop 54.)
    // (A seed that shows the mechanism, not a sweep's verdict:
    // over fresh seeds 1011-1170, of the 103 tracked up to the blackout, 84 are
    // re-acquired with it and 76 without; docs/recovery.md.) The re-acquisition is judged
    // without the free settling after it (`settle_frames` 0), which brings this seed's other
    // starts onto the hand as well and hides the pose's effect.
    assert!(FinderConfig::default().local_library_pose, "on by default");
    let with = FinderConfig {
        settle_frames: 0,
        ..FinderConfig::default()
    };
    let without = FinderConfig {
        local_library_pose: false,
        ..with
    };
    reacquired_only_with(1048, with, without, without_rows(), "the library pose");
}

#[test]
fn a_hand_back_in_view_that_the_local_reacquisition_cannot_take_goes_to_the_global_search() {
    // The local re-acquisition tries variants of the last good state; a hand that turned or
    // moved farther while hidden is back in view (its starts refine to something) but none
    // is accepted. After `FinderConfig::local_frames_in_view` (8) such frames the global
    // search takes over instead of waiting out all 60 local frames. `random-stereo` 1087 is
    // re-acquired only so. (A seed that shows the mechanism: over fresh seeds 1091-1250,
    // 132 of 160 are re-acquired after the blackout with it and 122 without;
    // docs/recovery.md.)
    let with = FinderConfig::default();
    assert!(with.local_frames_in_view > 0, "on by default");
    let without = FinderConfig {
        local_frames_in_view: 0,
        ..with
    };
    reacquired_only_with(
        1087,
        with,
        without,
        without_rows(),
        "the global search after 8 frames",
    );
}

#[test]
fn with_one_camera_the_local_reacquisition_runs_all_its_frames() {
    // One camera's global search acquires too rarely to give the local re-acquisition up
    // early: on `random-mono` 1011-1090 the global search after 8 frames took back 7 of the
    // 22 seeds tracked to the blackout, the local re-acquisition alone 12 (docs/recovery.md).
    // So `local_frames_in_view` applies with two or more cameras only. Even at 1, a mono
    // track (1082: its hand comes back and starts are refined without being taken) spends
    // every searching frame on the local re-acquisition until it claims the hand or its 60
    // frames end, while a stereo one (1087) turns to the global search.
    let dir = tempfile::tempdir().unwrap();
    let eager = FinderConfig {
        local_frames_in_view: 1,
        ..FinderConfig::default()
    };
    let first_search = 80 + LOST_FRAMES_BEFORE_SEARCH as usize;
    let searching = |line: &str| -> String {
        line[first_search..]
            .chars()
            .take(60)
            .take_while(|&c| c != 'y' && c != 'n')
            .collect()
    };
    let (_, line) = reacquired_after(
        dir.path(),
        "random-mono",
        1082,
        140,
        80..110,
        eager,
        without_rows(),
    );
    println!("mono:   {line}");
    let s = searching(&line);
    assert!(
        s.matches('L').count() >= 2,
        "the rule would not have applied: {line}"
    );
    assert!(
        s.chars().all(|c| c == 'l' || c == 'L'),
        "mono left the local search: {line}"
    );
    let (_, line) = reacquired_after(
        dir.path(),
        "random-stereo",
        1087,
        140,
        80..110,
        eager,
        without_rows(),
    );
    println!("stereo: {line}");
    assert!(
        searching(&line).contains('.'),
        "stereo never turned to the global search: {line}"
    );
}

#[test]
fn two_cameras_polish_the_fingers_of_a_re_acquisition_after_its_confirm_phase() {
    // Re-acquired after a blackout, a stereo track often holds the palm and has a finger or
    // two wrong. When the confirm phase ends, each finger of its best is given the library's
    // pose that scores best and the polished state, scoring more, is carried for another
    // phase (`FinderConfig::polish_margin`). `random-stereo` 5603 and 5663 (200 frames,
    // the search's and the tracker's defaults) are re-acquired only with it: under stop 77's
    // single-view width rows (`EstimatorConfig::single_view_width_weight` 0.25) the probe
    // named below, on 5601-5700, finds these two alone (of the 84 tracked to the blackout, 73
    // re-acquired with it, 71 without); 5469 and 5558 no longer are with it. (Seeds that
    // show the mechanism, not a sweep's verdict: under stop 73's defaults, the slice window at
    // 16 px and the outermost share 0.3, `acquire_probe --seeds A..=B --rigs stereo --frames
    // 200 --blackout 80..110 --limit-px 20` with and without `--polish-margin -1,-1`: of
    // 5415-5480, 5469 is re-acquired only with it and 5453 only without; of the 86 seeds of
    // 5481-5600 tracked to the blackout, 78 are re-acquired with it and 77 without, 5558 only
    // with it. Stop 72's 5377 and 5399, found on 5301-5414 under the share 0.5, show no
    // polish under 0.3; stop 69's 5029 and 5138, found under a 20 px window, none under
    // 16 px; stop 68's 5157 was re-acquired without it.)
    assert_eq!(
        FinderConfig::default().polish(2),
        Some(0.0),
        "on with two cameras by default"
    );
    assert_eq!(FinderConfig::default().polish(1), None, "off with one");
    let with = FinderConfig::default();
    let without = FinderConfig {
        polish_margin: [-1.0, -1.0],
        ..with
    };
    let dir = tempfile::tempdir().unwrap();
    for seed in [5603, 5663] {
        let run = |finder| {
            reacquired_after(
                dir.path(),
                "random-stereo",
                seed,
                200,
                80..110,
                finder,
                TrackerConfig::default(),
            )
        };
        let (back, line) = run(with);
        println!("{seed} polished:     {line}");
        assert!(
            back.is_some(),
            "{seed} not re-acquired with the polish: {line}"
        );
        let (back, line) = run(without);
        println!("{seed} not polished: {line}");
        assert!(
            back.is_none(),
            "{seed} re-acquired without the polish: {line}"
        );
    }
}

#[test]
fn the_local_reacquisition_turns_the_last_good_palm_far_enough_to_meet_a_rolled_hand() {
    // While the hand is hidden its palm turns on; the local re-acquisition's variants turn
    // the last good palm about each of its axes (`FinderConfig::local_turn_rad`). At 0.3 rad
    // `random-stereo` 3220 takes no start back in the 30 frames after its blackout; at 0.7
    // rad (the default) it is re-acquired, after ten frames on a wrong hand. (3214, whose
    // hand came back rolled 40-50 degrees, showed it until sines and cosines were computed
    // in single precision, stop 54, which moved its run by rounding; of the even seeds
    // 3202-3330, 3220 is the one re-acquired only at 0.7 rad whose runs agree up to the
    // blackout.)
    // (A seed that shows the mechanism, not a sweep's verdict: over 583 seeds of 2751-3550,
    // 531 of those tracked to the blackout are re-acquired at 0.7 rad and 522 at 0.3;
    // docs/recovery.md.)
    let with = FinderConfig::default();
    assert_eq!(with.local_turn_rad, LOCAL_TURN_RAD);
    assert!((LOCAL_TURN_RAD - 0.7).abs() < 1e-6, "0.7 rad by default");
    let without = FinderConfig {
        local_turn_rad: 0.3,
        ..with
    };
    reacquired_only_with(
        3220,
        with,
        without,
        TrackerConfig::default(),
        "the palm turned 0.7 rad",
    );
}
