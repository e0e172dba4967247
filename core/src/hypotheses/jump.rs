//! Kinematic jumps: a finger's other reading that the cameras see nearly alike.
//!
//! One camera sees a link's direction only up to its depth: turned towards the camera or as
//! far away from it, a link projects almost the same (the front/back flip of a finger). A
//! Gauss–Newton track that took the wrong side keeps it, and when the finger then moves, the
//! two readings part in the image and the track loses the finger. A jump proposes the other
//! side: one joint of the finger (the *pivot*) turned to the other angle at which its link's
//! far end projects where it did, then each joint after it turned so that its own link's end
//! projects where it did. The finger's outline stays nearly in place, its depth changes.
//! Refined and scored like any other hypothesis, the jump is kept when the image prefers it.
//!
//! The angles are found by a grid over each joint's range (the jump is a discrete choice;
//! Gauss–Newton refines the result on the frame).

use heapless::Vec;
use nalgebra::Vector3;

use super::fingers::{Fingers, MAX_FINGERS};
use crate::camera::Camera;
use crate::config::{MAX_JUMPS, MAX_LINKS, MAX_STATES};
use crate::float::Length;
use crate::kinematics::{row_transform, Pose, Poses};
use crate::model::{Model, Shape, Theta};

/// Angles tried over a joint's range.
const GRID_STEPS: usize = 48;

/// Two frame origins closer than this are one point (mm): a joint whose frame has no length
/// moves the next point that is not at its own origin.
const SAME_POINT_MM: f32 = 0.5;

/// One jump: a whole state, which finger it moved, and how far its points moved in the image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jump {
    /// The state after the jump (the other states as given).
    pub state: [f32; MAX_STATES],
    /// The finger jumped.
    pub finger: u8,
    /// The pivot's joint state.
    pub pivot: u8,
    /// The mean distance, over the finger's link ends and the cameras that see them, between
    /// where each projected before and after the jump (px).
    pub moved_px: f32,
    /// How far the finger's link ends moved in the world, summed (mm).
    pub moved_mm: f32,
}

/// One finger as a chain of frames from its first joint's frame to its tip.
struct Chain {
    /// Frames, root first.
    frames: Vec<u8, MAX_LINKS>,
    /// `joints[i]`: the joint state turning `frames[i]`, if any.
    joints: Vec<Option<u8>, MAX_LINKS>,
}

impl Chain {
    /// Finger `finger` of `model`, from the frame of its first joint state down its single line
    /// of children; `None` for a finger with no joint or that branches.
    fn of(model: &Model, fingers: &Fingers, finger: usize) -> Option<Chain> {
        let first = (0..model.n_states()).find(|&s| fingers.contains(finger, s))?;
        let mut frame = model.joint_frame(first)?;
        let mut chain = Chain {
            frames: Vec::new(),
            joints: Vec::new(),
        };
        loop {
            let link = model.links().get(frame)?;
            chain.frames.push(frame as u8).ok()?;
            let joint = match link.theta {
                Theta::State(s) => Some(s),
                _ => None,
            };
            chain.joints.push(joint).ok()?;
            match link.children.as_slice() {
                [] => return Some(chain),
                [child] => frame = usize::from(*child),
                _ => return None,
            }
        }
    }
}

/// The jumps of every finger of the hand at `q`, the least moved in the image first. For each
/// finger, of the pivots whose jump turns the pivot by at least `min_turn_rad` and moves the
/// finger's link ends at most `max_moved_px` in the image, the one that moves them furthest
/// in the world: the other reading of the finger, not a small change of one link. At most
/// [`MAX_JUMPS`] and `count`.
#[allow(clippy::too_many_arguments)]
#[inline(never)] // a stage of the hypotheses' loop: kept whole so profiles can attribute it
pub fn finger_jumps(
    model: &Model,
    cameras: &[Camera],
    fingers: &Fingers,
    q: &[f32],
    min_turn_rad: f32,
    max_moved_px: f32,
    count: usize,
) -> Vec<Jump, MAX_JUMPS> {
    let mut out: Vec<Jump, MAX_FINGERS> = Vec::new();
    let n = model.n_states().min(MAX_STATES);
    if count == 0 || q.len() != n || cameras.is_empty() {
        return Vec::new();
    }
    let Ok(poses) = Poses::compute(model, q) else {
        return Vec::new();
    };
    for finger in 0..fingers.count() {
        let Some(chain) = Chain::of(model, fingers, finger) else {
            continue;
        };
        let mut best: Option<Jump> = None;
        for (i, joint) in chain.joints.iter().enumerate() {
            let Some(pivot) = *joint else { continue };
            let turns_a_link = chain
                .frames
                .get(i)
                .and_then(|&f| model.links().get(usize::from(f)))
                .is_some_and(|l| matches!(l.shape, Shape::Cylinder { .. }));
            if !turns_a_link {
                continue;
            }
            let Some(jump) = jump_at(
                model,
                cameras,
                &poses,
                &chain,
                q,
                i,
                pivot,
                min_turn_rad,
                finger,
            ) else {
                continue;
            };
            if jump.moved_px <= max_moved_px && best.is_none_or(|b| jump.moved_mm > b.moved_mm) {
                best = Some(jump);
            }
        }
        if let Some(jump) = best {
            let _ = out.push(jump);
        }
    }
    out.sort_unstable_by(|a, b| a.moved_px.total_cmp(&b.moved_px));
    out.into_iter().take(count.min(MAX_JUMPS)).collect()
}

/// The jump of `chain` at its `pivot_index`-th frame (joint state `pivot`).
#[allow(clippy::too_many_arguments)]
fn jump_at(
    model: &Model,
    cameras: &[Camera],
    poses: &Poses,
    chain: &Chain,
    q: &[f32],
    pivot_index: usize,
    pivot: u8,
    min_turn_rad: f32,
    finger: usize,
) -> Option<Jump> {
    // The world poses of the chain's frames before the jump, and its points' projections.
    let mut world: Vec<Pose, MAX_LINKS> = Vec::new();
    for &f in &chain.frames {
        world.push(*poses.frame(usize::from(f))?).ok()?;
    }
    let mut state = [0.0f32; MAX_STATES];
    state[..q.len()].copy_from_slice(q);
    let before = world.clone();
    for i in pivot_index..chain.frames.len() {
        let Some(joint) = chain.joints[i] else {
            continue;
        };
        // The first point beyond frame i's origin: what turning joint i moves.
        let origin = world[i].t;
        let Some(target_index) =
            (i + 1..chain.frames.len()).find(|&k| (before[k].t - origin).length() > SAME_POINT_MM)
        else {
            // A pivot that moves no point cannot jump; a later joint that moves none keeps
            // its angle.
            if i == pivot_index {
                return None;
            }
            continue;
        };
        let target = before[target_index].t;
        let limit = model.limit(usize::from(joint))?;
        let now = state[usize::from(joint)];
        let mut chosen: Option<(f32, f32)> = None;
        for step in 0..=GRID_STEPS {
            let theta = limit.lo + (limit.hi - limit.lo) * step as f32 / GRID_STEPS as f32;
            if i == pivot_index && libm::fabsf(theta - now) < min_turn_rad {
                continue;
            }
            state[usize::from(joint)] = theta;
            let point = point_after(model, chain, &world, &state, i, target_index)?;
            let Some(d) = image_distance(cameras, &point, &target) else {
                continue;
            };
            if chosen.is_none_or(|(_, best)| d < best) {
                chosen = Some((theta, d));
            }
        }
        let (theta, _) = chosen?;
        state[usize::from(joint)] = theta;
        // The frames after i follow the new angle.
        for k in i + 1..chain.frames.len() {
            let parent = model.links().get(usize::from(chain.frames[k - 1]))?;
            world[k] = world[k - 1].compose(&row_transform(parent, &state));
        }
    }
    let mut moved_sum = 0.0f32;
    let mut moved_count = 0u32;
    let mut moved_mm = 0.0f32;
    for (after, was) in world.iter().zip(&before).skip(pivot_index + 1) {
        moved_mm += (after.t - was.t).length();
        if let Some(d) = image_distance(cameras, &after.t, &was.t) {
            moved_sum += d;
            moved_count += 1;
        }
    }
    if moved_count == 0 {
        return None;
    }
    Some(Jump {
        state,
        finger: finger as u8,
        pivot,
        moved_px: moved_sum / moved_count as f32,
        moved_mm,
    })
}

/// Where frame `target_index`'s origin lies with `state`, the frames up to `i` as in `world`.
fn point_after(
    model: &Model,
    chain: &Chain,
    world: &[Pose],
    state: &[f32],
    i: usize,
    target_index: usize,
) -> Option<Vector3<f32>> {
    let mut pose = *world.get(i)?;
    for k in i + 1..=target_index {
        let parent = model.links().get(usize::from(*chain.frames.get(k - 1)?))?;
        pose = pose.compose(&row_transform(parent, state));
    }
    Some(pose.t)
}

/// The mean over `cameras` of the image distance between `a` and `b` (px); `None` when no
/// camera projects both.
fn image_distance(cameras: &[Camera], a: &Vector3<f32>, b: &Vector3<f32>) -> Option<f32> {
    let mut sum = 0.0f32;
    let mut count = 0u32;
    for camera in cameras {
        if let (Some(pa), Some(pb)) = (camera.project(a), camera.project(b)) {
            sum += (pa - pb).length();
            count += 1;
        }
    }
    (count > 0).then(|| sum / count as f32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::BASE_STATES;

    /// The joint states of the chain used.
    fn chain_joints(
        model: &Model,
        fingers: &Fingers,
        finger: usize,
    ) -> Vec<u8, { crate::config::MAX_CHAIN }> {
        Chain::of(model, fingers, finger)
            .map(|c| c.joints.iter().flatten().copied().collect())
            .unwrap_or_default()
    }

    /// The middle finger's MCP flexion (state) and the frames at the ends of its first link.
    const MCP: usize = 12;
    const KNUCKLE_FRAME: usize = 11;
    const PIP_FRAME: usize = 12;

    fn hand_at(mcp: f32) -> (Model, [f32; 28]) {
        let model = Model::hand().unwrap();
        let mut q = [0.0f32; 28];
        q[0] = 1.0;
        q[MCP] = mcp;
        (model, q)
    }

    /// A camera on the line through the PIP knuckle at `a` and at `b` MCP flexion: both
    /// project to the same pixel, the two readings one camera cannot tell apart.
    fn camera_along(model: &Model, q: &[f32], a: f32, b: f32, distance_mm: f32) -> Camera {
        let mut qa = [0.0f32; 28];
        qa.copy_from_slice(q);
        qa[MCP] = a;
        let pa = Poses::compute(model, &qa)
            .unwrap()
            .origin(PIP_FRAME)
            .unwrap();
        qa[MCP] = b;
        let pb = Poses::compute(model, &qa)
            .unwrap()
            .origin(PIP_FRAME)
            .unwrap();
        let along = (pa - pb).normalized();
        let eye = pa + along * distance_mm;
        let up = if along.z.abs() < 0.9 {
            Vector3::z()
        } else {
            Vector3::y()
        };
        Camera::looking_along(eye, -along, up, (640, 480), 800.0).unwrap()
    }

    fn middle_finger_jump(cameras: &[Camera], q: &[f32]) -> Option<Jump> {
        let model = Model::hand().unwrap();
        let fingers = Fingers::of(&model);
        finger_jumps(&model, cameras, &fingers, q, 0.3, 4.0, MAX_JUMPS)
            .into_iter()
            .find(|j| j.finger == 1)
    }

    #[test]
    fn each_finger_chain_holds_its_own_joints_in_order() {
        let model = Model::hand().unwrap();
        let fingers = Fingers::of(&model);
        for f in 0..fingers.count() {
            let joints = chain_joints(&model, &fingers, f);
            let own: Vec<u8, { crate::config::MAX_CHAIN }> = (BASE_STATES..model.n_states())
                .filter(|&s| fingers.contains(f, s))
                .map(|s| s as u8)
                .collect();
            assert_eq!(joints.as_slice(), own.as_slice(), "finger {f}");
        }
    }

    #[test]
    fn a_link_seen_along_its_two_readings_jumps_to_the_other() {
        let (model, q) = hand_at(0.3);
        let camera = camera_along(&model, &q, 0.3, 1.1, 1500.0);
        let jump = middle_finger_jump(&[camera], &q).expect("the middle finger jumps");
        assert_eq!(usize::from(jump.pivot), MCP);
        assert!(
            (jump.state[MCP] - 1.1).abs() < 0.06,
            "MCP {} (the other reading is 1.1)",
            jump.state[MCP]
        );
        assert!(jump.moved_px < 4.0, "moved {} px", jump.moved_px);
        // The finger's depth changed: its PIP knuckle is elsewhere in the world.
        let before = Poses::compute(&model, &q)
            .unwrap()
            .origin(PIP_FRAME)
            .unwrap();
        let after = Poses::compute(&model, &jump.state[..28]).unwrap();
        assert!((after.origin(PIP_FRAME).unwrap() - before).length() > 15.0);
        // Only the middle finger's joints moved.
        for (s, (after, was)) in jump.state.iter().zip(&q).enumerate() {
            if !(MCP..=MCP + 2).contains(&s) {
                assert_eq!(after, was, "state {s}");
            }
        }
        assert!(after.origin(KNUCKLE_FRAME).unwrap() == before_knuckle(&model, &q));
    }

    fn before_knuckle(model: &Model, q: &[f32]) -> Vector3<f32> {
        Poses::compute(model, q)
            .unwrap()
            .origin(KNUCKLE_FRAME)
            .unwrap()
    }

    #[test]
    fn a_second_camera_across_the_flexion_rules_the_jump_out() {
        let (model, q) = hand_at(0.3);
        let along = camera_along(&model, &q, 0.3, 1.1, 1500.0);
        assert!(middle_finger_jump(&[along], &q).is_some());
        // Looking across the finger's flexion plane (along the MCP's axis), every flexion
        // projects differently.
        let poses = Poses::compute(&model, &q).unwrap();
        let knuckle = poses.origin(KNUCKLE_FRAME).unwrap();
        let axis = poses.frame(KNUCKLE_FRAME).unwrap().r.column(2).into_owned();
        let across = Camera::looking_along(
            knuckle + axis * 500.0,
            -axis,
            Vector3::z(),
            (640, 480),
            800.0,
        )
        .unwrap();
        assert!(middle_finger_jump(&[across], &q).is_none());
        assert!(middle_finger_jump(&[along, across], &q).is_none());
    }

    #[test]
    fn a_state_of_the_wrong_length_or_no_camera_gives_no_jump() {
        let (model, q) = hand_at(0.3);
        let fingers = Fingers::of(&model);
        let camera = camera_along(&model, &q, 0.3, 1.1, 1500.0);
        assert!(finger_jumps(&model, &[camera], &fingers, &q[..20], 0.3, 4.0, 2).is_empty());
        assert!(finger_jumps(&model, &[], &fingers, &q, 0.3, 4.0, 2).is_empty());
        let mut bad = q;
        bad[MCP] = f32::NAN;
        assert!(finger_jumps(&model, &[camera], &fingers, &bad, 0.3, 4.0, 2).is_empty());
        assert!(finger_jumps(&model, &[camera], &fingers, &q, 0.3, 4.0, 0).is_empty());
    }
}
