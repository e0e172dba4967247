//! With one camera, the confirm phase after an acquisition also carries the accepted state
//! with its palm moved `FinderConfig::confirm_depth_share` of its distance farther from and
//! nearer to the camera. One camera sees the hand's depth only through its size, and a leaf
//! placed with the wrong finger pose is placed at the wrong depth. On these mono seeds, under
//! the search's and the tracker's defaults, a depth variant refined by Gauss–Newton over the
//! confirming frames scores above the accepted leaf and comes onto the hand; without the
//! variants the same acceptance is held off it.

use digiteyes_core::acquire::FinderConfig;

mod common;
use common::search::{self, acquire_mono, WITHIN_FRAMES};

/// The search's defaults without the confirm phase's depth variants.
fn without_depth_variants() -> FinderConfig {
    FinderConfig {
        confirm_depth_share: [0.0, 0.0],
        ..FinderConfig::default()
    }
}

#[test]
fn the_confirm_phase_finds_the_depth_one_camera_misjudged() {
    assert!(
        FinderConfig::default().confirm_depth_share[1] > 0.0,
        "one camera's confirm phase carries depth variants by default"
    );
    // Found under the defaults of stop 73 (the slice window at 16 px, the outermost share
    // 0.3) by the scan of this test's own bars (`tests/tests/mechanism_scan.rs`: two more
    // hypotheses carried, acquired within 30 frames only with them, the same acceptance,
    // ending nearer by half): 31517 of 31301-31700, and 31861, 31866, 31870, 32008 and 32305 of
    // 31701-32500; these are the first two. (Stop 72's 31461, found under the share 0.5, fails
    // these bars under 0.3; stop 69's 30377 and 30873, found under a 20 px window, are no
    // longer acquired within 30 frames with the variants; stop 68's 30193 and 30212 came onto
    // the hand without them.)
    for seed in [31517, 31861] {
        let with = acquire_mono(seed, FinderConfig::default());
        let without = acquire_mono(seed, without_depth_variants());
        assert_eq!(
            with.most_hypotheses,
            without.most_hypotheses + 2,
            "seed {seed}: the two depth variants carried while confirming"
        );
        let (held, errors) = (with.held, with.errors);
        let (held_without, errors_without) = (without.held, without.errors);
        search::print_runs(
            seed,
            &[
                ("with the variants", &errors),
                ("without them", &errors_without),
            ],
        );
        assert!(
            held.is_some(),
            "seed {seed}: with the depth variants the hand is acquired within {WITHIN_FRAMES} frames"
        );
        assert_eq!(
            held_without, None,
            "seed {seed}: without them the same acceptance stays off the hand"
        );
        assert!(with.accepted.is_some(), "seed {seed}: a leaf accepted");
        assert_eq!(
            with.accepted, without.accepted,
            "seed {seed}: the same acceptance, on the same frame"
        );
        let last = |e: &[Option<f32>]| e.last().copied().flatten().expect("claimed at the end");
        assert!(
            last(&errors) < 0.5 * last(&errors_without),
            "seed {seed}: the fingertips end nearer the hand by half"
        );
    }
}

/// While the confirm phase carries a hypothesis at a rival depth that ranks within
/// `FinderConfig::confirm_rival_margin` of the best, its frame is not claimed: one camera
/// weighs two depths alike, and either may be 100 mm off. Checked against an oracle of the
/// rule, frame by frame, on the hypotheses the tracker carried: the frames withheld are
/// exactly the confirm frames with such a rival, every other frame is claimed as with the rule
/// off, and the track is the same, bit for bit (the rule changes what is reported, not what
/// is tracked). On these seeds (of 31301-31700 under stop 72's defaults, the slice window at
/// 16 px, the rule withholds five frames or more on 23, `tests/tests/mechanism_scan.rs`;
/// these are the first two) the first claim moves from frame 6 to 11 on both. (Stop 69's
/// 30031 and 30311, found under a 20 px window, no longer accept a leaf within the run; on
/// stop 68's 20298 no frame is withheld.)
#[test]
fn a_confirm_frame_with_a_rival_depth_alike_is_not_claimed() {
    let finder = FinderConfig::default();
    assert!(
        finder.confirm_rival_mm(1, 1000.0).is_some(),
        "one camera's confirm phase looks for rival depths by default"
    );
    for seed in [31320, 31345] {
        let ruled = acquire_mono(seed, finder);
        let unruled = acquire_mono(
            seed,
            FinderConfig {
                confirm_rival_margin: -1.0,
                ..finder
            },
        );
        search::print_runs(
            seed,
            &[("ruled", &ruled.errors), ("unruled", &unruled.errors)],
        );
        let accepted = ruled.accepted.expect("a leaf accepted");
        assert_eq!(
            Some(accepted),
            unruled.accepted,
            "seed {seed}: the same acceptance"
        );
        assert_eq!(
            ruled.carried, unruled.carried,
            "seed {seed}: the same hypotheses"
        );
        // The oracle: the leaf is carried first on the frame it is accepted on.
        let leaf_depth_mm = ruled.carried[accepted][0].0;
        let apart_mm = finder
            .confirm_rival_mm(1, leaf_depth_mm)
            .expect("rivals looked for");
        let last = accepted + usize::from(finder.confirm_frames);
        let confirming = accepted + 1..=last;
        let mut withheld = 0;
        for (k, carried) in ruled.carried.iter().enumerate() {
            if k == last {
                // The phase's last frame drops its hypotheses to the configured count before
                // they can be seen here: it is claimed as unruled, or withheld.
                assert!(
                    ruled.errors[k].is_none() || ruled.errors[k] == unruled.errors[k],
                    "seed {seed} frame {k}: the phase's last frame"
                );
                continue;
            }
            let rival = confirming.contains(&k)
                && carried.split_first().is_some_and(|(best, others)| {
                    others.iter().any(|h| {
                        (h.0 - best.0).abs() >= apart_mm
                            && h.1 >= best.1 - finder.confirm_rival_margin
                    })
                });
            let expected = if rival { None } else { unruled.errors[k] };
            assert_eq!(
                ruled.errors[k], expected,
                "seed {seed} frame {k}: claimed unless a rival depth ranks alike (rival: {rival})"
            );
            withheld += usize::from(rival && unruled.errors[k].is_some());
        }
        assert!(withheld > 0, "seed {seed}: frames withheld");
    }
}

#[test]
fn a_depth_share_outside_zero_to_one_carries_no_variant() {
    let without = acquire_mono(30377, without_depth_variants());
    for share in [1.0, 1.5, -0.12, f32::NAN, f32::INFINITY] {
        let finder = FinderConfig {
            confirm_depth_share: [share, share],
            ..FinderConfig::default()
        };
        let at = acquire_mono(30377, finder);
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
