//! A board's messages as Open Sound Control packets (OSC 1.0, one packet per UDP datagram).
//!
//! The address space (`docs/forwarding.md`), every argument a 32-bit int `i`, float `f` or
//! string `s`, booleans as ints 0/1 (what every OSC application reads):
//!
//! | address | arguments |
//! | --- | --- |
//! | `/digiteyes/state` | `i` frame, `i` lost (0/1), `f` rms_px, then `f` q0 .. q(n−1) |
//! | `/digiteyes/q/N` | `f` qN (one message per state: quaternion, mm, rad) |
//! | `/digiteyes/mouse` | `f` x_mm, `f` y_mm, `f` height_mm, `i` button 1, `i` button 2 |
//! | `/digiteyes/dropped` | `i` frame, `s` reason |
//! | `/digiteyes/stats` | `i` frames, `i` iterations, `i` lost, `i` dropped, `i` bad_frames, `i` crc_errors, `i` framing_errors |
//!
//! A State's messages (`state`, every `q/N`, and `mouse` when there is one) go as one bundle
//! with the time tag "immediately", so they arrive and apply together.

use anyhow::{anyhow, Result};
use digiteyes_core::protocol::{DropReason, Dropped, State, Stats};
use rosc::{OscBundle, OscMessage, OscPacket, OscTime, OscType};

use crate::mouse_pole::MousePole;

/// The address of a State's summary and values.
pub const STATE: &str = "/digiteyes/state";
/// The prefix of the one-value-per-state addresses, `/digiteyes/q/N`.
pub const Q_PREFIX: &str = "/digiteyes/q/";
/// The address of the 3D mouse.
pub const MOUSE: &str = "/digiteyes/mouse";
/// The address of a dropped frame.
pub const DROPPED: &str = "/digiteyes/dropped";
/// The address of the board's counters.
pub const STATS: &str = "/digiteyes/stats";

/// The OSC time tag "immediately" (OSC 1.0: seconds 0, fraction 1).
pub const IMMEDIATELY: OscTime = OscTime {
    seconds: 0,
    fractional: 1,
};

/// A State as one bundle: `/digiteyes/state`, `/digiteyes/q/N` for each of `q` (the values to
/// send: the state's own or smoothed ones), then `/digiteyes/mouse` if `mouse` is given.
pub fn state_bundle(state: &State, q: &[f32], mouse: Option<&MousePole>) -> OscPacket {
    let mut args = vec![
        int(state.frame),
        OscType::Int(i32::from(state.lost)),
        OscType::Float(state.rms_px),
    ];
    args.extend(q.iter().map(|&v| OscType::Float(v)));
    let mut content = vec![message(STATE, args)];
    content.extend(
        q.iter()
            .enumerate()
            .map(|(i, &v)| message(&format!("{Q_PREFIX}{i}"), vec![OscType::Float(v)])),
    );
    if let Some(m) = mouse {
        content.push(message(
            MOUSE,
            vec![
                OscType::Float(m.x_mm),
                OscType::Float(m.y_mm),
                OscType::Float(m.height_mm),
                OscType::Int(i32::from(m.buttons[0])),
                OscType::Int(i32::from(m.buttons[1])),
            ],
        ));
    }
    OscPacket::Bundle(OscBundle {
        timetag: IMMEDIATELY,
        content,
    })
}

/// A dropped frame: `/digiteyes/dropped frame reason`.
pub fn dropped_message(dropped: &Dropped) -> OscPacket {
    message(
        DROPPED,
        vec![
            int(dropped.frame),
            OscType::String(reason(&dropped.reason).to_string()),
        ],
    )
}

/// The board's counters: `/digiteyes/stats frames iterations lost dropped bad_frames
/// crc_errors framing_errors` (dropped: every reason together; the CRC and framing errors of
/// the board's receiver).
pub fn stats_message(stats: &Stats) -> OscPacket {
    let dropped = stats.dropped.total();
    message(
        STATS,
        [
            stats.frames,
            stats.iterations,
            stats.lost,
            dropped,
            stats.bad_frames,
            stats.link.crc_errors,
            stats.link.framing_errors,
        ]
        .into_iter()
        .map(int)
        .collect(),
    )
}

/// The reason of a drop as one word: `incomplete`, `wrong_size`, `too_large`, `not_ready`,
/// `superseded`, `tracker_error`.
pub fn reason(reason: &DropReason) -> &'static str {
    match reason {
        DropReason::Incomplete => "incomplete",
        DropReason::WrongSize(..) => "wrong_size",
        DropReason::TooLarge => "too_large",
        DropReason::NotReady => "not_ready",
        DropReason::Superseded => "superseded",
        DropReason::TrackerError => "tracker_error",
    }
}

/// The bytes of one packet (one UDP datagram).
pub fn encode(packet: &OscPacket) -> Result<Vec<u8>> {
    rosc::encoder::encode(packet).map_err(|e| anyhow!("cannot encode an OSC packet: {e:?}"))
}

fn message(addr: &str, args: Vec<OscType>) -> OscPacket {
    OscPacket::Message(OscMessage {
        addr: addr.to_string(),
        args,
    })
}

/// An OSC int32 from a counter, saturating past `i32::MAX`.
fn int(v: u32) -> OscType {
    OscType::Int(i32::try_from(v).unwrap_or(i32::MAX))
}

#[cfg(test)]
mod tests {
    use super::*;
    use digiteyes_core::protocol::{DropCounts, LinkCounters};

    fn decode(bytes: &[u8]) -> OscPacket {
        let (rest, packet) = rosc::decoder::decode_udp(bytes).unwrap();
        assert!(rest.is_empty(), "{} bytes left over", rest.len());
        packet
    }

    fn messages(packet: OscPacket) -> (OscTime, Vec<OscMessage>) {
        let OscPacket::Bundle(bundle) = packet else {
            panic!("not a bundle: {packet:?}");
        };
        let content = bundle
            .content
            .into_iter()
            .map(|p| match p {
                OscPacket::Message(m) => m,
                other => panic!("nested bundle {other:?}"),
            })
            .collect();
        (bundle.timetag, content)
    }

    pub(crate) fn state(frame: u32, q: &[f32]) -> State {
        State {
            frame,
            timestamp: 1_000 * u64::from(frame),
            q: q.iter().copied().collect(),
            rms_px: 0.75,
            lost: true,
            features_found: 20,
            features_expected: 24,
            iterations: 5,
            track_ticks: 1234,
            status: digiteyes_core::protocol::WireStatus::Lost,
            search_evaluations: 0,
        }
    }

    #[test]
    fn a_state_round_trips_as_one_bundle() {
        let q = [1.0, 0.0, 0.0, 0.0, 1.5, -2.0, 600.0, 0.25];
        let mouse = MousePole {
            x_mm: 1.5,
            y_mm: -2.0,
            height_mm: 33.5,
            tip_z_mm: 33.5,
            buttons: [false, true],
        };
        let bytes = encode(&state_bundle(&state(12, &q), &q, Some(&mouse))).unwrap();
        let (timetag, m) = messages(decode(&bytes));
        assert_eq!(timetag, IMMEDIATELY);
        assert_eq!(m.len(), 1 + q.len() + 1);
        assert_eq!(m[0].addr, "/digiteyes/state");
        let mut expected = vec![OscType::Int(12), OscType::Int(1), OscType::Float(0.75)];
        expected.extend(q.iter().map(|&v| OscType::Float(v)));
        assert_eq!(m[0].args, expected);
        for (i, &v) in q.iter().enumerate() {
            assert_eq!(m[1 + i].addr, format!("/digiteyes/q/{i}"));
            assert_eq!(m[1 + i].args, [OscType::Float(v)]);
        }
        let last = m.last().unwrap();
        assert_eq!(last.addr, "/digiteyes/mouse");
        assert_eq!(
            last.args,
            [
                OscType::Float(1.5),
                OscType::Float(-2.0),
                OscType::Float(33.5),
                OscType::Int(0),
                OscType::Int(1)
            ]
        );
        // Without a mouse, no mouse message; the values sent are the ones given.
        let smoothed = [0.5f32; 8];
        let (_, m) = messages(decode(
            &encode(&state_bundle(&state(3, &q), &smoothed, None)).unwrap(),
        ));
        assert_eq!(m.len(), 1 + q.len());
        assert_eq!(m[0].args[3], OscType::Float(0.5));
        assert!(m.iter().all(|m| m.addr != MOUSE));
    }

    #[test]
    fn drops_and_stats_round_trip() {
        let packet = dropped_message(&Dropped {
            frame: 8,
            reason: DropReason::WrongSize(320, 240),
        });
        let OscPacket::Message(m) = decode(&encode(&packet).unwrap()) else {
            panic!("not a message");
        };
        assert_eq!(m.addr, "/digiteyes/dropped");
        assert_eq!(
            m.args,
            [OscType::Int(8), OscType::String("wrong_size".into())]
        );
        let stats = Stats {
            frames: 100,
            iterations: 500,
            lost: 2,
            dropped: DropCounts {
                incomplete: 1,
                superseded: 2,
                tracker_error: 3,
                ..DropCounts::default()
            },
            bad_frames: 4,
            link: LinkCounters {
                crc_errors: 5,
                framing_errors: 6,
                ..LinkCounters::default()
            },
            capacity_overflows: 0,
            stale_chunks: 0,
        };
        let OscPacket::Message(m) = decode(&encode(&stats_message(&stats)).unwrap()) else {
            panic!("not a message");
        };
        assert_eq!(m.addr, "/digiteyes/stats");
        let ints: Vec<i32> = m.args.into_iter().map(|a| a.int().unwrap()).collect();
        assert_eq!(ints, [100, 500, 2, 6, 4, 5, 6]);
    }

    #[test]
    fn a_hand_state_fits_one_unfragmented_datagram() {
        // 1472 bytes: a 1500-byte Ethernet MTU less the IPv4 and UDP headers.
        let q = [0.5f32; 28];
        let bytes = encode(&state_bundle(
            &state(1, &q),
            &q,
            Some(&MousePole::default()),
        ))
        .unwrap();
        assert!(bytes.len() <= 1472, "{} bytes", bytes.len());
    }

    #[test]
    fn counters_past_i32_saturate() {
        let OscPacket::Message(m) = dropped_message(&Dropped {
            frame: u32::MAX,
            reason: DropReason::Superseded,
        }) else {
            panic!("not a message");
        };
        assert_eq!(m.args[0], OscType::Int(i32::MAX));
    }
}
