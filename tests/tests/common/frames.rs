//! A rendered sequence's frames as the core takes them.

use digiteyes_core::frame::FrameView;
use digiteyes_host::sequence::Sequence;
use image::GrayImage;

/// Every camera's frame `k` of `sequence`.
pub fn images(sequence: &Sequence, k: usize) -> Vec<GrayImage> {
    (0..sequence.cameras.len())
        .map(|c| sequence.read_frame(c, k).unwrap())
        .collect()
}

/// The core's views of `images`.
pub fn views(images: &[GrayImage]) -> Vec<FrameView<'_>> {
    images
        .iter()
        .map(|i| FrameView::packed(i.as_raw(), i.width() as usize, i.height() as usize).unwrap())
        .collect()
}

/// Every frame's true state of `sequence`, as the core takes states (f32).
pub fn truth_states(sequence: &Sequence) -> Vec<Vec<f32>> {
    let truth = sequence.read_truth().unwrap();
    truth
        .rows
        .iter()
        .map(|row| row.iter().map(|&v| v as f32).collect())
        .collect()
}

/// A plain tracker for `sequence` started at `start` (its first frame's true state, say),
/// estimating the sequence's free states under `config`.
pub fn tracker_at(
    sequence: &Sequence,
    start: &[f32],
    config: digiteyes_core::tracker::TrackerConfig,
) -> digiteyes_core::tracker::Tracker {
    digiteyes_core::tracker::Tracker::new(
        sequence.model.clone(),
        &sequence.cameras,
        start,
        sequence.free_mask(),
        config,
    )
    .unwrap()
}

/// A tracker of every state of `model` seen by `camera` alone, started at `start` under
/// `config`, after `frames` frames of the still `truth` (each rendered with its own noise).
pub fn track_still(
    renderer: &digiteyes_host::render::Renderer,
    model: &digiteyes_core::model::Model,
    camera: digiteyes_core::camera::Camera,
    (truth, start): (&[f32], &[f32]),
    config: digiteyes_core::tracker::TrackerConfig,
    frames: usize,
) -> digiteyes_core::tracker::Tracker {
    let mut tracker = digiteyes_core::tracker::Tracker::new(
        model.clone(),
        &[camera],
        start,
        digiteyes_core::estimator::FreeMask::all(model.n_states()),
        config,
    )
    .unwrap();
    for k in 0..frames {
        let image = renderer.render(truth, k as u64).unwrap();
        tracker.track(&views(std::slice::from_ref(&image))).unwrap();
    }
    tracker
}
