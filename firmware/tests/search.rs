//! The board's status machine on the wire (protocol version 4): a board told to search
//! answers every frame, within its search budget, with `Searching` (and `lost`); a tracking
//! board reports `Tracking`, then `Lost` frames once the hand is gone, then `Searching` after
//! `LOST_FRAMES_BEFORE_SEARCH` of them; `Configure` refuses a budget of 0 and a camera whose
//! edge map does not fit, and a changed `Configure` keeps the status.

mod common;

use common::*;
use digiteyes_core::auto_tracker::{AutoTracker, LOST_FRAMES_BEFORE_SEARCH};
use digiteyes_core::estimator::FreeMask;
use digiteyes_core::frame::FrameView;
use digiteyes_core::model::Model;
use digiteyes_core::protocol::*;
use digiteyes_core::status::Status;
use digiteyes_core::tracker::TrackerConfig;
use digiteyes_firmware::{edge_map_bytes, search_config, Board, Buffers, NoLed, Uploads};

const FRAME_BYTES: usize = (WIDTH * HEIGHT) as usize;

/// The mouse sub-model's free states (palm translation, finger 1, finger 4 and thumb).
const FREE: [u8; 7] = [4, 5, 8, 9, 10, 19, 24];

/// A small budget, so a search spans many frames.
const BUDGET: u16 = 40;

fn free_mask() -> u32 {
    FREE.iter().map(|&s| 1u32 << s).sum()
}

fn configure(iterations: u8, budget: u16) -> HostMessage<'static> {
    HostMessage::Configure(Configure {
        search_evaluations_per_frame: budget,
        ..Configure::new(
            CameraParams::from_camera(&camera()).unwrap(),
            TrackerParams {
                iterations,
                ..TrackerParams::default()
            },
        )
    })
}

fn reset(q: &[f32], start: Start) -> HostMessage<'static> {
    HostMessage::Reset(Reset {
        q: q.iter().copied().collect(),
        free: free_mask(),
        start,
    })
}

/// A frame with no hand: the background alone.
fn empty() -> Vec<u8> {
    vec![20u8; FRAME_BYTES]
}

/// Uploads `pixels` as frame `n` and returns the board's one answer, a `State`.
fn answer(board: &mut TestBoard<'_>, n: u32, pixels: &[u8]) -> State {
    board
        .serial_mut()
        .send_frame(n, WIDTH as u16, HEIGHT as u16, pixels);
    board.poll().unwrap();
    match &board.serial_mut().received()[..] {
        [BoardMessage::State(state)] => {
            assert_eq!(state.frame, n);
            state.clone()
        }
        other => panic!("frame {n}: one State expected, got {other:?}"),
    }
}

/// A board after boot, Configure (with `budget`) and Reset from `q0` with `start`.
fn started<'m>(buffer: &'m mut [u8], q0: &[f32], start: Start, budget: u16) -> TestBoard<'m> {
    let mut board = test_board("search", buffer);
    board.start().unwrap();
    board.serial_mut().send(&configure(8, budget));
    board.serial_mut().send(&reset(q0, start));
    board.poll().unwrap();
    let replies = board.serial_mut().received();
    assert!(
        replies.ends_with(&[BoardMessage::Ack(Command::Reset)]),
        "{replies:?}"
    );
    board
}

#[test]
fn a_board_told_to_search_answers_every_frame_searching_within_its_budget() {
    let model = Model::hand().unwrap();
    let cam = camera();
    let q0 = pose(&model, 0.2);
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = started(&mut buffer, &q0, Start::Search, BUDGET);
    // The same search in process, on the same frames: its work per frame is the board's.
    let mut reference = AutoTracker::new(
        model,
        &[cam],
        &q0,
        FreeMask(free_mask()),
        TrackerConfig::default(),
        search_config(BUDGET),
    )
    .unwrap();
    let mut edges = vec![0u8; edge_map_bytes(WIDTH as usize, HEIGHT as usize)];
    let pixels = empty();
    let mut total = 0u32;
    for n in 0..12 {
        let state = answer(&mut board, n, &pixels);
        let view = FrameView::packed(&pixels, WIDTH as usize, HEIGHT as usize).unwrap();
        let expected = reference.step(&[view], &mut [&mut edges[..]]).unwrap();
        assert_eq!(
            (state.status, state.lost),
            (WireStatus::Searching, true),
            "frame {n}: no hand in view, no hand claimed"
        );
        assert_eq!(state.search_evaluations, expected.evaluated, "frame {n}");
        // A step stops once its budget is spent; the item under way (one hypothesis, or one
        // slide of a template) is finished, so it may overrun by at most that item's cost.
        let bound = BUDGET + reference.acquirer().largest_item_cost;
        assert!(
            state.search_evaluations <= bound,
            "frame {n}: {} evaluations, budget {BUDGET} (+ {} for the item under way)",
            state.search_evaluations,
            reference.acquirer().largest_item_cost
        );
        total += u32::from(state.search_evaluations);
    }
    assert!(total > 0, "the board searched");
    let stats = board.stats();
    assert_eq!((stats.frames, stats.lost), (12, 12), "{stats:?}");
}

#[test]
fn a_tracking_board_reports_tracking_then_lost_then_searching() {
    let model = Model::hand().unwrap();
    let cam = camera();
    let q0 = pose(&model, 0.2);
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = started(&mut buffer, &q0, Start::Given, BUDGET);
    let mut statuses = Vec::new();
    let mut n = 0;
    for bend in [0.22f32, 0.24, 0.26] {
        let state = answer(&mut board, n, &render(&model, &cam, &pose(&model, bend)));
        assert!(!state.lost, "frame {n}: the hand is in view");
        statuses.push(Status::from(state.status));
        n += 1;
    }
    // The hand leaves the view.
    let gone = LOST_FRAMES_BEFORE_SEARCH + 3;
    for _ in 0..gone {
        let state = answer(&mut board, n, &empty());
        assert!(state.lost, "frame {n}: the hand is gone");
        let status = Status::from(state.status);
        if status != Status::Searching {
            assert_eq!(
                state.search_evaluations, 0,
                "frame {n}: no search while {status}"
            );
        }
        statuses.push(status);
        n += 1;
    }
    let lost_run = LOST_FRAMES_BEFORE_SEARCH as usize - 1;
    let mut expected = vec![Status::Tracking; 3];
    expected.extend(vec![Status::Lost; lost_run]);
    expected.extend(vec![Status::Searching; gone as usize - lost_run]);
    assert_eq!(statuses, expected);
}

#[test]
fn configure_refuses_a_zero_budget_and_an_edge_map_that_does_not_fit() {
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = test_board("search", &mut buffer);
    board.start().unwrap();
    board.serial_mut().send(&configure(8, 0));
    board.poll().unwrap();
    assert!(board.serial_mut().received().ends_with(&[BoardMessage::Nak(
        Command::Configure,
        Refusal::BadParameters
    )]));

    // The frame fits the frame buffer; its edge map does not fit the edge-map buffer.
    let mut frame = vec![0u8; FRAME_BYTES];
    let mut edge_map = vec![0u8; edge_map_bytes(WIDTH as usize, HEIGHT as usize) - 1];
    let mut small = Board::new(
        "small",
        Buffers {
            frame: &mut frame,
            overlay: None,
            edge_map: &mut edge_map,
        },
        Pipe::default(),
        Uploads,
        NoLed,
        StepClock(0),
    );
    small.start().unwrap();
    small.serial_mut().send(&configure(8, BUDGET));
    small.poll().unwrap();
    assert!(small.serial_mut().received().ends_with(&[BoardMessage::Nak(
        Command::Configure,
        Refusal::FrameTooLarge
    )]));
}

/// A second `Configure` that changes the parameters keeps the status and the state: a
/// tracking board tracks on from where it was, a searching board searches on.
#[test]
fn a_changed_configure_keeps_the_status() {
    let model = Model::hand().unwrap();
    let cam = camera();
    let q0 = pose(&model, 0.2);
    for start in [Start::Given, Start::Search] {
        let mut buffer = vec![0u8; FRAME_BYTES];
        let mut board = started(&mut buffer, &q0, start, BUDGET);
        let pixels = match start {
            Start::Given => render(&model, &cam, &pose(&model, 0.22)),
            Start::Search => empty(),
        };
        let before = answer(&mut board, 0, &pixels);
        board.serial_mut().send(&configure(3, BUDGET * 2));
        board.poll().unwrap();
        assert_eq!(
            board.serial_mut().received(),
            [BoardMessage::Ack(Command::Configure)]
        );
        let after = answer(&mut board, 1, &pixels);
        assert_eq!(after.status, before.status, "{start:?}");
        match start {
            Start::Given => {
                assert_eq!(after.status, WireStatus::Tracking);
                assert!(after.iterations <= 3, "the new parameters apply");
            }
            Start::Search => {
                assert_eq!(after.status, WireStatus::Searching);
                assert!(
                    after.search_evaluations > BUDGET,
                    "the new budget applies: {}",
                    after.search_evaluations
                );
            }
        }
    }
}
