//! After an acquisition the tracker runs `FinderConfig::settle_frames` frames without its
//! prior on the palm's position. One camera sees the hand's depth only through its size, and
//! the prior would hold the palm at the depth the accepted leaf guessed, the fingers bending
//! to make up the size. On these mono seeds, under the search's and the tracker's defaults,
//! the same acceptance held by the prior never comes onto the hand; settling freely, it does.
//! The tracker's own configuration is untouched throughout.

use digiteyes_core::acquire::FinderConfig;

mod common;
use common::search::{self, acquire_mono, WITHIN_FRAMES};

/// The search's defaults with `settle_frames`.
fn settling(settle_frames: u8) -> FinderConfig {
    FinderConfig {
        settle_frames,
        ..FinderConfig::default()
    }
}

#[test]
fn an_acquisition_settles_onto_the_hand_without_the_position_prior() {
    // Found on seeds 30001-30600 under stop 69's defaults, each seed run as below with and
    // without settling and kept when it passes this test's own bars (acquired within 30
    // frames settling, held off the hand at 10 px with the prior, ending nearer by half):
    // 30168, 30270, 30461 and 30574; these are the first two. (Stop 68's 30012 and 30112 now
    // come onto the hand with the prior too.)
    for seed in [30168, 30270] {
        let settled = acquire_mono(seed, settling(FinderConfig::default().settle_frames));
        let (held, errors) = (settled.held, settled.errors);
        let with_prior = acquire_mono(seed, settling(0));
        let (held_with_prior, errors_with_prior) = (with_prior.held, with_prior.errors);
        search::print_runs(
            seed,
            &[
                ("settling", &errors),
                ("with the prior", &errors_with_prior),
            ],
        );
        assert!(
            held.is_some(),
            "seed {seed}: settling freely, the hand is acquired within {WITHIN_FRAMES} frames"
        );
        assert_eq!(
            held_with_prior, None,
            "seed {seed}: the same acceptance held by the prior stays off the hand"
        );
        let last = |e: &[Option<f32>]| e.last().copied().flatten().expect("claimed at the end");
        assert!(
            last(&errors) < 0.5 * last(&errors_with_prior),
            "seed {seed}: settled, the fingertips end nearer the hand by half"
        );
    }
}
