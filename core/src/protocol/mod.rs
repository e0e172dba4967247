//! The board link: versioned messages between a board and its host.
//!
//! Every message is a postcard-encoded [`BoardMessage`] (board → host) or [`HostMessage`]
//! (host → board), followed by its CRC-32 (little-endian), COBS-encoded and delimited by zero
//! bytes on both sides:
//!
//! ```text
//! 0x00 ‖ COBS( postcard(message) ‖ CRC-32/ISO-HDLC(postcard(message)) as u32 LE ) ‖ 0x00
//! ```
//!
//! A receiver ([`Decoder`]) never panics: garbage, a corrupted byte, a frame longer than its
//! buffer or an unknown message each cost one frame and one count in [`LinkCounters`], and
//! the next frame decodes. The written spec is `docs/protocol.md`.

mod digest;
mod framing;
mod messages;
mod params;

pub use digest::{canonical_form, model_digest};
pub use framing::{encode, max_encoded_len, Decoder, EncodeError, LinkError};
pub use messages::*;
pub use params::{BadParameter, CameraParams, TrackerParams, WireResidual, WireRobust};

/// The protocol version in [`Hello`]; it rises whenever a message's layout changes.
/// Version 2: `Stats` gained `stale_chunks`, and the model digest is computed over the
/// canonical form of `docs/protocol.md` §7 (version 1 digested `write_dh`'s text).
/// Version 3: `Hold` and `Measure` (host), `LinkEdges` and `Measured` (board), `Command::Hold`:
/// one board per camera, measuring for a host that solves (docs/protocol.md §9).
/// Version 4: the board finds the hand itself: `State` gained `status` and
/// `search_evaluations`, `Reset` gained `start` (from the given state, or search), `Configure`
/// gained `search_evaluations_per_frame` (docs/protocol.md §10).
/// Version 5: several hypotheses: `Configure` gained `hypotheses` (the count K), and the board
/// sends `Hypotheses` (board message 10) after every `State` when K > 1 (docs/protocol.md
/// §11).
/// Version 6: the palm's outline edges (issue 9): `TrackerParams` gained `palm_edges`, and a
/// board answering `Measure` sends `PalmEdges` (board message 11) per palm outline edge with
/// anything to say, counted in `Measured::links` (docs/protocol.md §12).
/// Version 7: `TrackerParams` gained `max_edge_angle_rad`, the slice search's test of an
/// edge's direction (issue 9; docs/protocol.md §4).
/// Version 8: `TrackerParams` gained `outermost_share`, the slice search's choice of the
/// outermost edge where the model expects the background outside (issue 9; docs/protocol.md
/// §4).
/// Version 9: `Configure` gained `hypotheses_score_every`, the hypotheses scored one frame in
/// S (issue 11; docs/protocol.md §11).
/// Version 10: `Configure` gained `hypotheses_sample_iterations` and
/// `hypotheses_other_iterations`, caps on the Gauss–Newton iterations of the hypotheses other
/// than the best, and `hypotheses_keep_fingers`, whether the finger-undo candidates are weighed
/// (issue 11; docs/protocol.md §11). Since grouped, with versions 5 and 9's fields, into
/// `Configure.hypotheses` ([`HypothesesParams`]): the same bytes, so the same version.
pub const PROTOCOL_VERSION: u8 = 10;

/// Largest `FrameChunk` payload (bytes).
pub const MAX_CHUNK: usize = 1024;

/// Largest encoded message either side sends or accepts (bytes, both zero delimiters
/// included: at most `MAX_MESSAGE − 2` COBS bytes between them), so the size of every receive
/// and transmit buffer: the largest are a `Features` naming all
/// [`MAX_LINKS`](crate::config::MAX_LINKS) links (1,315 bytes), a `Hypotheses` of
/// [`MAX_HYPOTHESES`](crate::config::MAX_HYPOTHESES) states of
/// [`MAX_STATES`](crate::config::MAX_STATES) (1,122 bytes) and a full `FrameChunk` (about
/// 1,050 bytes); `tests/protocol.rs` checks they fit.
pub const MAX_MESSAGE: usize = 1408;

/// The CRC of every frame: CRC-32/ISO-HDLC (the zlib/Ethernet CRC-32).
pub(crate) static CRC: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC);
