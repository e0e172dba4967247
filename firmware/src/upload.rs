//! Frames uploaded over the link, reassembled from `FrameChunk`s into the frame buffer.
//!
//! Chunks of a frame must arrive in order with contiguous offsets from 0. Anything else
//! drops the frame, and every dropped frame is reported exactly once: a gap as
//! [`DropReason::Incomplete`] when it is seen, a partial frame as [`DropReason::Superseded`]
//! when a newer frame's chunk arrives. Later chunks of a dropped frame are ignored.

use digiteyes_core::protocol::{DropReason, Dropped, FrameChunk};

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

    /// Forgets any frame under way without reporting it (the caller reports it).
    pub fn abandon(&mut self) -> Option<u32> {
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
        let same_frame = self.state != Assembly::Idle && chunk.frame == self.frame;
        if same_frame {
            return (None, self.continue_frame(chunk, buffer));
        }
        let superseded = self.abandon().map(|frame| Dropped {
            frame,
            reason: DropReason::Superseded,
        });
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
            Some(_) if self.bytes() > buffer.len() => Some(DropReason::TooLarge),
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
