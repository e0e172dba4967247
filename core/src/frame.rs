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

    /// Row `y`'s `width` pixels, if inside.
    #[inline]
    pub fn row(&self, y: usize) -> Option<&'a [u8]> {
        if y < self.height {
            let start = y * self.stride;
            self.data.get(start..start + self.width)
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

    /// The 3×3 Sobel gradient `[∂x, ∂y]` at pixel `(x, y)` (grey levels × 8 per px), or
    /// `None` where the stencil would leave the frame. Eight byte loads, no interpolation.
    pub fn sobel(&self, x: usize, y: usize) -> Option<[i32; 2]> {
        if x == 0
            || y == 0
            || x >= self.width.saturating_sub(1)
            || y >= self.height.saturating_sub(1)
        {
            return None;
        }
        let row = |yy: usize| -> Option<[i32; 3]> {
            let at = yy * self.stride + x;
            let r = self.data.get(at - 1..=at + 1)?;
            Some([i32::from(r[0]), i32::from(r[1]), i32::from(r[2])])
        };
        let (up, mid, down) = (row(y - 1)?, row(y)?, row(y + 1)?);
        let dx = (up[2] - up[0]) + 2 * (mid[2] - mid[0]) + (down[2] - down[0]);
        let dy = (down[0] - up[0]) + 2 * (down[1] - up[1]) + (down[2] - up[2]);
        Some([dx, dy])
    }

    /// [`FrameView::sample`] at a point.
    pub fn sample_vec(&self, p: Vector2<f32>) -> Option<f32> {
        self.sample(p.x, p.y)
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
        // Fixed point (16.16): the sample points are `p0 + k·step` exactly, so with both ends
        // inside every point is, and each sample is integer adds, four byte loads and a
        // bilinear blend. Falls back to `sample` per point for frames too large for 16.16.
        const ONE: f32 = 65536.0;
        if self.width > 0x7fff || self.height > 0x7fff {
            for (k, o) in out.iter_mut().enumerate() {
                let p = start + step * k as f32;
                match self.sample(p.x, p.y) {
                    Some(v) => *o = v,
                    None => return false,
                }
            }
            return true;
        }
        let (mut xi, mut yi) = ((start.x * ONE) as i32, (start.y * ONE) as i32);
        let (sx, sy) = ((step.x * ONE) as i32, (step.y * ONE) as i32);
        let last = (n - 1) as i64;
        let (xe, ye) = (
            i64::from(xi) + i64::from(sx) * last,
            i64::from(yi) + i64::from(sy) * last,
        );
        let (wl, hl) = (
            ((self.width - 1) as i64) << 16,
            ((self.height - 1) as i64) << 16,
        );
        if !((0..=wl).contains(&xe) && (0..=hl).contains(&ye)) {
            return false;
        }
        // Interior segments (the usual case: neither end on the last column or row) need no
        // clamping of the 2×2 neighbourhood; the border case clamps as `sample` does.
        let interior = xi.max(xe as i32) < wl as i32 && yi.max(ye as i32) < hl as i32;
        let stride = self.stride;
        if interior {
            // Integer blend with 8-bit weights (positions to 1/256 px): the value times 2¹⁶,
            // exact in i32 and in f32 (at most 255·2¹⁶ < 2²⁴).
            for o in out.iter_mut() {
                let (x0, y0) = (xi >> 16, yi >> 16);
                let fx = (xi >> 8) & 0xff;
                let fy = (yi >> 8) & 0xff;
                let i = y0 as usize * stride + x0 as usize;
                let quad = &self.data[i..i + stride + 2];
                let (a, b) = (i32::from(quad[0]), i32::from(quad[1]));
                let (c, d) = (i32::from(quad[stride]), i32::from(quad[stride + 1]));
                let top = (a << 8) + (b - a) * fx;
                let bottom = (c << 8) + (d - c) * fx;
                *o = ((top << 8) + (bottom - top) * fy) as f32 * (1.0 / ONE);
                xi += sx;
                yi += sy;
            }
            return true;
        }
        let (xmax0, ymax0) = (
            self.width.saturating_sub(2) as i32,
            self.height.saturating_sub(2) as i32,
        );
        let dx = usize::from(self.width > 1);
        let dy = if self.height > 1 { self.stride } else { 0 };
        for o in out.iter_mut() {
            let x0 = (xi >> 16).min(xmax0);
            let y0 = (yi >> 16).min(ymax0);
            let fx = (xi - (x0 << 16)) as f32 * (1.0 / ONE);
            let fy = (yi - (y0 << 16)) as f32 * (1.0 / ONE);
            let i = y0 as usize * self.stride + x0 as usize;
            let (r0, r1) = (&self.data[i..=i + dx], &self.data[i + dy..=i + dy + dx]);
            let (a, b) = (f32::from(r0[0]), f32::from(r0[dx]));
            let (c, d) = (f32::from(r1[0]), f32::from(r1[dx]));
            let top = a + (b - a) * fx;
            let bottom = c + (d - c) * fx;
            *o = top + (bottom - top) * fy;
            xi += sx;
            yi += sy;
        }
        true
    }
}
