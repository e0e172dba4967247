//! What the search's tests set up alike: the base "from nothing" (every state free, the
//! identity palm at the origin), an acquirer and an auto tracker on it, and edge-map buffers.

use digiteyes_core::acquire::{AcquireConfig, Acquirer, WorkingVolume};
use digiteyes_core::auto_tracker::AutoTracker;
use digiteyes_core::camera::Camera;
use digiteyes_core::estimator::FreeMask;
use digiteyes_core::frame::FrameView;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::likelihood::{EdgeMap, LikelihoodConfig};
use digiteyes_core::model::{Model, Shape};
use digiteyes_core::tracker::TrackerConfig;
use digiteyes_host::sequence::Sequence;

/// The state searched from: the identity palm at the origin, joints at 0.
pub fn base(n_states: usize) -> Vec<f32> {
    let mut base = vec![0.0f32; n_states];
    base[0] = 1.0;
    base
}

/// An acquirer over every state of `sequence`, in the working volume its cameras see at
/// 600 mm.
pub fn acquirer(sequence: &Sequence, acquire: AcquireConfig) -> Acquirer {
    let free = FreeMask::all(sequence.n_states());
    let volume = WorkingVolume::from_cameras(&sequence.cameras, 600.0);
    Acquirer::new(
        &sequence.model,
        &base(sequence.n_states()),
        free,
        volume,
        acquire,
    )
}

/// The status machine of `track --init auto` on `sequence`, searching from the first frame,
/// with its edge-map buffers.
pub fn searching(sequence: &Sequence, acquire: AcquireConfig) -> (AutoTracker, Vec<Vec<u8>>) {
    searching_with(sequence, acquire, TrackerConfig::default())
}

/// [`searching`] with the tracker's parameters `tracker`.
pub fn searching_with(
    sequence: &Sequence,
    acquire: AcquireConfig,
    tracker: TrackerConfig,
) -> (AutoTracker, Vec<Vec<u8>>) {
    let auto = AutoTracker::new(
        sequence.model.clone(),
        &sequence.cameras,
        &base(sequence.n_states()),
        sequence.free_mask(),
        tracker,
        acquire,
    )
    .unwrap();
    (
        auto,
        buffers(&sequence.cameras, acquire.likelihood.stride_px),
    )
}

/// One edge-map buffer per camera at `stride_px`.
pub fn buffers(cameras: &[Camera], stride_px: u8) -> Vec<Vec<u8>> {
    cameras
        .iter()
        .map(|c| vec![0u8; EdgeMap::bytes_needed(c.width as usize, c.height as usize, stride_px)])
        .collect()
}

/// Each camera's edge map of `views` in its buffer of `buffers`.
pub fn edge_maps<'b>(
    buffers: &'b mut [Vec<u8>],
    views: &[FrameView<'_>],
    likelihood: &LikelihoodConfig,
) -> Vec<EdgeMap<'b>> {
    buffers
        .iter_mut()
        .zip(views)
        .map(|(b, v)| EdgeMap::build(b, v, likelihood).unwrap())
        .collect()
}

/// Mean fingertip distance (px) between states `a` and `b` over every camera.
pub fn tip_error_px(model: &Model, cameras: &[Camera], a: &[f32], b: &[f32]) -> f32 {
    let (pa, pb) = (
        Poses::compute(model, a).unwrap(),
        Poses::compute(model, b).unwrap(),
    );
    let tips =
        (0..model.links().len()).filter(|&i| matches!(model.links()[i].shape, Shape::Tip { .. }));
    let (mut sum, mut n) = (0.0f32, 0);
    for t in tips {
        for c in cameras {
            let (x, y) = (pa.origin(t).unwrap(), pb.origin(t).unwrap());
            sum += match (c.project(&x), c.project(&y)) {
                (Some(u), Some(v)) => (u - v).norm(),
                _ => 1e3,
            };
            n += 1;
        }
    }
    sum / n as f32
}
