//! A V4L2 camera (`/dev/videoN`) through the pure-Rust `linuxvideo` crate.
//!
//! Kept thin: open, pick a pixel layout the board can use (GREY, then YUYV, then MJPEG/JPEG),
//! negotiate the size, stream; each buffer goes through [`to_grey`](super::to_grey).

use std::fmt;
use std::io;
use std::path::{Path, PathBuf};

use digiteyes_firmware::{FrameSource, SourceError};
use linuxvideo::format::{PixFormat, PixelFormat};
use linuxvideo::stream::ReadStream;
use linuxvideo::{BufType, Device};

use super::convert::{to_grey, ConvertError, PixelLayout};

/// Why the camera cannot be used.
#[derive(Debug)]
pub enum CameraError {
    /// The device could not be opened or queried.
    Open {
        /// The device path.
        path: PathBuf,
        /// What the system said.
        source: io::Error,
    },
    /// The device offers none of GREY, YUYV, MJPG, JPEG.
    NoUsableFormat {
        /// The device path.
        path: PathBuf,
        /// The fourccs it offers.
        offered: Vec<String>,
    },
    /// The device would not deliver the size asked for.
    Size {
        /// The device path.
        path: PathBuf,
        /// Asked for (px).
        asked: (u32, u32),
        /// What the driver chose (px).
        got: (u32, u32),
    },
    /// Capturing failed.
    Capture {
        /// The device path.
        path: PathBuf,
        /// What the system said.
        source: io::Error,
    },
    /// A buffer did not convert.
    Convert {
        /// The device path.
        path: PathBuf,
        /// What was wrong with it.
        source: ConvertError,
    },
}

impl fmt::Display for CameraError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Open { path, source } => {
                write!(f, "cannot open camera {}: {source}", path.display())
            }
            Self::NoUsableFormat { path, offered } => write!(
                f,
                "camera {} offers no usable pixel format (it offers {}; the board reads GREY, \
                 YUYV, MJPG or JPEG)",
                path.display(),
                if offered.is_empty() {
                    "none".to_string()
                } else {
                    offered.join(", ")
                }
            ),
            Self::Size { path, asked, got } => write!(
                f,
                "camera {} gives {}x{} px, not the {}x{} asked for",
                path.display(),
                got.0,
                got.1,
                asked.0,
                asked.1
            ),
            Self::Capture { path, source } => {
                write!(f, "camera {}: capture failed: {source}", path.display())
            }
            Self::Convert { path, source } => write!(f, "camera {}: {source}", path.display()),
        }
    }
}

impl std::error::Error for CameraError {}

/// A streaming V4L2 capture delivering 8-bit grey frames.
pub struct V4l2Camera {
    path: PathBuf,
    stream: ReadStream,
    layout: PixelLayout,
    width: u32,
    height: u32,
    stride: usize,
    frames: u32,
}

impl fmt::Debug for V4l2Camera {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("V4l2Camera")
            .field("path", &self.path)
            .field("layout", &self.layout)
            .field("size", &(self.width, self.height))
            .finish()
    }
}

impl V4l2Camera {
    /// Opens `path` and starts streaming at `size` (px; `None`: the device's current size).
    pub fn open(path: &Path, size: Option<(u32, u32)>) -> Result<Self, CameraError> {
        let open_error = |source| CameraError::Open {
            path: path.to_path_buf(),
            source,
        };
        let device = Device::open(path).map_err(open_error)?;
        let mut offered = Vec::new();
        for desc in device.formats(BufType::VIDEO_CAPTURE) {
            offered.push(desc.map_err(open_error)?.pixel_format());
        }
        let preference = [PixelLayout::Grey, PixelLayout::Yuyv, PixelLayout::Jpeg];
        let Some((format, layout)) = preference.iter().find_map(|&want| {
            offered
                .iter()
                .find(|f| PixelLayout::from_fourcc(f.as_fourcc()) == Some(want))
                .map(|&f| (f, want))
        }) else {
            return Err(CameraError::NoUsableFormat {
                path: path.to_path_buf(),
                offered: offered.iter().map(|f| fourcc_text(*f)).collect(),
            });
        };
        let (width, height) = match size {
            Some(size) => size,
            None => match device.format(BufType::VIDEO_CAPTURE).map_err(open_error)? {
                linuxvideo::format::Format::VideoCapture(f) => (f.width(), f.height()),
                _ => (640, 480),
            },
        };
        let capture = device
            .video_capture(PixFormat::new(width, height, format))
            .map_err(open_error)?;
        let negotiated = capture.format();
        let got = (negotiated.width(), negotiated.height());
        if got != (width, height) {
            return Err(CameraError::Size {
                path: path.to_path_buf(),
                asked: (width, height),
                got,
            });
        }
        let stride =
            (negotiated.bytes_per_line() as usize).max(width as usize * layout.bytes_per_pixel());
        let stream = capture
            .into_stream()
            .map_err(|source| CameraError::Capture {
                path: path.to_path_buf(),
                source,
            })?;
        Ok(V4l2Camera {
            path: path.to_path_buf(),
            stream,
            layout,
            width,
            height,
            stride,
            frames: 0,
        })
    }

    /// The frame size (px).
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The pixel layout in use.
    pub fn layout(&self) -> PixelLayout {
        self.layout
    }

    /// Takes the next frame into `out` (`width × height` bytes) and returns its number
    /// (counting from 0). Waits for it when `wait`; otherwise `Ok(None)` if none is ready.
    pub fn capture(&mut self, out: &mut [u8], wait: bool) -> Result<Option<u32>, CameraError> {
        let capture_error = |source| CameraError::Capture {
            path: self.path.clone(),
            source,
        };
        if !wait && self.stream.will_block().map_err(capture_error)? {
            return Ok(None);
        }
        let (layout, w, h, stride) = (
            self.layout,
            self.width as usize,
            self.height as usize,
            self.stride,
        );
        let converted = self
            .stream
            .dequeue(|buf| Ok(to_grey(layout, &buf, w, h, stride, out)))
            .map_err(|source| CameraError::Capture {
                path: self.path.clone(),
                source,
            })?;
        converted.map_err(|source| CameraError::Convert {
            path: self.path.clone(),
            source,
        })?;
        let number = self.frames;
        self.frames = self.frames.wrapping_add(1);
        Ok(Some(number))
    }
}

impl FrameSource for V4l2Camera {
    fn poll_frame(
        &mut self,
        frame: &mut [u8],
        width: u16,
        height: u16,
    ) -> Result<Option<u32>, SourceError> {
        if (u32::from(width), u32::from(height)) != (self.width, self.height) {
            return Err(SourceError::Format);
        }
        let out = frame
            .get_mut(..usize::from(width) * usize::from(height))
            .ok_or(SourceError::Format)?;
        self.capture(out, false).map_err(|e| match e {
            CameraError::Convert { .. } => SourceError::Format,
            _ => SourceError::Device,
        })
    }
}

fn fourcc_text(format: PixelFormat) -> String {
    String::from_utf8_lossy(&format.as_fourcc()).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_camera_is_named() {
        let path = Path::new("/dev/video-digiteyes-missing");
        let err = V4l2Camera::open(path, Some((320, 240))).unwrap_err();
        assert!(matches!(err, CameraError::Open { .. }), "{err:?}");
        assert!(
            err.to_string().contains(&path.display().to_string()),
            "{err}"
        );
    }

    #[test]
    fn a_device_that_is_no_camera_is_refused_clearly() {
        // /dev/null opens, but answers no V4L2 query.
        let err = V4l2Camera::open(Path::new("/dev/null"), None).unwrap_err();
        assert!(err.to_string().contains("/dev/null"), "{err}");
    }

    #[test]
    fn no_usable_format_lists_what_the_camera_offers() {
        let err = CameraError::NoUsableFormat {
            path: PathBuf::from("/dev/video0"),
            offered: vec!["RGB3".into(), "BGR3".into()],
        };
        let text = err.to_string();
        assert!(
            text.contains("/dev/video0") && text.contains("RGB3") && text.contains("YUYV"),
            "{text}"
        );
    }
}
