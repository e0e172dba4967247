//! Property tests of the link decoder over random and corrupted streams.
//!
//! - random bytes, fed in random pieces, never panic, and every frame the decoder reports is
//!   counted exactly once;
//! - a stream of valid messages with bytes corrupted at random: every message whose frame (and
//!   both delimiters around it) was untouched decodes exactly as sent — the decoder is back in
//!   step at the first clean frame — and no corrupted frame is ever taken for a message;
//! - a decoder joining a stream of valid frames at any byte (a host opening a board's port)
//!   decodes every frame that arrives whole and reports no error for the cut one;
//! - random host messages round-trip;
//! - random `Hypotheses` (version 5: up to 8 hypotheses of up to 32 states, any floats) fit
//!   `MAX_MESSAGE`, round-trip, and decode from a stream cut into random pieces.
//!
//! Case counts: 4000 random streams (up to 4 KiB each), 4000 corrupted streams (8–40
//! messages each, corruption rates up to 5 %), 4000 round trips, 2000 `Hypotheses`: 14,000
//! cases, a few seconds.

use digiteyes_core::protocol::*;
use proptest::prelude::*;

const CASES: u32 = 4000;

type Rx = Decoder<MAX_MESSAGE>;

fn frame_of(message: &HostMessage) -> Vec<u8> {
    let mut buf = [0u8; MAX_MESSAGE];
    encode(message, &mut buf).unwrap().to_vec()
}

/// The messages `rx` decodes from `stream` fed in pieces of `piece` bytes, each encoded
/// again (so they compare as bytes, NaN states included).
fn decoded_frames(rx: &mut Rx, stream: &[u8], piece: usize) -> Vec<Vec<u8>> {
    let mut got = Vec::new();
    for chunk in stream.chunks(piece) {
        let mut rest = chunk;
        while !rest.is_empty() {
            let (used, out) = rx.feed::<HostMessage>(rest);
            if let Some(Ok(m)) = out {
                got.push(frame_of(&m));
            }
            rest = &rest[used..];
        }
    }
    got
}

/// A host message with owned data, so the strategy needs no borrowed buffer.
#[derive(Debug, Clone)]
enum Owned {
    Ping(u32),
    Chunk(u32, u16, u16, u32, Vec<u8>),
    Reset(Vec<f32>, u32, bool),
    Configure(u16, u8, u8, [u8; 2], bool),
}

impl Owned {
    fn message(&self) -> HostMessage<'_> {
        match self {
            Owned::Ping(t) => HostMessage::Ping(*t),
            Owned::Chunk(frame, width, height, offset, data) => {
                HostMessage::FrameChunk(FrameChunk {
                    frame: *frame,
                    width: *width,
                    height: *height,
                    offset: *offset,
                    data,
                })
            }
            Owned::Reset(q, free, search) => HostMessage::Reset(Reset {
                q: q.iter().copied().collect(),
                free: *free,
                start: if *search { Start::Search } else { Start::Given },
            }),
            Owned::Configure(budget, hypotheses, every, caps, keep) => {
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
                    stats_every: 0,
                    search_evaluations_per_frame: *budget,
                    hypotheses: HypothesesParams {
                        count: *hypotheses,
                        score_every: *every,
                        sample_iterations: caps[0],
                        other_iterations: caps[1],
                        keep_fingers: *keep,
                    },
                })
            }
        }
    }
}

fn owned() -> impl Strategy<Value = Owned> {
    prop_oneof![
        any::<u32>().prop_map(Owned::Ping),
        (
            any::<u32>(),
            any::<u16>(),
            any::<u16>(),
            any::<u32>(),
            prop::collection::vec(any::<u8>(), 0..=MAX_CHUNK)
        )
            .prop_map(|(f, w, h, o, d)| Owned::Chunk(f, w, h, o, d)),
        (
            prop::collection::vec(any::<f32>(), 0..=32),
            any::<u32>(),
            any::<bool>()
        )
            .prop_map(|(q, free, search)| Owned::Reset(q, free, search)),
        (
            any::<u16>(),
            any::<u8>(),
            any::<u8>(),
            any::<[u8; 2]>(),
            any::<bool>()
        )
            .prop_map(|(b, k, s, caps, keep)| Owned::Configure(b, k, s, caps, keep)),
    ]
}

/// A random `Hypotheses` message (version 5).
fn hypotheses() -> impl Strategy<Value = BoardMessage> {
    let one = (
        any::<f32>(),
        any::<u32>(),
        prop::collection::vec(any::<f32>(), 0..=32),
    );
    (
        any::<u32>(),
        prop::collection::vec(one, 0..=digiteyes_core::config::MAX_HYPOTHESES),
    )
        .prop_map(|(frame, list)| {
            BoardMessage::Hypotheses(Hypotheses {
                frame,
                hypotheses: list
                    .into_iter()
                    .map(|(score, age, q)| WireHypothesis {
                        score,
                        age,
                        q: q.into_iter().collect(),
                    })
                    .collect(),
            })
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]

    #[test]
    fn random_bytes_never_panic(
        bytes in prop::collection::vec(any::<u8>(), 0..4096),
        piece in 1usize..300,
    ) {
        let mut rx = Rx::new();
        let mut reported = 0u32;
        for chunk in bytes.chunks(piece) {
            let mut rest = chunk;
            while !rest.is_empty() {
                let (used, out) = rx.feed::<HostMessage>(rest);
                prop_assert!(used >= 1 && used <= rest.len());
                reported += u32::from(out.is_some());
                rest = &rest[used..];
            }
        }
        let c = rx.counters();
        prop_assert_eq!(
            reported,
            c.messages + c.crc_errors + c.framing_errors + c.decode_errors + c.overflows
        );
    }

    #[test]
    fn corruption_costs_only_the_corrupted_frames(
        seeds in prop::collection::vec((any::<u32>(), 0usize..=MAX_CHUNK), 8..40),
        rate in 0.0f64..0.05,
        flips in prop::collection::vec((any::<f64>(), any::<u8>()), 4096),
        piece in 1usize..2000,
    ) {
        let data: Vec<u8> = (0..MAX_CHUNK).map(|i| (i * 7 % 256) as u8).collect();
        let messages: Vec<HostMessage> = seeds
            .iter()
            .map(|&(token, n)| {
                if n % 3 == 0 {
                    HostMessage::Ping(token)
                } else {
                    HostMessage::FrameChunk(FrameChunk {
                        frame: token,
                        width: 64,
                        height: 48,
                        offset: n as u32,
                        data: &data[..n],
                    })
                }
            })
            .collect();
        let mut stream = Vec::new();
        let mut spans = Vec::new();
        for m in &messages {
            let f = frame_of(m);
            spans.push(stream.len()..stream.len() + f.len());
            stream.extend_from_slice(&f);
        }
        let mut corrupted = vec![false; stream.len()];
        for (i, byte) in stream.iter_mut().enumerate() {
            let (p, x) = flips[i % flips.len()];
            if p < rate && x != 0 {
                *byte ^= x;
                corrupted[i] = true;
            }
        }
        let got = decoded_frames(&mut Rx::new(), &stream, piece);
        // Every clean frame arrives, in order; nothing arrives that was not sent.
        let clean: Vec<Vec<u8>> = messages
            .iter()
            .zip(&spans)
            .filter(|(_, s)| !corrupted[(*s).clone()].contains(&true))
            .map(|(m, _)| frame_of(m))
            .collect();
        let sent: Vec<Vec<u8>> = messages.iter().map(frame_of).collect();
        for g in &got {
            prop_assert!(sent.contains(g), "a corrupted frame was taken for a message");
        }
        let mut it = got.iter();
        for c in &clean {
            prop_assert!(it.any(|g| g == c), "a clean frame was lost");
        }
    }

    #[test]
    fn joining_a_stream_anywhere_loses_no_whole_frame_and_reports_no_error(
        tokens in prop::collection::vec(any::<u32>(), 2..12),
        cut_share in 0.0f64..1.0,
        piece in 1usize..64,
    ) {
        // A host opening a board's port discards what arrived before, which can cut a frame
        // anywhere. The mid-stream decoder drops the tail without an error and decodes every
        // frame that arrives whole, even one whose leading delimiter was cut off; the plain
        // decoder counts such a tail as an error.
        let frames: Vec<Vec<u8>> = tokens.iter().map(|&t| frame_of(&HostMessage::Ping(t))).collect();
        let stream: Vec<u8> = frames.concat();
        let cut = ((stream.len() as f64) * cut_share) as usize;
        let feed_all = |rx: &mut Rx| decoded_frames(rx, &stream[cut..], piece);
        // The frames whose body (all but the leading delimiter) is after the cut.
        let mut start = 0;
        let mut whole = Vec::new();
        for f in &frames {
            if start + 1 >= cut {
                whole.push(f.clone());
            }
            start += f.len();
        }
        let mut rx = Rx::mid_stream();
        let got = feed_all(&mut rx);
        prop_assert_eq!(&got, &whole);
        let c = rx.counters();
        prop_assert_eq!(c.crc_errors + c.framing_errors + c.decode_errors + c.overflows, 0);
        let mut start = 0;
        let inside = frames.iter().any(|f| {
            let body = start + 1..start + f.len() - 1;
            start += f.len();
            body.contains(&cut) && cut > body.start
        });
        prop_assert_eq!(rx.joined_mid_frame(), u32::from(inside));
        let mut plain = Rx::new();
        let _ = feed_all(&mut plain);
        let c = plain.counters();
        prop_assert_eq!(c.crc_errors + c.framing_errors, u32::from(inside));
    }

    #[test]
    fn host_messages_round_trip(owned in owned()) {
        let message = owned.message();
        let f = frame_of(&message);
        prop_assert!(f.len() <= MAX_MESSAGE);
        let mut rx = Rx::new();
        let (used, out) = rx.feed::<HostMessage>(&f);
        prop_assert_eq!(used, f.len());
        let back = out.unwrap().unwrap();
        // Compare encodings: NaN states are not equal to themselves.
        prop_assert_eq!(frame_of(&back), f);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES / 2))]

    #[test]
    fn hypotheses_fit_and_round_trip_in_pieces(message in hypotheses(), piece in 1usize..64) {
        let mut buf = [0u8; MAX_MESSAGE];
        let f = encode(&message, &mut buf).unwrap().to_vec();
        prop_assert!(f.len() <= 1122, "{} bytes", f.len());
        let mut rx = Rx::new();
        let mut got = Vec::new();
        for chunk in f.chunks(piece) {
            let mut rest = chunk;
            while !rest.is_empty() {
                let (used, out) = rx.feed::<BoardMessage>(rest);
                if let Some(out) = out {
                    got.push(out);
                }
                rest = &rest[used..];
            }
        }
        prop_assert_eq!(got.len(), 1);
        let back = got.pop().unwrap().unwrap();
        // Compare encodings: NaN scores and states are not equal to themselves.
        let mut again = [0u8; MAX_MESSAGE];
        prop_assert_eq!(encode(&back, &mut again).unwrap(), &f[..]);
    }
}
