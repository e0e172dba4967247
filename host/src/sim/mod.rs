//! The simulated board (`digiteyes sim`, `digiteyes demo`, the link tests): the firmware's
//! [`Board`] on one side of a pseudo-terminal pair this process creates, in a thread; a host
//! connects to the other side's path (`/dev/pts/N`) exactly as it would to a UART. The
//! platform under it is the Linux board's (`digiteyes-platform-linux`: the tty port, the
//! clock); the rest lives here, in one place:
//!
//! - [`fault_injector`]: line noise ([`Corruption`]), an embedded-io wrapper around the
//!   board's serial port in the manner of smoltcp's fault injector;
//! - `line`: the PTY as the board reads it, one host message at a time, with a deaf spell
//!   ([`SimOptions::deaf`]) and the trigger of a power cycle ([`SimOptions::restart_after`]:
//!   the [`Board`] is dropped and a new one boots on the same PTY, losing whatever it had
//!   received of the frame in flight);
//! - [`tap`]: with [`SimOptions::frame_tap`] every tracked frame comes back as a [`SimFrame`]
//!   (pixels, the state sent, camera) over a channel; [`overlay`] draws them as PNGs
//!   (`sim --overlay`) and [`ui_tap`] feeds them to the UI page (`sim --ui`).

pub mod fault_injector;
mod line;
pub mod overlay;
mod port;
pub mod tap;
pub mod ui_tap;

use std::cell::RefCell;
use std::fmt;
use std::io;
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use anyhow::Context;
use digiteyes_core::protocol::Stats;
use digiteyes_firmware::{edge_map_bytes, Board, Buffers, NoLed, Tracked, Uploads};
use digiteyes_platform_linux::{MonotonicClock, TtySerial};
use serialport::{SerialPort, TTYPort};

pub use fault_injector::{Corruption, FaultInjector, Window};
pub use overlay::{overlay_tap, OVERLAY_QUEUE};
pub use tap::{FrameTap, SimFrame, TapMode};

use line::Line;
use port::SimPort;

/// The board name the simulator reports in `Hello`.
pub const SIM_BOARD_NAME: &str = "linux-sim";

/// How long an idle board waits for input before looking at its other work again.
const IDLE_WAIT: Duration = Duration::from_millis(5);

/// A board write nobody reads for this long is dropped, like a UART's bytes when no host is
/// listening (a PTY would block the board instead).
const UNREAD_WRITE_LIMIT: Duration = Duration::from_secs(1);

/// How the simulated board is set up.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct SimOptions {
    /// Bytes of the board's frame buffer: the largest frame it accepts (default VGA,
    /// 640 × 480).
    pub frame_buffer_bytes: usize,
    /// Bytes of the search's edge map: enough for the largest frame
    /// ([`digiteyes_firmware::edge_map_bytes`]; default VGA's, 115,200).
    pub edge_map_bytes: usize,
    /// Line noise, if any.
    pub corruption: Option<Corruption>,
    /// Power-cycle the board once, right after it has received the first chunk of the frame
    /// that follows this many uploaded frames.
    pub restart_after: Option<u32>,
    /// Where to hand every tracked frame, if anywhere.
    pub frame_tap: Option<FrameTap>,
    /// Deaf for a while, as a board whose cable is pulled and plugged back: every byte from
    /// the host is lost while the uploads of frames `after + 1 ..= after + frames` (counted
    /// from 1) are under way; then the board hears again, with all it had before.
    pub deaf: Option<Deafness>,
}

/// When a simulated board hears nothing ([`SimOptions::deaf`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Deafness {
    /// Uploaded frames heard before the board goes deaf.
    pub after: u32,
    /// Uploaded frames it does not hear.
    pub frames: u32,
}

impl Default for SimOptions {
    fn default() -> Self {
        SimOptions {
            frame_buffer_bytes: 640 * 480,
            edge_map_bytes: edge_map_bytes(640, 480),
            corruption: None,
            restart_after: None,
            frame_tap: None,
            deaf: None,
        }
    }
}

impl SimOptions {
    /// With line noise.
    pub fn corruption(mut self, corruption: Corruption) -> Self {
        self.corruption = Some(corruption);
        self
    }

    /// With one power cycle after `frames` uploaded frames.
    pub fn restart_after(mut self, frames: u32) -> Self {
        self.restart_after = Some(frames);
        self
    }

    /// Deaf through the uploads of `frames` frames after `after` ([`SimOptions::deaf`]).
    pub fn deaf(mut self, after: u32, frames: u32) -> Self {
        self.deaf = Some(Deafness { after, frames });
        self
    }

    /// Handing every tracked frame to `tap` (before the frame's `State` goes out).
    pub fn frame_tap(mut self, tap: FrameTap) -> Self {
        self.frame_tap = Some(tap);
        self
    }

    /// With a frame buffer of `bytes`, and an edge map for any frame that fits it.
    pub fn frame_buffer_bytes(mut self, bytes: usize) -> Self {
        self.frame_buffer_bytes = bytes;
        // The largest map a frame of `bytes` pixels can need is a one-pixel-high frame's.
        self.edge_map_bytes = edge_map_bytes(bytes, 1);
        self
    }

    /// With buffers for frames of `width × height` px at most (frame and edge map).
    pub fn max_frame(mut self, width: u32, height: u32) -> Self {
        self.frame_buffer_bytes = width as usize * height as usize;
        self.edge_map_bytes = edge_map_bytes(width as usize, height as usize);
        self
    }
}

/// What the simulated board and its line did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SimReport {
    /// Power cycles.
    pub restarts: u32,
    /// Bytes received from the host.
    pub bytes_in: u64,
    /// Bytes sent to the host.
    pub bytes_out: u64,
    /// Received bytes the line noise hit.
    pub corrupted_in: u64,
    /// Sent bytes the line noise hit.
    pub corrupted_out: u64,
    /// Sent bytes dropped because no host read them.
    pub discarded_out: u64,
    /// Received bytes lost while the board was deaf ([`SimOptions::deaf`]).
    pub deaf_in: u64,
    /// Serial errors the board loop returned (the loop goes on after each).
    pub serial_errors: u64,
    /// Tracked frames handed to the [`FrameTap`].
    pub tapped: u64,
    /// Tracked frames the [`FrameTap`] could not hand over (channel full in
    /// [`TapMode::Skip`], receiver gone, or the board stopped while waiting).
    pub tap_skipped: u64,
    /// The current board's counters (since its last boot).
    pub board: Stats,
}

impl fmt::Display for SimReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "board line: {} bytes in ({} corrupted), {} bytes out ({} corrupted, {} unread), \
             {} restart(s), {} serial error(s)",
            self.bytes_in,
            self.corrupted_in,
            self.bytes_out,
            self.corrupted_out,
            self.discarded_out,
            self.restarts,
            self.serial_errors
        )?;
        if self.tapped + self.tap_skipped > 0 {
            write!(
                f,
                "; frame tap: {} frame(s) handed over, {} skipped",
                self.tapped, self.tap_skipped
            )?;
        }
        Ok(())
    }
}

/// A running simulated board. Stops (and joins its thread) when dropped.
#[derive(Debug)]
pub struct SimBoard {
    path: PathBuf,
    stop: Arc<AtomicBool>,
    report: Arc<Mutex<SimReport>>,
    thread: Option<JoinHandle<io::Result<()>>>,
    /// The PTY's slave side, held open so the board's side never sees a hang-up between
    /// hosts.
    _slave: TTYPort,
}

impl SimBoard {
    /// Creates a PTY pair and boots the board on its master side; connect to [`SimBoard::path`].
    pub fn start(options: SimOptions) -> io::Result<SimBoard> {
        let (master, slave) = TTYPort::pair().map_err(io::Error::from)?;
        let path = slave
            .name()
            .map(PathBuf::from)
            .ok_or_else(|| io::Error::other("the PTY has no device path"))?;
        let mut tty = TtySerial::from_port(master);
        tty.discard_unread_writes(Some(UNREAD_WRITE_LIMIT));
        let stop = Arc::new(AtomicBool::new(false));
        let report = Arc::new(Mutex::new(SimReport::default()));
        let thread = std::thread::Builder::new()
            .name("digiteyes-sim-board".into())
            // The board value holds the tracker; give it room whatever the platform default.
            .stack_size(16 << 20)
            .spawn({
                let (stop, report) = (stop.clone(), report.clone());
                move || run(tty, options, &stop, &report)
            })?;
        Ok(SimBoard {
            path,
            stop,
            report,
            thread: Some(thread),
            _slave: slave,
        })
    }

    /// The device to connect to (e.g. `/dev/pts/3`).
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// What the board and its line have done so far.
    pub fn report(&self) -> SimReport {
        self.report.lock().map(|r| *r).unwrap_or_default()
    }

    /// Whether the board thread is still running (it stops only on [`SimBoard::stop`] or an
    /// unrecoverable error).
    pub fn is_running(&self) -> bool {
        self.thread.as_ref().is_some_and(|t| !t.is_finished())
    }

    /// Stops the board and returns its report, or the error that stopped it.
    pub fn stop(mut self) -> io::Result<SimReport> {
        self.shut_down()?;
        Ok(self.report())
    }

    /// Waits until the board thread ends (it runs until stopped: this is "until Ctrl-C").
    pub fn wait(mut self) -> io::Result<SimReport> {
        if let Some(thread) = self.thread.take() {
            join(thread)?;
        }
        Ok(self.report())
    }

    fn shut_down(&mut self) -> io::Result<()> {
        self.stop.store(true, Ordering::Relaxed);
        match self.thread.take() {
            Some(thread) => join(thread),
            None => Ok(()),
        }
    }
}

impl Drop for SimBoard {
    fn drop(&mut self) {
        let _ = self.shut_down();
    }
}

fn join(thread: JoinHandle<io::Result<()>>) -> io::Result<()> {
    thread
        .join()
        .map_err(|_| io::Error::other("the simulated board panicked"))?
}

/// The board thread: boot, poll until stopped, power-cycle when the line says so.
fn run(
    tty: TtySerial,
    options: SimOptions,
    stop: &AtomicBool,
    report: &Arc<Mutex<SimReport>>,
) -> io::Result<()> {
    let line = Rc::new(RefCell::new(FaultInjector::new(
        Line::new(tty, options.restart_after, options.deaf, report.clone()),
        options.corruption.clone(),
    )));
    let mut frame_buffer = vec![0u8; options.frame_buffer_bytes];
    let mut edge_map = vec![0u8; options.edge_map_bytes];
    let note = |f: &dyn Fn(&mut SimReport)| {
        if let Ok(mut r) = report.lock() {
            f(&mut r);
        }
    };
    let mut boot = 0u32;
    loop {
        let tap = options.frame_tap.clone();
        let mut hand = move |tracked: &Tracked<'_>| {
            if let Some(tap) = &tap {
                tap.hand(tracked, boot, stop, report);
            }
        };
        let mut board = Board::new(
            SIM_BOARD_NAME,
            Buffers {
                frame: &mut frame_buffer,
                overlay: None,
                edge_map: &mut edge_map,
            },
            SimPort {
                line: line.clone(),
                report: report.clone(),
            },
            Uploads,
            NoLed,
            MonotonicClock::new(),
        );
        if options.frame_tap.is_some() {
            board.set_tap(&mut hand);
        }
        if board.start().is_err() {
            note(&|r| r.serial_errors += 1);
        }
        loop {
            if stop.load(Ordering::Relaxed) {
                let stats = board.stats();
                note(&|r| r.board = stats);
                return Ok(());
            }
            if line.borrow().inner().restart_due() {
                break;
            }
            let busy = match board.poll() {
                Ok(busy) => busy,
                Err(_) => {
                    note(&|r| r.serial_errors += 1);
                    false
                }
            };
            let stats = board.stats();
            note(&|r| r.board = stats);
            if !busy {
                line.borrow_mut().inner_mut().wait_input(IDLE_WAIT)?;
            }
        }
        drop(board);
        line.borrow_mut().inner_mut().power_cycled();
        boot += 1;
    }
}

/// Starts the simulated board and returns it (its [`SimBoard::path`] is the device to
/// connect to); the error says it was the simulated board that could not start.
pub fn start(options: SimOptions) -> anyhow::Result<SimBoard> {
    SimBoard::start(options).context("cannot start the simulated board on a pseudo-terminal")
}
