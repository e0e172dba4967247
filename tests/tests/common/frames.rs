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
