//! The digiteyes tracker board on QEMU's emulated Cortex-M7: the firmware's `Board` loop with
//! frames arriving over UART0 as `FrameChunk`s and states leaving over it (`docs/protocol.md`).
//!
//! `cargo run --release` in this folder boots it (see `run-qemu`): the banner on the terminal
//! (semihosting) names the serial device to give `digiteyes stream --port`. Then it serves
//! hosts until QEMU is stopped (Ctrl-C). It prints the stack's high-water mark (the stack is
//! painted at reset) after boot and, between frames, whenever a stretch of frames went deeper
//! than any before.
//!
//! Memory is static: the frame buffer and the overlay buffer (VGA, 307,200 bytes each), the
//! search's edge map (115,200 bytes) and the `Board` (tracker and search, model, link
//! buffers) live in `static` cells; nothing is allocated.
#![no_std]
#![no_main]
#![deny(unsafe_code)]

use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use digiteyes_board_qemu_m7::{
    clock::{Clock, Delay, TICK_HZ},
    host,
    led::Led,
    stack,
    uart::{self, Uart, UART0_BASE},
    Peripherals,
};
use digiteyes_firmware::{edge_map_bytes, Board, Buffers, Uploads};
use embedded_hal::delay::DelayNs;
use static_cell::{ConstStaticCell, StaticCell};

/// The name the board gives in `Hello`.
const BOARD_NAME: &str = "qemu-m7";

/// The largest frame the board takes: VGA, 8-bit grey.
const FRAME_WIDTH_PX: usize = 640;
const FRAME_HEIGHT_PX: usize = 480;
const FRAME_BYTES: usize = FRAME_WIDTH_PX * FRAME_HEIGHT_PX;
/// The search's edge map of the largest frame (115,200 bytes for VGA).
const EDGE_MAP_BYTES: usize = edge_map_bytes(FRAME_WIDTH_PX, FRAME_HEIGHT_PX);

/// How long a pass of the loop that found nothing to do waits before the next (µs). Short:
/// QEMU hands UART0 the next received byte only after the firmware has read the previous one,
/// so a long idle wait would throttle uploads (`docs/boards/qemu-m7.md`).
const IDLE_US: u32 = 1;

/// The tracker board's type: UART0, frames uploaded over it, USERLED0, SysTick.
type TrackerBoard = Board<'static, Uart, Uploads, Led, Clock>;

/// The camera frame being uploaded and tracked.
static FRAME: ConstStaticCell<[u8; FRAME_BYTES]> = ConstStaticCell::new([0; FRAME_BYTES]);
/// The last tracked frame with the model drawn in (the IC40's video overlay).
static OVERLAY: ConstStaticCell<[u8; FRAME_BYTES]> = ConstStaticCell::new([0; FRAME_BYTES]);
/// The search's edge map (the board searches for the hand when asked or after losing it).
static EDGE_MAP: ConstStaticCell<[u8; EDGE_MAP_BYTES]> = ConstStaticCell::new([0; EDGE_MAP_BYTES]);
/// The board: tracker, model, link buffers, counters.
static BOARD: StaticCell<TrackerBoard> = StaticCell::new();

#[entry]
fn main() -> ! {
    let (Some(core), Some(peripherals)) = (cortex_m::Peripherals::take(), Peripherals::take())
    else {
        panic!("peripherals taken twice");
    };
    let clock = Clock::start(core.SYST);
    let serial = Uart::new(peripherals.uart0, uart::Config::default());
    let (status_led, _) = peripherals.fpgaio.leds();

    hprintln!(
        "digiteyes qemu-m7: tracker board up at tick {} (SysTick {TICK_HZ} Hz); frames up to \
         {FRAME_BYTES} bytes; protocol frames on UART0 ({UART0_BASE:#x})",
        clock.now_ticks()
    );
    let mut cmdline = [0u8; 256];
    match host::port(&mut cmdline) {
        Some(port) => hprintln!(
            "digiteyes qemu-m7: connect the host to {port}, e.g.\n\
             \x20   digiteyes stream --port {port} --seq DIR"
        ),
        None => hprintln!(
            "digiteyes qemu-m7: connect the host to UART0's serial device (the PTY QEMU named \
             above, or the other end of DIGITEYES_SERIAL's pair), e.g.\n\
             \x20   digiteyes stream --port /dev/pts/N --seq DIR"
        ),
    }

    let board = build(serial, status_led, clock);
    let Ok(()) = board.start();
    hprintln!(
        "digiteyes qemu-m7: stack: {} bytes deepest at boot (Board::new, Hello); {} bytes \
         available",
        stack::take_high_water(),
        stack::capacity()
    );
    serve(board, clock.delay())
}

/// The board in its static cell. Not inlined: the `Board` value may pass through this
/// function's stack frame on its way into the cell, and `main`'s frame (which lives forever)
/// should not keep room for it.
#[inline(never)]
fn build(serial: Uart, status_led: Led, clock: Clock) -> &'static mut TrackerBoard {
    BOARD.init_with(|| {
        Board::new(
            BOARD_NAME,
            Buffers {
                frame: FRAME.take(),
                overlay: Some(OVERLAY.take()),
                edge_map: EDGE_MAP.take(),
            },
            serial,
            Uploads,
            status_led,
            clock,
        )
    })
}

/// `Board::run` after `Board::start`, with stack reports between frames. Not inlined, so its
/// frame (the board loop, commands and tracking inlined into it) shows in the reports.
#[inline(never)]
fn serve(board: &mut TrackerBoard, mut delay: Delay) -> ! {
    let mut frames_seen = 0;
    // The deepest stretch between two frames after the first (None: none measured yet).
    let mut deepest: Option<usize> = None;
    loop {
        let Ok(busy) = board.poll();
        let frames = board.stats().frames;
        if frames != frames_seen {
            let used = stack::take_high_water();
            if frames_seen == 0 {
                hprintln!(
                    "digiteyes qemu-m7: stack: {used} bytes deepest up to the first frame \
                     tracked (set-up commands, e.g. Configure and Reset, included)"
                );
            } else if deepest.is_none_or(|d| used > d) {
                deepest = Some(used);
                hprintln!(
                    "digiteyes qemu-m7: stack: {used} bytes deepest since the previous frame, \
                     for frame {frames} tracked (the deepest such stretch so far)"
                );
            }
            frames_seen = frames;
        }
        if !busy {
            delay.delay_us(IDLE_US);
        }
    }
}
