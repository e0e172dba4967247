//! The small library of finger configurations the search tries (after Stenger et al.'s
//! tree of hand shapes): open, relaxed, spread, half curl, fist, pointing, pinch, and the
//! mid-range pose every joint swings about.

use crate::config::MAX_STATES;
use crate::estimator::FreeMask;

/// Finger poses of the library: (abduction, MCP, PIP, DIP) for fingers 1–4 (the thumb's
/// five states follow in [`THUMB_POSES`]).
const FINGER_POSES: [[[f32; 4]; 4]; POSE_COUNT] = [
    [[0.0, 0.0, 0.0, 0.0]; 4], // open
    [[0.0, 0.3, 0.4, 0.2]; 4], // relaxed
    [
        [-0.25, 0.0, 0.0, 0.0],
        [-0.08, 0.0, 0.0, 0.0],
        [0.08, 0.0, 0.0, 0.0],
        [0.25, 0.0, 0.0, 0.0],
    ], // spread
    [[0.0, 0.7, 0.9, 0.5]; 4], // half curl
    [[0.0, 1.3, 1.5, 0.9]; 4], // fist
    [
        [0.0, 0.0, 0.0, 0.0],
        [0.0, 1.3, 1.5, 0.9],
        [0.0, 1.3, 1.5, 0.9],
        [0.0, 1.3, 1.5, 0.9],
    ], // pointing
    [
        [0.0, 0.6, 0.8, 0.4],
        [0.0, 0.3, 0.4, 0.2],
        [0.0, 0.3, 0.4, 0.2],
        [0.0, 0.3, 0.4, 0.2],
    ], // pinch
    [[0.0, 0.7, 0.8, 0.6]; 4], // mid-range: every joint halfway
];

/// The thumb's states (q23..q27) for each pose of [`FINGER_POSES`].
const THUMB_POSES: [[f32; 5]; POSE_COUNT] = [
    [0.0; 5],
    [0.0, 0.1, 0.2, 0.2, 0.2],
    [0.0, 0.3, 0.0, 0.0, 0.0],
    [0.0, 0.2, 0.4, 0.5, 0.3],
    [0.0, 0.4, 0.6, 0.8, 0.5],
    [0.0, 0.4, 0.6, 0.8, 0.5],
    [0.0, 0.3, 0.5, 0.6, 0.4],
    [0.4, -0.15, 0.0, -0.4, -0.55],
];

/// Poses in the library.
pub const POSE_COUNT: usize = 8;

/// The library's poses, by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum FingerPose {
    /// Every joint straight.
    Open = 0,
    /// A light curl.
    Relaxed = 1,
    /// Straight and spread.
    Spread = 2,
    /// Half curled.
    HalfCurl = 3,
    /// Curled into the palm.
    Fist = 4,
    /// The index straight, the others curled.
    Pointing = 5,
    /// The index curled toward the thumb.
    Pinch = 6,
    /// Every joint halfway through its range.
    MidRange = 7,
}

/// First state of finger `f` (0..4: fingers 1–4, then the thumb).
pub(crate) const fn finger_start(f: usize) -> usize {
    7 + 4 * f
}

/// Fingers the library poses: fingers 1–4 and the thumb.
pub const FINGERS: usize = 5;

/// Sets the free states of finger `finger` (0..4: fingers 1–4; 4: the thumb) of `q` (the
/// first `n_states`) to their values in library pose `pose`; the other fingers kept.
pub(crate) fn set_finger(
    q: &mut [f32; MAX_STATES],
    pose: usize,
    finger: usize,
    n_states: usize,
    free: FreeMask,
) {
    let values: &[f32] = match (FINGER_POSES.get(pose), THUMB_POSES.get(pose)) {
        (Some(fingers), _) if finger < 4 => &fingers[finger],
        (_, Some(thumb)) if finger == 4 => thumb,
        _ => return,
    };
    for (k, v) in values.iter().enumerate() {
        let s = finger_start(finger) + k;
        if s < n_states && free.contains(s) {
            if let Some(d) = q.get_mut(s) {
                *d = *v;
            }
        }
    }
}

/// Sets the free finger states of `q` (the first `n_states`) to library pose `pose`.
pub(crate) fn set_fingers(q: &mut [f32; MAX_STATES], pose: usize, n_states: usize, free: FreeMask) {
    let Some(fingers) = FINGER_POSES.get(pose) else {
        return;
    };
    let mut set = |s: usize, v: f32| {
        if s < n_states && free.contains(s) {
            if let Some(d) = q.get_mut(s) {
                *d = v;
            }
        }
    };
    for (f, values) in fingers.iter().enumerate() {
        for (k, v) in values.iter().enumerate() {
            set(finger_start(f) + k, *v);
        }
    }
    if let Some(thumb) = THUMB_POSES.get(pose) {
        for (k, v) in thumb.iter().enumerate() {
            set(finger_start(4) + k, *v);
        }
    }
}
