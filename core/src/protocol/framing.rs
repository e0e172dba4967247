//! Frames on the byte stream: `0x00, COBS(postcard(message) ‖ CRC-32 LE), 0x00`.
//!
//! Encoding and decoding use postcard's COBS and CRC flavours and the `cobs` crate; this
//! module only finds the delimiters and keeps count of what went wrong.

use postcard::ser_flavors::{crc::CrcModifier, Cobs, Slice};
use serde::{Deserialize, Serialize};

use super::messages::LinkCounters;
use super::CRC;

/// Why a message could not be encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum EncodeError {
    /// The output buffer is too small for the encoded message.
    BufferFull,
}

impl core::fmt::Display for EncodeError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "message does not fit the transmit buffer")
    }
}

/// Why a received frame was not a message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LinkError {
    /// The frame is not valid COBS.
    Framing,
    /// The CRC-32 does not match: bytes were corrupted.
    Crc,
    /// The CRC matched but the bytes are not a message of this protocol version.
    Decode,
    /// The frame was longer than the receive buffer; it was discarded.
    Overflow,
}

impl core::fmt::Display for LinkError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::Framing => "framing error (bad COBS)",
            Self::Crc => "CRC mismatch",
            Self::Decode => "undecodable message",
            Self::Overflow => "frame longer than the receive buffer",
        })
    }
}

/// Encodes `message` as one delimited frame into `buf`; returns the bytes to send.
pub fn encode<'b, T: Serialize + ?Sized>(
    message: &T,
    buf: &'b mut [u8],
) -> Result<&'b [u8], EncodeError> {
    let (first, rest) = buf.split_first_mut().ok_or(EncodeError::BufferFull)?;
    *first = 0;
    let cobs = Cobs::try_new(Slice::new(rest)).map_err(|_| EncodeError::BufferFull)?;
    let written = postcard::serialize_with_flavor(message, CrcModifier::new(cobs, CRC.digest()))
        .map_err(|_| EncodeError::BufferFull)?
        .len();
    buf.get(..written + 1).ok_or(EncodeError::BufferFull)
}

/// At most this many bytes once `message` is encoded (delimiters included: COBS adds at most
/// one byte per 254); `None` if it cannot be encoded.
pub fn max_encoded_len<T: Serialize + ?Sized>(message: &T) -> Option<usize> {
    let raw = postcard::experimental::serialized_size(message).ok()? + 4;
    // COBS adds one byte per started 254 bytes; plus both delimiters.
    Some(raw + raw / 254 + 1 + 2)
}

/// Splits a byte stream into frames and decodes them, accepting frames of at most `N` bytes
/// with both delimiters (`N − 2` between them).
///
/// Garbage between frames is discarded at the next delimiter and counted; a corrupted frame
/// costs that frame only, so the stream resynchronises by the next one.
#[derive(Debug, Clone)]
pub struct Decoder<const N: usize> {
    buf: [u8; N],
    len: usize,
    overflowed: bool,
    counters: LinkCounters,
}

impl<const N: usize> Default for Decoder<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> Decoder<N> {
    /// An empty decoder.
    pub const fn new() -> Self {
        Decoder {
            buf: [0; N],
            len: 0,
            overflowed: false,
            counters: LinkCounters {
                messages: 0,
                crc_errors: 0,
                framing_errors: 0,
                decode_errors: 0,
                overflows: 0,
            },
        }
    }

    /// What this decoder has seen so far.
    pub fn counters(&self) -> LinkCounters {
        self.counters
    }

    /// Forgets a partly received frame (the counters stay).
    pub fn clear(&mut self) {
        self.len = 0;
        self.overflowed = false;
    }

    /// Takes bytes from `input` up to and including the next frame delimiter. Returns how many
    /// bytes were taken and, when a frame ended, the message or why it is not one. Call again
    /// with the rest of `input` once the message has been handled.
    pub fn feed<'d, T: Deserialize<'d>>(
        &'d mut self,
        input: &[u8],
    ) -> (usize, Option<Result<T, LinkError>>) {
        for (i, &byte) in input.iter().enumerate() {
            if byte != 0 {
                // `N` counts both delimiters: at most `N − 2` bytes between them.
                match self.buf.get_mut(self.len).filter(|_| self.len + 2 < N) {
                    Some(slot) => {
                        *slot = byte;
                        self.len += 1;
                    }
                    None => self.overflowed = true,
                }
                continue;
            }
            let len = core::mem::replace(&mut self.len, 0);
            if core::mem::replace(&mut self.overflowed, false) {
                self.counters.overflows += 1;
                return (i + 1, Some(Err(LinkError::Overflow)));
            }
            if len == 0 {
                continue;
            }
            return (i + 1, Some(self.decode(len)));
        }
        (input.len(), None)
    }

    fn decode<'d, T: Deserialize<'d>>(&'d mut self, len: usize) -> Result<T, LinkError> {
        let frame = self.buf.get_mut(..len).unwrap_or_default();
        let Ok(n) = cobs::decode_in_place(frame) else {
            self.counters.framing_errors += 1;
            return Err(LinkError::Framing);
        };
        // The CRC is checked before decoding, so a corrupted frame counts as a CRC error
        // whatever its bytes happen to decode as.
        let payload = self.buf.get(..n).unwrap_or_default();
        let Some((body, crc)) = payload.split_last_chunk::<4>() else {
            self.counters.crc_errors += 1;
            return Err(LinkError::Crc);
        };
        if CRC.checksum(body) != u32::from_le_bytes(*crc) {
            self.counters.crc_errors += 1;
            return Err(LinkError::Crc);
        }
        match postcard::take_from_bytes(body) {
            Ok((message, [])) => {
                self.counters.messages += 1;
                Ok(message)
            }
            _ => {
                self.counters.decode_errors += 1;
                Err(LinkError::Decode)
            }
        }
    }
}
