//! The memory a Linux board takes besides its frame buffer (bytes, this target):
//! `cargo run -p digiteyes-board-linux --example linux_memory`. Figures are in docs/boards/linux.md.

use std::mem::size_of;

use digiteyes_board_linux::{Source, StatusLed};
use digiteyes_core::protocol::{Decoder, MAX_MESSAGE};
use digiteyes_core::tracker::Tracker;
use digiteyes_firmware::Board;
use digiteyes_platform_linux::{MonotonicClock, TtySerial};

fn main() {
    let board = size_of::<Board<'static, TtySerial, Source, StatusLed, MonotonicClock>>();
    println!("Board<TtySerial, Source, StatusLed, MonotonicClock>: {board} B");
    println!("  of which the tracker: {} B", size_of::<Tracker>());
    println!(
        "  of which the receive buffer: {} B",
        size_of::<Decoder<MAX_MESSAGE>>()
    );
    println!("  of which the transmit buffer: {MAX_MESSAGE} B");
    println!("  serial port handle: {} B", size_of::<TtySerial>());
    println!("  frame source (enum): {} B", size_of::<Source>());
    for (name, w, h) in [("QQVGA", 160, 120), ("QVGA", 320, 240), ("VGA", 640, 480)] {
        let grey = w * h;
        println!(
            "{name} {w}x{h}: frame buffer {grey} B; V4L2 buffers (2, mmap) GREY {} / YUYV {} B; \
             MJPEG decode up to {} B (RGB decode + luma, freed per frame)",
            2 * grey,
            2 * 2 * grey,
            4 * grey
        );
    }
}
