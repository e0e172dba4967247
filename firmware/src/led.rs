//! A status LED for boards without one.

use core::convert::Infallible;

use embedded_hal::digital::{ErrorType, OutputPin};

/// An [`OutputPin`] that drives nothing.
#[derive(Debug, Default, Clone, Copy)]
pub struct NoLed;

impl ErrorType for NoLed {
    type Error = Infallible;
}

impl OutputPin for NoLed {
    fn set_low(&mut self) -> Result<(), Infallible> {
        Ok(())
    }

    fn set_high(&mut self) -> Result<(), Infallible> {
        Ok(())
    }
}
