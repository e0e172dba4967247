//! The board never panics, whatever arrives: random bytes, and valid sessions with bytes
//! corrupted at random. Every frame it tracks or drops is answered once, and its counters
//! agree with what it sent.
//!
//! Case counts: 300 random streams (up to 8 KiB) and 200 corrupted sessions of 3 frames
//! (160×120, corruption up to 2 % of bytes): 500 cases, a few seconds.

mod common;

use common::*;
use digiteyes_core::model::Model;
use digiteyes_core::protocol::*;
use digiteyes_firmware::{Board, NoLed, Uploads};
use proptest::prelude::*;

const FRAME_BYTES: usize = (WIDTH * HEIGHT) as usize;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn random_bytes_never_panic_the_board(
        bytes in prop::collection::vec(any::<u8>(), 0..8192),
    ) {
        let mut buffer = vec![0u8; FRAME_BYTES];
        let mut board = Board::new("f", buffers(&mut buffer, None), Pipe::default(), Uploads, NoLed, StepClock(0));
        board.serial_mut().to_board.extend(bytes);
        board.poll().unwrap();
        let got = board.serial_mut().received();
        let stats = board.stats();
        prop_assert_eq!(stats.frames, 0);
        // Each reply answers a decoded message, at most two per message (Reset: Hello + Ack;
        // Ping: Stats + Pong).
        prop_assert!(got.len() <= 2 * stats.link.messages as usize);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn corrupted_sessions_answer_every_frame_at_most_once(
        rate in 0.0f64..0.02,
        flips in prop::collection::vec((any::<f64>(), 1u8..=255), 1024),
    ) {
        let model = Model::hand().unwrap();
        let cam = camera();
        let q0 = pose(&model, 0.2);
        let pixels = render(&model, &cam, &q0);
        let mut host = Pipe::default();
        host.send(&HostMessage::Configure(Configure {
            features_every: 1,
            stats_every: 1,
            ..Configure::new(
                CameraParams::from_camera(&cam).unwrap(),
                TrackerParams { iterations: 2, ..TrackerParams::default() },
            )
        }));
        host.send(&HostMessage::Reset(Reset { q: q0.iter().copied().collect(), free: 0b1111_0000, start: Start::Given }));
        for n in 0..3 {
            host.send_frame(n, WIDTH as u16, HEIGHT as u16, &pixels);
        }
        for (i, b) in host.to_board.iter_mut().enumerate() {
            let (p, x) = flips[i % flips.len()];
            if p < rate {
                *b ^= x;
            }
        }
        let mut buffer = vec![0u8; FRAME_BYTES];
        let mut board = Board::new("f", buffers(&mut buffer, None), host, Uploads, NoLed, StepClock(0));
        board.poll().unwrap();
        let got = board.serial_mut().received();
        let mut answered = Vec::new();
        for m in &got {
            match m {
                BoardMessage::State(s) => answered.push(s.frame),
                BoardMessage::Dropped(d) => answered.push(d.frame),
                _ => {}
            }
        }
        let mut unique = answered.clone();
        unique.dedup();
        prop_assert_eq!(&unique, &answered, "a frame answered twice");
        let stats = board.stats();
        let dropped = stats.dropped.total();
        prop_assert_eq!(stats.frames + dropped, answered.len() as u32);
    }
}
