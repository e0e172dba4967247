//! Where the board's frames come from: a V4L2 camera, or uploads over the link.

use digiteyes_firmware::{FrameSource, SourceError, Uploads};

use digiteyes_platform_linux::camera::V4l2Camera;

/// The board's frame source, chosen at start-up.
#[derive(Debug)]
pub enum Source {
    /// Frames arrive as `FrameChunk`s over the serial link (no camera).
    Uploads(Uploads),
    /// Frames come from a V4L2 camera.
    Camera(Box<V4l2Camera>),
}

impl FrameSource for Source {
    fn poll_frame(
        &mut self,
        frame: &mut [u8],
        width: u16,
        height: u16,
    ) -> Result<Option<u32>, SourceError> {
        match self {
            Source::Uploads(uploads) => uploads.poll_frame(frame, width, height),
            Source::Camera(camera) => camera.poll_frame(frame, width, height),
        }
    }
}
