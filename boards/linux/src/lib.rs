//! # digiteyes-board-linux
//!
//! digiteyes on a Linux board (Raspberry-Pi class): the board-agnostic firmware loop of
//! `digiteyes-firmware`, wired to Linux peripherals. Like an embassy board crate, this crate
//! only wires peripherals:
//!
//! - [`serial`]: the link to the host, a tty (`/dev/ttyAMA0`, `/dev/ttyUSB0`, a PTY) through
//!   linux-embedded-hal, as embedded-io `Read + Write + ReadReady`;
//! - [`led`]: an optional status LED on a GPIO line (gpio-cdev);
//! - [`clock`]: the monotonic system clock in µs;
//! - [`camera`]: a V4L2 camera (GREY, YUYV or MJPEG converted to 8-bit grey), or frames
//!   uploaded over the link ([`source::Source`]);
//! - [`sim`]: the same board in a thread on a pseudo-terminal pair, with line noise and
//!   power cycles for tests — what `digiteyes sim`, `digiteyes demo` and the link tests run.
//!
//! The `digiteyes-board` binary runs the board on a real tty; `docs/boards/linux.md` says how
//! and how much memory it takes.
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod camera;
pub mod clock;
mod frame_size;
pub mod led;
pub mod serial;
pub mod sim;
pub mod source;

pub use clock::MonotonicClock;
pub use frame_size::parse_frame_size;
pub use led::StatusLed;
pub use serial::TtySerial;
pub use sim::{Corruption, FrameTap, SimBoard, SimFrame, SimOptions, SimReport, TapMode, Window};
pub use source::Source;

/// The board name a Linux board reports in `Hello`.
pub const BOARD_NAME: &str = "linux";
