//! Tests of `--forward` parsing and of forwarding over loopback UDP.

use std::time::Duration;

use digiteyes_core::protocol::{Capacities, DropReason, Dropped, Stats};
use rosc::{OscMessage, OscPacket, OscType};

use super::*;

#[test]
fn forward_urls() {
    let addr: SocketAddr = "127.0.0.1:9000".parse().unwrap();
    assert_eq!(
        parse_forward("udp://127.0.0.1:9000").unwrap(),
        Forward::Json(addr)
    );
    assert_eq!(
        parse_forward("osc://127.0.0.1:9000").unwrap(),
        Forward::Osc(addr)
    );
    assert_eq!(
        parse_forward("osc://[::1]:57120").unwrap(),
        Forward::Osc("[::1]:57120".parse().unwrap())
    );
    assert_eq!(
        parse_forward("osc://localhost:9000").unwrap().addr().port(),
        9000
    );
    assert_eq!(Forward::Osc(addr).to_string(), "osc://127.0.0.1:9000");
    for bad in [
        "tcp://127.0.0.1:9000",
        "127.0.0.1:9000",
        "udp://127.0.0.1",
        "osc://127.0.0.1:port",
        "osc://",
    ] {
        let err = format!("{:#}", parse_forward(bad).unwrap_err());
        assert!(
            err.contains(bad) && err.contains("udp://HOST:PORT") && err.contains("osc://HOST:PORT"),
            "{bad}: {err}"
        );
    }
}

/// A receiver on loopback, with a generous limit so a broken sender fails instead of hanging.
fn receiver() -> (UdpSocket, SocketAddr) {
    let socket = UdpSocket::bind("127.0.0.1:0").unwrap();
    socket
        .set_read_timeout(Some(Duration::from_secs(10)))
        .unwrap();
    let addr = socket.local_addr().unwrap();
    (socket, addr)
}

fn recv(socket: &UdpSocket) -> Vec<u8> {
    let mut buf = [0u8; 65_536];
    let n = socket.recv(&mut buf).expect("a datagram");
    buf[..n].to_vec()
}

fn recv_osc(socket: &UdpSocket) -> OscPacket {
    let bytes = recv(socket);
    let (rest, packet) = rosc::decoder::decode_udp(&bytes).unwrap();
    assert!(rest.is_empty());
    packet
}

fn recv_json(socket: &UdpSocket) -> serde_json::Value {
    let bytes = recv(socket);
    let line = std::str::from_utf8(&bytes).unwrap();
    assert!(line.ends_with('\n'), "{line:?}");
    serde_json::from_str(line.trim_end()).unwrap()
}

/// The messages of a bundle.
fn bundle(packet: OscPacket) -> Vec<OscMessage> {
    match packet {
        OscPacket::Bundle(b) => b
            .content
            .into_iter()
            .map(|p| match p {
                OscPacket::Message(m) => m,
                other => panic!("nested {other:?}"),
            })
            .collect(),
        other => panic!("not a bundle: {other:?}"),
    }
}

fn find<'a>(messages: &'a [OscMessage], addr: &str) -> Option<&'a OscMessage> {
    messages.iter().find(|m| m.addr == addr)
}

/// The `mouse` scenario's initial state.
fn table_pose() -> Vec<f32> {
    crate::scenarios::scenario("mouse")
        .unwrap()
        .base
        .iter()
        .map(|&v| v as f32)
        .collect()
}

fn state(frame: u32, timestamp: u64, q: &[f32]) -> State {
    State {
        frame,
        timestamp,
        q: q.iter().copied().collect(),
        rms_px: 0.5,
        lost: false,
        features_found: 20,
        features_expected: 24,
        iterations: 5,
        track_ticks: 1234,
        status: digiteyes_core::protocol::WireStatus::Tracking,
        search_evaluations: 0,
    }
}

fn hello(model_digest: u32, clock_hz: u32) -> Hello {
    Hello {
        version: 1,
        board: "test".try_into().unwrap(),
        model_digest,
        clock_hz,
        capacities: Capacities {
            states: 28,
            max_states: 28,
            max_links: 37,
            max_frame_bytes: 640 * 480,
            max_chunk: 1024,
            max_message: 2048,
        },
    }
}

fn hand_digest() -> u32 {
    model_digest(&Model::hand().unwrap())
}

#[test]
fn json_and_osc_at_once_over_loopback() {
    let (json_rx, json_addr) = receiver();
    let (osc_rx, osc_addr) = receiver();
    let mut forwarder = Forwarder::new(
        &[Forward::Json(json_addr), Forward::Osc(osc_addr)],
        ForwardOptions::default(),
    )
    .unwrap();
    let now = Instant::now();
    let rest = table_pose();
    let mut q = rest.clone();
    q[4] = 10.0;
    q[19] += 0.3; // finger 4 abducted: button 1 down
    let messages = [
        BoardMessage::State(state(7, 7_000, &q)),
        BoardMessage::Dropped(Dropped {
            frame: 8,
            reason: DropReason::Incomplete,
        }),
        BoardMessage::Stats(Stats {
            frames: 9,
            ..Stats::default()
        }),
        BoardMessage::Pong(5),
    ];
    let sent: Vec<usize> = messages
        .iter()
        .map(|m| forwarder.send(m, now).unwrap())
        .collect();
    assert_eq!(sent, [2, 2, 2, 1], "a Pong goes as JSON only");

    // JSON: every message, byte for byte the line `listen --json` prints.
    for m in &messages {
        let line = String::from_utf8(recv(&json_rx)).unwrap();
        assert_eq!(line, format!("{}\n", serde_json::to_string(m).unwrap()));
    }

    // OSC: the State's bundle first. No --setup and no Hello: the first state is the rest,
    // so its abducted finger 4 is where the button rests (up).
    let state_msgs = bundle(recv_osc(&osc_rx));
    let s = find(&state_msgs, "/digiteyes/state").unwrap();
    assert_eq!(
        s.args[..3],
        [OscType::Int(7), OscType::Int(0), OscType::Float(0.5)]
    );
    assert_eq!(s.args.len(), 3 + 28);
    assert_eq!(s.args[3 + 4], OscType::Float(10.0));
    assert_eq!(
        find(&state_msgs, "/digiteyes/q/19").unwrap().args,
        [OscType::Float(q[19])]
    );
    let mouse = find(&state_msgs, "/digiteyes/mouse").unwrap();
    assert_eq!(mouse.args[0], OscType::Float(10.0));
    assert_eq!(mouse.args[3..], [OscType::Int(0), OscType::Int(0)]);
    let OscPacket::Message(d) = recv_osc(&osc_rx) else {
        panic!("dropped is a message")
    };
    assert_eq!(d.addr, "/digiteyes/dropped");
    assert_eq!(
        d.args,
        [OscType::Int(8), OscType::String("incomplete".into())]
    );
    let OscPacket::Message(s) = recv_osc(&osc_rx) else {
        panic!("stats is a message")
    };
    assert_eq!(s.addr, "/digiteyes/stats");
    assert_eq!(s.args[0], OscType::Int(9));
}

#[test]
fn the_mouse_rests_at_the_setup_state_and_needs_the_hand() {
    let (rx, addr) = receiver();
    let mut forwarder = Forwarder::new(&[Forward::Osc(addr)], ForwardOptions::default()).unwrap();
    let rest = table_pose();
    forwarder.set_up(&hello(hand_digest(), 1_000_000), &rest);
    let now = Instant::now();
    let mut q = rest.clone();
    q[19] += 0.3;
    q[24] -= 0.05;
    forwarder
        .send(&BoardMessage::State(state(1, 1_000, &q)), now)
        .unwrap();
    let msgs = bundle(recv_osc(&rx));
    let mouse = find(&msgs, "/digiteyes/mouse").unwrap();
    assert_eq!(mouse.args[3..], [OscType::Int(1), OscType::Int(0)]);
    // A lost state carries no mouse.
    let mut lost = state(2, 2_000, &q);
    lost.lost = true;
    forwarder.send(&BoardMessage::State(lost), now).unwrap();
    let msgs = bundle(recv_osc(&rx));
    assert!(find(&msgs, "/digiteyes/state").is_some());
    assert!(find(&msgs, "/digiteyes/mouse").is_none());
    // A board with another model: no mouse either.
    forwarder
        .send(
            &BoardMessage::Hello(hello(hand_digest() ^ 1, 1_000_000)),
            now,
        )
        .unwrap();
    forwarder
        .send(&BoardMessage::State(state(3, 3_000, &q)), now)
        .unwrap();
    assert!(find(&bundle(recv_osc(&rx)), "/digiteyes/mouse").is_none());
    // Nor for a state vector that is not the hand's (no Hello seen).
    let mut forwarder = Forwarder::new(&[Forward::Osc(addr)], ForwardOptions::default()).unwrap();
    let seven = [1.0, 0.0, 0.0, 0.0, 1.5, -2.0, 600.0];
    forwarder
        .send(&BoardMessage::State(state(4, 4_000, &seven)), now)
        .unwrap();
    let msgs = bundle(recv_osc(&rx));
    assert_eq!(msgs.len(), 1 + 7);
    assert!(find(&msgs, "/digiteyes/mouse").is_none());
}

#[test]
fn smoothing_uses_the_board_clock_and_restarts_with_a_hello() {
    let (rx, addr) = receiver();
    let options = ForwardOptions {
        smoothing: Some(Smoothing::default()),
        ..ForwardOptions::default()
    };
    let mut forwarder = Forwarder::new(&[Forward::Json(addr)], options).unwrap();
    let rest = table_pose();
    forwarder.set_up(&hello(hand_digest(), 1_000), &rest);
    // The host's clock stands still; the board's advances 1 s between the states: a step of
    // 10 mm then comes through almost whole. Seen 1 ms apart, it would be cut to a few %.
    let now = Instant::now();
    let step = |forwarder: &mut Forwarder, timestamp: u64, x: f32| {
        let mut q = rest.clone();
        q[4] = x;
        forwarder
            .send(&BoardMessage::State(state(1, timestamp, &q)), now)
            .unwrap();
        let line = recv_json(&rx);
        let q: Vec<f64> = serde_json::from_value(line["State"]["q"].clone()).unwrap();
        let norm: f64 = q[..4].iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!((norm - 1.0).abs() < 1e-5, "{q:?}");
        q[4]
    };
    assert_eq!(step(&mut forwarder, 0, 0.0), 0.0);
    let slow = step(&mut forwarder, 1_000, 10.0);
    assert!(slow > 8.0 && slow < 10.0, "{slow}");
    let fast = step(&mut forwarder, 1_001, 20.0);
    assert!(fast > slow && fast < slow + 1.0, "{fast}");
    // A restarted board: its first state passes through.
    forwarder
        .send(&BoardMessage::Hello(hello(hand_digest(), 1_000)), now)
        .unwrap();
    let _ = recv_json(&rx);
    assert_eq!(step(&mut forwarder, 5, -3.0), -3.0);
}
