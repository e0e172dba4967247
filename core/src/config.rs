//! Capacities: every fixed-size buffer in the core is sized by one of these constants.

/// Most links (rows of `hand.dh`, each a coordinate frame) a model may have (the whole hand
/// has 37). Named for links, not video frames.
pub const MAX_LINKS: usize = 48;
/// Most states a model may have (the whole hand has 28).
pub const MAX_STATES: usize = 32;
/// Most frames one frame's `next` list may name (the palm names 5).
pub const MAX_CHILDREN: usize = 6;
/// Most characters in a frame name.
pub const MAX_NAME_LEN: usize = 24;
/// Most cameras the tracker fuses in one solve.
pub const MAX_CAMERAS: usize = 4;
/// Most slices placed along one link.
pub const MAX_SLICES_PER_LINK: usize = 16;
/// Most samples along one slice search window (pixels, one sample per pixel).
pub const MAX_WINDOW: usize = 64;
/// Most revolute joints between the palm and any link (the thumb has 5).
pub const MAX_CHAIN: usize = 8;
/// Most non-zero entries in one residual row: 7 palm states plus a joint chain.
pub const MAX_ROW_NONZEROS: usize = 7 + MAX_CHAIN;
/// Most hypotheses a [`MultiTracker`](crate::hypotheses::MultiTracker) carries between frames.
pub const MAX_HYPOTHESES: usize = 8;
/// Most new hypotheses sampled on one frame.
pub const MAX_SPAWN: usize = 4;
/// Most fingers jumped to their other reading on one frame (`hypotheses::jump`); the jumps
/// take the places of samples, so samples and jumps together are at most [`MAX_SPAWN`].
pub const MAX_JUMPS: usize = 2;
/// Most hypotheses weighed on one frame: those carried, those sampled along weak directions
/// or jumped, and the best with one finger (or all) kept where it was (`hypotheses::fingers`).
pub const MAX_CANDIDATES: usize =
    MAX_HYPOTHESES + MAX_SPAWN + crate::hypotheses::fingers::MAX_FINGERS + 1;
