//! Bring-up firmware for the emulated board: a semihosting banner, then UART0 echoes every
//! byte it receives. USERLED0 toggles every 4 KiB echoed.
//!
//! Run it with `cargo run --release --bin echo` in this folder (see `run-qemu`);
//! `tests/echo.sh` measures the UART's round trip with it.
#![no_std]
#![no_main]
#![deny(unsafe_code)]

use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use digiteyes_board_qemu_m7::{
    clock::{Clock, TICK_HZ},
    uart::{self, Uart, UART0_BASE},
    Peripherals,
};
use embedded_hal::digital::StatefulOutputPin;
use embedded_io::{Read, Write};

/// Bytes echoed between two toggles of USERLED0.
const LED_TOGGLE_BYTES: usize = 4096;

#[entry]
fn main() -> ! {
    let (Some(core), Some(board)) = (cortex_m::Peripherals::take(), Peripherals::take()) else {
        panic!("peripherals taken twice");
    };
    let clock = Clock::start(core.SYST);
    let mut serial = Uart::new(board.uart0, uart::Config::default());
    let (mut led, _) = board.fpgaio.leds();

    hprintln!(
        "digiteyes qemu-m7 echo: up at tick {}; UART0 ({UART0_BASE:#x}) echoes what it receives; \
         SysTick {TICK_HZ} Hz",
        clock.now_ticks()
    );

    let mut buf = [0u8; 64];
    let mut since_toggle = 0;
    loop {
        let Ok(n) = serial.read(&mut buf);
        let Ok(()) = serial.write_all(&buf[..n]);
        since_toggle += n;
        if since_toggle >= LED_TOGGLE_BYTES {
            since_toggle = 0;
            let Ok(()) = led.toggle();
        }
    }
}
