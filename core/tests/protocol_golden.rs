//! The wire format pinned to bytes: one golden frame per message type, both directions,
//! as `docs/protocol.md` specifies them. Encoding each fixed message must give exactly these
//! bytes (delimiters, COBS, postcard body, CRC-32), and decoding them must give the message
//! back, so reordering a field, changing an integer's width or a variant's index fails here
//! even though a round trip would still pass. Two of them (`Ping`, `Dropped`) are worked
//! through byte by byte in the spec; the model digest's worked example is checked too. The
//! messages an older version laid out differently are decode errors.

use digiteyes_core::model::Model;
use digiteyes_core::protocol::*;

fn host_messages(data: &[u8]) -> Vec<(&'static str, HostMessage<'_>)> {
    vec![
        (
            "Reset",
            HostMessage::Reset(Reset {
                q: heapless::Vec::from_slice(&[1.0, 0.0, 0.0, 0.0, 5.0, -2.5, 400.0]).unwrap(),
                free: 0b111_0000,
                start: Start::Given,
            }),
        ),
        (
            "Reset (search)",
            HostMessage::Reset(Reset {
                q: heapless::Vec::from_slice(&[1.0, 0.0, 0.0, 0.0, 5.0, -2.5, 400.0]).unwrap(),
                free: 0b111_0000,
                start: Start::Search,
            }),
        ),
        (
            "Configure",
            HostMessage::Configure(Configure {
                camera: CameraParams {
                    width: 320,
                    height: 240,
                    intrinsics: [500.0, 500.0, 159.5, 119.5],
                    r: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
                    t: [0.0, 0.0, 600.0],
                },
                tracker: TrackerParams::default(),
                features_every: 0,
                stats_every: 30,
                search_evaluations_per_frame: 1000,
                hypotheses: 4,
                hypotheses_score_every: 3,
            }),
        ),
        (
            "FrameChunk",
            HostMessage::FrameChunk(FrameChunk {
                frame: 7,
                width: 4,
                height: 2,
                offset: 0,
                data,
            }),
        ),
        ("Ping", HostMessage::Ping(0x0102_0304)),
        ("Hold", HostMessage::Hold),
        (
            "Measure",
            HostMessage::Measure(Measure {
                frame: 9,
                iteration: 1,
                q: heapless::Vec::from_slice(&[1.0, 0.0, 0.0, 0.0, 5.0, -2.5, 400.0]).unwrap(),
            }),
        ),
    ]
}

fn board_messages() -> Vec<(&'static str, BoardMessage)> {
    let mut links = heapless::Vec::new();
    links
        .push(LinkMeasurement {
            link: 4,
            axis: Some(AxisLine {
                point: [10.0, 20.0],
                direction: [0.6, 0.8],
            }),
            tip: None,
        })
        .unwrap();
    links
        .push(LinkMeasurement {
            link: 6,
            axis: None,
            tip: Some([12.5, 30.0]),
        })
        .unwrap();
    vec![
        (
            "Hello",
            BoardMessage::Hello(Hello {
                version: 5,
                board: heapless::String::try_from("qemu-m7").unwrap(),
                model_digest: 0xd4f6_1ba4,
                clock_hz: 25_000_000,
                capacities: Capacities {
                    states: 28,
                    max_states: 32,
                    max_links: 48,
                    max_frame_bytes: 307_200,
                    max_chunk: 1024,
                    max_message: 1408,
                },
            }),
        ),
        (
            "State",
            BoardMessage::State(State {
                frame: 7,
                timestamp: 1000,
                q: heapless::Vec::from_slice(&[1.0, 0.0, 0.5]).unwrap(),
                rms_px: 0.25,
                lost: false,
                features_found: 10,
                features_expected: 12,
                iterations: 3,
                track_ticks: 4096,
                status: WireStatus::Tracking,
                search_evaluations: 0,
            }),
        ),
        (
            "State (searching)",
            BoardMessage::State(State {
                frame: 8,
                timestamp: 1100,
                q: heapless::Vec::from_slice(&[1.0, 0.0, 0.5]).unwrap(),
                rms_px: 0.0,
                lost: true,
                features_found: 0,
                features_expected: 0,
                iterations: 0,
                track_ticks: 90_000,
                status: WireStatus::Searching,
                search_evaluations: 1000,
            }),
        ),
        (
            "State (lost)",
            BoardMessage::State(State {
                frame: 9,
                timestamp: 1200,
                q: heapless::Vec::from_slice(&[1.0, 0.0, 0.5]).unwrap(),
                rms_px: 9.5,
                lost: true,
                features_found: 2,
                features_expected: 12,
                iterations: 8,
                track_ticks: 5000,
                status: WireStatus::Lost,
                search_evaluations: 0,
            }),
        ),
        (
            "Features",
            BoardMessage::Features(Features {
                frame: 7,
                camera: 0,
                links,
            }),
        ),
        (
            "Stats",
            BoardMessage::Stats(Stats {
                frames: 1,
                iterations: 2,
                lost: 3,
                dropped: DropCounts {
                    incomplete: 4,
                    wrong_size: 5,
                    too_large: 6,
                    not_ready: 7,
                    superseded: 8,
                    tracker_error: 9,
                },
                bad_frames: 10,
                link: LinkCounters {
                    messages: 300,
                    crc_errors: 11,
                    framing_errors: 12,
                    decode_errors: 13,
                    overflows: 14,
                },
                capacity_overflows: 15,
                stale_chunks: 16,
            }),
        ),
        (
            "Dropped",
            BoardMessage::Dropped(Dropped {
                frame: 9,
                reason: DropReason::WrongSize(320, 240),
            }),
        ),
        ("Ack", BoardMessage::Ack(Command::Reset)),
        (
            "Nak",
            BoardMessage::Nak(Command::Configure, Refusal::BadParameters),
        ),
        ("Pong", BoardMessage::Pong(0x0102_0304)),
        (
            "LinkEdges",
            BoardMessage::LinkEdges(LinkEdges {
                frame: 9,
                iteration: 1,
                index: 2,
                link: 5,
                edges: heapless::Vec::from_slice(&[WireEdge {
                    s: 0.5,
                    side: -1,
                    position: [10.0, 20.0],
                }])
                .unwrap(),
                tip: Some([12.5, 30.0]),
                expected: 3,
                masked: 1,
            }),
        ),
        (
            "Measured",
            BoardMessage::Measured(Measured {
                frame: 9,
                iteration: 1,
                held: true,
                links: 1,
                silhouette: Some(0.75),
            }),
        ),
        (
            "Hypotheses",
            BoardMessage::Hypotheses(Hypotheses {
                frame: 7,
                hypotheses: heapless::Vec::from_slice(&[
                    WireHypothesis {
                        score: 0.75,
                        age: 12,
                        q: heapless::Vec::from_slice(&[1.0, 0.0, 0.5]).unwrap(),
                    },
                    WireHypothesis {
                        score: 0.5,
                        age: 0,
                        q: heapless::Vec::from_slice(&[1.0, 0.0, -0.5]).unwrap(),
                    },
                ])
                .unwrap(),
            }),
        ),
        (
            "PalmEdges",
            BoardMessage::PalmEdges(PalmEdges {
                frame: 9,
                iteration: 1,
                corners: [3, 7],
                edges: heapless::Vec::from_slice(&[WireEdge {
                    s: 0.5,
                    side: -1,
                    position: [10.0, 20.0],
                }])
                .unwrap(),
                expected: 3,
                masked: 1,
            }),
        ),
    ]
}

/// The pixels of the golden `FrameChunk` (a zero byte among them, to exercise COBS).
const PIXELS: [u8; 8] = [1, 2, 3, 0, 255, 4, 5, 6];

fn golden_host(name: &str) -> &'static [u8] {
    match name {
        "Reset" => &[
            0x00, 0x01, 0x02, 0x07, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01,
            0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x03, 0xa0, 0x40, 0x01, 0x03, 0x20, 0xc0,
            0x01, 0x04, 0xc8, 0x43, 0x70, 0x05, 0x45, 0xf0, 0x46, 0x6c, 0x00,
        ],
        "Reset (search)" => &[
            0x00, 0x01, 0x02, 0x07, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01,
            0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x03, 0xa0, 0x40, 0x01, 0x03, 0x20, 0xc0,
            0x01, 0x09, 0xc8, 0x43, 0x70, 0x01, 0xd3, 0xc0, 0x41, 0x1b, 0x00,
        ],
        "Configure" => &[
            0x00, 0x06, 0x01, 0xc0, 0x02, 0xf0, 0x01, 0x01, 0x03, 0xfa, 0x43, 0x01, 0x03, 0xfa,
            0x43, 0x04, 0x80, 0x1f, 0x43, 0x01, 0x03, 0xef, 0x42, 0x01, 0x03, 0x80, 0x3f, 0x01,
            0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x03, 0x80,
            0x3f, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01,
            0x03, 0x80, 0x3f, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x07, 0x16,
            0x44, 0x08, 0x01, 0x05, 0x14, 0x01, 0x05, 0x80, 0x40, 0x02, 0x01, 0x01, 0x01, 0x02,
            0x40, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x07, 0x7a, 0x44, 0x9a,
            0x99, 0x99, 0x3e, 0x01, 0x08, 0xc0, 0x40, 0x01, 0x92, 0x0a, 0x06, 0x3f, 0x01, 0x01,
            0x02, 0x3f, 0x0a, 0x1e, 0xe8, 0x07, 0x04, 0x03, 0x15, 0x8a, 0x64, 0x84, 0x00,
        ],
        "FrameChunk" => &[
            0x00, 0x05, 0x02, 0x07, 0x04, 0x02, 0x05, 0x08, 0x01, 0x02, 0x03, 0x09, 0xff, 0x04,
            0x05, 0x06, 0xd0, 0x07, 0xad, 0x3d, 0x00,
        ],
        "Ping" => &[
            0x00, 0x0a, 0x03, 0x84, 0x86, 0x88, 0x08, 0xe2, 0x51, 0x80, 0xfb, 0x00,
        ],
        "Hold" => &[0x00, 0x06, 0x04, 0x94, 0x2b, 0x6f, 0xd5, 0x00],
        "Measure" => &[
            0x00, 0x05, 0x05, 0x09, 0x01, 0x07, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01, 0x01, 0x01,
            0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x03, 0xa0, 0x40, 0x01, 0x03,
            0x20, 0xc0, 0x01, 0x07, 0xc8, 0x43, 0x3c, 0x69, 0xa6, 0x03, 0x00,
        ],
        _ => unreachable!("no golden frame for {name}"),
    }
}

fn golden_board(name: &str) -> &'static [u8] {
    match name {
        "Hello" => &[
            0x00, 0x01, 0x21, 0x05, 0x07, 0x71, 0x65, 0x6d, 0x75, 0x2d, 0x6d, 0x37, 0xa4, 0xb7,
            0xd8, 0xa7, 0x0d, 0xc0, 0xf0, 0xf5, 0x0b, 0x1c, 0x20, 0x30, 0x80, 0xe0, 0x12, 0x80,
            0x08, 0x80, 0x0b, 0xc4, 0xff, 0x6c, 0xbb, 0x00,
        ],
        "State" => &[
            0x00, 0x06, 0x01, 0x07, 0xe8, 0x07, 0x03, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01, 0x01,
            0x01, 0x01, 0x01, 0x02, 0x3f, 0x01, 0x03, 0x80, 0x3e, 0x07, 0x0a, 0x0c, 0x03, 0x80,
            0x20, 0x01, 0x05, 0x8b, 0xae, 0xbc, 0x64, 0x00,
        ],
        "State (searching)" => &[
            0x00, 0x06, 0x01, 0x08, 0xcc, 0x08, 0x03, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01, 0x01,
            0x01, 0x01, 0x01, 0x02, 0x3f, 0x01, 0x01, 0x01, 0x02, 0x01, 0x01, 0x01, 0x04, 0x90,
            0xbf, 0x05, 0x07, 0xe8, 0x07, 0xf6, 0x43, 0xed, 0x7c, 0x00,
        ],
        "State (lost)" => &[
            0x00, 0x06, 0x01, 0x09, 0xb0, 0x09, 0x03, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01, 0x01,
            0x01, 0x01, 0x01, 0x02, 0x3f, 0x01, 0x0a, 0x18, 0x41, 0x01, 0x02, 0x0c, 0x08, 0x88,
            0x27, 0x02, 0x05, 0xb2, 0xb8, 0x28, 0xa6, 0x00,
        ],
        "Features" => &[
            0x00, 0x03, 0x02, 0x07, 0x04, 0x02, 0x04, 0x01, 0x01, 0x03, 0x20, 0x41, 0x01, 0x0b,
            0xa0, 0x41, 0x9a, 0x99, 0x19, 0x3f, 0xcd, 0xcc, 0x4c, 0x3f, 0x02, 0x06, 0x02, 0x01,
            0x01, 0x03, 0x48, 0x41, 0x01, 0x07, 0xf0, 0x41, 0xfb, 0x65, 0x0f, 0x05, 0x00,
        ],
        "Stats" => &[
            0x00, 0x18, 0x03, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0a, 0xac,
            0x02, 0x0b, 0x0c, 0x0d, 0x0e, 0x0f, 0x10, 0x0b, 0xa7, 0x33, 0xc5, 0x00,
        ],
        "Dropped" => &[
            0x00, 0x0c, 0x04, 0x09, 0x01, 0xc0, 0x02, 0xf0, 0x01, 0x56, 0x68, 0x3e, 0x65, 0x00,
        ],
        "Ack" => &[0x00, 0x02, 0x05, 0x05, 0xba, 0xe6, 0xae, 0x3c, 0x00],
        "Nak" => &[0x00, 0x08, 0x06, 0x01, 0x01, 0x77, 0xa4, 0xd0, 0x95, 0x00],
        "Pong" => &[
            0x00, 0x08, 0x07, 0x84, 0x86, 0x88, 0x08, 0x22, 0xf7, 0x02, 0x0e, 0x00,
        ],
        "LinkEdges" => &[
            0x00, 0x07, 0x08, 0x09, 0x01, 0x02, 0x05, 0x01, 0x01, 0x01, 0x03, 0x3f, 0xff, 0x01,
            0x03, 0x20, 0x41, 0x01, 0x04, 0xa0, 0x41, 0x01, 0x01, 0x03, 0x48, 0x41, 0x01, 0x09,
            0xf0, 0x41, 0x03, 0x01, 0x79, 0xae, 0x6a, 0x6d, 0x00,
        ],
        "Measured" => &[
            0x00, 0x07, 0x09, 0x09, 0x01, 0x01, 0x01, 0x01, 0x01, 0x07, 0x40, 0x3f, 0xe0, 0x66,
            0xc2, 0x69, 0x00,
        ],
        "Hypotheses" => &[
            0x00, 0x04, 0x0a, 0x07, 0x02, 0x01, 0x05, 0x40, 0x3f, 0x0c, 0x03, 0x01, 0x03, 0x80,
            0x3f, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x02, 0x3f, 0x01, 0x01, 0x02, 0x3f, 0x02,
            0x03, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x06, 0xbf, 0x82,
            0xff, 0x53, 0xb5, 0x00,
        ],
        "PalmEdges" => &[
            0x00, 0x07, 0x0b, 0x09, 0x01, 0x03, 0x07, 0x01, 0x01, 0x01, 0x03, 0x3f, 0xff, 0x01,
            0x03, 0x20, 0x41, 0x01, 0x09, 0xa0, 0x41, 0x03, 0x01, 0xe9, 0xa8, 0x5f, 0x53, 0x00,
        ],
        _ => unreachable!("no golden frame for {name}"),
    }
}

#[test]
fn every_host_message_encodes_to_its_golden_bytes_and_back() {
    let mut buf = [0u8; MAX_MESSAGE];
    let messages = host_messages(&PIXELS);
    assert_eq!(
        messages.len(),
        7,
        "one golden frame per HostMessage variant (and per Reset start)"
    );
    for (name, message) in messages {
        let golden = golden_host(name);
        assert_eq!(encode(&message, &mut buf).unwrap(), golden, "{name}");
        let mut rx = Decoder::<MAX_MESSAGE>::new();
        let (used, decoded) = rx.feed::<HostMessage>(golden);
        assert_eq!(used, golden.len(), "{name}: one frame, all of it");
        assert_eq!(decoded.unwrap().unwrap(), message, "{name}");
    }
}

#[test]
fn every_board_message_encodes_to_its_golden_bytes_and_back() {
    let mut buf = [0u8; MAX_MESSAGE];
    let messages = board_messages();
    assert_eq!(
        messages.len(),
        14,
        "one golden frame per BoardMessage variant (and per State status)"
    );
    for (name, message) in messages {
        let golden = golden_board(name);
        assert_eq!(encode(&message, &mut buf).unwrap(), golden, "{name}");
        let mut rx = Decoder::<MAX_MESSAGE>::new();
        let mut decoded = None;
        let mut rest = golden;
        while decoded.is_none() && !rest.is_empty() {
            let (used, out) = rx.feed::<BoardMessage>(rest);
            decoded = out;
            rest = &rest[used..];
        }
        assert_eq!(decoded.unwrap().unwrap(), message, "{name}");
    }
}

/// Version 3's `State` (no `status`, no `search_evaluations`) and `Reset` (no `start`), as
/// a version 3 peer sends them: a version 4 receiver counts them as decode errors — never
/// takes them for something else — so an old board is refused by its `Hello`'s version and
/// an old host's `Reset` goes unanswered.
#[test]
fn version_3_state_and_reset_are_decode_errors() {
    const V3_STATE: &[u8] = &[
        0x00, 0x06, 0x01, 0x07, 0xe8, 0x07, 0x03, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01, 0x01, 0x01,
        0x01, 0x01, 0x02, 0x3f, 0x01, 0x03, 0x80, 0x3e, 0x0a, 0x0a, 0x0c, 0x03, 0x80, 0x20, 0x8f,
        0x95, 0x7a, 0x6e, 0x00,
    ];
    const V3_RESET: &[u8] = &[
        0x00, 0x01, 0x02, 0x07, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01,
        0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x03, 0xa0, 0x40, 0x01, 0x03, 0x20, 0xc0, 0x01, 0x08,
        0xc8, 0x43, 0x70, 0x72, 0xd8, 0x0f, 0x4f, 0x00,
    ];
    // What each frame decoded to: `Some(true)` for a decode error.
    let mut rx = Decoder::<MAX_MESSAGE>::new();
    let mut rest = V3_STATE;
    let mut state = None;
    while state.is_none() && !rest.is_empty() {
        let (used, out) = rx.feed::<BoardMessage>(rest);
        state = out.map(|r| matches!(r, Err(LinkError::Decode)));
        rest = &rest[used..];
    }
    assert_eq!(state, Some(true), "a version 3 State");
    let mut rx = Decoder::<MAX_MESSAGE>::new();
    let mut rest = V3_RESET;
    let mut reset = None;
    while reset.is_none() && !rest.is_empty() {
        let (used, out) = rx.feed::<HostMessage>(rest);
        reset = out.map(|r| matches!(r, Err(LinkError::Decode)));
        rest = &rest[used..];
    }
    assert_eq!(reset, Some(true), "a version 3 Reset");
    assert_eq!(rx.counters().decode_errors, 1);
}

/// `old`, a `Configure` as an older host sends it, is a decode error here (counted, nothing
/// answered), and today's `Configure` is `grown` bytes longer, for `why`.
fn an_older_configure_is_a_decode_error(old: &[u8], grown: usize, why: &str) {
    let mut rx = Decoder::<MAX_MESSAGE>::new();
    let (used, out) = rx.feed::<HostMessage>(old);
    assert_eq!(used, old.len());
    assert!(matches!(out, Some(Err(LinkError::Decode))), "{out:?}");
    assert_eq!(rx.counters().decode_errors, 1);
    let mut buf = [0u8; MAX_MESSAGE];
    let today = host_messages(&PIXELS)
        .into_iter()
        .find(|(name, _)| *name == "Configure")
        .unwrap()
        .1;
    let frame = encode(&today, &mut buf).unwrap();
    assert_eq!(frame.len(), old.len() + grown, "{why}");
}

/// Version 8's `Configure` (no `hypotheses_score_every`), as a version 8 host sends it: a
/// version 9 board counts it as a decode error and answers nothing.
#[test]
fn version_8_configure_is_a_decode_error() {
    const V8_CONFIGURE: &[u8] = &[
        0x00, 0x06, 0x01, 0xc0, 0x02, 0xf0, 0x01, 0x01, 0x03, 0xfa, 0x43, 0x01, 0x03, 0xfa, 0x43,
        0x04, 0x80, 0x1f, 0x43, 0x01, 0x03, 0xef, 0x42, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01, 0x01,
        0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01,
        0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x03, 0x80, 0x3f, 0x01,
        0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x07, 0x16, 0x44, 0x08, 0x01, 0x05, 0x14,
        0x01, 0x05, 0x80, 0x40, 0x02, 0x01, 0x01, 0x01, 0x02, 0x40, 0x01, 0x03, 0x80, 0x3f, 0x01,
        0x03, 0x80, 0x3f, 0x01, 0x07, 0x7a, 0x44, 0x9a, 0x99, 0x99, 0x3e, 0x01, 0x08, 0xc0, 0x40,
        0x01, 0x92, 0x0a, 0x06, 0x3f, 0x01, 0x01, 0x02, 0x3f, 0x09, 0x1e, 0xe8, 0x07, 0x04, 0x36,
        0xbb, 0xa1, 0xd5, 0x00,
    ];
    an_older_configure_is_a_decode_error(V8_CONFIGURE, 1, "one byte more: the score-every count");
}

/// Version 7's `Configure` (no `outermost_share` in its tracker parameters), as a version 7
/// host sends it: a version 8 or 9 board counts it as a decode error and answers nothing.
#[test]
fn version_7_configure_is_a_decode_error() {
    const V7_CONFIGURE: &[u8] = &[
        0x00, 0x06, 0x01, 0xc0, 0x02, 0xf0, 0x01, 0x01, 0x03, 0xfa, 0x43, 0x01, 0x03, 0xfa, 0x43,
        0x04, 0x80, 0x1f, 0x43, 0x01, 0x03, 0xef, 0x42, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01, 0x01,
        0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01,
        0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x03, 0x80, 0x3f, 0x01,
        0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x07, 0x16, 0x44, 0x08, 0x01, 0x05, 0x14,
        0x01, 0x05, 0x80, 0x40, 0x02, 0x01, 0x01, 0x01, 0x02, 0x40, 0x01, 0x03, 0x80, 0x3f, 0x01,
        0x03, 0x80, 0x3f, 0x01, 0x07, 0x7a, 0x44, 0x9a, 0x99, 0x99, 0x3e, 0x01, 0x08, 0xc0, 0x40,
        0x01, 0x92, 0x0a, 0x06, 0x3f, 0x09, 0x1e, 0xe8, 0x07, 0x04, 0xfa, 0xa2, 0xa8, 0xf4, 0x00,
    ];
    an_older_configure_is_a_decode_error(
        V7_CONFIGURE,
        4 + 1,
        "four bytes more for the share's f32, one for version 9's score-every count",
    );
}

/// Version 6's `Configure` (no `max_edge_angle_rad` in its tracker parameters), as a version 6
/// host sends it: a version 7 to 9 board counts it as a decode error and answers nothing.
#[test]
fn version_6_configure_is_a_decode_error() {
    const V6_CONFIGURE: &[u8] = &[
        0x00, 0x06, 0x01, 0xc0, 0x02, 0xf0, 0x01, 0x01, 0x03, 0xfa, 0x43, 0x01, 0x03, 0xfa, 0x43,
        0x04, 0x80, 0x1f, 0x43, 0x01, 0x03, 0xef, 0x42, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01, 0x01,
        0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01,
        0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x03, 0x80, 0x3f, 0x01,
        0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x07, 0x16, 0x44, 0x08, 0x01, 0x05, 0x14,
        0x01, 0x05, 0x80, 0x40, 0x02, 0x01, 0x01, 0x01, 0x02, 0x40, 0x01, 0x03, 0x80, 0x3f, 0x01,
        0x03, 0x80, 0x3f, 0x01, 0x07, 0x7a, 0x44, 0x9a, 0x99, 0x99, 0x3e, 0x01, 0x04, 0xc0, 0x40,
        0x01, 0x09, 0x1e, 0xe8, 0x07, 0x04, 0xc1, 0xc3, 0x7d, 0xd3, 0x00,
    ];
    an_older_configure_is_a_decode_error(
        V6_CONFIGURE,
        4 + 4 + 1,
        "four bytes more for the angle's f32, four for version 8's share, one for version 9's \
         count",
    );
}

/// Version 5's `Configure` (no `palm_edges` in its tracker parameters), as a version 5 host
/// sends it: a version 6 to 9 board counts it as a decode error and answers nothing.
#[test]
fn version_5_configure_is_a_decode_error() {
    const V5_CONFIGURE: &[u8] = &[
        0x00, 0x06, 0x01, 0xc0, 0x02, 0xf0, 0x01, 0x01, 0x03, 0xfa, 0x43, 0x01, 0x03, 0xfa, 0x43,
        0x04, 0x80, 0x1f, 0x43, 0x01, 0x03, 0xef, 0x42, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01, 0x01,
        0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01,
        0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x03, 0x80, 0x3f, 0x01,
        0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x07, 0x16, 0x44, 0x08, 0x01, 0x05, 0x14,
        0x01, 0x05, 0x80, 0x40, 0x02, 0x01, 0x01, 0x01, 0x02, 0x40, 0x01, 0x03, 0x80, 0x3f, 0x01,
        0x03, 0x80, 0x3f, 0x01, 0x07, 0x7a, 0x44, 0x9a, 0x99, 0x99, 0x3e, 0x01, 0x03, 0xc0, 0x40,
        0x09, 0x1e, 0xe8, 0x07, 0x04, 0xa2, 0xf2, 0x5d, 0xd8, 0x00,
    ];
    an_older_configure_is_a_decode_error(
        V5_CONFIGURE,
        1 + 4 + 4 + 1,
        "one byte more for the flag, four for version 7's angle, four for version 8's share, \
         one for version 9's count",
    );
}

/// Version 4's `Configure` (no `hypotheses`), as a version 4 host sends it: a version 5 board
/// counts it as a decode error and answers nothing, so an old host never configures a new
/// board with a count it did not mean. (The version 4 `Hello` is refused by the host.)
#[test]
fn version_4_configure_is_a_decode_error() {
    const V4_CONFIGURE: &[u8] = &[
        0x00, 0x06, 0x01, 0xc0, 0x02, 0xf0, 0x01, 0x01, 0x03, 0xfa, 0x43, 0x01, 0x03, 0xfa, 0x43,
        0x04, 0x80, 0x1f, 0x43, 0x01, 0x03, 0xef, 0x42, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01, 0x01,
        0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x03, 0x80, 0x3f, 0x01, 0x01,
        0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x03, 0x80, 0x3f, 0x01,
        0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x01, 0x07, 0x16, 0x44, 0x08, 0x01, 0x05, 0x14,
        0x01, 0x05, 0x80, 0x40, 0x02, 0x01, 0x01, 0x01, 0x02, 0x40, 0x01, 0x03, 0x80, 0x3f, 0x01,
        0x03, 0x80, 0x3f, 0x01, 0x07, 0x7a, 0x44, 0x9a, 0x99, 0x99, 0x3e, 0x01, 0x03, 0xc0, 0x40,
        0x08, 0x1e, 0xe8, 0x07, 0x8a, 0x08, 0xb3, 0x5f, 0x00,
    ];
    an_older_configure_is_a_decode_error(
        V4_CONFIGURE,
        2 + 4 + 4 + 1,
        "the count, version 6's palm flag, version 7's angle, version 8's share and version \
         9's score-every count",
    );
}

/// The spec's worked example of the model digest (§7), computed from the bytes written out
/// there, independently of the code that produces the canonical form.
#[test]
fn the_digest_of_the_worked_example_is_the_crc_of_the_bytes_in_the_spec() {
    let tiny = "0 palm base 0 0 0 box 10 20 5 1\n\
                1 f q7 0 30 0 cyl 5 2\n\
                2 t 0 0 0 0 tip 4 -\n\
                limit q7 0 1.5\n";
    let f = |v: f32| v.to_le_bytes();
    let mut bytes = vec![3u8];
    // Frame 0: base; d, a, alpha = 0; box 10 20 5 at the palm's default centre; next [1].
    bytes.push(0);
    for v in [0.0, 0.0, 0.0] {
        bytes.extend(f(v));
    }
    bytes.push(3);
    for v in [10.0, 20.0, 5.0, 2.5, -9.0, 0.0] {
        bytes.extend(f(v));
    }
    bytes.extend([1, 1]);
    // Frame 1: q7; d 0, a 30, alpha 0; cyl 5; next [2].
    bytes.extend([1, 7]);
    for v in [0.0, 30.0, 0.0] {
        bytes.extend(f(v));
    }
    bytes.push(1);
    bytes.extend(f(5.0));
    bytes.extend([1, 2]);
    // Frame 2: constant theta 0; d, a, alpha 0; tip 4; no next.
    bytes.push(2);
    for v in [0.0, 0.0, 0.0, 0.0] {
        bytes.extend(f(v));
    }
    bytes.push(2);
    bytes.extend(f(4.0));
    bytes.push(0);
    // One limit: q7 in [0, 1.5].
    bytes.extend([1, 7]);
    bytes.extend(f(0.0));
    bytes.extend(f(1.5));
    assert_eq!(bytes.len(), 95);
    let crc = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC).checksum(&bytes);
    assert_eq!(crc, 0x1800_0900, "the spec's value");
    let model = Model::parse(tiny).unwrap();
    assert_eq!(model_digest(&model), crc);
    let mut canonical = Vec::new();
    canonical_form(&model, |b| canonical.extend_from_slice(b));
    assert_eq!(canonical, bytes);
    // The built-in hand, as the spec gives it; names and number spellings do not count.
    assert_eq!(model_digest(&Model::hand().unwrap()), 0x02f9_1b5a);
    let respelled = tiny.replace("0 30 0", "0 3e1 0").replace(" f ", " finger ");
    assert_eq!(model_digest(&Model::parse(&respelled).unwrap()), crc);
}

#[test]
#[ignore = "prints the golden bytes of every message, for a deliberate layout change"]
fn print_golden_bytes() {
    let mut buf = [0u8; MAX_MESSAGE];
    for (name, m) in host_messages(&PIXELS) {
        println!("host {name}: {:02x?}", encode(&m, &mut buf).unwrap());
    }
    for (name, m) in board_messages() {
        println!("board {name}: {:02x?}", encode(&m, &mut buf).unwrap());
    }
}
