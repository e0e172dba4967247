//! # digiteyes-platform-linux
//!
//! The Linux platform under digiteyes: what both the Linux board (`boards/linux`) and the
//! `digiteyes` host command (its link to a board, `stream --camera`, the simulated board) need.
//! A library, not a board: it wires nothing.
//!
//! - [`serial`]: a tty (`/dev/ttyAMA0`, `/dev/ttyUSB0`, a PTY) through linux-embedded-hal, as
//!   embedded-io `Read + Write + ReadReady`;
//! - [`clock`]: the monotonic system clock in µs;
//! - [`camera`]: a V4L2 camera (GREY, YUYV or MJPEG converted to 8-bit grey);
//! - [`parse_frame_size`]: `WxH` frame sizes as command lines give them.
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod camera;
pub mod clock;
mod frame_size;
pub mod serial;

pub use clock::MonotonicClock;
pub use frame_size::parse_frame_size;
pub use serial::TtySerial;
