//! Where frames come from.

use core::fmt;

/// Why a camera could not deliver a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SourceError {
    /// The device failed or went away.
    Device,
    /// The device's frames are not of the configured size or a usable pixel format.
    Format,
}

impl fmt::Display for SourceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Device => "camera device error",
            Self::Format => "camera frame size or pixel format unusable",
        })
    }
}

/// A camera: fills the board's frame buffer with its next frame.
pub trait FrameSource {
    /// Fills `frame` (`width × height` bytes, 8-bit grey, packed rows) with the next frame if
    /// one is ready and returns its frame number; `Ok(None)` when none is ready yet. Must not
    /// block for long: the board handles the serial link between calls.
    fn poll_frame(
        &mut self,
        frame: &mut [u8],
        width: u16,
        height: u16,
    ) -> Result<Option<u32>, SourceError>;
}

/// The source of a board without a camera: frames arrive only as `FrameChunk`s on the link.
#[derive(Debug, Default, Clone, Copy)]
pub struct Uploads;

impl FrameSource for Uploads {
    fn poll_frame(&mut self, _: &mut [u8], _: u16, _: u16) -> Result<Option<u32>, SourceError> {
        Ok(None)
    }
}
