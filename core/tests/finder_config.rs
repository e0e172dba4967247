//! `FinderConfig`'s derived settings: which confirm-phase depth share applies to a rig, and
//! how many hypotheses the confirm phase may then carry, and how far its best may lie in depth
//! and be claimed.

use digiteyes_core::acquire::{FinderConfig, DEPTH_VARIANTS, HELD_VARIANTS};

fn with_shares(shared: f32, one_camera: f32) -> FinderConfig {
    FinderConfig {
        confirm_depth_share: [shared, one_camera],
        ..FinderConfig::default()
    }
}

#[test]
fn the_default_carries_depth_variants_with_one_camera_only() {
    let f = FinderConfig::default();
    assert_eq!(f.confirm_depth(1), Some(f.confirm_depth_share[1]));
    assert_eq!(f.confirm_depth(2), None);
    assert_eq!(f.confirm_depth(3), None);
    assert_eq!(
        f.confirm_capacity(1),
        f.confirm_hypotheses + DEPTH_VARIANTS + HELD_VARIANTS
    );
    assert_eq!(f.confirm_capacity(2), f.confirm_hypotheses);
}

#[test]
fn the_last_claimed_depth_takes_a_place_only_while_weighed() {
    assert!(FinderConfig::default().confirm_held_weight > 0.0);
    for weight in [0.0, -1.0, f32::NAN] {
        let f = FinderConfig {
            confirm_held_weight: weight,
            ..FinderConfig::default()
        };
        assert_eq!(
            f.confirm_capacity(1),
            f.confirm_hypotheses + DEPTH_VARIANTS,
            "weight {weight}"
        );
    }
}

#[test]
fn each_rig_takes_its_own_share() {
    let f = with_shares(0.05, 0.2);
    assert_eq!(f.confirm_depth(2), Some(0.05));
    assert_eq!(f.confirm_depth(1), Some(0.2));
    assert_eq!(f.confirm_depth(0), Some(0.2), "no camera reads as one");
}

#[test]
fn a_share_outside_zero_to_one_carries_no_variant() {
    for share in [
        0.0,
        -0.1,
        1.0,
        1.5,
        f32::NAN,
        f32::INFINITY,
        f32::NEG_INFINITY,
    ] {
        let f = with_shares(share, share);
        for n in [1, 2] {
            assert_eq!(f.confirm_depth(n), None, "share {share}, {n} cameras");
            assert_eq!(f.confirm_capacity(n), f.confirm_hypotheses, "share {share}");
        }
    }
}

#[test]
fn the_capacity_saturates_instead_of_overflowing() {
    let f = FinderConfig {
        confirm_hypotheses: u8::MAX,
        ..FinderConfig::default()
    };
    assert_eq!(f.confirm_capacity(1), u8::MAX);
}

#[test]
fn rival_depths_lie_a_share_of_the_variants_offset_apart() {
    let f = FinderConfig {
        confirm_rival_share: 0.5,
        confirm_rival_margin: 0.005,
        ..with_shares(0.0, 0.1)
    };
    let apart = f
        .confirm_rival_mm(1, 1000.0)
        .expect("one camera carries variants");
    assert!((apart - 50.0).abs() < 1e-3, "half of 10 % of 1 m: {apart}");
    assert_eq!(
        f.confirm_rival_mm(2, 1000.0),
        None,
        "no variants, no rivals"
    );
    for off in [0.0, -0.5, f32::NAN] {
        let share_off = FinderConfig {
            confirm_rival_share: off,
            ..f
        };
        assert_eq!(
            share_off.confirm_rival_mm(1, 1000.0),
            None,
            "share {off}: off"
        );
    }
    for off in [-0.001, f32::NAN] {
        let margin_off = FinderConfig {
            confirm_rival_margin: off,
            ..f
        };
        assert_eq!(
            margin_off.confirm_rival_mm(1, 1000.0),
            None,
            "margin {off}: off"
        );
    }
    let never_claimed = FinderConfig {
        confirm_rival_margin: f32::INFINITY,
        ..f
    };
    assert!(never_claimed.confirm_rival_mm(1, 1000.0).is_some());
}
