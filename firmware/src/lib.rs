//! # digiteyes-firmware
//!
//! The board loop of digiteyes, like the IC40 board of DigitEyes (Rehg 1995, Sec. 4.3.2): one
//! board per camera, no operating system, all image processing and estimation on the board,
//! states out over a serial line.
//!
//! ```text
//! serial ─▶ Decoder ─▶ commands (Configure, Reset, Ping)
//!                   └▶ FrameChunk ─▶ Upload ─┐
//! FrameSource (camera) ──────────────────────┴▶ frame buffer ─▶ AutoTracker ─▶ State ─▶ serial
//!                                                  (search: edge map) └▶ overlay buffer
//! ```
//!
//! A board crate only wires peripherals: a serial port (embedded-io 0.7 `Read + Write +
//! ReadReady`), a status LED (embedded-hal 1.0 `OutputPin`), a [`Clock`], a [`FrameSource`]
//! and caller-owned [`Buffers`], then calls [`Board::run`]. The board finds the hand itself
//! (`Reset` with `Start::Search`, or after losing it): searching, tracking or lost, its
//! status is in every `State`. The session protocol the loop follows
//! is `docs/protocol.md`. Memory is static: the frame and overlay buffers are the caller's,
//! everything else lives in the [`Board`] value (`docs/firmware.md` gives the sizes).
#![no_std]
#![deny(unsafe_code)]
#![warn(missing_docs)]

mod board;
mod clock;
mod led;
mod log;
mod memory;
pub mod overlay;
mod source;
mod upload;

pub use board::{Board, Tap, Tracked};
pub use clock::Clock;
pub use led::NoLed;
pub use memory::{edge_map_bytes, hypotheses_config, search_config, Buffers, SEARCH_STRIDE_PX};
pub use source::{FrameSource, SourceError, Uploads};
pub use upload::{ChunkOutcome, Upload};
