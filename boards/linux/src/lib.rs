//! # digiteyes-board-linux
//!
//! digiteyes on a Linux board (Raspberry-Pi class): the board-agnostic firmware loop of
//! `digiteyes-firmware`, wired to the Linux platform of `digiteyes-platform-linux`. Like an
//! embassy board crate, this crate only wires peripherals, and nothing depends on it:
//!
//! - the link to the host: a tty ([`digiteyes_platform_linux::TtySerial`]);
//! - [`led`]: an optional status LED on a GPIO line (gpio-cdev);
//! - the clock: [`digiteyes_platform_linux::MonotonicClock`];
//! - [`source`]: a V4L2 camera, or frames uploaded over the link.
//!
//! The `digiteyes-board` binary runs the board on a real tty; `docs/boards/linux.md` says how
//! and how much memory it takes. The simulated board of `digiteyes sim` is the host's
//! (`digiteyes_host::sim`).
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod led;
pub mod source;

pub use led::StatusLed;
pub use source::Source;

/// The board name a Linux board reports in `Hello`.
pub const BOARD_NAME: &str = "linux";
