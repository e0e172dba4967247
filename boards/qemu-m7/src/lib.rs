//! The emulated Cortex-M7 board for digiteyes: QEMU's `mps2-an500` machine.
//!
//! Peripherals, each self-contained so a firmware crate only wires them together:
//!
//! - [`uart::Uart`]: UART0 (CMSDK APB UART) as an `embedded-io` `Read + ReadReady + Write +
//!   WriteReady` serial port. It carries only binary protocol frames.
//! - [`clock::Clock`]: a monotonic 64-bit tick counter from SysTick at [`clock::TICK_HZ`]
//!   (exactly 40 instructions per tick under `-icount shift=0`), and [`clock::Delay`], an
//!   `embedded-hal` `DelayNs` on it.
//! - [`led::Led`]: the two FPGAIO user LEDs as `embedded-hal` `OutputPin`s.
//! - [`stack`]: the stack's high-water mark (the stack is painted at reset).
//! - [`host`]: the command line QEMU passes through semihosting (the host's serial device).
//!
//! [`clock::Clock`] is also the `digiteyes_firmware::Clock` of the tracker board (`src/main.rs`).
//!
//! Human-readable logs go through semihosting (`cortex_m_semihosting::hprintln!`) to QEMU's
//! stdout, never onto the UART. A panic prints its message the same way and exits QEMU with a
//! failure status (panic-semihosting's `exit` feature).
#![no_std]
#![deny(unsafe_code)]
#![warn(missing_docs)]

// The panic handler: message over semihosting, then QEMU exits with status 1.
use panic_semihosting as _;

pub mod clock;
pub mod host;
pub mod led;
mod mmio;
pub mod stack;
pub mod uart;

use core::sync::atomic::{AtomicBool, Ordering};

/// The board's own peripherals (the Cortex-M core's are `cortex_m::Peripherals`).
#[derive(Debug)]
#[non_exhaustive]
pub struct Peripherals {
    /// UART0, for [`uart::Uart::new`].
    pub uart0: uart::Uart0,
    /// The FPGA I/O block, for [`led::FpgaIo::leds`].
    pub fpgaio: led::FpgaIo,
}

impl Peripherals {
    /// The peripherals, the first time; `None` after that, so each has one driver.
    pub fn take() -> Option<Self> {
        static TAKEN: AtomicBool = AtomicBool::new(false);
        if TAKEN.swap(true, Ordering::SeqCst) {
            return None;
        }
        Some(Self {
            uart0: uart::Uart0 { _private: () },
            fpgaio: led::FpgaIo { _private: () },
        })
    }
}
