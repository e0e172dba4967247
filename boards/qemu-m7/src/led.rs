//! The two user LEDs of the MPS2 FPGA I/O block as `embedded-hal` output pins.
//!
//! QEMU emulates them: the FPGAIO `LED0` register at `0x4002_8000` holds one bit per LED
//! (bit 0 USERLED0, bit 1 USERLED1), reads back what was written, and QEMU reports changes
//! through its `led_set_intensity` trace event (`-trace 'led_*'`).

use core::convert::Infallible;

use embedded_hal::digital::{ErrorType, OutputPin, StatefulOutputPin};

use crate::mmio::Reg;

/// Base address of the FPGA system control and I/O block on mps2-an500.
pub const FPGAIO_BASE: usize = 0x4002_8000;

/// The LED register: bit `n` lights USERLED`n`.
const LED0: Reg = Reg::at(FPGAIO_BASE);

/// The right to drive the FPGAIO LEDs: only [`crate::Peripherals::take`] makes one.
#[derive(Debug)]
pub struct FpgaIo {
    pub(crate) _private: (),
}

impl FpgaIo {
    /// The two user LEDs, both switched off.
    pub fn leds(self) -> (Led, Led) {
        LED0.write(0);
        (Led { mask: 1 << 0 }, Led { mask: 1 << 1 })
    }
}

/// One user LED (lit when high). Stand-in for a board's status LED.
#[derive(Debug)]
pub struct Led {
    mask: u32,
}

impl Led {
    fn update(&mut self, lit: bool) {
        // The LEDs share one register: read-modify-write it without an interrupt between.
        cortex_m::interrupt::free(|_| {
            let bits = LED0.read();
            LED0.write(if lit {
                bits | self.mask
            } else {
                bits & !self.mask
            });
        });
    }
}

impl ErrorType for Led {
    type Error = Infallible;
}

impl OutputPin for Led {
    fn set_low(&mut self) -> Result<(), Infallible> {
        self.update(false);
        Ok(())
    }

    fn set_high(&mut self) -> Result<(), Infallible> {
        self.update(true);
        Ok(())
    }
}

impl StatefulOutputPin for Led {
    fn is_set_high(&mut self) -> Result<bool, Infallible> {
        Ok(LED0.read() & self.mask != 0)
    }

    fn is_set_low(&mut self) -> Result<bool, Infallible> {
        Ok(LED0.read() & self.mask == 0)
    }
}
