//! The host's side of the board link (`docs/protocol.md`, `docs/link.md`): open a serial
//! port to a board, set the board up from a sequence, upload frames and collect what became
//! of each, and report the link's figures.
//!
//! - [`Link`]: the serial port, framing and byte counts;
//! - [`SessionSetup`]: camera, tracker parameters, initial state, free states, model digest;
//! - [`Session`]: the handshake, one frame at a time, reboots followed, the final ping;
//! - [`set_up_board`]: Configure + Reset from a description, for a board with its own camera;
//! - [`FrameOutcome`] / [`DropCause`]: every frame is tracked or dropped with a reason;
//! - [`LinkReport`]: states/s, bytes, CRC/framing errors on both ends, drops by reason.

mod outcome;
mod port;
mod report;
mod session;
mod setup;

pub use outcome::{DropCause, FrameOutcome};
pub use port::Link;
pub use report::LinkReport;
pub use session::{set_up_board, set_up_board_starting, Session, SetUpBoard};
pub use setup::{SessionSetup, DEFAULT_REPLY_TIMEOUT};
