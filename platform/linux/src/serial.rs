//! The board's serial link: a tty opened through linux-embedded-hal, seen as embedded-io 0.7.
//!
//! linux-embedded-hal's [`Serial`] implements the byte-at-a-time embedded-hal-nb traits; the
//! firmware wants embedded-io's `Read + Write + ReadReady` on whole buffers. [`TtySerial`]
//! is that thin adapter over the same [`TTYPort`]: reads and writes go straight to the tty,
//! and `ReadReady` asks the kernel how many bytes wait (`FIONREAD`), so the board loop never
//! blocks on a quiet line. It works the same on a UART (`/dev/ttyAMA0`, `/dev/ttyUSB0`) and on
//! either side of a pseudo-terminal pair.

use std::fmt;
use std::io::{self, Read as _, Write as _};
use std::os::fd::AsRawFd;
use std::time::{Duration, Instant};

use linux_embedded_hal::Serial;
use serialport::{SerialPort, TTYPort};

/// How long one kernel wait inside `read`/`write` lasts before it is retried (the blocking
/// calls loop over it).
const WAIT: Duration = Duration::from_millis(100);

/// The tty could not be opened.
#[derive(Debug)]
pub struct OpenError {
    /// The device path.
    pub path: String,
    /// What the system said.
    pub source: serialport::Error,
}

impl fmt::Display for OpenError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "cannot open serial port {}: {}",
            self.path, self.source.description
        )
    }
}

impl std::error::Error for OpenError {}

/// A tty as an embedded-io serial port: blocking `read`/`write`, non-blocking `read_ready`.
pub struct TtySerial {
    port: Serial,
    /// When set, a write that cannot proceed for this long is discarded instead of blocking.
    give_up_after: Option<Duration>,
    discarded: u64,
}

impl fmt::Debug for TtySerial {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("TtySerial")
            .field("name", &self.port.0.name())
            .field("discarded", &self.discarded)
            .finish()
    }
}

impl TtySerial {
    /// Opens the tty at `path` (raw mode, 8N1, no flow control) at `baud` bits/s. Pending input
    /// from before the open is discarded.
    pub fn open(path: &str, baud: u32) -> Result<Self, OpenError> {
        let error = |source| OpenError {
            path: path.to_string(),
            source,
        };
        let builder = serialport::new(path, baud).timeout(WAIT);
        let port = Serial::open_from_builder(builder).map_err(error)?;
        port.0
            .clear(serialport::ClearBuffer::Input)
            .map_err(error)?;
        Ok(Self::from_port(port.0))
    }

    /// Wraps an open port (e.g. one side of [`TTYPort::pair`]).
    pub fn from_port(mut port: TTYPort) -> Self {
        // The timeout only bounds each kernel wait; the blocking calls loop over it.
        let _ = port.set_timeout(WAIT);
        // Non-blocking at the kernel: the waits above are the only blocking, so a write into a
        // full buffer returns after WAIT instead of hanging in write(2) until all is taken.
        let _ = nix::fcntl::fcntl(
            port.as_raw_fd(),
            nix::fcntl::FcntlArg::F_SETFL(nix::fcntl::OFlag::O_NONBLOCK),
        );
        TtySerial {
            port: Serial(port),
            give_up_after: None,
            discarded: 0,
        }
    }

    /// Makes writes that cannot proceed for `after` drop their bytes instead of blocking, like
    /// a UART whose far end is not listening. A pseudo-terminal with no reader blocks its
    /// writer forever; a simulated board should not. `None` (the default) blocks.
    pub fn discard_unread_writes(&mut self, after: Option<Duration>) {
        self.give_up_after = after;
    }

    /// Bytes dropped by [`TtySerial::discard_unread_writes`] so far.
    pub fn discarded(&self) -> u64 {
        self.discarded
    }

    /// The device path, when the port was opened by path.
    pub fn name(&self) -> Option<String> {
        self.port.0.name()
    }

    /// Waits up to `timeout` for input, then reads what is there into `buf`; `Ok(0)` when
    /// nothing came.
    pub fn read_within(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        if buf.is_empty() {
            return Ok(0);
        }
        self.port.0.set_timeout(timeout).map_err(io::Error::from)?;
        let result = self.port.0.read(buf);
        self.port.0.set_timeout(WAIT).map_err(io::Error::from)?;
        match result {
            Ok(n) => Ok(n),
            Err(e) if transient(&e) => Ok(0),
            Err(e) => Err(e),
        }
    }

    /// Writes what the kernel takes within `timeout` (at least one byte unless it timed out);
    /// `Ok(0)` when it took nothing.
    pub fn write_within(&mut self, buf: &[u8], timeout: Duration) -> io::Result<usize> {
        if buf.is_empty() {
            return Ok(0);
        }
        self.port.0.set_timeout(timeout).map_err(io::Error::from)?;
        let result = self.port.0.write(buf);
        self.port.0.set_timeout(WAIT).map_err(io::Error::from)?;
        match result {
            Ok(n) => Ok(n),
            Err(e) if transient(&e) => Ok(0),
            Err(e) => Err(e),
        }
    }

    /// Bytes received and not yet read.
    pub fn bytes_to_read(&self) -> io::Result<u32> {
        self.port.0.bytes_to_read().map_err(io::Error::from)
    }

    /// The underlying port.
    pub fn port(&self) -> &TTYPort {
        &self.port.0
    }
}

fn transient(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        io::ErrorKind::TimedOut | io::ErrorKind::WouldBlock | io::ErrorKind::Interrupted
    )
}

impl embedded_io::ErrorType for TtySerial {
    type Error = io::Error;
}

impl embedded_io::Read for TtySerial {
    /// Blocks until at least one byte has arrived.
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if buf.is_empty() {
            return Ok(0);
        }
        loop {
            match self.port.0.read(buf) {
                Ok(n) => return Ok(n),
                Err(e) if transient(&e) => continue,
                Err(e) => return Err(e),
            }
        }
    }
}

impl embedded_io::ReadReady for TtySerial {
    fn read_ready(&mut self) -> io::Result<bool> {
        Ok(self.bytes_to_read()? > 0)
    }
}

impl embedded_io::Write for TtySerial {
    /// Blocks until the kernel has taken at least one byte (or, with
    /// [`TtySerial::discard_unread_writes`], drops them all after that long).
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        if buf.is_empty() {
            return Ok(0);
        }
        let start = Instant::now();
        loop {
            match self.port.0.write(buf) {
                Ok(n) => return Ok(n),
                Err(e) if transient(&e) => {
                    if self
                        .give_up_after
                        .is_some_and(|after| start.elapsed() >= after)
                    {
                        self.discarded += buf.len() as u64;
                        return Ok(buf.len());
                    }
                }
                Err(e) => return Err(e),
            }
        }
    }

    /// The kernel transmits what it was given on its own: nothing to wait for here. (Waiting
    /// for the line to drain, `tcdrain`, would stall tracking for the whole transmission, and
    /// on a pseudo-terminal nobody reads it would never return.)
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use embedded_io::{Read, ReadReady, Write};

    /// Both ends of a PTY pair: the master as the board's port, the slave opened by path like
    /// a host opens a UART.
    fn pair() -> (TtySerial, TtySerial, TTYPort) {
        let (master, slave) = TTYPort::pair().unwrap();
        let path = slave.name().unwrap();
        let host = TtySerial::open(&path, 115_200).unwrap();
        (TtySerial::from_port(master), host, slave)
    }

    #[test]
    fn every_byte_value_crosses_a_pty_both_ways_and_read_ready_tells_when() {
        let (mut board, mut host, _slave) = pair();
        assert!(!board.read_ready().unwrap());
        let all: Vec<u8> = (0..=255u8).chain((0..=255u8).rev()).collect();
        host.write_all(&all).unwrap();
        let mut got = Vec::new();
        let deadline = Instant::now() + Duration::from_secs(5);
        while got.len() < all.len() {
            assert!(
                Instant::now() < deadline,
                "only {} bytes arrived",
                got.len()
            );
            if board.read_ready().unwrap() {
                let mut buf = [0u8; 64];
                let n = board.read(&mut buf).unwrap();
                got.extend_from_slice(&buf[..n]);
            }
        }
        assert_eq!(got, all);
        assert!(!board.read_ready().unwrap());
        board.write_all(&all).unwrap();
        board.flush().unwrap();
        let mut back = vec![0u8; all.len()];
        host.read_exact(&mut back).unwrap();
        assert_eq!(back, all);
    }

    #[test]
    fn read_within_returns_nothing_on_a_quiet_line() {
        let (mut board, _host, _slave) = pair();
        let mut buf = [0u8; 8];
        assert_eq!(
            board
                .read_within(&mut buf, Duration::from_millis(20))
                .unwrap(),
            0
        );
    }

    #[test]
    fn writes_nobody_reads_are_discarded_when_asked() {
        let (master, _slave) = TTYPort::pair().unwrap();
        let mut board = TtySerial::from_port(master);
        board.discard_unread_writes(Some(Duration::from_millis(50)));
        // Far more than a PTY buffers (~68 KB on Linux): without discarding this would block
        // forever.
        let block = vec![0x55u8; 1 << 18];
        board.write_all(&block).unwrap();
        assert!(board.discarded() > 0);
    }

    #[test]
    fn a_missing_device_is_named() {
        let err = TtySerial::open("/nonexistent/ttyX", 115_200).unwrap_err();
        assert!(err.to_string().contains("/nonexistent/ttyX"), "{err}");
    }
}
