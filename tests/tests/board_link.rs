//! The host and the simulated Linux board over a real pseudo-terminal serial link: states
//! equal to the in-process tracker's, a noisy window, a power cycle, a wrong-size frame, and
//! a missing device. Every wait is on a message or a condition, with a timeout that fails.

use std::path::Path;
use std::time::Duration;

use digiteyes_core::frame::FrameView;
use digiteyes_core::protocol::{DropReason, Start, State, WireStatus};
use digiteyes_host::acquire::Status;
use digiteyes_host::link::{DropCause, FrameOutcome, Link, Session, SessionSetup};
use digiteyes_host::sequence::Sequence;
use digiteyes_host::sim::{Corruption, SimBoard, SimOptions, SimReport, Window};
use digiteyes_host::track::{sequence_auto_tracker, Init, TrackOptions};
use digiteyes_host::{
    render_scenario, sequence_tracker, stream_sequence, RenderOptions, StreamOptions,
    StreamSummary, TrackerConfig,
};

mod common;
use common::mouse;

/// Streams `seq` to a simulated board set up with `options`.
fn stream_to_sim(
    seq: &Path,
    options: SimOptions,
    reply_timeout: Duration,
) -> (StreamSummary, SimReport) {
    let board = SimBoard::start(options).unwrap();
    let out = seq.join("board-states.csv");
    let stream =
        StreamOptions::new(board.path().display().to_string()).reply_timeout(reply_timeout);
    let summary = stream_sequence(seq, &out, &stream).unwrap();
    let report = board.stop().unwrap();
    (summary, report)
}

fn tracked(outcome: &FrameOutcome) -> bool {
    matches!(outcome, FrameOutcome::Tracked(_))
}

/// Calls `f` with each frame's number, the frame as the in-process tracker reads it, and the
/// board's `State` for it; fails on a frame the board did not answer with one.
fn each_answered(
    sequence: &Sequence,
    summary: &StreamSummary,
    mut f: impl FnMut(usize, FrameView<'_>, &State),
) {
    for (k, outcome) in summary.outcomes.iter().enumerate() {
        let image = sequence.read_frame(0, k).unwrap();
        let view = FrameView::packed(
            image.as_raw(),
            image.width() as usize,
            image.height() as usize,
        )
        .unwrap();
        let FrameOutcome::Tracked(state) = outcome else {
            panic!("frame {k} not answered by the board: {outcome:?}");
        };
        f(k, view, state);
    }
}

fn bits(q: &[f32]) -> Vec<u32> {
    q.iter().map(|v| v.to_bits()).collect()
}

#[test]
fn states_over_the_link_equal_the_in_process_tracker() {
    let dir = tempfile::tempdir().unwrap();
    let seq = mouse(dir.path(), 12);
    let (summary, _) = stream_to_sim(&seq, SimOptions::default(), Duration::from_secs(5));
    assert_eq!(summary.outcomes.len(), 12);

    // The in-process tracker, exactly as `digiteyes track` sets it up.
    let sequence = Sequence::open(&seq).unwrap();
    let mut tracker = sequence_tracker(&sequence, TrackerConfig::default()).unwrap();
    each_answered(&sequence, &summary, |k, view, state| {
        let report = tracker.track(&[view]).unwrap();
        assert_eq!(state.frame, k as u32);
        assert_eq!(
            bits(&state.q),
            bits(tracker.state()),
            "frame {k}: board {:?} host {:?}",
            state.q,
            tracker.state()
        );
        assert_eq!(state.rms_px.to_bits(), report.rms_px.to_bits(), "frame {k}");
        assert_eq!(
            (
                state.iterations,
                state.features_found,
                state.features_expected,
                state.lost
            ),
            (
                report.iterations,
                report.features_found,
                report.features_expected,
                report.lost
            ),
            "frame {k}"
        );
    });
    let link = &summary.link;
    assert!(link.pong, "the final ping was answered");
    assert_eq!(link.host_link.crc_errors + link.host_link.framing_errors, 0);
    let board = link.board.unwrap();
    assert_eq!(board.frames, 12);
    assert_eq!(board.link.crc_errors + board.link.framing_errors, 0);
}

#[test]
fn one_percent_noise_mid_stream_costs_only_the_noisy_frames() {
    const FRAMES: usize = 16;
    const NOISY: std::ops::Range<u32> = 6..9;
    let dir = tempfile::tempdir().unwrap();
    let seq = mouse(dir.path(), FRAMES);
    let noise = Corruption {
        rate: 0.01,
        window: Window::Frames(NOISY),
        seed: 3,
    };
    let (summary, line) = stream_to_sim(
        &seq,
        SimOptions::default().corruption(noise),
        Duration::from_secs(1),
    );
    let link = &summary.link;
    let board = link.board.expect("the board's counters after the noise");
    println!("{summary}");
    println!("{line}");
    println!(
        "corruption figures: {} frames, {} delivered, {} dropped {:?}; bytes hit: {} of {} \
         host->board, {} of {} board->host; CRC errors: board {} (+{} framing), host {} (+{} \
         framing)",
        summary.frames,
        link.tracked,
        link.dropped_total(),
        summary.dropped(),
        line.corrupted_in,
        line.bytes_in,
        line.corrupted_out,
        line.bytes_out,
        board.link.crc_errors,
        board.link.framing_errors,
        link.host_link.crc_errors,
        link.host_link.framing_errors
    );

    // Every frame is accounted for, in order.
    assert_eq!(summary.outcomes.len(), FRAMES);
    assert_eq!(link.tracked + link.dropped_total(), FRAMES);
    for (k, outcome) in summary.outcomes.iter().enumerate() {
        if !NOISY.contains(&(k as u32)) {
            // Before the window, and from the first frame after it: resynchronised.
            assert!(tracked(outcome), "frame {k} outside the noise: {outcome:?}");
        }
    }
    assert!(
        summary.outcomes[NOISY.start as usize..NOISY.end as usize]
            .iter()
            .any(|o| !tracked(o)),
        "1% of the bytes of ~1 KB chunks should cost frames"
    );
    // The noise reached both directions and both receivers counted it.
    assert!(line.corrupted_in > 0 && line.corrupted_out > 0, "{line}");
    let board_errors = board.link.crc_errors + board.link.framing_errors + board.link.overflows;
    assert!(board_errors > 0, "{board:?}");
    // Plausible: no more damaged frames than bytes hit (one hit spoils at most one frame,
    // though a hit delimiter may merge two frames into one bad one).
    assert!(
        u64::from(board_errors) <= line.corrupted_in,
        "{board:?} {line}"
    );
    let host_errors =
        link.host_link.crc_errors + link.host_link.framing_errors + link.host_link.overflows;
    assert!(
        u64::from(host_errors) <= line.corrupted_out,
        "{link:?} {line}"
    );
}

#[test]
fn a_board_power_cycle_mid_sequence_is_followed() {
    let dir = tempfile::tempdir().unwrap();
    let seq = mouse(dir.path(), 10);
    let (summary, line) = stream_to_sim(
        &seq,
        SimOptions::default().restart_after(5),
        Duration::from_secs(5),
    );
    println!("{summary}");
    assert_eq!(line.restarts, 1);
    assert_eq!(summary.link.restarts, 1);
    for (k, outcome) in summary.outcomes.iter().enumerate() {
        if k == 5 {
            // The frame in flight when the board rebooted.
            assert_eq!(
                outcome,
                &FrameOutcome::Dropped(DropCause::BoardRestarted),
                "frame 5"
            );
        } else {
            assert!(tracked(outcome), "frame {k}: {outcome:?}");
        }
    }
    // The rebooted board counted from its boot: the frames after the restart.
    assert_eq!(summary.link.board.unwrap().frames, 4);
}

/// A board finds the hand from nothing, loses it while the camera sees no hand, and finds it
/// again once it is back — state for state and status for status what `digiteyes track
/// --init auto` does in process (the same status machine, search and budget).
#[test]
fn a_board_finds_the_hand_loses_it_in_a_blackout_and_finds_it_again_as_the_host_does() {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("mouse");
    let (dark, n) = (30..50, 70);
    let options = RenderOptions {
        frames: Some(n),
        size: Some((320, 240)),
        supersample: 2,
        blackout: Some(dark.clone()),
        ..RenderOptions::default()
    };
    render_scenario("mouse", &seq, &options).unwrap();
    let board = SimBoard::start(SimOptions::default()).unwrap();
    let out = seq.join("board-states.csv");
    let stream = StreamOptions::new(board.path().display().to_string())
        .reply_timeout(Duration::from_secs(10))
        .start(Some(Start::Search));
    let summary = stream_sequence(&seq, &out, &stream).unwrap();
    board.stop().unwrap();

    let sequence = Sequence::open(&seq).unwrap();
    let track = TrackOptions {
        init: Some(Init::Auto),
        ..TrackOptions::default()
    };
    let mut host = sequence_auto_tracker(&sequence, TrackerConfig::default(), &track).unwrap();
    let mut statuses = String::new();
    each_answered(&sequence, &summary, |k, view, state| {
        let expected = host.step(&[view]).unwrap();
        assert_eq!(Status::from(state.status), expected.status, "frame {k}");
        assert_eq!(bits(&state.q), bits(host.state()), "frame {k}");
        statuses.push_str(&expected.status.as_str()[..1]);
    });
    // Found from nothing, lost in the dark (and searched for), found again after it.
    let first = statuses.find('t').expect("never acquired");
    assert!(first < 10, "acquired at frame {first}: {statuses}");
    assert!(
        statuses[dark.clone()].chars().all(|c| c != 't'),
        "a hand claimed in the dark: {statuses}"
    );
    assert!(statuses[dark.clone()].contains('s'), "{statuses}");
    let back = statuses[dark.end..].find('t').expect("never re-acquired") + dark.end;
    assert!(
        back < dark.end + 10,
        "re-acquired at frame {back}: {statuses}"
    );
    assert!(statuses[back..].chars().all(|c| c == 't'), "{statuses}");
}

/// A board that was searching when it rebooted is set up to search again (not to track the
/// state it sent while searching, which is no estimate); one that was tracking resumes from its
/// last state.
#[test]
fn a_searching_board_that_reboots_searches_again() {
    let dir = tempfile::tempdir().unwrap();
    let seq = mouse(dir.path(), 4);
    let sequence = Sequence::open(&seq).unwrap();
    for (start, after_reboot) in [
        (Start::Search, WireStatus::Searching),
        (Start::Given, WireStatus::Tracking),
    ] {
        let board = SimBoard::start(SimOptions::default().restart_after(1)).unwrap();
        let link = Link::open(&board.path().display().to_string(), 115_200).unwrap();
        let mut setup = SessionSetup::from_sequence(&sequence, None).unwrap();
        setup.start = start;
        setup.reply_timeout = Duration::from_secs(5);
        let mut session = Session::start(link, setup).unwrap();
        let frame = |k| sequence.read_frame(0, k).unwrap().into_raw();
        let status = |outcome: FrameOutcome| match outcome {
            FrameOutcome::Tracked(state) => state.status,
            other => panic!("{start:?}: {other:?}"),
        };
        // The first frame of a search can only search; a given start tracks.
        let first = status(session.track(0, &frame(0), 320, 240).unwrap());
        let expected_first = match start {
            Start::Search => WireStatus::Searching,
            Start::Given => WireStatus::Tracking,
        };
        assert_eq!(first, expected_first);
        assert_eq!(
            session.track(1, &frame(1), 320, 240).unwrap(),
            FrameOutcome::Dropped(DropCause::BoardRestarted),
            "{start:?}: the board rebooted under frame 1"
        );
        let next = status(session.track(2, &frame(2), 320, 240).unwrap());
        assert_eq!(next, after_reboot, "{start:?}: the frame after the reboot");
        board.stop().unwrap();
    }
}

#[test]
fn a_wrong_size_frame_is_refused_and_the_next_one_tracked() {
    let dir = tempfile::tempdir().unwrap();
    let seq = mouse(dir.path(), 2);
    let sequence = Sequence::open(&seq).unwrap();
    let board = SimBoard::start(SimOptions::default()).unwrap();
    let link = Link::open(&board.path().display().to_string(), 115_200).unwrap();
    let mut session =
        Session::start(link, SessionSetup::from_sequence(&sequence, None).unwrap()).unwrap();
    let frame = |k| sequence.read_frame(0, k).unwrap().into_raw();

    assert!(tracked(&session.track(0, &frame(0), 320, 240).unwrap()));
    let small = vec![0u8; 160 * 120];
    assert_eq!(
        session.track(1, &small, 160, 120).unwrap(),
        FrameOutcome::Dropped(DropCause::Board(DropReason::WrongSize(160, 120)))
    );
    assert!(tracked(&session.track(2, &frame(1), 320, 240).unwrap()));
    let report = session.finish().unwrap();
    assert_eq!(report.board.unwrap().dropped.wrong_size, 1);
}

#[test]
fn a_stereo_sequence_needs_a_camera_picked() {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("stereo");
    let options = RenderOptions {
        frames: Some(1),
        size: Some((160, 120)),
        supersample: 1,
        ..RenderOptions::default()
    };
    render_scenario("fullhand-stereo", &seq, &options).unwrap();
    let sequence = Sequence::open(&seq).unwrap();
    let err = SessionSetup::from_sequence(&sequence, None).unwrap_err();
    assert!(format!("{err:#}").contains("--camera-index"), "{err:#}");
    assert!(SessionSetup::from_sequence(&sequence, Some(1)).is_ok());
    assert!(SessionSetup::from_sequence(&sequence, Some(2)).is_err());
}

#[test]
fn a_missing_device_is_named() {
    let err = Link::open("/nonexistent/ttyDIGITEYES", 115_200).unwrap_err();
    assert!(
        format!("{err:#}").contains("/nonexistent/ttyDIGITEYES"),
        "{err:#}"
    );
}
