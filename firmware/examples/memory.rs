//! Prints the static memory a board takes besides its frame buffers (bytes, this target):
//! `cargo run -p digiteyes-firmware --example memory`. Figures are in docs/firmware.md.

use core::mem::size_of;

use digiteyes_core::acquire::Acquirer;
use digiteyes_core::auto_tracker::AutoTracker;
use digiteyes_core::model::Model;
use digiteyes_core::protocol::{Decoder, MAX_MESSAGE};
use digiteyes_core::tracker::Tracker;
use digiteyes_firmware::{edge_map_bytes, Board, Clock, NoLed, Uploads};

struct NullSerial;
impl embedded_io::ErrorType for NullSerial {
    type Error = core::convert::Infallible;
}
impl embedded_io::Read for NullSerial {
    fn read(&mut self, _: &mut [u8]) -> Result<usize, Self::Error> {
        Ok(0)
    }
}
impl embedded_io::ReadReady for NullSerial {
    fn read_ready(&mut self) -> Result<bool, Self::Error> {
        Ok(false)
    }
}
impl embedded_io::Write for NullSerial {
    fn write(&mut self, b: &[u8]) -> Result<usize, Self::Error> {
        Ok(b.len())
    }
    fn flush(&mut self) -> Result<(), Self::Error> {
        Ok(())
    }
}
struct NullClock;
impl Clock for NullClock {
    fn ticks(&mut self) -> u64 {
        0
    }
    fn hz(&self) -> u32 {
        1
    }
}

fn main() {
    let board = size_of::<Board<'static, NullSerial, Uploads, NoLed, NullClock>>();
    let tracker = size_of::<Tracker>();
    let auto = size_of::<AutoTracker>();
    let acquirer = size_of::<Acquirer>();
    let model = size_of::<Model>();
    let decoder = size_of::<Decoder<MAX_MESSAGE>>();
    let measuring = size_of::<Option<digiteyes_core::remote::MeasureWork>>();
    println!("board (all but frame buffers): {board} B");
    println!("  status machine (AutoTracker: tracker, search, leaves): {auto} B");
    println!("    tracker (incl. its model and working memory): {tracker} B");
    println!("    search (Acquirer: poses, one projection, the best hypotheses): {acquirer} B");
    println!("  board's own copy of the model: {model} B");
    println!("  receive buffer (decoder): {decoder} B");
    println!("  transmit buffer: {MAX_MESSAGE} B");
    println!("  measuring memory (one board per camera, after Hold): {measuring} B");
    for (name, w, h) in [("QQVGA", 160, 120), ("QVGA", 320, 240), ("VGA", 640, 480)] {
        println!(
            "frame buffer {name} {w}x{h}: {} B (+ the same again for an overlay); search's \
             edge map {} B",
            w * h,
            edge_map_bytes(w, h)
        );
    }
}
