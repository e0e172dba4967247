//! `FinderConfig`'s derived settings: which confirm-phase depth share applies to a rig, and
//! how many hypotheses the confirm phase may then carry.

use digiteyes_core::acquire::{FinderConfig, DEPTH_VARIANTS};

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
    assert_eq!(f.confirm_capacity(1), f.confirm_hypotheses + DEPTH_VARIANTS);
    assert_eq!(f.confirm_capacity(2), f.confirm_hypotheses);
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
