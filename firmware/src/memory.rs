//! The memory a board crate gives the board loop, and the search's share of it.
//!
//! The board's search ([`AutoTracker`](digiteyes_core::auto_tracker::AutoTracker)) needs an
//! edge map of the frame: per cell of [`SEARCH_STRIDE_PX`] × [`SEARCH_STRIDE_PX`] px, one
//! byte per orientation bin ([`EDGE_BINS`]). A board crate sizes it for its largest frame
//! with [`edge_map_bytes`], a `const fn`, so it can live in a `static`. The same buffer
//! serves the likelihood of several hypotheses ([`hypotheses_config`]: the same stride), which
//! builds its map on tracking frames, while the search builds its own on searching frames:
//! never both on one frame.

use digiteyes_core::acquire::AcquireConfig;
use digiteyes_core::hypotheses::HypothesesConfig;
use digiteyes_core::likelihood::{LikelihoodConfig, EDGE_BINS};
use digiteyes_core::protocol::Configure;

/// Side of an edge-map cell (px) on a board: the search's default (4 keeps a VGA frame's map
/// at 115,200 bytes).
pub const SEARCH_STRIDE_PX: u8 = 4;

/// Bytes of edge map the search needs for `width × height` frames (at [`SEARCH_STRIDE_PX`]).
pub const fn edge_map_bytes(width: usize, height: usize) -> usize {
    let s = SEARCH_STRIDE_PX as usize;
    width.div_ceil(s) * height.div_ceil(s) * EDGE_BINS
}

/// The search a board runs: the search's defaults, at most `evaluations_per_frame`
/// evaluations per frame (`Configure`'s budget), edge maps at [`SEARCH_STRIDE_PX`].
pub fn search_config(evaluations_per_frame: u16) -> AcquireConfig {
    let defaults = AcquireConfig::default();
    AcquireConfig {
        evaluations_per_frame,
        likelihood: LikelihoodConfig {
            stride_px: SEARCH_STRIDE_PX,
            ..defaults.likelihood
        },
        ..defaults
    }
}

/// The hypotheses a board tracks: the tracker's defaults with `Configure`'s
/// [`HypothesesParams`](digiteyes_core::protocol::HypothesesParams) in place, their
/// likelihood's edge map at [`SEARCH_STRIDE_PX`] so it fits the search's buffer
/// ([`Buffers::edge_map`]).
pub fn hypotheses_config(configure: &Configure) -> HypothesesConfig {
    let defaults = HypothesesConfig::default();
    configure.hypotheses.over(HypothesesConfig {
        likelihood: LikelihoodConfig {
            stride_px: SEARCH_STRIDE_PX,
            ..defaults.likelihood
        },
        ..defaults
    })
}

/// The caller-owned memory of a [`Board`](crate::Board), each part as long as the largest
/// frame the board takes needs.
#[derive(Debug)]
pub struct Buffers<'m> {
    /// One frame (8-bit grey, packed): its length is the largest frame accepted.
    pub frame: &'m mut [u8],
    /// When given, receives each tracked frame with the model drawn in (as long as `frame`).
    pub overlay: Option<&'m mut [u8]>,
    /// The search's edge map: at least [`edge_map_bytes`] of the largest frame. A camera whose
    /// map does not fit is refused (`Nak(Configure, FrameTooLarge)`).
    pub edge_map: &'m mut [u8],
}

#[cfg(test)]
mod tests {
    use super::*;
    use digiteyes_core::likelihood::EdgeMap;
    use digiteyes_core::protocol::{CameraParams, HypothesesParams, TrackerParams};

    /// A `Configure` asking for `count` hypotheses scored one frame in `score_every`, their
    /// iterations capped at `[sample, other]`, without the finger-undo candidates.
    fn configure(count: u8, score_every: u8, iterations: [u8; 2]) -> Configure {
        let camera = CameraParams {
            width: 320,
            height: 240,
            intrinsics: [400.0, 400.0, 160.0, 120.0],
            r: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
            t: [0.0, 0.0, 500.0],
        };
        Configure {
            hypotheses: HypothesesParams {
                count,
                score_every,
                sample_iterations: iterations[0],
                other_iterations: iterations[1],
                keep_fingers: false,
            },
            ..Configure::new(camera, TrackerParams::default())
        }
    }

    #[test]
    fn edge_map_bytes_is_what_the_search_asks_for() {
        for (w, h) in [(640, 480), (320, 240), (161, 119), (1, 1)] {
            assert_eq!(
                edge_map_bytes(w, h),
                EdgeMap::bytes_needed(w, h, search_config(1).likelihood.stride_px),
                "{w}x{h}"
            );
        }
        assert_eq!(edge_map_bytes(640, 480), 115_200);
    }

    /// Several hypotheses build their likelihood's edge map in the search's buffer: the same
    /// stride, so the same bytes.
    #[test]
    fn the_hypotheses_edge_map_fits_the_search_buffer() {
        for k in 1..=8u8 {
            let config = hypotheses_config(&configure(k, 3, [2, 1]));
            assert_eq!(config.count, k);
            assert_eq!(config.score_every_frames, 3);
            assert_eq!((config.sample_iterations, config.other_iterations), (2, 1));
            assert!(!config.keep_fingers);
            assert_eq!(config.likelihood.stride_px, SEARCH_STRIDE_PX);
            for (w, h) in [(640, 480), (320, 240), (161, 119)] {
                assert_eq!(
                    EdgeMap::bytes_needed(w, h, config.likelihood.stride_px),
                    edge_map_bytes(w, h),
                    "{w}x{h}"
                );
            }
        }
    }
}
