//! The host's end of a board link: a serial port, the framing, and byte counts.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use anyhow::{anyhow, Context, Result};
use digiteyes_core::protocol::{
    encode, BoardMessage, Decoder, HostMessage, LinkCounters, MAX_MESSAGE,
};
use digiteyes_platform_linux::TtySerial;

/// Longest single wait inside [`Link::recv_until`], so a deadline is met closely.
const WAIT_STEP: Duration = Duration::from_millis(20);

/// How long a write may wait for the board to take bytes before the link counts as stuck.
const WRITE_LIMIT: Duration = Duration::from_secs(5);

/// A serial link to a board: sends [`HostMessage`]s, receives [`BoardMessage`]s.
#[derive(Debug)]
pub struct Link {
    port: TtySerial,
    path: String,
    rx: Decoder<MAX_MESSAGE>,
    inbox: VecDeque<BoardMessage>,
    bytes_up: u64,
    bytes_down: u64,
}

impl Link {
    /// Opens the serial device at `path` (raw, 8N1, `baud` bits/s) and discards anything
    /// the board sent before; the discard can cut a frame the board was sending, whose tail
    /// is then dropped without counting as an error ([`Link::joined_mid_frame`]). Fails
    /// naming the path when it is missing or cannot be opened.
    pub fn open(path: &str, baud: u32) -> Result<Link> {
        let port = TtySerial::open(path, baud)?;
        Ok(Link {
            port,
            path: path.to_string(),
            rx: Decoder::mid_stream(),
            inbox: VecDeque::new(),
            bytes_up: 0,
            bytes_down: 0,
        })
    }

    /// The device path.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// Encodes and sends one message, taking in the board's answers meanwhile (so neither
    /// side waits on a full buffer).
    pub fn send(&mut self, message: &HostMessage<'_>) -> Result<()> {
        let mut tx = [0u8; MAX_MESSAGE];
        let frame = encode(message, &mut tx)
            .map_err(|e| anyhow!("cannot encode a message for {}: {e}", self.path))?;
        self.write_frame(frame)
    }

    fn write_frame(&mut self, frame: &[u8]) -> Result<()> {
        let mut rest: &[u8] = frame;
        let mut stalled = Duration::ZERO;
        while !rest.is_empty() {
            let n = self
                .port
                .write_within(rest, WAIT_STEP)
                .with_context(|| format!("serial port {}", self.path))?;
            if n == 0 {
                stalled += WAIT_STEP;
                if stalled >= WRITE_LIMIT {
                    return Err(anyhow!(
                        "serial port {}: the board has taken no bytes for {} s",
                        self.path,
                        WRITE_LIMIT.as_secs()
                    ));
                }
            } else {
                stalled = Duration::ZERO;
            }
            rest = &rest[n..];
            self.bytes_up += n as u64;
            self.pump()?;
        }
        Ok(())
    }

    /// Reads whatever has arrived, without waiting, and decodes it.
    pub fn pump(&mut self) -> Result<()> {
        while self
            .port
            .bytes_to_read()
            .with_context(|| format!("serial port {}", self.path))?
            > 0
        {
            self.read_some(WAIT_STEP)?;
        }
        Ok(())
    }

    /// The next message, waiting until `deadline` at most; `None` if none came by then.
    pub fn recv_until(&mut self, deadline: Instant) -> Result<Option<BoardMessage>> {
        loop {
            if let Some(message) = self.inbox.pop_front() {
                return Ok(Some(message));
            }
            let now = Instant::now();
            if now >= deadline {
                return Ok(None);
            }
            self.read_some((deadline - now).min(WAIT_STEP))?;
        }
    }

    /// The next message, waiting `timeout` at most.
    pub fn recv(&mut self, timeout: Duration) -> Result<Option<BoardMessage>> {
        self.recv_until(Instant::now() + timeout)
    }

    /// Bytes sent to the board.
    pub fn bytes_up(&self) -> u64 {
        self.bytes_up
    }

    /// Bytes received from the board.
    pub fn bytes_down(&self) -> u64 {
        self.bytes_down
    }

    /// What the host's decoder has seen: messages, CRC and framing errors.
    pub fn counters(&self) -> LinkCounters {
        self.rx.counters()
    }

    /// Frame tails dropped on opening the port: the end of a frame the board was sending
    /// when the port's pending input was discarded (0 or 1).
    pub fn joined_mid_frame(&self) -> u32 {
        self.rx.joined_mid_frame()
    }

    fn read_some(&mut self, wait: Duration) -> Result<()> {
        let mut buf = [0u8; 4096];
        let n = self
            .port
            .read_within(&mut buf, wait.max(Duration::from_millis(1)))
            .with_context(|| format!("serial port {}", self.path))?;
        self.bytes_down += n as u64;
        let mut input = &buf[..n];
        while !input.is_empty() {
            let (used, decoded) = self.rx.feed::<BoardMessage>(input);
            if let Some(Ok(message)) = decoded {
                self.inbox.push_back(message);
            }
            input = &input[used..];
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serialport::{SerialPort, TTYPort};
    use std::io::Write;

    /// Opening the port discards what arrived before, which can cut the frame the board was
    /// sending (its boot `Hello`, say): the tail that follows is dropped and reported apart,
    /// not counted as a framing or CRC error, and the next frame decodes.
    #[test]
    fn the_tail_of_a_frame_cut_by_opening_the_port_is_dropped_without_an_error() {
        let (mut board, slave) = TTYPort::pair().unwrap();
        let mut link = Link::open(&slave.name().unwrap(), 115_200).unwrap();
        let mut buf = [0u8; MAX_MESSAGE];
        let cut = encode(&BoardMessage::Pong(3), &mut buf).unwrap().to_vec();
        let mut buf = [0u8; MAX_MESSAGE];
        let whole = encode(&BoardMessage::Pong(4), &mut buf).unwrap().to_vec();
        board.write_all(&cut[cut.len() / 2..]).unwrap();
        board.write_all(&whole).unwrap();
        board.flush().unwrap();
        let got = link.recv(Duration::from_secs(10)).unwrap();
        assert_eq!(got, Some(BoardMessage::Pong(4)));
        let c = link.counters();
        assert_eq!((c.messages, c.crc_errors, c.framing_errors), (1, 0, 0));
        assert_eq!(link.joined_mid_frame(), 1);
        // Later garbage is an error as ever.
        board.write_all(&cut[cut.len() / 2..]).unwrap();
        board.write_all(&whole).unwrap();
        board.flush().unwrap();
        assert_eq!(
            link.recv(Duration::from_secs(10)).unwrap(),
            Some(BoardMessage::Pong(4))
        );
        let c = link.counters();
        assert_eq!(c.messages, 2);
        assert_eq!(c.crc_errors + c.framing_errors, 1);
        assert_eq!(link.joined_mid_frame(), 1);
    }
}
