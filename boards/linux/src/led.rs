//! The status LED: a GPIO line through the kernel's character device (`/dev/gpiochipN`), or
//! none.

use std::convert::Infallible;
use std::fmt;

use digiteyes_firmware::NoLed;
use embedded_hal::digital::{ErrorKind, ErrorType, OutputPin};
use linux_embedded_hal::gpio_cdev::{Chip, LineRequestFlags};
use linux_embedded_hal::CdevPin;

/// The LED line could not be claimed.
#[derive(Debug)]
pub struct LedError {
    /// The GPIO chip device.
    pub chip: String,
    /// The line offset on that chip.
    pub line: u32,
    /// What the kernel said.
    pub message: String,
}

impl fmt::Display for LedError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "cannot use line {} of {} as the status LED: {}",
            self.line, self.chip, self.message
        )
    }
}

impl std::error::Error for LedError {}

/// The board's status LED.
pub enum StatusLed {
    /// A GPIO line driven high for "on".
    Gpio(CdevPin),
    /// No LED wired.
    None(NoLed),
}

impl StatusLed {
    /// Claims line `line` of GPIO chip `chip` (e.g. `/dev/gpiochip0`, 17) as an output, off.
    pub fn gpio(chip: &str, line: u32) -> Result<Self, LedError> {
        let error = |message: String| LedError {
            chip: chip.to_string(),
            line,
            message,
        };
        let mut device = Chip::new(chip).map_err(|e| error(e.to_string()))?;
        let handle = device
            .get_line(line)
            .and_then(|l| l.request(LineRequestFlags::OUTPUT, 0, "digiteyes-led"))
            .map_err(|e| error(e.to_string()))?;
        let pin = CdevPin::new(handle).map_err(|e| error(e.to_string()))?;
        Ok(StatusLed::Gpio(pin))
    }
}

impl fmt::Debug for StatusLed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StatusLed::Gpio(pin) => write!(f, "StatusLed::Gpio({:?})", pin.0.line()),
            StatusLed::None(_) => f.write_str("StatusLed::None"),
        }
    }
}

/// A failed LED write (the board loop ignores it: an LED is not worth stopping for).
#[derive(Debug, Clone, Copy)]
pub struct LedWriteError;

impl embedded_hal::digital::Error for LedWriteError {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Other
    }
}

impl ErrorType for StatusLed {
    type Error = LedWriteError;
}

impl OutputPin for StatusLed {
    fn set_low(&mut self) -> Result<(), LedWriteError> {
        match self {
            StatusLed::Gpio(pin) => pin.set_low().map_err(|_| LedWriteError),
            StatusLed::None(led) => never(led.set_low()),
        }
    }

    fn set_high(&mut self) -> Result<(), LedWriteError> {
        match self {
            StatusLed::Gpio(pin) => pin.set_high().map_err(|_| LedWriteError),
            StatusLed::None(led) => never(led.set_high()),
        }
    }
}

fn never(result: Result<(), Infallible>) -> Result<(), LedWriteError> {
    match result {
        Ok(()) => Ok(()),
        Err(e) => match e {},
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_gpio_chip_is_named() {
        let err = StatusLed::gpio("/dev/gpiochip-nonexistent", 17).unwrap_err();
        let text = err.to_string();
        assert!(
            text.contains("/dev/gpiochip-nonexistent") && text.contains("17"),
            "{text}"
        );
    }

    #[test]
    fn no_led_accepts_every_write() {
        let mut led = StatusLed::None(NoLed);
        assert!(led.set_high().is_ok() && led.set_low().is_ok());
    }
}
