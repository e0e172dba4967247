//! `digiteyes ui --port`: a board's messages read off a serial line into what the page shows,
//! with a corrupted frame on the line counted, not fatal.

use std::io::Write;
use std::time::{Duration, Instant};

use digiteyes_core::protocol::{encode, BoardMessage, DropReason, Dropped, State, MAX_MESSAGE};
use digiteyes_host::ui::{RunningUi, UiOptions, UiSource};
use serialport::{SerialPort, TTYPort};

fn state(frame: u32, q4: f32) -> BoardMessage {
    let mut q = [0.0f32; 28];
    q[0] = 1.0;
    q[4] = q4;
    q[6] = 45.0;
    BoardMessage::State(State {
        frame,
        timestamp: 1000 * u64::from(frame),
        q: q.into_iter().collect(),
        rms_px: 0.5,
        lost: frame == 9,
        features_found: 20,
        features_expected: 24,
        iterations: 5,
        track_ticks: 1234,
        status: digiteyes_core::protocol::WireStatus::Tracking,
        search_evaluations: 0,
    })
}

fn frame_of(message: &BoardMessage) -> Vec<u8> {
    let mut buf = [0u8; MAX_MESSAGE];
    encode(message, &mut buf).unwrap().to_vec()
}

#[test]
fn a_board_on_a_serial_port_feeds_the_page() {
    let (mut board, slave) = TTYPort::pair().unwrap();
    let port = slave.name().unwrap();
    let options = UiOptions {
        bind: "127.0.0.1:0".parse().unwrap(),
        source: UiSource::Serial {
            port,
            baud: 115_200,
            setup: None,
            camera_index: None,
        },
        duration: None,
    };
    let mut said = Vec::new();
    let ui = RunningUi::start(&options, &mut said).unwrap();
    let said = String::from_utf8(said).unwrap();
    assert!(said.contains("UI: http://127.0.0.1:"), "{said}");

    let mut corrupted = frame_of(&state(8, 99.0));
    let middle = corrupted.len() / 2;
    corrupted[middle] ^= 0x10;
    let mut bytes = frame_of(&state(7, 12.5));
    bytes.extend(corrupted);
    bytes.extend(frame_of(&BoardMessage::Dropped(Dropped {
        frame: 8,
        reason: DropReason::Incomplete,
    })));
    bytes.extend(frame_of(&state(9, 14.0)));
    board.write_all(&bytes).unwrap();

    let deadline = Instant::now() + Duration::from_secs(20);
    let snapshot = loop {
        let s = ui.hub().snapshot();
        if s.link.states >= 2 && s.link.dropped >= 1 {
            break s;
        }
        assert!(
            Instant::now() < deadline,
            "the UI did not get the board's messages"
        );
        std::thread::sleep(Duration::from_millis(20));
    };
    let shown = snapshot.state.expect("a state");
    assert_eq!((shown.frame, shown.q[4], shown.lost), (9, 14.0, true));
    assert_eq!(snapshot.link.states, 2, "the corrupted state was taken");
    assert_eq!(snapshot.link.lost_states, 1);
    assert_eq!(snapshot.link.crc_errors, 1);
    assert_eq!(snapshot.link.drops.values().sum::<u64>(), 1);
    assert_eq!(snapshot.shapes.len(), 16, "no 3D hand for a 28-state hand");
    let mouse = snapshot
        .mouse
        .expect("a mouse reading for the built-in hand");
    assert_eq!(mouse["x_mm"], 14.0);
    ui.stop().unwrap();
}

#[test]
fn a_board_with_its_own_camera_is_set_up_from_a_sequence_folder() {
    use digiteyes_host::link::{set_up_board, Link};
    use digiteyes_host::scenarios::{render_scenario, RenderOptions};
    use digiteyes_host::sim::SimOptions;

    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("mouse");
    let render = RenderOptions {
        frames: Some(1),
        size: Some((160, 120)),
        supersample: 1,
        ..RenderOptions::default()
    };
    render_scenario("mouse", &seq, &render).unwrap();
    let board = digiteyes_host::sim::start(SimOptions::default()).unwrap();
    let port = board.path().display().to_string();

    let mut said = Vec::new();
    let set_up = set_up_board(Link::open(&port, 115_200).unwrap(), &seq, None, &mut said).unwrap();
    let said = String::from_utf8(said).unwrap();
    assert!(said.starts_with("board linux-sim set up from "), "{said}");
    assert!(said.contains("sequence.json"), "{said}");
    assert_eq!(set_up.hello.board.as_str(), "linux-sim");
    assert_eq!(set_up.sequence.free_states(), vec![4, 5, 8, 9, 10, 19, 24]);

    // A folder without a sequence.json is named in the error, and the board is left alone.
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let err = set_up_board(set_up.link, &empty, None, &mut std::io::sink()).unwrap_err();
    let err = format!("{err:#}");
    assert!(
        err.contains("empty") && err.contains("sequence.json"),
        "{err}"
    );
    board.stop().unwrap();
}
