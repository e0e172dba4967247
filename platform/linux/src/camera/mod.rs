//! The camera frame source: V4L2 capture and the conversion of its pixels to 8-bit grey.

mod convert;
mod v4l2;

pub use convert::{to_grey, ConvertError, PixelLayout};
pub use v4l2::{CameraError, V4l2Camera};
