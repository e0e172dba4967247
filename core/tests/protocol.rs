//! The board link: every message round-trips, the largest fit the buffers, the digest tells
//! models apart, parameters are range-checked, and the decoder counts and survives garbage.

use digiteyes_core::model::{Limit, Model};
use digiteyes_core::protocol::*;
use digiteyes_core::tracker::TrackerConfig;
use heapless::{String, Vec};

type Rx = Decoder<MAX_MESSAGE>;

fn full_q(n: usize) -> Vec<f32, 32> {
    (0..n).map(|i| i as f32 * 0.125 - 1.0).collect()
}

fn camera() -> CameraParams {
    CameraParams {
        width: 640,
        height: 480,
        intrinsics: [600.0, 600.0, 319.5, 239.5],
        r: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
        t: [0.0, 0.0, 500.0],
    }
}

fn board_messages() -> std::vec::Vec<BoardMessage> {
    let mut links = Vec::new();
    for link in 0..48u8 {
        // Every link with both an axis and a tip: the largest Features there can be.
        let axis = Some(AxisLine {
            point: [f32::from(link), 2.5],
            direction: [0.6, -0.8],
        });
        let tip = Some([1.0, f32::from(link)]);
        links.push(LinkMeasurement { link, axis, tip }).unwrap();
    }
    let frame = u32::MAX;
    vec![
        BoardMessage::Hello(Hello {
            version: PROTOCOL_VERSION,
            board: String::try_from("a-board-name-of-24-bytes").unwrap(),
            model_digest: 0xdead_beef,
            clock_hz: 25_000_000,
            capacities: Capacities {
                states: 28,
                max_states: 32,
                max_links: 48,
                max_frame_bytes: 640 * 480,
                max_chunk: MAX_CHUNK as u16,
                max_message: MAX_MESSAGE as u16,
            },
        }),
        BoardMessage::State(State {
            frame: u32::MAX,
            timestamp: u64::MAX,
            q: full_q(32),
            rms_px: f32::NAN,
            lost: true,
            features_found: u16::MAX,
            features_expected: u16::MAX,
            iterations: u8::MAX,
            track_ticks: u32::MAX,
            status: WireStatus::Lost,
            search_evaluations: u16::MAX,
        }),
        BoardMessage::Features(Features {
            frame,
            camera: u8::MAX,
            links,
        }),
        BoardMessage::Stats(Stats {
            frames: u32::MAX,
            iterations: u32::MAX,
            lost: u32::MAX,
            dropped: DropCounts {
                incomplete: u32::MAX,
                wrong_size: u32::MAX,
                too_large: u32::MAX,
                not_ready: u32::MAX,
                superseded: u32::MAX,
                tracker_error: u32::MAX,
            },
            bad_frames: u32::MAX,
            link: LinkCounters {
                messages: u32::MAX,
                crc_errors: u32::MAX,
                framing_errors: u32::MAX,
                decode_errors: u32::MAX,
                overflows: u32::MAX,
            },
            capacity_overflows: u32::MAX,
            stale_chunks: u32::MAX,
        }),
        BoardMessage::Dropped(Dropped {
            frame: 3,
            reason: DropReason::WrongSize(320, 240),
        }),
        BoardMessage::Dropped(Dropped {
            frame: 4,
            reason: DropReason::Incomplete,
        }),
        BoardMessage::Ack(Command::Configure),
        BoardMessage::Nak(Command::Reset, Refusal::BadFreeMask),
        BoardMessage::Pong(0x0102_0304),
        // The largest answer to a Measure: every edge a link can have, worst-case varints.
        BoardMessage::LinkEdges(LinkEdges {
            frame: u32::MAX,
            iteration: u8::MAX,
            index: u8::MAX,
            link: u8::MAX,
            edges: (0..digiteyes_core::features::MAX_LINK_EDGES)
                .map(|i| WireEdge {
                    s: i as f32 / 7.0,
                    side: -1,
                    position: [f32::MAX, f32::MIN],
                })
                .collect(),
            tip: Some([f32::MAX, f32::MIN]),
            expected: u16::MAX,
            masked: u16::MAX,
        }),
        BoardMessage::Measured(Measured {
            frame: u32::MAX,
            iteration: u8::MAX,
            held: false,
            links: u8::MAX,
            silhouette: Some(f32::NAN),
        }),
        BoardMessage::Ack(Command::Hold),
        // The largest palm outline answer: a slice's edge each, worst-case varints (version 6).
        BoardMessage::PalmEdges(PalmEdges {
            frame: u32::MAX,
            iteration: u8::MAX,
            corners: [7, 6],
            edges: (0..digiteyes_core::config::MAX_SLICES_PER_LINK)
                .map(|i| WireEdge {
                    s: i as f32 / 7.0,
                    side: 1,
                    position: [f32::MAX, f32::MIN],
                })
                .collect(),
            expected: u16::MAX,
            masked: u16::MAX,
        }),
        // The largest Hypotheses: every hypothesis a board carries, each with every state a
        // message carries, worst-case varints (version 5).
        largest_hypotheses(),
    ]
}

fn largest_hypotheses() -> BoardMessage {
    BoardMessage::Hypotheses(Hypotheses {
        frame: u32::MAX,
        hypotheses: (0..digiteyes_core::config::MAX_HYPOTHESES)
            .map(|i| WireHypothesis {
                score: -(i as f32) / 3.0,
                age: u32::MAX,
                q: full_q(32),
            })
            .collect(),
    })
}

fn host_messages(data: &[u8]) -> std::vec::Vec<HostMessage<'_>> {
    vec![
        HostMessage::Reset(Reset {
            q: full_q(32),
            free: u32::MAX,
            start: Start::Search,
        }),
        HostMessage::Configure(Configure {
            camera: camera(),
            tracker: TrackerParams::default(),
            features_every: u16::MAX,
            stats_every: u16::MAX,
            search_evaluations_per_frame: u16::MAX,
            hypotheses: HypothesesParams {
                count: u8::MAX,
                score_every: u8::MAX,
                sample_iterations: u8::MAX,
                other_iterations: u8::MAX,
                keep_fingers: true,
            },
        }),
        HostMessage::FrameChunk(FrameChunk {
            frame: u32::MAX,
            width: u16::MAX,
            height: u16::MAX,
            offset: u32::MAX,
            data,
        }),
        HostMessage::Ping(u32::MAX),
        HostMessage::Hold,
        HostMessage::Measure(Measure {
            frame: u32::MAX,
            iteration: u8::MAX,
            q: full_q(32),
        }),
    ]
}

/// Feeds a whole stream; collects what each frame decoded to.
fn decode_all<T, F>(rx: &mut Rx, mut stream: &[u8], mut each: F)
where
    F: FnMut(Result<T, LinkError>),
    T: for<'d> serde::Deserialize<'d>,
{
    while !stream.is_empty() {
        let (used, out) = rx.feed::<T>(stream);
        if let Some(out) = out {
            each(out);
        }
        stream = &stream[used..];
    }
}

fn same(a: &BoardMessage, b: &BoardMessage) -> bool {
    // NaN != NaN: compare the encodings instead.
    let (mut x, mut y) = ([0u8; MAX_MESSAGE], [0u8; MAX_MESSAGE]);
    encode(a, &mut x).unwrap() == encode(b, &mut y).unwrap()
}

#[test]
fn every_board_message_round_trips_and_fits() {
    for message in board_messages() {
        let mut buf = [0u8; MAX_MESSAGE];
        let frame = encode(&message, &mut buf).unwrap();
        assert!(frame.len() <= MAX_MESSAGE);
        assert!(frame.len() <= max_encoded_len(&message).unwrap());
        assert_eq!((frame[0], frame[frame.len() - 1]), (0, 0));
        assert!(
            !frame[1..frame.len() - 1].contains(&0),
            "COBS leaves no zero inside"
        );
        let mut rx = Rx::new();
        let (used, out) = rx.feed::<BoardMessage>(frame);
        assert_eq!(used, frame.len());
        assert!(same(&out.unwrap().unwrap(), &message), "{message:?}");
    }
}

#[test]
fn every_host_message_round_trips_and_the_largest_chunk_fits() {
    let data: std::vec::Vec<u8> = (0..MAX_CHUNK).map(|i| (i % 251) as u8).collect();
    for message in host_messages(&data) {
        let mut buf = [0u8; MAX_MESSAGE];
        let frame = encode(&message, &mut buf).unwrap().to_vec();
        assert!(frame.len() <= MAX_MESSAGE, "{} bytes", frame.len());
        let mut rx = Rx::new();
        let (_, out) = rx.feed::<HostMessage>(&frame);
        assert_eq!(out.unwrap().unwrap(), message);
    }
}

#[test]
fn encoding_into_a_small_buffer_is_an_error_not_a_panic() {
    let message = BoardMessage::Pong(5);
    let mut buf = [0u8; 64];
    let full = encode(&message, &mut buf).unwrap().len();
    for size in 0..full {
        let mut small = vec![0u8; size];
        assert_eq!(encode(&message, &mut small), Err(EncodeError::BufferFull));
    }
}

#[test]
fn a_stream_cut_anywhere_decodes_the_same() {
    let mut stream = std::vec::Vec::new();
    let messages = board_messages();
    for m in &messages {
        let mut buf = [0u8; MAX_MESSAGE];
        stream.extend_from_slice(encode(m, &mut buf).unwrap());
    }
    for piece in [1, 2, 3, 7, 64, 1000] {
        let mut rx = Rx::new();
        let mut got = std::vec::Vec::new();
        for chunk in stream.chunks(piece) {
            decode_all::<BoardMessage, _>(&mut rx, chunk, |m| got.push(m.unwrap()));
        }
        assert_eq!(got.len(), messages.len());
        assert!(got.iter().zip(&messages).all(|(a, b)| same(a, b)));
        assert_eq!(rx.counters().messages as usize, messages.len());
    }
}

#[test]
fn garbage_before_a_message_costs_only_the_garbage() {
    let mut buf = [0u8; MAX_MESSAGE];
    let frame = encode(&BoardMessage::Pong(9), &mut buf).unwrap();
    let mut stream = b"\x13\x37 line noise without a delimiter".to_vec();
    stream.extend_from_slice(frame);
    let mut rx = Rx::new();
    let mut got = std::vec::Vec::new();
    decode_all::<BoardMessage, _>(&mut rx, &stream, |m| got.push(m));
    assert_eq!(got.len(), 2);
    assert!(got[0].is_err());
    assert_eq!(got[1], Ok(BoardMessage::Pong(9)));
}

#[test]
fn each_kind_of_error_is_told_apart_and_counted() {
    let mut rx = Rx::new();
    let mut buf = [0u8; MAX_MESSAGE];
    let good = encode(&BoardMessage::Pong(1), &mut buf).unwrap().to_vec();

    // One flipped bit inside the payload: the CRC catches it.
    let mut flipped = good.clone();
    flipped[3] ^= 0x10;
    let mut errors = std::vec::Vec::new();
    decode_all::<BoardMessage, _>(&mut rx, &flipped, |m| errors.push(m.unwrap_err()));
    assert_eq!(errors, [LinkError::Crc]);

    // A COBS code byte pointing past the frame's end.
    decode_all::<BoardMessage, _>(&mut rx, &[0, 0x40, 1, 2, 0], |m| {
        assert_eq!(m.unwrap_err(), LinkError::Framing)
    });

    // A good CRC over bytes that are no message (variant 200).
    let mut raw = [200u8, 1, 0, 0, 0, 0, 0, 0, 0];
    let crc = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC).checksum(&raw[..1]);
    raw[1..5].copy_from_slice(&crc.to_le_bytes());
    let mut cobs_buf = [0u8; 16];
    let n = cobs::encode(&raw[..5], &mut cobs_buf);
    let mut frame = vec![0];
    frame.extend_from_slice(&cobs_buf[..n]);
    frame.push(0);
    decode_all::<BoardMessage, _>(&mut rx, &frame, |m| {
        assert_eq!(m.unwrap_err(), LinkError::Decode)
    });

    // Longer than the receive buffer.
    let long = vec![0x55u8; MAX_MESSAGE + 10];
    decode_all::<BoardMessage, _>(&mut rx, &long, |_| panic!("no delimiter yet"));
    decode_all::<BoardMessage, _>(&mut rx, &[0], |m| {
        assert_eq!(m.unwrap_err(), LinkError::Overflow)
    });

    // And the next good frame still decodes.
    decode_all::<BoardMessage, _>(&mut rx, &good, |m| {
        assert_eq!(m.unwrap(), BoardMessage::Pong(1))
    });
    let c = rx.counters();
    assert_eq!(
        (
            c.crc_errors,
            c.framing_errors,
            c.decode_errors,
            c.overflows,
            c.messages
        ),
        (1, 1, 1, 1, 1)
    );
}

#[test]
fn a_message_for_the_other_direction_is_a_decode_error() {
    let mut buf = [0u8; MAX_MESSAGE];
    let frame = encode(&HostMessage::Ping(3), &mut buf).unwrap();
    let mut rx = Rx::new();
    let (_, out) = rx.feed::<BoardMessage>(frame);
    // Ping (variant 3) reads as a Stats whose fields run out: never mistaken for a message.
    assert_eq!(out, Some(Err(LinkError::Decode)));
}

#[test]
fn model_digest_tells_models_apart() {
    let hand = Model::hand().unwrap();
    let reparsed = Model::parse(digiteyes_core::model::HAND_DH).unwrap();
    assert_eq!(model_digest(&hand), model_digest(&reparsed));
    let mut changed = hand.clone();
    changed.set_limit(7, Some(Limit { lo: -0.5, hi: 0.25 }));
    assert_ne!(model_digest(&hand), model_digest(&changed));
}

#[test]
fn tracker_parameters_round_trip_and_are_range_checked() {
    let config = TrackerConfig::default();
    let params = TrackerParams::from_config(&config);
    assert_eq!(params.to_config().unwrap(), config);

    type Spoil = fn(&mut TrackerParams);
    let bad: [(&str, Spoil); 15] = [
        ("iterations", |p| p.iterations = 0),
        ("slices_per_link", |p| p.slices_per_link = 200),
        ("window_px", |p| p.window_px = 2),
        ("min_contrast", |p| p.min_contrast = f32::NAN),
        ("conditioning", |p| p.conditioning[2] = -1.0),
        ("lost_min_found", |p| p.lost_min_found = 1.5),
        ("lost_rms_px", |p| p.lost_rms_px = f32::INFINITY),
        ("robust", |p| p.robust = WireRobust::Huber(0.0)),
        ("robust", |p| p.robust = WireRobust::Tukey(f32::NAN)),
        ("max_edge_angle_rad", |p| p.max_edge_angle_rad = -0.1),
        ("max_edge_angle_rad", |p| p.max_edge_angle_rad = 2.0),
        ("max_edge_angle_rad", |p| p.max_edge_angle_rad = f32::NAN),
        ("outermost_share", |p| p.outermost_share = -0.1),
        ("outermost_share", |p| p.outermost_share = 1.5),
        ("outermost_share", |p| p.outermost_share = f32::NAN),
    ];
    for (name, spoil) in bad {
        let mut p = params;
        spoil(&mut p);
        assert_eq!(p.to_config(), Err(BadParameter(name)));
    }
}

#[test]
fn camera_parameters_round_trip_and_bad_cameras_are_refused() {
    let wire = camera();
    let cam = wire.to_camera().unwrap();
    assert_eq!(CameraParams::from_camera(&cam), Some(wire));
    assert_eq!(wire.frame_bytes(), 640 * 480);
    let mut bad = wire;
    bad.intrinsics[0] = 0.0;
    assert!(bad.to_camera().is_err());
    let mut bad = wire;
    bad.r[0] = 2.0;
    assert!(bad.to_camera().is_err());
    let mut bad = wire;
    bad.width = 0;
    assert!(bad.to_camera().is_err());
}

#[test]
fn the_largest_messages_nearly_fill_max_message() {
    // MAX_MESSAGE is sized by the largest message, not guessed: within 10 % of it.
    let largest = board_messages()
        .iter()
        .map(|m| {
            let mut buf = [0u8; MAX_MESSAGE];
            encode(m, &mut buf).unwrap().len()
        })
        .max()
        .unwrap();
    assert!(
        largest * 10 >= MAX_MESSAGE * 9,
        "{largest} of {MAX_MESSAGE}"
    );
}

/// `MAX_MESSAGE` counts both delimiters: an encoded frame of exactly 1408 bytes decodes, one
/// of 1409 is an overflow, counted, and the next frame still decodes.
#[test]
fn the_size_limit_counts_both_delimiters() {
    let mut buf = [0u8; 2 * MAX_MESSAGE];
    let data = [7u8; 1400];
    let frame_of = |len: usize, buf: &mut [u8]| -> std::vec::Vec<u8> {
        let chunk = HostMessage::FrameChunk(FrameChunk {
            frame: 1,
            width: 1,
            height: 1,
            offset: 0,
            data: &data[..len],
        });
        encode(&chunk, buf).unwrap().to_vec()
    };
    let mut at = |total: usize| {
        (1000..1400)
            .map(|len| frame_of(len, &mut buf))
            .find(|f| f.len() == total)
            .unwrap_or_else(|| panic!("no chunk encodes to {total} bytes"))
    };
    let (fits, over) = (at(MAX_MESSAGE), at(MAX_MESSAGE + 1));
    let mut rx = Rx::new();
    let mut outcomes = std::vec::Vec::new();
    let stream: std::vec::Vec<u8> = [&fits[..], &over[..], &fits[..]].concat();
    let mut rest = &stream[..];
    while !rest.is_empty() {
        let (used, out) = rx.feed::<HostMessage>(rest);
        if let Some(out) = out {
            outcomes.push(out.map(|_| ()));
        }
        rest = &rest[used..];
    }
    assert_eq!(outcomes, [Ok(()), Err(LinkError::Overflow), Ok(())]);
    assert_eq!(rx.counters().overflows, 1);
}

#[test]
fn drop_counts_record_each_reason_in_its_counter_and_total_them() {
    use digiteyes_core::protocol::{DropCounts, DropReason};
    let mut counts = DropCounts::default();
    let reasons = [
        DropReason::Incomplete,
        DropReason::WrongSize(1, 2),
        DropReason::TooLarge,
        DropReason::NotReady,
        DropReason::Superseded,
        DropReason::TrackerError,
    ];
    for (k, reason) in reasons.iter().enumerate() {
        for _ in 0..=k {
            counts.record(reason);
        }
    }
    assert_eq!(
        counts,
        DropCounts {
            incomplete: 1,
            wrong_size: 2,
            too_large: 3,
            not_ready: 4,
            superseded: 5,
            tracker_error: 6,
        }
    );
    assert_eq!(counts.total(), 21);
    counts.tracker_error = u32::MAX;
    counts.record(&DropReason::TrackerError);
    assert_eq!((counts.tracker_error, counts.total()), (u32::MAX, u32::MAX));
}

/// The hypothesis count a board takes is 1..=MAX_HYPOTHESES, and the host's default is in it;
/// the largest `Hypotheses` (8 × 32 states) is well within `MAX_MESSAGE`.
#[test]
fn hypothesis_counts_and_the_largest_hypotheses_message() {
    use digiteyes_core::config::MAX_HYPOTHESES;
    assert!(!hypotheses_in_range(0));
    assert!((1..=MAX_HYPOTHESES as u8).all(hypotheses_in_range));
    assert!(!hypotheses_in_range(MAX_HYPOTHESES as u8 + 1));
    assert!(!hypotheses_in_range(u8::MAX));
    assert!(hypotheses_in_range(HypothesesParams::default().count));
    let mut buf = [0u8; MAX_MESSAGE];
    let message = largest_hypotheses();
    let n = encode(&message, &mut buf).unwrap().len();
    // Body 1,111 bytes + CRC 4, COBS at most 5 more, 2 delimiters: 1,122 at most
    // (docs/protocol.md §11); these values need 1,118.
    assert!((1100..=1122).contains(&n), "{n} bytes");
    let BoardMessage::Hypotheses(h) = message else {
        unreachable!()
    };
    assert_eq!(h.hypotheses.len(), MAX_HYPOTHESES);
}

/// The hypotheses a host sends by default are the tracker's own, and applying them to the
/// tracker's configuration changes nothing; every part of them reaches the configuration, and
/// a board takes a count in 1..=MAX_HYPOTHESES scored at least one frame in 255.
#[test]
fn the_hypotheses_parameters_are_the_trackers_own_and_reach_its_configuration() {
    use digiteyes_core::config::MAX_HYPOTHESES;
    use digiteyes_core::hypotheses::HypothesesConfig;
    let own = HypothesesConfig::default();
    let defaults = HypothesesParams::default();
    assert_eq!(defaults.over(own), own);
    assert!(defaults.is_valid());
    let asked = HypothesesParams {
        count: 3,
        score_every: 4,
        sample_iterations: 1,
        other_iterations: 2,
        keep_fingers: !own.keep_fingers,
    };
    let expected = HypothesesConfig {
        count: 3,
        score_every_frames: 4,
        sample_iterations: 1,
        other_iterations: 2,
        keep_fingers: !own.keep_fingers,
        ..own
    };
    assert_eq!(asked.over(own), expected, "only the host's part changes");
    for (count, score_every, valid) in [
        (1, 1, true),
        (MAX_HYPOTHESES as u8, 255, true),
        (0, 1, false),
        (MAX_HYPOTHESES as u8 + 1, 1, false),
        (2, 0, false),
    ] {
        let params = HypothesesParams {
            count,
            score_every,
            ..defaults
        };
        assert_eq!(params.is_valid(), valid, "{params:?}");
    }
}

/// `Configure::new` is what a host sends when it names only the camera and the tracker: each
/// other field at its published default, and it round-trips like any message.
#[test]
fn a_configure_with_the_defaults_names_only_the_camera_and_the_tracker() {
    let tracker = TrackerParams {
        iterations: 3,
        ..TrackerParams::default()
    };
    let configure = Configure::new(camera(), tracker);
    assert_eq!((configure.camera, configure.tracker), (camera(), tracker));
    assert_eq!((configure.features_every, configure.stats_every), (0, 0));
    assert_eq!(
        configure.search_evaluations_per_frame,
        default_search_evaluations()
    );
    assert_eq!(configure.hypotheses, HypothesesParams::default());
    assert!(configure.hypotheses.is_valid());
    let message = HostMessage::Configure(configure);
    let mut buf = [0u8; MAX_MESSAGE];
    let frame = encode(&message, &mut buf).unwrap();
    let mut rx = Decoder::<MAX_MESSAGE>::new();
    let (_, decoded) = rx.feed::<HostMessage>(frame);
    assert_eq!(decoded.unwrap().unwrap(), message);
}
