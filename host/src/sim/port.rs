//! The serial port a simulated board is given: a handle on the line it shares with the
//! boards booted before and after it (a power cycle drops the board, not the line), through
//! the line noise.

use std::cell::RefCell;
use std::io;
use std::rc::Rc;
use std::sync::{Arc, Mutex};

use super::fault_injector::FaultInjector;
use super::line::Line;
use super::SimReport;

/// The line as the board sees it: noise ([`FaultInjector`]) over the PTY's bookkeeping.
pub(crate) type NoisyLine = FaultInjector<Line>;

/// One board's handle on the [`NoisyLine`]. Dropping the board drops only the handle; the
/// next board gets a new one on the same line.
pub(crate) struct SimPort {
    pub(crate) line: Rc<RefCell<NoisyLine>>,
    pub(crate) report: Arc<Mutex<SimReport>>,
}

impl SimPort {
    /// Copies the injector's counts into the report.
    fn note_noise(&self, line: &NoisyLine) {
        let injected = line.injected();
        if let Ok(mut r) = self.report.lock() {
            r.corrupted_in = injected.corrupted_in;
            r.corrupted_out = injected.corrupted_out;
        }
    }
}

impl embedded_io::ErrorType for SimPort {
    type Error = io::Error;
}

impl embedded_io::Read for SimPort {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let mut line = self.line.borrow_mut();
        let n = line.read(buf)?;
        self.note_noise(&line);
        Ok(n)
    }
}

impl embedded_io::ReadReady for SimPort {
    fn read_ready(&mut self) -> io::Result<bool> {
        self.line.borrow_mut().read_ready()
    }
}

impl embedded_io::Write for SimPort {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let mut line = self.line.borrow_mut();
        let n = line.write(buf)?;
        self.note_noise(&line);
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.line.borrow_mut().flush()
    }
}
