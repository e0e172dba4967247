//! Several hypotheses on the board (protocol version 5): `Configure` sets the count K; a board
//! with K > 1 answers each frame with its `State` and then a `Hypotheses` message, and both
//! are bit-equal to an in-process `AutoTracker` with the same K on the same frames of a
//! rendered whole hand; K = 1 sends no `Hypotheses`; K = 0 or more than `MAX_HYPOTHESES` is
//! refused; a `Configure` that changes only K applies it from the next frame. Scored one
//! frame in S (protocol version 9), the board is bit-equal to the tracker in process with the
//! same S, and S = 0 is refused.

mod common;

use common::*;
use digiteyes_core::auto_tracker::AutoTracker;
use digiteyes_core::config::MAX_HYPOTHESES;
use digiteyes_core::estimator::FreeMask;
use digiteyes_core::frame::FrameView;
use digiteyes_core::model::Model;
use digiteyes_core::protocol::*;
use digiteyes_core::status::Status;
use digiteyes_firmware::{edge_map_bytes, hypotheses_config, search_config};

const FRAME_BYTES: usize = (WIDTH * HEIGHT) as usize;

/// Every state of the whole hand is estimated.
fn free_all(model: &Model) -> u32 {
    (0..model.n_states()).map(|s| 1u32 << s).sum()
}

/// `Configure` with `hypotheses` scored one frame in `score_every`, their Gauss–Newton
/// iterations capped at `caps` = `[sample, other]` (0: the tracker's own), the finger-undo
/// candidates weighed.
fn configure_capped(hypotheses: u8, score_every: u8, caps: [u8; 2]) -> Configure {
    Configure {
        hypotheses: HypothesesParams {
            count: hypotheses,
            score_every,
            sample_iterations: caps[0],
            other_iterations: caps[1],
            ..HypothesesParams::default()
        },
        ..Configure::new(
            CameraParams::from_camera(&camera()).unwrap(),
            TrackerParams::default(),
        )
    }
}

fn configure(hypotheses: u8, score_every: u8) -> HostMessage<'static> {
    HostMessage::Configure(configure_capped(hypotheses, score_every, [0, 0]))
}

/// A board after boot, `Configure`d as `wanted`, and `Reset` tracking from `q0`.
fn started<'m>(buffer: &'m mut [u8], wanted: Configure, q0: &[f32], free: u32) -> TestBoard<'m> {
    let mut board = test_board("hypotheses", buffer);
    board.start().unwrap();
    board.serial_mut().send(&HostMessage::Configure(wanted));
    board.serial_mut().send(&HostMessage::Reset(Reset {
        q: q0.iter().copied().collect(),
        free,
        start: Start::Given,
    }));
    board.poll().unwrap();
    let replies = board.serial_mut().received();
    assert!(
        replies.contains(&BoardMessage::Ack(Command::Configure))
            && replies.ends_with(&[BoardMessage::Ack(Command::Reset)]),
        "{replies:?}"
    );
    board
}

/// The bits of a list of floats, so NaN and −0 compare exactly.
fn bits(values: &[f32]) -> Vec<u32> {
    values.iter().map(|v| v.to_bits()).collect()
}

/// A hypothesis as bits: score, age, state.
fn hypothesis_bits(h: &WireHypothesis) -> (u32, u32, Vec<u32>) {
    (h.score.to_bits(), h.age, bits(&h.q))
}

/// The whole hand, fingers bending a little more each frame, rendered at 160×120.
fn sequence(model: &Model) -> Vec<Vec<u8>> {
    let cam = camera();
    [0.22f32, 0.26, 0.31, 0.37, 0.44, 0.52]
        .iter()
        .map(|&bend| render(model, &cam, &pose(model, bend)))
        .collect()
}

/// The board `Configure`d as `wanted` against `AutoTracker` in process with the same
/// hypotheses: every frame's `State` (state, status,
/// report) and `Hypotheses` (scores, ages, states, best first) bit-equal. Returns the most
/// hypotheses any frame carried.
fn board_matches_in_process(wanted: Configure) -> usize {
    let k = wanted.hypotheses.count;
    let model = Model::hand().unwrap();
    let q0 = pose(&model, 0.2);
    let free = free_all(&model);
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = started(&mut buffer, wanted, &q0, free);
    let tracker = TrackerParams::default().to_config().unwrap();
    let mut reference = AutoTracker::tracking(
        model.clone(),
        &[camera()],
        &q0,
        FreeMask(free),
        tracker,
        search_config(default_search_evaluations()),
    )
    .unwrap();
    reference.set_hypotheses(hypotheses_config(&wanted));
    let mut edges = vec![0u8; edge_map_bytes(WIDTH as usize, HEIGHT as usize)];
    let mut most = 0;
    for (n, pixels) in sequence(&model).iter().enumerate() {
        let n = n as u32;
        board
            .serial_mut()
            .send_frame(n, WIDTH as u16, HEIGHT as u16, pixels);
        board.poll().unwrap();
        let view = FrameView::packed(pixels, WIDTH as usize, HEIGHT as usize).unwrap();
        let expected = reference.step(&[view], &mut [&mut edges[..]]).unwrap();
        let (state, hypotheses) = match &board.serial_mut().received()[..] {
            [BoardMessage::State(s), BoardMessage::Hypotheses(h)] => (s.clone(), h.clone()),
            other => panic!("K = {k}, frame {n}: a State then Hypotheses expected, got {other:?}"),
        };
        assert_eq!((state.frame, hypotheses.frame), (n, n));
        assert_eq!(
            bits(&state.q),
            bits(reference.state()),
            "K = {k}, frame {n}"
        );
        assert_eq!(
            Status::from(state.status),
            expected.status,
            "K = {k}, frame {n}"
        );
        assert_eq!(
            (
                state.rms_px.to_bits(),
                state.iterations,
                state.features_found,
                state.features_expected
            ),
            (
                expected.report.rms_px.to_bits(),
                expected.report.iterations,
                expected.report.features_found,
                expected.report.features_expected
            ),
            "K = {k}, frame {n}"
        );
        let want: Vec<_> = reference
            .hypotheses()
            .iter()
            .map(|h| hypothesis_bits(&WireHypothesis::from(h)))
            .collect();
        let got: Vec<_> = hypotheses.hypotheses.iter().map(hypothesis_bits).collect();
        assert_eq!(got, want, "K = {k}, frame {n}: the hypotheses");
        assert_eq!(
            got.len(),
            usize::from(expected.hypotheses),
            "K = {k}, frame {n}"
        );
        assert!(got.len() <= usize::from(k));
        // The best hypothesis is the state reported.
        assert_eq!(got[0].2, bits(&state.q), "K = {k}, frame {n}: best first");
        most = most.max(got.len());
    }
    most
}

#[test]
fn a_board_with_two_hypotheses_is_bit_equal_to_the_tracker_in_process() {
    let most = board_matches_in_process(configure_capped(2, 1, [0, 0]));
    assert_eq!(most, 2, "two hypotheses were carried on some frame");
}

#[test]
fn a_board_scoring_one_frame_in_three_is_bit_equal_to_the_tracker_in_process() {
    let most = board_matches_in_process(configure_capped(2, 3, [0, 0]));
    assert_eq!(most, 2, "two hypotheses were carried on some frame");
}

/// Every hypothesis message a board `Configure`d as `wanted` sends over the test sequence,
/// as bits.
fn carried(wanted: Configure) -> Vec<Vec<(u32, u32, Vec<u32>)>> {
    let model = Model::hand().unwrap();
    let q0 = pose(&model, 0.2);
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = started(&mut buffer, wanted, &q0, free_all(&model));
    let mut all = Vec::new();
    for (n, pixels) in sequence(&model).iter().enumerate() {
        board
            .serial_mut()
            .send_frame(n as u32, WIDTH as u16, HEIGHT as u16, pixels);
        board.poll().unwrap();
        for message in board.serial_mut().received() {
            if let BoardMessage::Hypotheses(h) = message {
                all.push(h.hypotheses.iter().map(hypothesis_bits).collect::<Vec<_>>());
            }
        }
    }
    all
}

/// Scored one frame in S, the hypotheses differ from those scored every frame: S reaches
/// the board's tracker (the bit-equal test above would pass if both sides ignored it).
#[test]
fn scoring_one_frame_in_three_changes_what_the_board_carries() {
    let every = carried(configure_capped(2, 1, [0, 0]));
    let one_in_three = carried(configure_capped(2, 3, [0, 0]));
    assert_eq!(every.len(), one_in_three.len());
    assert_eq!(
        every[0], one_in_three[0],
        "the first frame is scored either way"
    );
    assert_ne!(every, one_in_three);
}

/// Capped at one iteration, the samples and the carried hypotheses other than the best
/// differ from those refined uncapped: both caps reach the board's tracker (the bit-equal
/// tests above would pass if both sides ignored them). (On these frames no finger-undo
/// candidate is ever kept, so its switch shows nothing here; `hypotheses_config` is checked
/// to carry it in `firmware/src/memory.rs`.)
#[test]
fn capping_the_hypotheses_budget_changes_what_the_board_carries() {
    let own = carried(configure_capped(2, 1, [0, 0]));
    let samples_capped = carried(configure_capped(2, 1, [1, 0]));
    let others_capped = carried(configure_capped(2, 1, [0, 1]));
    assert_eq!(own.len(), samples_capped.len());
    assert_ne!(own, samples_capped, "the sample cap changed nothing");
    assert_ne!(own, others_capped, "the cap on the others changed nothing");
    // A cap at or above the tracker's own number is no cap.
    let own_iterations = TrackerParams::default().iterations;
    assert_eq!(own, carried(configure_capped(2, 1, [own_iterations; 2])));
}

#[test]
fn a_board_with_four_hypotheses_is_bit_equal_to_the_tracker_in_process() {
    let most = board_matches_in_process(configure_capped(4, 1, [0, 0]));
    assert!(most >= 2, "several hypotheses were carried: at most {most}");
}

#[test]
fn a_board_with_capped_iterations_is_bit_equal_to_the_tracker_in_process() {
    let most = board_matches_in_process(configure_capped(4, 1, [1, 1]));
    assert!(most >= 2, "several hypotheses were carried: at most {most}");
}

#[test]
fn a_board_without_the_finger_undo_is_bit_equal_to_the_tracker_in_process() {
    let mut wanted = configure_capped(2, 4, [2, 2]);
    wanted.hypotheses.keep_fingers = false;
    let most = board_matches_in_process(wanted);
    assert_eq!(most, 2, "two hypotheses were carried on some frame");
}

#[test]
fn one_hypothesis_sends_no_hypotheses_message() {
    let model = Model::hand().unwrap();
    let q0 = pose(&model, 0.2);
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = started(
        &mut buffer,
        configure_capped(1, 1, [0, 0]),
        &q0,
        free_all(&model),
    );
    let pixels = render(&model, &camera(), &pose(&model, 0.22));
    board
        .serial_mut()
        .send_frame(0, WIDTH as u16, HEIGHT as u16, &pixels);
    board.poll().unwrap();
    assert!(matches!(
        &board.serial_mut().received()[..],
        [BoardMessage::State(s)] if s.status == WireStatus::Tracking
    ));
}

#[test]
fn configure_refuses_zero_hypotheses_more_than_the_capacity_and_scoring_never() {
    // (K, S): no hypotheses, more than the capacity, and scored one frame in none.
    for (k, s) in [
        (0u8, 1u8),
        (MAX_HYPOTHESES as u8 + 1, 1),
        (u8::MAX, 1),
        (2, 0),
    ] {
        let mut buffer = vec![0u8; FRAME_BYTES];
        let mut board = test_board("hypotheses", &mut buffer);
        board.start().unwrap();
        board.serial_mut().send(&configure(k, s));
        board.poll().unwrap();
        assert!(
            board.serial_mut().received().ends_with(&[BoardMessage::Nak(
                Command::Configure,
                Refusal::BadParameters
            )]),
            "K = {k}, S = {s}"
        );
        // Refused: the board has no camera, so a Reset is refused too.
        board.serial_mut().send(&HostMessage::Reset(Reset {
            q: pose(&Model::hand().unwrap(), 0.2).into_iter().collect(),
            free: 0,
            start: Start::Given,
        }));
        board.poll().unwrap();
        assert_eq!(
            board.serial_mut().received(),
            [BoardMessage::Nak(Command::Reset, Refusal::NotConfigured)],
            "K = {k}, S = {s}"
        );
    }
    // The largest count is taken.
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = test_board("hypotheses", &mut buffer);
    board.start().unwrap();
    board.serial_mut().send(&configure(MAX_HYPOTHESES as u8, 1));
    board.poll().unwrap();
    assert!(board
        .serial_mut()
        .received()
        .ends_with(&[BoardMessage::Ack(Command::Configure)]));
}

/// A `Configure` that changes only K keeps the board tracking (status, state, motion) and
/// applies the new count from the next frame: the `Hypotheses` message starts, and stops
/// again when K returns to 1.
#[test]
fn a_configure_changing_only_the_count_applies_it_from_the_next_frame() {
    let model = Model::hand().unwrap();
    let q0 = pose(&model, 0.2);
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = started(
        &mut buffer,
        configure_capped(1, 1, [0, 0]),
        &q0,
        free_all(&model),
    );
    let frames = sequence(&model);
    let mut kinds = Vec::new();
    for (n, (pixels, k)) in frames.iter().zip([1u8, 3, 3, 1]).enumerate() {
        board.serial_mut().send(&configure(k, 1));
        board
            .serial_mut()
            .send_frame(n as u32, WIDTH as u16, HEIGHT as u16, pixels);
        board.poll().unwrap();
        let replies = board.serial_mut().received();
        assert_eq!(replies[0], BoardMessage::Ack(Command::Configure));
        let BoardMessage::State(state) = &replies[1] else {
            panic!("frame {n}: {replies:?}")
        };
        assert_eq!(state.status, WireStatus::Tracking, "frame {n}");
        kinds.push(match &replies[2..] {
            [] => 0,
            [BoardMessage::Hypotheses(h)] => {
                assert!(!h.hypotheses.is_empty() && h.hypotheses.len() <= usize::from(k));
                h.hypotheses.len()
            }
            other => panic!("frame {n}: {other:?}"),
        });
    }
    assert_eq!(kinds[0], 0, "K = 1: no Hypotheses");
    assert!(kinds[1] >= 1 && kinds[2] >= 1, "K = 3: Hypotheses follow");
    assert_eq!(kinds[3], 0, "K = 1 again: none");
}
