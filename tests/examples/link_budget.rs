//! The board link's budget, from real encoded messages: bytes per `State`, states per second,
//! and the time to upload a frame, at common baud rates (8N1: 10 bits per byte).
//!
//! `cargo run --release -p digiteyes-tests --example link_budget` prints the tables of
//! `docs/link.md`.

use digiteyes_core::model::Model;
use digiteyes_core::protocol::{
    encode, BoardMessage, DropReason, Dropped, FrameChunk, HostMessage, State, Stats, WireStatus,
    MAX_CHUNK, MAX_MESSAGE,
};

const BAUDS: [u32; 2] = [115_200, 921_600];

/// Encoded bytes of a board message, delimiters included.
fn size(message: &BoardMessage) -> usize {
    let mut buf = [0u8; MAX_MESSAGE];
    encode(message, &mut buf).expect("fits").len()
}

/// Encoded bytes of a host message, delimiters included.
fn host_size(message: &HostMessage<'_>) -> usize {
    let mut buf = [0u8; MAX_MESSAGE];
    encode(message, &mut buf).expect("fits").len()
}

/// A state message of a tracked frame: `q` every model state, realistic counters (frame
/// 1000, 33 s and 5 ms on a 1 MHz board clock).
fn state(q: &[f32]) -> BoardMessage {
    BoardMessage::State(State {
        frame: 1000,
        timestamp: 33_000_000,
        q: q.iter().copied().collect(),
        rms_px: 0.8,
        lost: false,
        features_found: 60,
        features_expected: 68,
        iterations: 8,
        track_ticks: 5_000,
        status: WireStatus::Tracking,
        search_evaluations: 0,
    })
}

/// Bytes to upload one `width × height` frame: every `FrameChunk`, encoded. Pixels are never
/// 0 here, the worst case for COBS (one extra byte per 254).
fn upload_bytes(width: u16, height: u16) -> usize {
    let pixels = vec![0x80u8; usize::from(width) * usize::from(height)];
    pixels
        .chunks(MAX_CHUNK)
        .enumerate()
        .map(|(i, data)| {
            host_size(&HostMessage::FrameChunk(FrameChunk {
                frame: 1000,
                width,
                height,
                offset: (i * MAX_CHUNK) as u32,
                data,
            }))
        })
        .sum()
}

fn bytes_per_second(baud: u32) -> f64 {
    f64::from(baud) / 10.0
}

fn main() {
    let hand = Model::hand().expect("the built-in hand");
    let n = hand.n_states();
    // The whole hand: a pose and bent fingers (every value a full f32 anyway).
    let mut q_hand = vec![0.3f32; n];
    q_hand[..7].copy_from_slice(&[0.98, 0.1, -0.1, 0.12, 12.5, -30.25, 600.0]);
    // The 3D mouse is the same 28-state model with 7 states free: its State carries all 28.
    let mut q_mouse = vec![0.0f32; n];
    q_mouse[..7].copy_from_slice(&[0.0, 0.0, 0.997_551, -0.069_942_85, 1.25, 0.55, 45.0]);
    let worst = BoardMessage::State(State {
        frame: u32::MAX,
        timestamp: u64::MAX,
        q: q_hand.iter().copied().collect(),
        rms_px: 0.8,
        lost: true,
        features_found: u16::MAX,
        features_expected: u16::MAX,
        iterations: u8::MAX,
        track_ticks: u32::MAX,
        status: WireStatus::Searching,
        search_evaluations: u16::MAX,
    });
    let dropped = BoardMessage::Dropped(Dropped {
        frame: 1000,
        reason: DropReason::Incomplete,
    });
    let stats = BoardMessage::Stats(Stats::default());
    let rows = [
        ("State, whole hand (28 states)", size(&state(&q_hand))),
        (
            "State, 3D mouse (same 28 states, 7 free)",
            size(&state(&q_mouse)),
        ),
        ("State, largest (every varint at its maximum)", size(&worst)),
        ("Dropped", size(&dropped)),
        ("Stats (counters small)", size(&stats)),
        ("Ping (host → board)", host_size(&HostMessage::Ping(1))),
        ("Pong", size(&BoardMessage::Pong(1))),
    ];
    println!("| message | bytes on the wire |");
    println!("|---|---:|");
    for (what, bytes) in rows {
        println!("| {what} | {bytes} |");
    }

    let state_bytes = size(&state(&q_hand));
    println!();
    println!("| baud (8N1) | bytes/s | States/s (board with its own camera) |");
    println!("|---:|---:|---:|");
    for baud in BAUDS {
        let bps = bytes_per_second(baud);
        println!("| {baud} | {bps:.0} | {:.0} |", bps / state_bytes as f64);
    }

    println!();
    println!(
        "| frame | pixels (bytes) | chunks | upload bytes | overhead | {} |",
        BAUDS
            .iter()
            .map(|b| format!("upload at {b} | frames/s at {b}"))
            .collect::<Vec<_>>()
            .join(" | ")
    );
    println!(
        "|---|---:|---:|---:|---:|{}",
        "---:|".repeat(2 * BAUDS.len())
    );
    for (name, w, h) in [("QVGA", 320u16, 240u16), ("VGA", 640, 480)] {
        let pixels = usize::from(w) * usize::from(h);
        let chunks = pixels.div_ceil(MAX_CHUNK);
        let up = upload_bytes(w, h);
        let per_baud: Vec<String> = BAUDS
            .iter()
            .map(|&baud| {
                let seconds = up as f64 / bytes_per_second(baud);
                // Stop-and-wait: the frame up, then its State down.
                let cycle = seconds + state_bytes as f64 / bytes_per_second(baud);
                format!("{seconds:.2} s | {:.2}", 1.0 / cycle)
            })
            .collect();
        println!(
            "| {name} {w}×{h} | {pixels} | {chunks} | {up} | {:.2}% | {} |",
            100.0 * (up - pixels) as f64 / pixels as f64,
            per_baud.join(" | ")
        );
    }
}
