//! Frames uploaded over the link, reassembled from `FrameChunk`s into the frame buffer.
//!
//! The rule, for any sequence of chunks (`docs/protocol.md` §6): **every frame number is
//! answered at most once**, and every frame whose chunks start arriving is answered exactly
//! once — tracked, or dropped with a reason — unless the upload is abandoned by a
//! `Configure` or `Reset`, which answers it as superseded.
//!
//! - Chunks of a frame must arrive in order with contiguous offsets from 0; a gap drops the
//!   frame as [`DropReason::Incomplete`], a chunk of more than [`MAX_CHUNK`] bytes or past the
//!   frame's end as [`DropReason::TooLarge`].
//! - Frame numbers increase: a chunk of a *higher* number than the frame under way supersedes
//!   it ([`DropReason::Superseded`]) and starts the new frame. A chunk of a number at or below
//!   the highest one started (a frame already answered, or an older one) is ignored and
//!   counted (the board's `stale_chunks`): it can neither restart nor supersede anything.
//! - A `Configure` or `Reset` ([`Upload::restart`]) forgets the numbers: a host may count from
//!   0 again.

use digiteyes_core::protocol::{DropReason, Dropped, FrameChunk, MAX_CHUNK};

/// What one chunk did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ChunkOutcome {
    /// Stored; the frame is not complete yet.
    Partial,
    /// Stored; the frame is complete in the buffer and ready to track.
    Complete {
        /// The frame number.
        frame: u32,
        /// Its width (px).
        width: u16,
        /// Its height (px).
        height: u16,
    },
    /// This chunk's frame is dropped now.
    Dropped(Dropped),
    /// A chunk of a frame already dropped or complete: nothing to do.
    Ignored,
    /// A chunk of a frame number at or below the highest started, not the frame under way:
    /// ignored and counted.
    Stale,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Assembly {
    /// No frame under way.
    Idle,
    /// `received` bytes of frame `frame` are in the buffer.
    Receiving { received: usize },
    /// The frame was dropped or completed; its further chunks are ignored.
    Finished,
}

/// Reassembles uploaded frames.
#[derive(Debug, Clone, Copy)]
pub struct Upload {
    frame: u32,
    width: u16,
    height: u16,
    state: Assembly,
}

impl Default for Upload {
    fn default() -> Self {
        Self::new()
    }
}

impl Upload {
    /// Nothing received yet.
    pub const fn new() -> Self {
        Upload {
            frame: 0,
            width: 0,
            height: 0,
            state: Assembly::Idle,
        }
    }

    /// A frame is partly received.
    pub fn in_progress(&self) -> bool {
        matches!(self.state, Assembly::Receiving { .. })
    }

    /// Forgets any frame under way without reporting it (the caller reports it), and the
    /// frame numbers seen: after a `Configure` or `Reset` numbering may start again.
    pub fn restart(&mut self) -> Option<u32> {
        let was = self.in_progress().then_some(self.frame);
        self.state = Assembly::Idle;
        was
    }

    /// Takes one chunk into `buffer`. `expected` is the configured camera size, `None` when the
    /// board cannot track yet. Returns the partial frame this chunk superseded, if any, and
    /// what became of the chunk's own frame.
    pub fn accept(
        &mut self,
        chunk: &FrameChunk<'_>,
        expected: Option<(u16, u16)>,
        buffer: &mut [u8],
    ) -> (Option<Dropped>, ChunkOutcome) {
        let started = self.state != Assembly::Idle;
        if started && chunk.frame == self.frame {
            return (None, self.continue_frame(chunk, buffer));
        }
        if started && chunk.frame < self.frame {
            return (None, ChunkOutcome::Stale);
        }
        let superseded = self.in_progress().then_some(Dropped {
            frame: self.frame,
            reason: DropReason::Superseded,
        });
        self.state = Assembly::Idle;
        (superseded, self.start_frame(chunk, expected, buffer))
    }

    fn start_frame(
        &mut self,
        chunk: &FrameChunk<'_>,
        expected: Option<(u16, u16)>,
        buffer: &mut [u8],
    ) -> ChunkOutcome {
        self.frame = chunk.frame;
        self.width = chunk.width;
        self.height = chunk.height;
        self.state = Assembly::Finished;
        let reason = match expected {
            None => Some(DropReason::NotReady),
            Some(size) if size != (chunk.width, chunk.height) => {
                Some(DropReason::WrongSize(chunk.width, chunk.height))
            }
            Some(_) if self.bytes() > buffer.len() || chunk.data.len() > MAX_CHUNK => {
                Some(DropReason::TooLarge)
            }
            Some(_) if chunk.offset != 0 => Some(DropReason::Incomplete),
            Some(_) => None,
        };
        if let Some(reason) = reason {
            return self.drop_frame(reason);
        }
        self.state = Assembly::Receiving { received: 0 };
        self.continue_frame(chunk, buffer)
    }

    fn continue_frame(&mut self, chunk: &FrameChunk<'_>, buffer: &mut [u8]) -> ChunkOutcome {
        let Assembly::Receiving { received } = self.state else {
            return ChunkOutcome::Ignored;
        };
        if (chunk.width, chunk.height) != (self.width, self.height) {
            return self.drop_frame(DropReason::WrongSize(chunk.width, chunk.height));
        }
        if usize::try_from(chunk.offset).ok() != Some(received) {
            return self.drop_frame(DropReason::Incomplete);
        }
        if chunk.data.len() > MAX_CHUNK {
            return self.drop_frame(DropReason::TooLarge);
        }
        let end = received + chunk.data.len();
        let Some(slot) = buffer
            .get_mut(received..end)
            .filter(|_| end <= self.bytes())
        else {
            return self.drop_frame(DropReason::TooLarge);
        };
        slot.copy_from_slice(chunk.data);
        if end < self.bytes() {
            self.state = Assembly::Receiving { received: end };
            return ChunkOutcome::Partial;
        }
        self.state = Assembly::Finished;
        ChunkOutcome::Complete {
            frame: self.frame,
            width: self.width,
            height: self.height,
        }
    }

    fn drop_frame(&mut self, reason: DropReason) -> ChunkOutcome {
        self.state = Assembly::Finished;
        ChunkOutcome::Dropped(Dropped {
            frame: self.frame,
            reason,
        })
    }

    fn bytes(&self) -> usize {
        usize::from(self.width) * usize::from(self.height)
    }
}
