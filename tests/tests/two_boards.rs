//! Two simulated boards, one hand (issue 13): each board holds one camera's frames and
//! searches them at the host's state; the host fuses both in one solve per iteration. The
//! states must be those of the in-process stereo tracker at the same iteration count, and a
//! board that goes deaf mid-run must be left out and taken back.

use std::path::{Path, PathBuf};
use std::time::Duration;

use digiteyes_core::frame::FrameView;
use digiteyes_core::protocol::TrackerParams;
use digiteyes_host::sequence::{read_states, Sequence};
use digiteyes_host::sim::{SimBoard, SimOptions};
use digiteyes_host::stereo::{
    boards_config, stream_stereo, wire_config, StereoOptions, StereoSummary,
};
use digiteyes_host::{render_scenario, sequence_tracker, RenderOptions, TrackerConfig};

/// A short whole-hand stereo sequence at 320×240 in `dir/stereo`.
fn stereo(dir: &Path, frames: usize) -> PathBuf {
    let seq = dir.join("stereo");
    let options = RenderOptions {
        frames: Some(frames),
        size: Some((320, 240)),
        supersample: 2,
        ..RenderOptions::default()
    };
    render_scenario("fullhand-stereo", &seq, &options).unwrap();
    seq
}

fn config(iterations: u8) -> TrackerConfig {
    let mut config = TrackerConfig::default();
    config.iterations = iterations;
    wire_config(&config).unwrap()
}

/// The in-process stereo tracker's states, frame by frame.
fn in_process(seq: &Path, config: TrackerConfig) -> Vec<Vec<f32>> {
    let sequence = Sequence::open(seq).unwrap();
    let mut tracker = sequence_tracker(&sequence, config).unwrap();
    (0..sequence.frames)
        .map(|k| {
            let images: Vec<_> = (0..sequence.cameras.len())
                .map(|c| sequence.read_frame(c, k).unwrap())
                .collect();
            let views: Vec<_> = images
                .iter()
                .map(|i| FrameView::packed(i.as_raw(), i.width() as usize, i.height() as usize))
                .collect::<Result<_, _>>()
                .unwrap();
            tracker.track(&views).unwrap();
            tracker.state().to_vec()
        })
        .collect()
}

/// Streams `seq` to one simulated board per option set.
fn two_boards(
    seq: &Path,
    boards: [SimOptions; 2],
    iterations: u8,
    reply_timeout: Duration,
) -> StereoSummary {
    let boards = boards.map(|o| SimBoard::start(o).unwrap());
    let ports = boards
        .iter()
        .map(|b| b.path().display().to_string())
        .collect();
    let mut options = StereoOptions::new(ports);
    options.tracker = TrackerParams::from_config(&config(iterations));
    options.reply_timeout = reply_timeout;
    let summary = stream_stereo(seq, &seq.join("two-boards.csv"), &options).unwrap();
    for b in boards {
        b.stop().unwrap();
    }
    summary
}

fn rows(seq: &Path, n_states: usize) -> Vec<Vec<f32>> {
    let table = read_states(&seq.join("two-boards.csv"), n_states).unwrap();
    table
        .rows
        .iter()
        .map(|r| r.iter().map(|&v| v as f32).collect())
        .collect()
}

#[test]
fn two_boards_give_the_in_process_stereo_states() {
    let dir = tempfile::tempdir().unwrap();
    let seq = stereo(dir.path(), 8);
    for iterations in [1, 4] {
        let summary = two_boards(
            &seq,
            [SimOptions::default(), SimOptions::default()],
            iterations,
            Duration::from_secs(5),
        );
        println!("{summary}");
        assert_eq!(summary.frames, 8);
        for b in &summary.boards {
            assert_eq!(b.unanswered, 0, "{b:?}");
            assert_eq!(b.frames_without, 0, "{b:?}");
            assert!(b.answered >= 8, "{b:?}");
        }
        // The host's solve over boards has no region rows (the boards send features, not
        // frames): the in-process reference is the same tracker without them.
        let wire = TrackerParams::from_config(&config(iterations));
        let reference = in_process(&seq, boards_config(&wire).unwrap());
        let got = rows(&seq, reference[0].len());
        assert_eq!(got.len(), reference.len());
        let mut worst = 0.0f32;
        for (k, (a, b)) in got.iter().zip(&reference).enumerate() {
            for (s, (x, y)) in a.iter().zip(b).enumerate() {
                let d = (x - y).abs();
                assert!(d <= 1e-4, "frame {k} q{s}: boards {x}, in process {y}");
                worst = worst.max(d);
            }
        }
        println!("{iterations} iteration(s): largest difference {worst:e}");
    }
}

#[test]
fn a_board_that_goes_deaf_is_left_out_and_taken_back() {
    let dir = tempfile::tempdir().unwrap();
    let seq = stereo(dir.path(), 12);
    // Board 1 hears nothing while frames 4..=7 are uploaded (counted from 1: frames 3..=6).
    let summary = two_boards(
        &seq,
        [SimOptions::default(), SimOptions::default().deaf(3, 4)],
        2,
        Duration::from_millis(500),
    );
    println!("{summary}");
    assert_eq!(summary.frames, 12, "every frame gets its row");
    let (steady, deaf) = (&summary.boards[0], &summary.boards[1]);
    assert_eq!(steady.frames_without, 0, "{steady:?}");
    assert_eq!(steady.unanswered, 0, "{steady:?}");
    assert_eq!(deaf.left_out, 1, "{deaf:?}");
    assert_eq!(deaf.taken_back, 1, "{deaf:?}");
    assert_eq!(deaf.frames_without, 4, "{deaf:?}");
    assert!(deaf.last_problem.is_some());
    // The hand is still tracked on one camera meanwhile, and by both after.
    let truth = Sequence::open(&seq).unwrap().read_truth().unwrap();
    let got = rows(&seq, truth.rows[0].len());
    for (k, (row, t)) in got.iter().zip(&truth.rows).enumerate() {
        let palm_mm = (4..7)
            .map(|s| (f64::from(row[s]) - t[s]).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!(palm_mm < 15.0, "frame {k}: palm {palm_mm:.1} mm off");
    }
}
