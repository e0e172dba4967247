//! A borrowed view of an 8-bit grey frame and bounds-checked sub-pixel sampling.

use core::fmt;

use nalgebra::Vector2;

/// An 8-bit grey image borrowed from a caller-owned buffer: row-major, top row first,
/// `stride` bytes from one row to the next. Pixel (0, 0) is the centre of the top-left pixel.
#[derive(Debug, Clone, Copy)]
pub struct FrameView<'a> {
    data: &'a [u8],
    width: usize,
    height: usize,
    stride: usize,
}

/// Why a buffer cannot be viewed as a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum FrameError {
    /// Width or height is zero.
    ZeroSize,
    /// The stride is smaller than the width.
    StrideTooSmall,
    /// The buffer holds fewer bytes than the frame needs.
    BufferTooSmall {
        /// Bytes needed.
        needed: usize,
        /// Bytes given.
        got: usize,
    },
    /// The frame is not the size the camera was calibrated for.
    WrongSize {
        /// Expected width (px).
        expected_width: u32,
        /// Expected height (px).
        expected_height: u32,
    },
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::ZeroSize => write!(f, "frame width and height must be positive"),
            Self::StrideTooSmall => write!(f, "frame stride is smaller than its width"),
            Self::BufferTooSmall { needed, got } => {
                write!(f, "frame buffer has {got} bytes, needs {needed}")
            }
            Self::WrongSize {
                expected_width,
                expected_height,
            } => write!(
                f,
                "frame size differs from the camera's {expected_width}x{expected_height}"
            ),
        }
    }
}

impl core::error::Error for FrameError {}

impl<'a> FrameView<'a> {
    /// Views `data` as a `width × height` frame whose rows start `stride` bytes apart.
    pub fn new(
        data: &'a [u8],
        width: usize,
        height: usize,
        stride: usize,
    ) -> Result<Self, FrameError> {
        if width == 0 || height == 0 {
            return Err(FrameError::ZeroSize);
        }
        if stride < width {
            return Err(FrameError::StrideTooSmall);
        }
        let needed = stride
            .checked_mul(height - 1)
            .and_then(|v| v.checked_add(width))
            .ok_or(FrameError::BufferTooSmall {
                needed: usize::MAX,
                got: data.len(),
            })?;
        if data.len() < needed {
            return Err(FrameError::BufferTooSmall {
                needed,
                got: data.len(),
            });
        }
        Ok(FrameView {
            data,
            width,
            height,
            stride,
        })
    }

    /// A tightly packed frame (`stride == width`).
    pub fn packed(data: &'a [u8], width: usize, height: usize) -> Result<Self, FrameError> {
        Self::new(data, width, height, width)
    }

    /// Width (px).
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height (px).
    pub fn height(&self) -> usize {
        self.height
    }

    /// Bytes between row starts.
    pub fn stride(&self) -> usize {
        self.stride
    }

    /// The pixel at column `x`, row `y`, if inside.
    pub fn pixel(&self, x: usize, y: usize) -> Option<u8> {
        if x < self.width && y < self.height {
            self.data.get(y * self.stride + x).copied()
        } else {
            None
        }
    }

    /// Bilinear intensity at sub-pixel `(x, y)`; `None` outside `[0, w−1] × [0, h−1]` or for
    /// non-finite coordinates.
    pub fn sample(&self, x: f32, y: f32) -> Option<f32> {
        if !(x >= 0.0 && y >= 0.0) {
            return None;
        }
        let (wmax, hmax) = ((self.width - 1) as f32, (self.height - 1) as f32);
        if !(x <= wmax && y <= hmax) {
            return None;
        }
        let x0 = (x as usize).min(self.width.saturating_sub(2));
        let y0 = (y as usize).min(self.height.saturating_sub(2));
        let fx = x - x0 as f32;
        let fy = y - y0 as f32;
        let x1 = (x0 + 1).min(self.width - 1);
        let y1 = (y0 + 1).min(self.height - 1);
        let at = |xx: usize, yy: usize| f32::from(self.data[yy * self.stride + xx]);
        let top = at(x0, y0) + (at(x1, y0) - at(x0, y0)) * fx;
        let bottom = at(x0, y1) + (at(x1, y1) - at(x0, y1)) * fx;
        Some(top + (bottom - top) * fy)
    }

    /// Samples `out.len()` points `start + k · step`, k = 0, 1, ... Returns false, leaving
    /// `out` partly written, if any point falls outside the frame.
    pub fn sample_segment(&self, start: Vector2<f32>, step: Vector2<f32>, out: &mut [f32]) -> bool {
        let n = out.len();
        if n == 0 {
            return true;
        }
        let end = start + step * (n - 1) as f32;
        let (wmax, hmax) = ((self.width - 1) as f32, (self.height - 1) as f32);
        let inside = |p: Vector2<f32>| p.x >= 0.0 && p.y >= 0.0 && p.x <= wmax && p.y <= hmax;
        if !(inside(start) && inside(end)) {
            return false;
        }
        if self.width < 2 || self.height < 2 {
            for (k, o) in out.iter_mut().enumerate() {
                let p = start + step * k as f32;
                match self.sample(p.x, p.y) {
                    Some(v) => *o = v,
                    None => return false,
                }
            }
            return true;
        }
        // Both ends are inside, so every point between is: the hot loop of the slice search
        // reads the 2×2 neighbourhood as two row pairs, with no per-point range checks.
        let (xmax, ymax) = (self.width - 2, self.height - 2);
        let (mut x, mut y) = (start.x, start.y);
        for o in out.iter_mut() {
            let x0 = (x as usize).min(xmax);
            let y0 = (y as usize).min(ymax);
            let (fx, fy) = (x - x0 as f32, y - y0 as f32);
            let i = y0 * self.stride + x0;
            let (Some(top), Some(bottom)) = (
                self.data.get(i..i + 2),
                self.data.get(i + self.stride..i + self.stride + 2),
            ) else {
                return false;
            };
            let (t0, t1) = (f32::from(top[0]), f32::from(top[1]));
            let (b0, b1) = (f32::from(bottom[0]), f32::from(bottom[1]));
            let upper = t0 + (t1 - t0) * fx;
            let lower = b0 + (b1 - b0) * fx;
            *o = upper + (lower - upper) * fy;
            x += step.x;
            y += step.y;
        }
        true
    }
}
