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
