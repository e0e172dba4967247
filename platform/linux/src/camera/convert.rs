//! Camera pixels to the tracker's 8-bit grey: packed rows of `width` bytes, top row first.
//!
//! V4L2 buffers may pad every row (`bytes_per_line` ≥ the row's bytes); the conversions take
//! that stride and write packed rows.

use std::fmt;

/// The pixel layouts a camera may deliver that the board can use, in order of preference.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PixelLayout {
    /// `GREY`: one 8-bit luma byte per pixel.
    Grey,
    /// `YUYV` (4:2:2): `Y0 U Y1 V` for every two pixels; the Y bytes are the grey image.
    Yuyv,
    /// `MJPG`/`JPEG`: each buffer is one JPEG image, decoded to luma.
    Jpeg,
}

impl PixelLayout {
    /// The layout of a V4L2 fourcc, if the board can use it.
    pub fn from_fourcc(fourcc: [u8; 4]) -> Option<Self> {
        match &fourcc {
            b"GREY" => Some(PixelLayout::Grey),
            b"YUYV" => Some(PixelLayout::Yuyv),
            b"MJPG" | b"JPEG" => Some(PixelLayout::Jpeg),
            _ => None,
        }
    }

    /// Bytes of one pixel in a row (0 for compressed layouts).
    pub fn bytes_per_pixel(self) -> usize {
        match self {
            PixelLayout::Grey => 1,
            PixelLayout::Yuyv => 2,
            PixelLayout::Jpeg => 0,
        }
    }
}

/// A camera buffer that does not hold the frame it should.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ConvertError {
    /// The buffer is shorter than `height` rows of `stride` bytes (the last row may be
    /// unpadded).
    ShortBuffer {
        /// Bytes needed.
        needed: usize,
        /// Bytes in the buffer.
        got: usize,
    },
    /// The stride is shorter than one row of pixels.
    BadStride {
        /// Bytes per row given.
        stride: usize,
        /// Bytes one row of pixels takes.
        row: usize,
    },
    /// The output is not `width × height` bytes.
    OutputSize {
        /// Bytes needed.
        needed: usize,
        /// Bytes given.
        got: usize,
    },
    /// The JPEG did not decode.
    Jpeg(String),
    /// The decoded JPEG is not the expected size.
    JpegSize {
        /// Its width and height (px).
        got: (u32, u32),
        /// The camera's (px).
        expected: (u32, u32),
    },
}

impl fmt::Display for ConvertError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::ShortBuffer { needed, got } => {
                write!(
                    f,
                    "camera buffer holds {got} bytes, the frame needs {needed}"
                )
            }
            Self::BadStride { stride, row } => {
                write!(
                    f,
                    "row stride {stride} bytes is shorter than a row ({row} bytes)"
                )
            }
            Self::OutputSize { needed, got } => {
                write!(f, "frame buffer is {got} bytes, the frame is {needed}")
            }
            Self::Jpeg(e) => write!(f, "MJPEG frame does not decode: {e}"),
            Self::JpegSize { got, expected } => write!(
                f,
                "MJPEG frame is {}x{} px, the camera was set to {}x{}",
                got.0, got.1, expected.0, expected.1
            ),
        }
    }
}

impl std::error::Error for ConvertError {}

/// Converts one camera buffer of `layout` (`width × height` px, rows `stride` bytes apart for
/// uncompressed layouts) into `out` (`width × height` bytes of packed grey).
pub fn to_grey(
    layout: PixelLayout,
    src: &[u8],
    width: usize,
    height: usize,
    stride: usize,
    out: &mut [u8],
) -> Result<(), ConvertError> {
    match layout {
        PixelLayout::Grey => grey_rows(src, width, height, stride, out, 1),
        PixelLayout::Yuyv => grey_rows(src, width, height, stride, out, 2),
        PixelLayout::Jpeg => jpeg_to_grey(src, width, height, out),
    }
}

/// Copies every `step`-th byte of each row, from the first: the luma of GREY (step 1) and of
/// YUYV (step 2).
fn grey_rows(
    src: &[u8],
    width: usize,
    height: usize,
    stride: usize,
    out: &mut [u8],
    step: usize,
) -> Result<(), ConvertError> {
    let needed_out = width * height;
    if out.len() != needed_out {
        return Err(ConvertError::OutputSize {
            needed: needed_out,
            got: out.len(),
        });
    }
    let row = width * step;
    if stride < row {
        return Err(ConvertError::BadStride { stride, row });
    }
    if height == 0 || width == 0 {
        return Ok(());
    }
    let needed = stride * (height - 1) + row;
    if src.len() < needed {
        return Err(ConvertError::ShortBuffer {
            needed,
            got: src.len(),
        });
    }
    for (dst, line) in out.chunks_exact_mut(width).zip(src.chunks(stride)) {
        if step == 1 {
            dst.copy_from_slice(&line[..width]);
        } else {
            for (d, pixel) in dst.iter_mut().zip(line.chunks_exact(step)) {
                *d = pixel[0];
            }
        }
    }
    Ok(())
}

/// Decodes a JPEG to luma. (V4L2 MJPEG frames may omit the Huffman tables; the decoder
/// falls back to the standard ones.)
fn jpeg_to_grey(
    src: &[u8],
    width: usize,
    height: usize,
    out: &mut [u8],
) -> Result<(), ConvertError> {
    if out.len() != width * height {
        return Err(ConvertError::OutputSize {
            needed: width * height,
            got: out.len(),
        });
    }
    let image = image::load_from_memory_with_format(src, image::ImageFormat::Jpeg)
        .map_err(|e| ConvertError::Jpeg(e.to_string()))?
        .into_luma8();
    let got = image.dimensions();
    let expected = (width as u32, height as u32);
    if got != expected {
        return Err(ConvertError::JpegSize { got, expected });
    }
    out.copy_from_slice(image.as_raw());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fourccs_map_to_layouts() {
        assert_eq!(PixelLayout::from_fourcc(*b"GREY"), Some(PixelLayout::Grey));
        assert_eq!(PixelLayout::from_fourcc(*b"YUYV"), Some(PixelLayout::Yuyv));
        assert_eq!(PixelLayout::from_fourcc(*b"MJPG"), Some(PixelLayout::Jpeg));
        assert_eq!(PixelLayout::from_fourcc(*b"RGB3"), None);
    }

    #[test]
    fn grey_rows_drop_the_padding() {
        // 3×2 px, rows padded to 5 bytes; the last row unpadded.
        let src = [1, 2, 3, 99, 99, 4, 5, 6];
        let mut out = [0u8; 6];
        to_grey(PixelLayout::Grey, &src, 3, 2, 5, &mut out).unwrap();
        assert_eq!(out, [1, 2, 3, 4, 5, 6]);
    }

    #[test]
    fn yuyv_keeps_the_luma_of_every_pixel() {
        // 4×2 px: Y0 U Y1 V Y2 U Y3 V, rows padded to 10 bytes.
        let src = [
            10, 128, 20, 129, 30, 130, 40, 131, 0, 0, //
            50, 132, 60, 133, 70, 134, 80, 135, 0, 0,
        ];
        let mut out = [0u8; 8];
        to_grey(PixelLayout::Yuyv, &src, 4, 2, 10, &mut out).unwrap();
        assert_eq!(out, [10, 20, 30, 40, 50, 60, 70, 80]);
    }

    #[test]
    fn short_buffers_and_strides_are_refused() {
        let mut out = [0u8; 8];
        assert_eq!(
            to_grey(PixelLayout::Yuyv, &[0; 10], 4, 2, 8, &mut out),
            Err(ConvertError::ShortBuffer {
                needed: 16,
                got: 10
            })
        );
        assert_eq!(
            to_grey(PixelLayout::Yuyv, &[0; 16], 4, 2, 6, &mut out),
            Err(ConvertError::BadStride { stride: 6, row: 8 })
        );
        assert!(matches!(
            to_grey(PixelLayout::Grey, &[0; 16], 4, 2, 4, &mut [0u8; 7]),
            Err(ConvertError::OutputSize { needed: 8, got: 7 })
        ));
    }

    /// A grey JPEG made here: a left-to-right ramp, 32×16 px.
    fn ramp_jpeg() -> (Vec<u8>, image::GrayImage) {
        let ramp = image::GrayImage::from_fn(32, 16, |x, _| image::Luma([(x * 8) as u8]));
        let mut jpeg = Vec::new();
        image::codecs::jpeg::JpegEncoder::new_with_quality(&mut jpeg, 95)
            .encode_image(&ramp)
            .unwrap();
        (jpeg, ramp)
    }

    #[test]
    fn mjpeg_frames_decode_to_grey() {
        let (jpeg, ramp) = ramp_jpeg();
        let mut out = vec![0u8; 32 * 16];
        to_grey(PixelLayout::Jpeg, &jpeg, 32, 16, 0, &mut out).unwrap();
        let worst = out
            .iter()
            .zip(ramp.as_raw())
            .map(|(&a, &b)| a.abs_diff(b))
            .max()
            .unwrap();
        assert!(worst <= 8, "JPEG luma off by {worst} grey levels");
    }

    #[test]
    fn bad_or_wrong_size_jpegs_are_refused() {
        let (jpeg, _) = ramp_jpeg();
        let mut out = vec![0u8; 16 * 16];
        assert_eq!(
            to_grey(PixelLayout::Jpeg, &jpeg, 16, 16, 0, &mut out),
            Err(ConvertError::JpegSize {
                got: (32, 16),
                expected: (16, 16)
            })
        );
        assert!(matches!(
            to_grey(PixelLayout::Jpeg, &jpeg[..40], 16, 16, 0, &mut out),
            Err(ConvertError::Jpeg(_))
        ));
    }
}
