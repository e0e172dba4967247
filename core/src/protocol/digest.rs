//! A model's fingerprint, so a host can tell that a board tracks the model it expects.

use core::fmt;

use super::CRC;
use crate::model::Model;
use crate::model_writer::write_dh;

/// CRC-32/ISO-HDLC of the model written in the `hand.dh` format by [`write_dh`]: equal models
/// (same links, states and limits) give equal digests whatever their source text looked like.
pub fn model_digest(model: &Model) -> u32 {
    let mut digest = DigestWriter(CRC.digest());
    // Writing into a digest cannot fail.
    let _ = write_dh(model, &mut digest);
    digest.0.finalize()
}

struct DigestWriter(crc::Digest<'static, u32>);

impl fmt::Write for DigestWriter {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        self.0.update(s.as_bytes());
        Ok(())
    }
}
