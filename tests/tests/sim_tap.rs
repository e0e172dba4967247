//! The simulated board's frame tap: every tracked frame handed to the host with the state the
//! board streamed back for it (bit for bit), its pixels and camera; frames a skipping tap has
//! no room for counted, not lost silently; and `sim --overlay`'s PNG writer. Every wait is on
//! a message, a channel or a thread, never a sleep.

use std::path::Path;
use std::sync::mpsc::sync_channel;
use std::time::Duration;

use digiteyes_host::link::FrameOutcome;
use digiteyes_host::overlay::{colours, overlay_path};
use digiteyes_host::sequence::Sequence;
use digiteyes_host::sim::{FrameTap, SimBoard, SimFrame, SimOptions, SimReport, TapMode};
use digiteyes_host::{stream_sequence, StreamOptions, StreamSummary};

mod common;
use common::mouse;

/// Streams `seq` to a simulated board set up with `options`, then stops the board.
fn stream_to_sim(seq: &Path, options: SimOptions) -> (StreamSummary, SimReport) {
    let board = SimBoard::start(options).unwrap();
    let stream = StreamOptions::new(board.path().display().to_string())
        .reply_timeout(Duration::from_secs(5));
    let summary = stream_sequence(seq, &seq.join("board-states.csv"), &stream).unwrap();
    let report = board.stop().unwrap();
    (summary, report)
}

fn bits(q: &[f32]) -> Vec<u32> {
    q.iter().map(|v| v.to_bits()).collect()
}

#[test]
fn every_tracked_frame_is_tapped_with_the_state_streamed_back() {
    let dir = tempfile::tempdir().unwrap();
    let seq = mouse(dir.path(), 8);
    // A channel of 2 the test drains on a thread of its own: the board waits for it at times.
    let (sender, receiver) = sync_channel::<SimFrame>(2);
    let collector = std::thread::spawn(move || receiver.iter().collect::<Vec<_>>());
    let tap = FrameTap::every(sender);
    assert_eq!(tap.mode(), TapMode::Every);
    let (summary, report) = stream_to_sim(&seq, SimOptions::default().frame_tap(tap));
    // The board is stopped: its tap is dropped, so the collector's channel has closed.
    let frames = collector.join().unwrap();

    let sequence = Sequence::open(&seq).unwrap();
    let camera = sequence.cameras[0];
    assert_eq!(summary.outcomes.len(), 8);
    assert_eq!(frames.len(), 8, "one tapped frame per tracked frame");
    assert_eq!((report.tapped, report.tap_skipped), (8, 0));
    assert!(report
        .to_string()
        .contains("8 frame(s) handed over, 0 skipped"));
    for (k, (outcome, tapped)) in summary.outcomes.iter().zip(&frames).enumerate() {
        let FrameOutcome::Tracked(state) = outcome else {
            panic!("frame {k} not tracked: {outcome:?}");
        };
        assert_eq!(tapped.frame, k as u32);
        assert_eq!(tapped.frame, state.frame);
        assert_eq!(bits(&tapped.q), bits(&state.q), "frame {k}");
        assert_eq!(tapped.lost, state.lost);
        assert_eq!(tapped.rms_px.to_bits(), state.rms_px.to_bits());
        assert_eq!(tapped.iterations, state.iterations);
        assert_eq!(
            (tapped.features_found, tapped.features_expected),
            (state.features_found, state.features_expected)
        );
        assert_eq!(tapped.boot, 0);
        assert_eq!((tapped.width, tapped.height), (320, 240));
        let image = sequence.read_frame(0, k).unwrap();
        assert!(tapped.pixels == *image.as_raw(), "frame {k}: pixels differ");
        assert_eq!(
            (tapped.camera.width, tapped.camera.height),
            (camera.width, camera.height)
        );
        for (a, b) in [
            (tapped.camera.fx, camera.fx),
            (tapped.camera.cy, camera.cy),
            (tapped.camera.t.z, camera.t.z),
            (tapped.camera.r[(2, 1)], camera.r[(2, 1)]),
        ] {
            assert!((a - b).abs() <= 1e-4 * b.abs().max(1.0), "{a} vs {b}");
        }
    }
}

#[test]
fn a_skipping_tap_counts_the_frames_it_had_no_room_for() {
    let dir = tempfile::tempdir().unwrap();
    let seq = mouse(dir.path(), 6);
    // Room for one frame and nobody reading until the board stops: the first frame goes in,
    // the other five are skipped, and counted.
    let (sender, receiver) = sync_channel::<SimFrame>(1);
    let options = SimOptions::default().frame_tap(FrameTap::skipping(sender));
    let (summary, report) = stream_to_sim(&seq, options);
    assert_eq!(summary.tracked(), 6, "skipping never holds the board up");
    assert_eq!((report.tapped, report.tap_skipped), (1, 5));
    let frames: Vec<SimFrame> = receiver.iter().collect();
    assert_eq!(frames.len(), 1);
    assert_eq!(frames[0].frame, 0);

    // A tap whose receiver is gone: every frame counted as skipped, the board unaffected.
    let (sender, receiver) = sync_channel::<SimFrame>(4);
    drop(receiver);
    let options = SimOptions::default().frame_tap(FrameTap::every(sender));
    let (summary, report) = stream_to_sim(&seq, options);
    assert_eq!(summary.tracked(), 6);
    assert_eq!((report.tapped, report.tap_skipped), (0, 6));
}

#[test]
fn sim_overlay_writes_every_tracked_frame_as_a_png() {
    let dir = tempfile::tempdir().unwrap();
    let seq = mouse(dir.path(), 5);
    let out = dir.path().join("overlay");
    let (tap, writer) = digiteyes_host::sim::overlay_tap(&out).unwrap();
    let (summary, report) = stream_to_sim(&seq, SimOptions::default().frame_tap(tap));
    assert_eq!(summary.tracked(), 5);
    assert_eq!((report.tapped, report.tap_skipped), (5, 0));
    let stats = writer.finish().unwrap();
    assert_eq!((stats.files, stats.undrawable), (5, 0));
    for k in 0..5 {
        let path = overlay_path(&out, 0, k);
        let image = image::open(&path).unwrap().into_rgb8();
        assert_eq!(image.dimensions(), (320, 240), "{path:?}");
        let axis = image.pixels().filter(|p| **p == colours::AXIS).count();
        assert!(axis > 20, "{path:?}: {axis} axis pixels");
    }
}

#[test]
fn sim_ui_shows_the_last_tracked_frame_and_its_state() {
    use digiteyes_host::sim::ui_tap::ui_tap;
    use digiteyes_host::ui::Hub;

    let dir = tempfile::tempdir().unwrap();
    let seq = mouse(dir.path(), 4);
    let hub = Hub::new(
        digiteyes_core::model::Model::hand().unwrap(),
        Vec::new(),
        "simulated board",
    );
    let (tap, feeder) = ui_tap(std::sync::Arc::clone(&hub)).unwrap();
    let (summary, report) = stream_to_sim(&seq, SimOptions::default().frame_tap(tap));
    // The board is stopped and its tap dropped: the feeder has handed over all it was given.
    feeder.join().unwrap();
    assert_eq!(report.tapped + report.tap_skipped, 4);
    let snapshot = hub.snapshot();
    assert_eq!(snapshot.link.states, report.tapped);
    let Some(FrameOutcome::Tracked(last)) = summary.outcomes.last() else {
        panic!("the last frame was not tracked");
    };
    // The board hands over the newest frames it has room for; the last one always fits once
    // the feeder has drained the queue, but a busy feeder may have skipped it, so compare
    // with the frame the page shows, whichever it is.
    let shown = snapshot.state.expect("a state on the page");
    let camera_frame = snapshot.camera_frame.expect("a camera frame on the page");
    assert_eq!(camera_frame, shown.frame);
    let outcome = &summary.outcomes[shown.frame as usize];
    let FrameOutcome::Tracked(state) = outcome else {
        panic!("frame {} not tracked", shown.frame);
    };
    assert_eq!(bits(&shown.q), bits(&state.q));
    assert_eq!(shown.features_found, state.features_found);
    assert!(shown.frame <= last.frame);
    let frame = hub.camera_frame().unwrap();
    assert_eq!(frame.image.dimensions(), (320, 240));
    assert_eq!(snapshot.shapes.len(), 16);
}
