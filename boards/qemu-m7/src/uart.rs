//! The CMSDK APB UART (Arm DDI 0479C, section 4.3) as an `embedded-io` serial port.
//!
//! Registers, from the UART's base: DATA `+0x00`, STATE `+0x04` (bit 0 TX full, bit 1 RX full,
//! bit 2 TX overrun, bit 3 RX overrun; the overrun bits are write-1-to-clear), CTRL `+0x08`
//! (bit 0 TX enable, bit 1 RX enable), BAUDDIV `+0x10`. It is always 8N1 with a one-byte
//! holding register each way and no FIFO.
//!
//! On QEMU the receive side is flow-controlled: QEMU hands the UART the next byte only once
//! the firmware has read the previous one (so bytes are never lost, but nothing arrives while
//! the firmware is busy elsewhere). Read often: call [`ReadReady::read_ready`] between pieces
//! of work. On the real part a byte that arrives while RX is full overruns
//! ([`Uart::take_rx_overrun`]).

use core::convert::Infallible;

use embedded_io::{ErrorType, Read, ReadReady, Write, WriteReady};

use crate::mmio::Reg;

/// Base address of UART0 on mps2-an500 (UART1..4: `0x4000_5000`, `6000`, `7000`, `9000`).
pub const UART0_BASE: usize = 0x4000_4000;

/// The clock the UARTs divide for their baud rate, Hz (the board's 25 MHz system clock).
pub const PCLK_HZ: u32 = 25_000_000;

const DATA: usize = 0x00;
const STATE: usize = 0x04;
const CTRL: usize = 0x08;
const BAUDDIV: usize = 0x10;

const STATE_TX_FULL: u32 = 1 << 0;
const STATE_RX_FULL: u32 = 1 << 1;
const STATE_TX_OVERRUN: u32 = 1 << 2;
const STATE_RX_OVERRUN: u32 = 1 << 3;
const CTRL_TX_RX_ENABLE: u32 = 0b11;

/// The smallest divider the UART accepts (QEMU ignores smaller ones as "not programmed").
const BAUDDIV_MIN: u32 = 16;
/// BAUDDIV is a 20-bit field.
const BAUDDIV_MAX: u32 = 0xF_FFFF;

/// The right to drive UART0: only [`crate::Peripherals::take`] makes one.
#[derive(Debug)]
pub struct Uart0 {
    pub(crate) _private: (),
}

/// UART settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct Config {
    /// Line rate, baud (bits/s). QEMU passes it to a real serial port backend and otherwise
    /// ignores it: through a PTY bytes move as fast as the emulator runs.
    pub baud: u32,
}

impl Default for Config {
    fn default() -> Self {
        Self { baud: 115_200 }
    }
}

/// A CMSDK APB UART, enabled for transmit and receive.
///
/// Implements `embedded-io`'s `Read` (blocks until at least one byte), `ReadReady`, `Write`
/// (blocks until at least one byte is taken), `WriteReady` and `flush`. It never fails:
/// the error type is [`Infallible`].
#[derive(Debug)]
pub struct Uart {
    data: Reg,
    state: Reg,
}

impl Uart {
    /// Takes UART0, sets its divider for `config.baud` (clamped to what the hardware takes)
    /// and enables transmit and receive.
    pub fn new(uart0: Uart0, config: Config) -> Self {
        let _ = uart0;
        let base = UART0_BASE;
        let bauddiv = (PCLK_HZ / config.baud.max(1)).clamp(BAUDDIV_MIN, BAUDDIV_MAX);
        Reg::at(base + CTRL).write(0);
        Reg::at(base + BAUDDIV).write(bauddiv);
        // Clear overrun flags left from before (write 1 to clear).
        Reg::at(base + STATE).write(STATE_TX_OVERRUN | STATE_RX_OVERRUN);
        Reg::at(base + CTRL).write(CTRL_TX_RX_ENABLE);
        Self {
            data: Reg::at(base + DATA),
            state: Reg::at(base + STATE),
        }
    }

    #[inline(always)]
    fn rx_full(&self) -> bool {
        self.state.read() & STATE_RX_FULL != 0
    }

    #[inline(always)]
    fn tx_full(&self) -> bool {
        self.state.read() & STATE_TX_FULL != 0
    }

    /// Whether a received byte was lost because the previous one had not been read yet, since
    /// the last call (the flag is cleared). Never true on QEMU, whose UART holds input back
    /// instead.
    pub fn take_rx_overrun(&mut self) -> bool {
        let overrun = self.state.read() & STATE_RX_OVERRUN != 0;
        if overrun {
            self.state.write(STATE_RX_OVERRUN);
        }
        overrun
    }
}

impl ErrorType for Uart {
    type Error = Infallible;
}

impl ReadReady for Uart {
    /// True when a received byte is waiting, so the next `read` returns without blocking.
    #[inline]
    fn read_ready(&mut self) -> Result<bool, Infallible> {
        Ok(self.rx_full())
    }
}

impl Read for Uart {
    /// Waits for a byte, then takes it and any that follow at once, up to `buf.len()`.
    /// Returns `Ok(0)` only for an empty `buf`. On QEMU this is nearly always one byte.
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
        if buf.is_empty() {
            return Ok(0);
        }
        while !self.rx_full() {
            core::hint::spin_loop();
        }
        let mut n = 0;
        for slot in buf.iter_mut() {
            if !self.rx_full() {
                break;
            }
            // Reading DATA clears RX full; the register holds the byte in bits 7:0.
            *slot = self.data.read() as u8;
            n += 1;
        }
        Ok(n)
    }
}

impl WriteReady for Uart {
    /// True when the transmit holding register is free, so the next `write` does not block.
    #[inline]
    fn write_ready(&mut self) -> Result<bool, Infallible> {
        Ok(!self.tx_full())
    }
}

impl Write for Uart {
    /// Waits until the UART takes the first byte, then hands it more while it keeps taking
    /// them without waiting. Returns `Ok(0)` only for an empty `buf`.
    fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
        let mut n = 0;
        for &byte in buf {
            if self.tx_full() {
                if n > 0 {
                    break;
                }
                while self.tx_full() {
                    core::hint::spin_loop();
                }
            }
            self.data.write(u32::from(byte));
            n += 1;
        }
        Ok(n)
    }

    /// Waits until the last byte has left the holding register for the line (on QEMU: has
    /// been handed to the host's character device).
    fn flush(&mut self) -> Result<(), Infallible> {
        while self.tx_full() {
            core::hint::spin_loop();
        }
        Ok(())
    }
}
