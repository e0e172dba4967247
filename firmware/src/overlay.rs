//! The back-projected model drawn over the frame, like the IC40's video generator.
//!
//! Each link in view is drawn as its axis (mid grey) and its two silhouette lines (white);
//! the frame's own pixels are dimmed to half so the lines stand out.

use digiteyes_core::camera::Camera;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::Model;
use digiteyes_core::nalgebra::Vector2;
use digiteyes_core::projection::ProjectedModel;

/// Grey level of the silhouette lines.
pub const EDGE_GREY: u8 = 255;
/// Grey level of the link axes.
pub const AXIS_GREY: u8 = 160;

/// Copies `frame` into `out` (both `camera.width × camera.height`, packed) at half brightness
/// and draws the model at state `q`. Returns the links drawn; 0 when the sizes do not match
/// or the state is unusable (then `out` holds only the dimmed frame, or is untouched).
pub fn draw(model: &Model, camera: &Camera, q: &[f32], frame: &[u8], out: &mut [u8]) -> usize {
    let width = camera.width as usize;
    let height = camera.height as usize;
    let n = width * height;
    let (Some(frame), Some(out)) = (frame.get(..n), out.get_mut(..n)) else {
        return 0;
    };
    for (o, &f) in out.iter_mut().zip(frame) {
        *o = f / 2;
    }
    let Ok(poses) = Poses::compute(model, q) else {
        return 0;
    };
    let mut view = ProjectedModel::new();
    view.update(model, &poses, camera, 1.0);
    let mut canvas = Canvas { out, width, height };
    for link in &view.links {
        if link.length() < 1e-3 {
            continue;
        }
        canvas.line(link.a, link.b, AXIS_GREY);
        for side in [1, -1] {
            let (a, b) = link.silhouette(side);
            canvas.line(a, b, EDGE_GREY);
        }
    }
    view.links.len()
}

struct Canvas<'a> {
    out: &'a mut [u8],
    width: usize,
    height: usize,
}

impl Canvas<'_> {
    /// A line from `a` to `b` (px), one sample per pixel step, clipped to the frame.
    fn line(&mut self, a: Vector2<f32>, b: Vector2<f32>, grey: u8) {
        let d = b - a;
        let steps = d.x.abs().max(d.y.abs());
        if !steps.is_finite() {
            return;
        }
        // Lines longer than the frame's perimeter are clipped by the pixel test anyway.
        let limit = 2.0 * (self.width + self.height) as f32;
        let steps = steps.min(limit) as usize + 1;
        for i in 0..=steps {
            let p = a + d * (i as f32 / steps as f32);
            self.plot(p.x, p.y, grey);
        }
    }

    fn plot(&mut self, x: f32, y: f32, grey: u8) {
        let (x, y) = (x + 0.5, y + 0.5);
        if x < 0.0 || y < 0.0 || x >= self.width as f32 || y >= self.height as f32 {
            return;
        }
        let i = y as usize * self.width + x as usize;
        if let Some(p) = self.out.get_mut(i) {
            *p = grey;
        }
    }
}
