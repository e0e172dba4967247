//! With one camera, the confirm phase after an acquisition also carries the accepted state
//! with its palm moved `FinderConfig::confirm_depth_share` of its distance farther from and
//! nearer to the camera. One camera sees the hand's depth only through its size, and a leaf
//! placed with the wrong finger pose is placed at the wrong depth: on these mono seeds the
//! accepted leaf's palm is 96 and 164 mm off the hand (`acquire_probe --trace`), its
//! fingertips over 10 px (at 320 wide) off, and none of the search's other leaves is better. A depth variant, refined by
//! Gauss–Newton over the confirming frames, scores above the accepted leaf and comes onto the
//! hand; without the variants the same acceptance is held off it.

use digiteyes_core::acquire::FinderConfig;

mod common;
use common::search::{self, acquire_mono, WITHIN_FRAMES};

/// The search's defaults with one camera's depth variants at `share`.
fn with_depth_share(share: f32) -> FinderConfig {
    FinderConfig {
        confirm_depth_share: [0.0, share],
        ..FinderConfig::default()
    }
}

/// The search's defaults without the confirm phase's depth variants.
fn without_depth_variants() -> FinderConfig {
    with_depth_share(0.0)
}

/// The share the mechanism is shown with: these seeds' leaves lie about 12 % of the camera's
/// distance off (96 and 164 mm). The default (0.08 since stop 55) was chosen on 3,600 fresh
/// seeds by the acquisitions it wins (`docs/recovery.md`, "The depth share again"); at 0.08
/// seed 4247 is acquired but its tips end at 11.9 px against 17.5 px without the variants.
const SHOWN_SHARE: f32 = 0.12;

#[test]
fn the_confirm_phase_finds_the_depth_one_camera_misjudged() {
    assert!(
        FinderConfig::default().confirm_depth_share[1] > 0.0,
        "one camera's confirm phase carries depth variants by default"
    );
    for seed in [4247, 4808] {
        let with = acquire_mono(seed, with_depth_share(SHOWN_SHARE));
        let without = acquire_mono(seed, without_depth_variants());
        assert_eq!(
            with.most_hypotheses,
            without.most_hypotheses + 2,
            "seed {seed}: the two depth variants carried while confirming"
        );
        let (held, errors) = (with.held, with.errors);
        let (held_without, errors_without) = (without.held, without.errors);
        println!(
            "seed {seed} with the variants: {}",
            search::format_errors(&errors)
        );
        println!(
            "seed {seed} without them: {}",
            search::format_errors(&errors_without)
        );
        assert!(
            held.is_some(),
            "seed {seed}: with the depth variants the hand is acquired within {WITHIN_FRAMES} frames"
        );
        assert_eq!(
            held_without, None,
            "seed {seed}: without them the same acceptance stays off the hand"
        );
        let first_claim = |e: &[Option<f32>]| e.iter().position(Option::is_some);
        assert_eq!(
            first_claim(&errors),
            first_claim(&errors_without),
            "seed {seed}: the same acceptance, on the same frame"
        );
        let last = |e: &[Option<f32>]| e.last().copied().flatten().expect("claimed at the end");
        assert!(
            last(&errors) < 0.5 * last(&errors_without),
            "seed {seed}: the fingertips end nearer the hand by half"
        );
    }
}

#[test]
fn a_depth_share_outside_zero_to_one_carries_no_variant() {
    let without = acquire_mono(4247, without_depth_variants());
    for share in [1.0, 1.5, -0.12, f32::NAN, f32::INFINITY] {
        let finder = FinderConfig {
            confirm_depth_share: [share, share],
            ..FinderConfig::default()
        };
        let at = acquire_mono(4247, finder);
        assert_eq!(
            at.most_hypotheses, without.most_hypotheses,
            "share {share}: no variant carried"
        );
        assert_eq!(at.held, without.held, "share {share}: the same acquisition");
        assert_eq!(
            at.errors, without.errors,
            "share {share}: every frame as without the variants, bit for bit"
        );
    }
}
