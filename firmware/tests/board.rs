//! The board loop against an in-memory serial port: the session of docs/protocol.md, states
//! equal to an in-process tracker's, every drop reported once with its reason, refusals,
//! corruption counted and survived, the camera source, features and the overlay.

mod common;

use common::*;
use digiteyes_core::estimator::FreeMask;
use digiteyes_core::frame::FrameView;
use digiteyes_core::model::Model;
use digiteyes_core::protocol::*;
use digiteyes_core::tracker::{Tracker, TrackerConfig};
use digiteyes_firmware::{Board, NoLed, Uploads};

const FRAME_BYTES: usize = (WIDTH * HEIGHT) as usize;

/// The mouse sub-model's free states (palm translation, finger 1, finger 4 and thumb).
const FREE: [u8; 7] = [4, 5, 8, 9, 10, 19, 24];

fn free_mask() -> u32 {
    FREE.iter().map(|&s| 1u32 << s).sum()
}

fn configure(stats_every: u16, features_every: u16) -> HostMessage<'static> {
    HostMessage::Configure(Configure {
        features_every,
        stats_every,
        ..Configure::new(
            CameraParams::from_camera(&camera()).unwrap(),
            TrackerParams::default(),
        )
    })
}

fn reset(q: &[f32]) -> HostMessage<'static> {
    HostMessage::Reset(Reset {
        q: q.iter().copied().collect(),
        free: free_mask(),
        start: Start::Given,
    })
}

/// A board after boot, Configure and Reset, with the replies checked.
fn ready_board<'m>(buffer: &'m mut [u8], q0: &[f32]) -> Board<'m, Pipe, Uploads, NoLed, StepClock> {
    let mut board = test_board("test", buffer);
    board.start().unwrap();
    board.serial_mut().send(&configure(0, 0));
    board.serial_mut().send(&reset(q0));
    board.poll().unwrap();
    let replies = board.serial_mut().received();
    assert!(
        matches!(
            &replies[..],
            [
                BoardMessage::Hello(_),
                BoardMessage::Ack(Command::Configure),
                BoardMessage::Hello(_),
                BoardMessage::Ack(Command::Reset)
            ]
        ),
        "{replies:?}"
    );
    board
}

#[test]
fn hello_names_the_board_and_its_model() {
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = test_board("qemu-m7", &mut buffer);
    board.start().unwrap();
    let [BoardMessage::Hello(hello)] = &board.serial_mut().received()[..] else {
        panic!("one Hello at boot");
    };
    assert_eq!(hello.version, PROTOCOL_VERSION);
    assert_eq!(hello.board.as_str(), "qemu-m7");
    assert_eq!(hello.model_digest, model_digest(&Model::hand().unwrap()));
    assert_eq!(hello.capacities.states, 28);
    assert_eq!(hello.capacities.max_frame_bytes as usize, FRAME_BYTES);
    assert_eq!(hello.clock_hz, 1_000_000);
}

#[test]
fn uploaded_frames_give_the_in_process_trackers_states() {
    let model = Model::hand().unwrap();
    let cam = camera();
    let q0 = pose(&model, 0.2);
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = ready_board(&mut buffer, &q0);
    let mut reference = Tracker::new(
        model.clone(),
        &[cam],
        &q0,
        FreeMask(free_mask()),
        TrackerConfig::default(),
    )
    .unwrap();
    for (n, bend) in [0.25f32, 0.3, 0.35, 0.4].into_iter().enumerate() {
        let pixels = render(&model, &cam, &pose(&model, bend));
        board
            .serial_mut()
            .send_frame(n as u32, WIDTH as u16, HEIGHT as u16, &pixels);
        board.poll().unwrap();
        let report = reference
            .track(&[FrameView::packed(&pixels, WIDTH as usize, HEIGHT as usize).unwrap()])
            .unwrap();
        let [BoardMessage::State(state)] = &board.serial_mut().received()[..] else {
            panic!("one State per frame");
        };
        assert_eq!(state.frame, n as u32);
        assert_eq!(&state.q[..], reference.state(), "bit-exact states");
        assert_eq!(state.rms_px.to_bits(), report.rms_px.to_bits());
        assert_eq!(
            (
                state.lost,
                state.features_found,
                state.features_expected,
                state.iterations
            ),
            (
                report.lost,
                report.features_found,
                report.features_expected,
                report.iterations
            )
        );
        assert!(state.track_ticks > 0);
        // A board reset from a given state tracks (it never searches here): `Tracking`, or
        // `Lost` on a frame the tracker flags (the palm's outline, which these capsule-only
        // frames do not draw, turns the last frames' palm a little: lost by the silhouette).
        let tracked = if report.lost {
            WireStatus::Lost
        } else {
            WireStatus::Tracking
        };
        assert_eq!(
            (state.status, state.search_evaluations),
            (tracked, 0),
            "a board reset from a given state tracks"
        );
        assert!(
            report.features_found > 0,
            "the synthetic frame shows the hand"
        );
    }
    let stats = board.stats();
    assert_eq!(
        (stats.frames, stats.dropped, stats.bad_frames),
        (4, DropCounts::default(), 0)
    );
}

#[test]
fn every_dropped_frame_is_reported_once_with_its_reason() {
    let model = Model::hand().unwrap();
    let q0 = pose(&model, 0.2);
    let pixels = render(&model, &camera(), &q0);
    let (w, h) = (WIDTH as u16, HEIGHT as u16);
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = ready_board(&mut buffer, &q0);
    let pipe = board.serial_mut();

    // Wrong size: 2 px narrower.
    pipe.send(&HostMessage::FrameChunk(FrameChunk {
        frame: 1,
        width: w - 2,
        height: h,
        offset: 0,
        data: &pixels[..100],
    }));
    // A gap: the second chunk of frame 2 is missing.
    pipe.send(&HostMessage::FrameChunk(FrameChunk {
        frame: 2,
        width: w,
        height: h,
        offset: 0,
        data: &pixels[..1024],
    }));
    pipe.send(&HostMessage::FrameChunk(FrameChunk {
        frame: 2,
        width: w,
        height: h,
        offset: 2048,
        data: &pixels[2048..3072],
    }));
    pipe.send(&HostMessage::FrameChunk(FrameChunk {
        frame: 2,
        width: w,
        height: h,
        offset: 3072,
        data: &pixels[3072..4096],
    }));
    // Frame 3 half sent, then frame 4 whole: 3 is superseded, 4 tracked.
    pipe.send(&HostMessage::FrameChunk(FrameChunk {
        frame: 3,
        width: w,
        height: h,
        offset: 0,
        data: &pixels[..1024],
    }));
    pipe.send_frame(4, w, h, &pixels);
    // A chunk running past the frame's end.
    pipe.send(&HostMessage::FrameChunk(FrameChunk {
        frame: 5,
        width: w,
        height: h,
        offset: 0,
        data: &pixels[..1024],
    }));
    let end = FRAME_BYTES as u32 - 10;
    let long = &pixels[..1024];
    board.poll().unwrap();
    board
        .serial_mut()
        .send(&HostMessage::FrameChunk(FrameChunk {
            frame: 5,
            width: w,
            height: h,
            offset: 1024,
            data: long,
        }));
    board
        .serial_mut()
        .send(&HostMessage::FrameChunk(FrameChunk {
            frame: 6,
            width: w,
            height: h,
            offset: end,
            data: &long[..20],
        }));
    board.poll().unwrap();

    let got = board.serial_mut().received();
    let drops: Vec<(u32, DropReason)> = got
        .iter()
        .filter_map(|m| match m {
            BoardMessage::Dropped(d) => Some((d.frame, d.reason)),
            _ => None,
        })
        .collect();
    let states: Vec<u32> = got
        .iter()
        .filter_map(|m| match m {
            BoardMessage::State(s) => Some(s.frame),
            _ => None,
        })
        .collect();
    assert_eq!(
        drops,
        [
            (1, DropReason::WrongSize(w - 2, h)),
            (2, DropReason::Incomplete),
            (3, DropReason::Superseded),
            (5, DropReason::Superseded),
            (6, DropReason::Incomplete),
        ]
    );
    assert_eq!(states, [4]);
    let stats = board.stats();
    assert_eq!(stats.dropped.wrong_size, 1);
    assert_eq!(stats.dropped.incomplete, 2);
    assert_eq!(stats.dropped.superseded, 2);
    assert_eq!(stats.bad_frames, 1);
    assert_eq!(stats.frames, 1);
}

#[test]
fn a_chunk_past_the_frames_end_is_too_large() {
    let model = Model::hand().unwrap();
    let q0 = pose(&model, 0.2);
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = ready_board(&mut buffer, &q0);
    let (w, h) = (WIDTH as u16, HEIGHT as u16);
    let data = vec![7u8; 1000];
    let pipe = board.serial_mut();
    let mut offset = 0u32;
    while offset as usize + 1000 < FRAME_BYTES {
        pipe.send(&HostMessage::FrameChunk(FrameChunk {
            frame: 9,
            width: w,
            height: h,
            offset,
            data: &data,
        }));
        offset += 1000;
    }
    // The frame has FRAME_BYTES - offset bytes left; send more than that.
    pipe.send(&HostMessage::FrameChunk(FrameChunk {
        frame: 9,
        width: w,
        height: h,
        offset,
        data: &data,
    }));
    board.poll().unwrap();
    let got = board.serial_mut().received();
    assert_eq!(
        got,
        [BoardMessage::Dropped(Dropped {
            frame: 9,
            reason: DropReason::TooLarge
        })]
    );
    assert_eq!(board.stats().bad_frames, 1);
}

#[test]
fn frames_before_configure_and_reset_are_not_ready() {
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = test_board("t", &mut buffer);
    board
        .serial_mut()
        .send_frame(1, WIDTH as u16, HEIGHT as u16, &vec![0u8; FRAME_BYTES]);
    board.serial_mut().send(&configure(0, 0));
    board
        .serial_mut()
        .send_frame(2, WIDTH as u16, HEIGHT as u16, &vec![0u8; FRAME_BYTES]);
    board.poll().unwrap();
    let got = board.serial_mut().received();
    assert_eq!(
        got,
        [
            BoardMessage::Dropped(Dropped {
                frame: 1,
                reason: DropReason::NotReady
            }),
            BoardMessage::Ack(Command::Configure),
            BoardMessage::Dropped(Dropped {
                frame: 2,
                reason: DropReason::NotReady
            }),
        ]
    );
    assert_eq!(board.stats().dropped.not_ready, 2);
}

#[test]
fn bad_commands_are_refused_and_change_nothing() {
    let model = Model::hand().unwrap();
    let q0 = pose(&model, 0.2);
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = test_board("t", &mut buffer);
    let pipe = board.serial_mut();
    pipe.send(&reset(&q0));
    let mut cam = CameraParams::from_camera(&camera()).unwrap();
    let good_cam = cam;
    cam.intrinsics[0] = -1.0;
    let mut params = TrackerParams::default();
    pipe.send(&HostMessage::Configure(Configure::new(cam, params)));
    params.iterations = 0;
    pipe.send(&HostMessage::Configure(Configure::new(good_cam, params)));
    let mut big = good_cam;
    big.width *= 2;
    pipe.send(&HostMessage::Configure(Configure::new(
        big,
        TrackerParams::default(),
    )));
    pipe.send(&configure(0, 0));
    pipe.send(&HostMessage::Reset(Reset {
        q: q0[..7].iter().copied().collect(),
        free: free_mask(),
        start: Start::Given,
    }));
    let mut nan = q0.clone();
    nan[9] = f32::NAN;
    pipe.send(&reset(&nan));
    pipe.send(&HostMessage::Reset(Reset {
        q: q0.iter().copied().collect(),
        free: 1 << 30,
        start: Start::Given,
    }));
    board.poll().unwrap();
    let got = board.serial_mut().received();
    assert_eq!(
        got,
        [
            BoardMessage::Nak(Command::Reset, Refusal::NotConfigured),
            BoardMessage::Nak(Command::Configure, Refusal::BadCamera),
            BoardMessage::Nak(Command::Configure, Refusal::BadParameters),
            BoardMessage::Nak(Command::Configure, Refusal::FrameTooLarge),
            BoardMessage::Ack(Command::Configure),
            BoardMessage::Nak(Command::Reset, Refusal::BadState),
            BoardMessage::Nak(Command::Reset, Refusal::BadState),
            BoardMessage::Nak(Command::Reset, Refusal::BadFreeMask),
        ]
    );
}

#[test]
fn garbage_on_the_link_is_counted_and_the_next_frame_tracked() {
    let model = Model::hand().unwrap();
    let q0 = pose(&model, 0.2);
    let pixels = render(&model, &camera(), &q0);
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = ready_board(&mut buffer, &q0);
    let pipe = board.serial_mut();
    // Frame 1 with one byte flipped in its third chunk: that chunk fails its CRC, so the frame
    // has a gap and is dropped; frame 2 arrives clean.
    let start = pipe.to_board.len();
    pipe.send_frame(1, WIDTH as u16, HEIGHT as u16, &pixels);
    let third_chunk = start + 2 * (MAX_CHUNK + 20) + 100;
    pipe.to_board[third_chunk] ^= 0x5a;
    pipe.to_board.extend([0x11, 0x22, 0x33]);
    pipe.send_frame(2, WIDTH as u16, HEIGHT as u16, &pixels);
    pipe.send(&HostMessage::Ping(77));
    board.poll().unwrap();
    let got = board.serial_mut().received();
    let [BoardMessage::Dropped(d), BoardMessage::State(s), BoardMessage::Stats(stats), BoardMessage::Pong(77)] =
        &got[..]
    else {
        panic!("{got:?}");
    };
    assert_eq!((d.frame, d.reason), (1, DropReason::Incomplete));
    assert_eq!(s.frame, 2);
    assert_eq!(
        stats.link.crc_errors + stats.link.framing_errors,
        2,
        "{stats:?}"
    );
    assert_eq!(stats.dropped.incomplete, 1);
}

#[test]
fn a_camera_source_is_tracked_without_uploads() {
    let model = Model::hand().unwrap();
    let cam = camera();
    let q0 = pose(&model, 0.2);
    let frames = [0.22f32, 0.24, 0.26].map(|b| render(&model, &cam, &pose(&model, b)));
    let source = Frames {
        frames: frames.into_iter().collect(),
        next: 0,
    };
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = Board::new(
        "cam",
        buffers(&mut buffer, None),
        Pipe::default(),
        source,
        NoLed,
        StepClock(0),
    );
    assert!(
        !board.poll().unwrap(),
        "nothing to do before Configure/Reset"
    );
    board.serial_mut().send(&configure(3, 0));
    board.serial_mut().send(&reset(&q0));
    while board.poll().unwrap() {}
    let got = board.serial_mut().received();
    let states: Vec<u32> = got
        .iter()
        .filter_map(|m| {
            if let BoardMessage::State(s) = m {
                Some(s.frame)
            } else {
                None
            }
        })
        .collect();
    assert_eq!(states, [100, 101, 102]);
    assert!(matches!(got.last(), Some(BoardMessage::Stats(s)) if s.frames == 3));
}

#[test]
fn features_are_sent_every_n_frames_and_name_links_in_view() {
    let model = Model::hand().unwrap();
    let cam = camera();
    let q0 = pose(&model, 0.2);
    let pixels = render(&model, &cam, &q0);
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = test_board("t", &mut buffer);
    board.serial_mut().send(&configure(0, 2));
    board.serial_mut().send(&reset(&q0));
    for n in 0..4 {
        board
            .serial_mut()
            .send_frame(n, WIDTH as u16, HEIGHT as u16, &pixels);
    }
    board.poll().unwrap();
    let features: Vec<Features> = board
        .serial_mut()
        .received()
        .into_iter()
        .filter_map(|m| {
            if let BoardMessage::Features(f) = m {
                Some(f)
            } else {
                None
            }
        })
        .collect();
    assert_eq!(features.iter().map(|f| f.frame).collect::<Vec<_>>(), [1, 3]);
    let f = &features[0];
    assert!(
        f.links.iter().filter(|l| l.axis.is_some()).count() >= 8,
        "{f:?}"
    );
    assert!(f.links.iter().any(|l| l.tip.is_some()));
    // A measured axis lies close to the link's projected axis at the true state.
    for l in f.links.iter() {
        if let Some(axis) = l.axis {
            let n = (axis.direction[0].powi(2) + axis.direction[1].powi(2)).sqrt();
            assert!((n - 1.0).abs() < 1e-4);
        }
    }
}

#[test]
fn the_overlay_draws_the_model_over_the_dimmed_frame() {
    let model = Model::hand().unwrap();
    let cam = camera();
    let q0 = pose(&model, 0.2);
    let pixels = render(&model, &cam, &q0);
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut overlay = vec![0u8; FRAME_BYTES];
    let mut board = Board::new(
        "t",
        buffers(&mut buffer, Some(&mut overlay)),
        Pipe::default(),
        Uploads,
        NoLed,
        StepClock(0),
    );
    assert!(board.overlay().is_none());
    board.serial_mut().send(&configure(0, 0));
    board.serial_mut().send(&reset(&q0));
    board
        .serial_mut()
        .send_frame(0, WIDTH as u16, HEIGHT as u16, &pixels);
    board.poll().unwrap();
    let out = board.overlay().expect("an overlay after a tracked frame");
    let edges = out.iter().filter(|&&p| p == 255).count();
    let axes = out.iter().filter(|&&p| p == 160).count();
    assert!(edges > 200 && axes > 100, "{edges} edge px, {axes} axis px");
    let dimmed = out
        .iter()
        .zip(&pixels)
        .filter(|(o, p)| **o == **p / 2)
        .count();
    assert!(dimmed > FRAME_BYTES * 3 / 4);
}

/// The frame numbers a board answered (`State` or `Dropped`), in order.
fn answered(messages: &[BoardMessage]) -> Vec<u32> {
    messages
        .iter()
        .filter_map(|m| match m {
            BoardMessage::State(s) => Some(s.frame),
            BoardMessage::Dropped(d) => Some(d.frame),
            _ => None,
        })
        .collect()
}

fn chunk(frame: u32, pixels: &[u8], from: usize, to: usize) -> HostMessage<'_> {
    HostMessage::FrameChunk(FrameChunk {
        frame,
        width: WIDTH as u16,
        height: HEIGHT as u16,
        offset: from as u32,
        data: &pixels[from..to],
    })
}

/// The tester's sequence: A's chunks 0–9, one chunk of B, A's chunks 10 to the end. A is
/// superseded by B and answered once; its later chunks are stale, counted, never answered.
#[test]
fn interleaved_chunks_never_answer_a_frame_twice() {
    let model = Model::hand().unwrap();
    let q0 = pose(&model, 0.2);
    let pixels = render(&model, &camera(), &q0);
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = ready_board(&mut buffer, &q0);
    let chunks: Vec<(usize, usize)> = (0..FRAME_BYTES)
        .step_by(MAX_CHUNK)
        .map(|from| (from, (from + MAX_CHUNK).min(FRAME_BYTES)))
        .collect();
    let (a, b) = (10, 11);
    for &(from, to) in &chunks[..10] {
        board.serial_mut().send(&chunk(a, &pixels, from, to));
    }
    board.serial_mut().send(&chunk(b, &pixels, 0, MAX_CHUNK));
    for &(from, to) in &chunks[10..] {
        board.serial_mut().send(&chunk(a, &pixels, from, to));
    }
    // A lower number never supersedes the frame under way either.
    board.serial_mut().send(&chunk(9, &pixels, 0, MAX_CHUNK));
    board.poll().unwrap();
    board
        .serial_mut()
        .send_frame(12, WIDTH as u16, HEIGHT as u16, &pixels);
    board.poll().unwrap();
    let got = board.serial_mut().received();
    assert_eq!(answered(&got), [a, b, 12], "{got:?}");
    let stats = board.stats();
    assert_eq!(stats.stale_chunks, (chunks.len() - 10) as u32 + 1);
    assert_eq!(stats.dropped.superseded, 2);
    assert_eq!(stats.frames, 1);
}

/// For any order of chunks of any frames (a seeded sweep of 200 random streams), no frame
/// number is answered twice, and a frame sent whole after the chaos is tracked.
#[test]
fn no_order_of_chunks_answers_a_frame_twice() {
    let model = Model::hand().unwrap();
    let q0 = pose(&model, 0.2);
    let pixels = render(&model, &camera(), &q0);
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = ready_board(&mut buffer, &q0);
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = move |n: u64| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed % n
    };
    let per_frame = FRAME_BYTES.div_ceil(MAX_CHUNK) as u64;
    for round in 0..200u32 {
        let base = 100 * round;
        for _ in 0..12 {
            let frame = base + next(5) as u32;
            let k = next(per_frame) as usize;
            let from = k * MAX_CHUNK;
            let to = (from + MAX_CHUNK).min(FRAME_BYTES);
            board.serial_mut().send(&chunk(frame, &pixels, from, to));
        }
        board.poll().unwrap();
        let got = answered(&board.serial_mut().received());
        let mut seen = std::collections::HashSet::new();
        for frame in &got {
            assert!(
                seen.insert(*frame),
                "round {round}: frame {frame} answered twice: {got:?}"
            );
        }
        // Whatever is under way is superseded by the next round's higher numbers: answered
        // once in that round, never again.
    }
    board
        .serial_mut()
        .send_frame(1_000_000, WIDTH as u16, HEIGHT as u16, &pixels);
    board.poll().unwrap();
    let got = board.serial_mut().received();
    assert!(
        got.iter()
            .any(|m| matches!(m, BoardMessage::State(s) if s.frame == 1_000_000)),
        "{got:?}"
    );
}

/// `MAX_CHUNK` is enforced: a 1025-byte chunk drops its frame as too large, counted.
#[test]
fn a_chunk_over_max_chunk_drops_its_frame() {
    let model = Model::hand().unwrap();
    let q0 = pose(&model, 0.2);
    let pixels = render(&model, &camera(), &q0);
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = ready_board(&mut buffer, &q0);
    board
        .serial_mut()
        .send(&chunk(1, &pixels, 0, MAX_CHUNK + 1));
    board.serial_mut().send(&chunk(2, &pixels, 0, MAX_CHUNK));
    board
        .serial_mut()
        .send(&chunk(2, &pixels, MAX_CHUNK, 2 * MAX_CHUNK + 1));
    board.poll().unwrap();
    let got = board.serial_mut().received();
    let drops: Vec<(u32, DropReason)> = got
        .iter()
        .filter_map(|m| match m {
            BoardMessage::Dropped(d) => Some((d.frame, d.reason)),
            _ => None,
        })
        .collect();
    assert_eq!(
        drops,
        [(1, DropReason::TooLarge), (2, DropReason::TooLarge)],
        "{got:?}"
    );
    assert_eq!(board.stats().dropped.too_large, 2);
}

/// A board started at a bend of 0.2 rad tracks four frames bending further, with `message`
/// sent before the last: what it answered, and the last `State`'s state.
fn bend_with(message: Option<&HostMessage<'_>>) -> (Vec<BoardMessage>, Vec<f32>) {
    let model = Model::hand().unwrap();
    let cam = camera();
    let mut buffer = vec![0u8; FRAME_BYTES];
    let mut board = ready_board(&mut buffer, &pose(&model, 0.2));
    for (n, bend) in [0.26f32, 0.32, 0.38, 0.44].into_iter().enumerate() {
        if let (3, Some(message)) = (n, message) {
            board.serial_mut().send(message);
        }
        let pixels = render(&model, &cam, &pose(&model, bend));
        board
            .serial_mut()
            .send_frame(n as u32, WIDTH as u16, HEIGHT as u16, &pixels);
        board.poll().unwrap();
    }
    let got = board.serial_mut().received();
    let q = match got.last() {
        Some(BoardMessage::State(s)) => s.q.to_vec(),
        other => panic!("{other:?}"),
    };
    (got, q)
}

/// A second `Configure` keeps the state, the free states and the motion: the next frame's
/// state is bit-equal to that of a board that was not reconfigured.
#[test]
fn a_second_configure_keeps_the_motion() {
    let (got, reconfigured) = bend_with(Some(&configure(0, 0)));
    assert!(
        got.contains(&BoardMessage::Ack(Command::Configure)),
        "{got:?}"
    );
    assert_eq!(reconfigured, bend_with(None).1);
}

/// A `Reset` the tracker's own constructor refuses (a free state beyond the model, after the
/// board has checked the state) builds nothing in the board's slot: the running tracker, its
/// state and its motion stay, bit for bit.
#[test]
fn a_refused_reset_keeps_the_running_tracker_and_its_motion() {
    let model = Model::hand().unwrap();
    let refused = HostMessage::Reset(Reset {
        q: pose(&model, 1.2).iter().copied().collect(),
        free: 1 << 30,
        start: Start::Given,
    });
    let (got, kept) = bend_with(Some(&refused));
    assert!(
        got.contains(&BoardMessage::Nak(Command::Reset, Refusal::BadFreeMask)),
        "{got:?}"
    );
    assert_eq!(kept, bend_with(None).1);
}
