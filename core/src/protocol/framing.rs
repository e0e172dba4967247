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
///
/// A decoder that joins a stream already flowing ([`Decoder::mid_stream`]: a host opening a
/// board's serial port, which discards what arrived before) may first see the tail of a
/// frame. Its first frame, when it is not a message, is dropped and counted in
/// [`Decoder::joined_mid_frame`], not as an error of the link.
#[derive(Debug, Clone)]
pub struct Decoder<const N: usize> {
    buf: [u8; N],
    len: usize,
    overflowed: bool,
    counters: LinkCounters,
    /// No delimiter seen yet by a decoder that joined the stream mid-way.
    joining: bool,
    joined_mid_frame: u32,
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
            joining: false,
            joined_mid_frame: 0,
        }
    }

    /// An empty decoder for a stream that may already be flowing: a first frame that is not
    /// a message is the tail of one sent before this end listened, and is dropped without
    /// counting as an error ([`Decoder::joined_mid_frame`]).
    pub const fn mid_stream() -> Self {
        let mut decoder = Self::new();
        decoder.joining = true;
        decoder
    }

    /// First frames dropped as the tail of a frame sent before this end listened (0 or 1).
    pub fn joined_mid_frame(&self) -> u32 {
        self.joined_mid_frame
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
            let joining = core::mem::replace(&mut self.joining, false);
            if core::mem::replace(&mut self.overflowed, false) {
                if joining {
                    self.joined_mid_frame += 1;
                    return (i + 1, None);
                }
                self.counters.overflows += 1;
                return (i + 1, Some(Err(LinkError::Overflow)));
            }
            if len == 0 {
                continue;
            }
            let body = match self.unframe(len) {
                Ok(body) => body,
                Err(_) if joining => {
                    self.joined_mid_frame += 1;
                    return (i + 1, None);
                }
                Err(e) => {
                    match e {
                        LinkError::Framing => self.counters.framing_errors += 1,
                        _ => self.counters.crc_errors += 1,
                    }
                    return (i + 1, Some(Err(e)));
                }
            };
            return (i + 1, Some(self.parse(body)));
        }
        (input.len(), None)
    }

    /// Undoes the COBS of the `len` bytes received and checks the CRC; returns the length of
    /// the body before the CRC (nothing counted here).
    fn unframe(&mut self, len: usize) -> Result<usize, LinkError> {
        let frame = self.buf.get_mut(..len).unwrap_or_default();
        let n = cobs::decode_in_place(frame).map_err(|_| LinkError::Framing)?;
        // The CRC is checked before decoding, so a corrupted frame counts as a CRC error
        // whatever its bytes happen to decode as.
        let payload = self.buf.get(..n).unwrap_or_default();
        let (body, crc) = payload.split_last_chunk::<4>().ok_or(LinkError::Crc)?;
        if CRC.checksum(body) != u32::from_le_bytes(*crc) {
            return Err(LinkError::Crc);
        }
        Ok(body.len())
    }

    /// The message in the first `len` bytes of the unframed body.
    fn parse<'d, T: Deserialize<'d>>(&'d mut self, len: usize) -> Result<T, LinkError> {
        let body = self.buf.get(..len).unwrap_or_default();
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
