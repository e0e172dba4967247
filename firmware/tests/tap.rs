//! The board's tap: each tracked frame handed over with its own pixels and the state the
//! board then sends, even when several frames arrive in one pass of the loop (the frame
//! buffer is reused by the next upload, so only a tap at tracking time sees every frame).

mod common;

use common::*;
use digiteyes_core::model::Model;
use digiteyes_core::protocol::*;
use digiteyes_firmware::{Board, NoLed, Tracked, Uploads};

/// What the test keeps of a tapped frame: number, pixels, state, lost, camera width.
type Seen = (u32, Vec<u8>, Vec<f32>, bool, u32);

#[test]
fn the_tap_sees_every_frame_of_a_pass_with_its_pixels_and_state() {
    let model = Model::hand().unwrap();
    let cam = camera();
    let q0 = pose(&model, 0.2);
    let mut buffer = vec![0u8; (WIDTH * HEIGHT) as usize];
    let mut seen: Vec<Seen> = Vec::new();
    let mut tap = |t: &Tracked<'_>| {
        seen.push((
            t.frame,
            t.pixels.to_vec(),
            t.q.to_vec(),
            t.report.lost,
            t.camera.width,
        ))
    };
    let mut board = Board::new(
        "test",
        buffers(&mut buffer, None),
        Pipe::default(),
        Uploads,
        NoLed,
        StepClock(0),
    );
    board.set_tap(&mut tap);
    board.start().unwrap();
    board
        .serial_mut()
        .send(&HostMessage::Configure(Configure::new(
            CameraParams::from_camera(&cam).unwrap(),
            TrackerParams::default(),
        )));
    board.serial_mut().send(&HostMessage::Reset(Reset {
        q: q0.iter().copied().collect(),
        free: [4u8, 5, 8, 9, 10, 19, 24].iter().map(|&s| 1u32 << s).sum(),
        start: Start::Given,
    }));
    board.poll().unwrap();
    let _ = board.serial_mut().received();

    // Three frames queued before one poll: all three tracked in that pass.
    let frames: Vec<Vec<u8>> = [0.25f32, 0.3, 0.35]
        .iter()
        .map(|&bend| render(&model, &cam, &pose(&model, bend)))
        .collect();
    for (n, pixels) in frames.iter().enumerate() {
        board
            .serial_mut()
            .send_frame(10 + n as u32, WIDTH as u16, HEIGHT as u16, pixels);
    }
    board.poll().unwrap();
    let states: Vec<State> = board
        .serial_mut()
        .received()
        .into_iter()
        .filter_map(|m| match m {
            BoardMessage::State(s) => Some(s),
            _ => None,
        })
        .collect();
    drop(board);

    assert_eq!(states.len(), 3);
    assert_eq!(seen.len(), 3);
    for ((state, pixels), (frame, tapped, q, lost, width)) in states.iter().zip(&frames).zip(&seen)
    {
        assert_eq!(*frame, state.frame);
        assert!(tapped == pixels, "frame {frame}: the tap saw other pixels");
        let bits = |q: &[f32]| q.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(q), bits(&state.q), "frame {frame}");
        assert_eq!(*lost, state.lost);
        assert_eq!(*width, WIDTH);
    }
}
