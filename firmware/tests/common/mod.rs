//! Test doubles for the board: an in-memory serial port, a clock, a camera, and a crude
//! renderer that fills the projected capsules of the hand model.
#![allow(dead_code)]

use std::collections::VecDeque;
use std::convert::Infallible;

use digiteyes_core::camera::Camera;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::Model;
use digiteyes_core::nalgebra::{Matrix3, Vector2, Vector3};
use digiteyes_core::projection::ProjectedModel;
use digiteyes_core::protocol::{
    encode, BoardMessage, Decoder, FrameChunk, HostMessage, MAX_CHUNK, MAX_MESSAGE,
};
use digiteyes_firmware::{
    edge_map_bytes, Board, Buffers, Clock, FrameSource, NoLed, SourceError, Uploads,
};

pub const WIDTH: u32 = 160;
pub const HEIGHT: u32 = 120;

/// Bytes the host sent (the board reads them) and bytes the board wrote.
#[derive(Default)]
pub struct Pipe {
    pub to_board: VecDeque<u8>,
    pub from_board: Vec<u8>,
}

impl embedded_io::ErrorType for Pipe {
    type Error = Infallible;
}

impl embedded_io::Read for Pipe {
    fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
        let n = buf.len().min(self.to_board.len());
        for b in buf.iter_mut().take(n) {
            *b = self.to_board.pop_front().unwrap_or(0);
        }
        Ok(n)
    }
}

impl embedded_io::ReadReady for Pipe {
    fn read_ready(&mut self) -> Result<bool, Infallible> {
        Ok(!self.to_board.is_empty())
    }
}

impl embedded_io::Write for Pipe {
    fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
        self.from_board.extend_from_slice(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> Result<(), Infallible> {
        Ok(())
    }
}

impl Pipe {
    pub fn send(&mut self, message: &HostMessage<'_>) {
        let mut buf = [0u8; MAX_MESSAGE];
        self.to_board.extend(encode(message, &mut buf).unwrap());
    }

    /// Sends a frame as chunks of at most `MAX_CHUNK` bytes.
    pub fn send_frame(&mut self, frame: u32, width: u16, height: u16, pixels: &[u8]) {
        for (i, data) in pixels.chunks(MAX_CHUNK).enumerate() {
            self.send(&HostMessage::FrameChunk(FrameChunk {
                frame,
                width,
                height,
                offset: (i * MAX_CHUNK) as u32,
                data,
            }));
        }
    }

    /// Every message the board wrote since the last call.
    pub fn received(&mut self) -> Vec<BoardMessage> {
        let mut rx = Decoder::<MAX_MESSAGE>::new();
        let bytes = std::mem::take(&mut self.from_board);
        let mut rest = &bytes[..];
        let mut out = Vec::new();
        while !rest.is_empty() {
            let (used, m) = rx.feed::<BoardMessage>(rest);
            if let Some(m) = m {
                out.push(m.expect("the board writes only good frames"));
            }
            rest = &rest[used..];
        }
        out
    }
}

/// A clock that advances 10 ticks per reading.
#[derive(Default)]
pub struct StepClock(pub u64);

impl Clock for StepClock {
    fn ticks(&mut self) -> u64 {
        self.0 += 10;
        self.0
    }

    fn hz(&self) -> u32 {
        1_000_000
    }
}

/// A camera that yields the given frames once each, numbered from 100.
pub struct Frames {
    pub frames: VecDeque<Vec<u8>>,
    pub next: u32,
}

impl FrameSource for Frames {
    fn poll_frame(
        &mut self,
        frame: &mut [u8],
        width: u16,
        height: u16,
    ) -> Result<Option<u32>, SourceError> {
        let Some(f) = self.frames.pop_front() else {
            return Ok(None);
        };
        if f.len() != usize::from(width) * usize::from(height) || frame.len() != f.len() {
            return Err(SourceError::Format);
        }
        frame.copy_from_slice(&f);
        self.next += 1;
        Ok(Some(self.next + 99))
    }
}

/// A camera 420 mm above the palm looking down at it.
pub fn camera() -> Camera {
    let eye = Vector3::new(40.0f32, -60.0, 420.0);
    let target = Vector3::new(40.0f32, -20.0, 0.0);
    let z = (target - eye).normalize();
    let x = z.cross(&Vector3::new(0.0, 1.0, 0.0)).normalize();
    let y = z.cross(&x);
    let r = Matrix3::from_rows(&[x.transpose(), y.transpose(), z.transpose()]);
    Camera {
        width: WIDTH,
        height: HEIGHT,
        fx: 250.0,
        fy: 250.0,
        cx: (WIDTH as f32 - 1.0) / 2.0,
        // The fingers point up the image: the palm sits low so the fingertips are in view.
        cy: (HEIGHT as f32 - 1.0) / 2.0 + 30.0,
        r,
        t: -(r * eye),
    }
}

/// The hand at rest with finger joints bent by `bend` (rad).
pub fn pose(model: &Model, bend: f32) -> Vec<f32> {
    let mut q = vec![0.0f32; model.n_states()];
    q[0] = 1.0;
    for (i, v) in q.iter_mut().enumerate().skip(7) {
        if let Some(limit) = model.limit(i) {
            *v = (bend).clamp(limit.lo, limit.hi);
        }
    }
    q
}

/// Bright capsules on a dark background: every pixel within a link's projected radius of its
/// projected axis.
pub fn render(model: &Model, camera: &Camera, q: &[f32]) -> Vec<u8> {
    let poses = Poses::compute(model, q).unwrap();
    let mut view = ProjectedModel::new();
    view.update(model, &poses, camera, 0.5);
    let mut img = vec![20u8; (camera.width * camera.height) as usize];
    for y in 0..camera.height {
        for x in 0..camera.width {
            let p = Vector2::new(x as f32, y as f32);
            let inside = view.links.iter().any(|l| {
                let (s, d) = l.closest(&p);
                d.abs() <= l.radius_at(s)
            });
            if inside {
                img[(y * camera.width + x) as usize] = 200;
            }
        }
    }
    img
}

/// A board on the in-memory port, taking uploaded frames, with a step clock.
pub type TestBoard<'m> = Board<'m, Pipe, Uploads, NoLed, StepClock>;

/// A board's memory: `frame` and `overlay`, and an edge map for [`WIDTH`] × [`HEIGHT`] frames
/// (leaked: a test's few kilobytes, as long-lived as a board's `static`).
pub fn buffers<'m>(frame: &'m mut [u8], overlay: Option<&'m mut [u8]>) -> Buffers<'m> {
    let edge_map = vec![0u8; edge_map_bytes(WIDTH as usize, HEIGHT as usize)];
    Buffers {
        frame,
        overlay,
        edge_map: Box::leak(edge_map.into_boxed_slice()),
    }
}

/// A [`TestBoard`] named `name` with frame buffer `buffer` (not yet started).
pub fn test_board<'m>(name: &'static str, buffer: &'m mut [u8]) -> TestBoard<'m> {
    Board::new(
        name,
        buffers(buffer, None),
        Pipe::default(),
        Uploads,
        NoLed,
        StepClock(0),
    )
}
