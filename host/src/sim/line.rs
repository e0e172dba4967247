//! The simulated board's serial line: the PTY, plus what a test bench adds to it — a tap that
//! watches the host's messages, a deaf spell, and the trigger of a power cycle. Line noise is
//! not here: it is a [`FaultInjector`](super::FaultInjector) between this line and the board.
//!
//! Inbound bytes are handed to the board one message at a time (up to and including each
//! frame delimiter): the tap decodes a message before the board sees it, so noise can be
//! aimed at the chunks of given frames ([`UploadedFrame`]) and a power cycle can fall right
//! after a given chunk. The board sees the same bytes in the same order, only a message later
//! at most.

use std::collections::VecDeque;
use std::io;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use digiteyes_core::protocol::{Decoder, HostMessage, MAX_MESSAGE};
use digiteyes_platform_linux::TtySerial;
use embedded_io::{Read, ReadReady};

use super::fault_injector::UploadedFrame;
use super::{Deafness, SimReport};

/// Most inbound bytes held back waiting for a delimiter; past this they go to the board as
/// they are (its decoder counts the overflow).
const HOLD_LIMIT: usize = 2 * MAX_MESSAGE;

/// The line and its bench state; shared by the successive boards of a power-cycled run.
pub(crate) struct Line {
    tty: TtySerial,
    /// Bytes read from the PTY, not yet looked at.
    raw: VecDeque<u8>,
    /// The message being collected (up to its delimiter).
    pending: Vec<u8>,
    /// Bytes released to the board.
    ready: VecDeque<u8>,
    tap: Decoder<MAX_MESSAGE>,
    /// The frame of the last `FrameChunk` released to the board.
    last_frame: Option<u32>,
    /// Distinct frames whose chunks were released.
    frames_started: u32,
    /// Power-cycle once the first chunk of frame number `frames_started == n + 1` is in.
    restart_after: Option<u32>,
    /// A power cycle is due: release nothing more until it is done.
    hold: bool,
    /// Lose the host's bytes during these uploads.
    deaf: Option<Deafness>,
    report: Arc<Mutex<SimReport>>,
}

impl Line {
    pub(crate) fn new(
        tty: TtySerial,
        restart_after: Option<u32>,
        deaf: Option<Deafness>,
        report: Arc<Mutex<SimReport>>,
    ) -> Self {
        Line {
            tty,
            raw: VecDeque::new(),
            pending: Vec::new(),
            ready: VecDeque::new(),
            tap: Decoder::new(),
            last_frame: None,
            frames_started: 0,
            restart_after,
            hold: false,
            deaf,
            report,
        }
    }

    /// A power cycle is due.
    pub(crate) fn restart_due(&self) -> bool {
        self.hold
    }

    /// The board was power-cycled: release bytes again (once only per run).
    pub(crate) fn power_cycled(&mut self) {
        self.hold = false;
        self.restart_after = None;
        self.update_report(|r| r.restarts += 1);
    }

    /// Waits up to `timeout` for input from the host (for an idle board).
    pub(crate) fn wait_input(&mut self, timeout: Duration) -> io::Result<()> {
        if !self.ready.is_empty() || self.hold {
            return Ok(());
        }
        let mut buf = [0u8; 256];
        let n = self.tty.read_within(&mut buf, timeout)?;
        self.raw.extend(&buf[..n]);
        Ok(())
    }

    fn pull(&mut self) -> io::Result<()> {
        while self.tty.read_ready()? {
            let mut buf = [0u8; 1024];
            let n = self.tty.read(&mut buf)?;
            self.raw.extend(&buf[..n]);
            if n < buf.len() {
                break;
            }
        }
        Ok(())
    }

    /// Moves the next whole message (or garbage up to [`HOLD_LIMIT`]) from `raw` to `ready`.
    fn release(&mut self) {
        while self.ready.is_empty() && !self.hold {
            let Some(byte) = self.raw.pop_front() else {
                return;
            };
            self.pending.push(byte);
            if byte == 0 || self.pending.len() >= HOLD_LIMIT {
                self.release_pending();
            }
        }
    }

    fn release_pending(&mut self) {
        let message = std::mem::take(&mut self.pending);
        let (_, decoded) = self.tap.feed::<HostMessage>(&message);
        let chunk = match decoded {
            Some(Ok(HostMessage::FrameChunk(c))) => Some(c.frame),
            _ => None,
        };
        if let Some(frame) = chunk {
            if self.last_frame != Some(frame) {
                self.frames_started += 1;
            }
            self.last_frame = Some(frame);
        }
        let deaf = self.deaf.is_some_and(|d| {
            self.frames_started > d.after && self.frames_started <= d.after + d.frames
        });
        if deaf {
            let n = message.len() as u64;
            self.update_report(|r| r.deaf_in += n);
            return;
        }
        let n = message.len() as u64;
        self.update_report(|r| r.bytes_in += n);
        self.ready.extend(message);
        if chunk.is_some() && self.restart_after.is_some_and(|n| self.frames_started > n) {
            self.hold = true;
        }
    }

    fn update_report(&self, f: impl FnOnce(&mut SimReport)) {
        if let Ok(mut report) = self.report.lock() {
            f(&mut report);
        }
    }
}

impl UploadedFrame for Line {
    /// The frame of the last `FrameChunk` released to the board: the bytes it reads now are
    /// that chunk's, or a message sent during that frame's upload.
    fn uploaded_frame(&self) -> Option<u32> {
        self.last_frame
    }
}

impl embedded_io::ErrorType for Line {
    type Error = io::Error;
}

impl embedded_io::ReadReady for Line {
    fn read_ready(&mut self) -> io::Result<bool> {
        if self.ready.is_empty() {
            self.pull()?;
            self.release();
        }
        Ok(!self.ready.is_empty())
    }
}

impl embedded_io::Read for Line {
    /// Bytes of one message at most (see the module's doc).
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        while self.ready.is_empty() && !buf.is_empty() {
            self.release();
            if self.ready.is_empty() {
                let mut block = [0u8; 256];
                let n = self.tty.read(&mut block)?;
                self.raw.extend(&block[..n]);
            }
        }
        let n = buf.len().min(self.ready.len());
        for (dst, src) in buf.iter_mut().zip(self.ready.drain(..n)) {
            *dst = src;
        }
        Ok(n)
    }
}

impl embedded_io::Write for Line {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.tty.write_all(buf)?;
        let (n, discarded) = (buf.len() as u64, self.tty.discarded());
        self.update_report(|r| {
            r.bytes_out += n;
            r.discarded_out = discarded;
        });
        Ok(buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}
