//! The debug overlay of the IC40's video generator, in colour: a frame dimmed to half, with the
//! back-projected model at a state, the slices the tracker searches at that state, the edge
//! points and fingertips the search found (colours: [`colours`], `docs/overlay.md`).
//!
//! The search drawn is core's own ([`find_link_features`] over every projected link, as
//! `core::measurement` runs it), so the overlay shows exactly what the tracker would measure
//! at `q` with `config`'s full window (the tracker's later iterations of a frame narrow it).

use anyhow::{bail, Result};
use digiteyes_core::camera::Camera;
use digiteyes_core::features::{find_link_features, FeatureConfig, LinkFeatures};
use digiteyes_core::frame::FrameView;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::Model;
use digiteyes_core::nalgebra::Vector2;
use digiteyes_core::projection::ProjectedModel;
use image::{GrayImage, Rgb, RgbImage};

/// The overlay's colours (RGB).
pub mod colours {
    use image::Rgb;

    /// A link's projected axis.
    pub const AXIS: Rgb<u8> = Rgb([255, 170, 0]);
    /// A link's two projected silhouette lines.
    pub const SILHOUETTE: Rgb<u8> = Rgb([0, 220, 255]);
    /// A search window along a slice (or beyond a tip) that was sampled.
    pub const SLICE: Rgb<u8> = Rgb([40, 70, 200]);
    /// A silhouette edge point found on a slice (a 3×3 px square).
    pub const EDGE: Rgb<u8> = Rgb([255, 40, 40]);
    /// A fingertip found beyond a distal link (a 7 px cross).
    pub const TIP: Rgb<u8> = Rgb([60, 255, 60]);
}

/// Draws the overlay of `model` at state `q` (model order: quaternion, mm, rad) as `camera`
/// sees it on `frame`, searched with `config`: an RGB copy of `frame` at half brightness with
/// the model's axes and silhouette lines, the search windows, the edge points and the
/// fingertips found. Fails (never panics) when `frame` is not `camera.width × camera.height`,
/// when `camera` is invalid, or when `q` has the wrong length or a NaN or infinite value.
pub fn draw_overlay(
    model: &Model,
    camera: &Camera,
    q: &[f32],
    frame: &GrayImage,
    config: &FeatureConfig,
) -> Result<RgbImage> {
    if frame.width() != camera.width || frame.height() != camera.height {
        bail!(
            "overlay: the frame is {}x{} px but the camera is calibrated for {}x{}",
            frame.width(),
            frame.height(),
            camera.width,
            camera.height
        );
    }
    if let Err(e) = camera.validate() {
        bail!("overlay: invalid camera: {e}");
    }
    if q.len() != model.n_states() {
        bail!(
            "overlay: the state has {} values but the model has {} states",
            q.len(),
            model.n_states()
        );
    }
    if let Some(i) = q.iter().position(|v| !v.is_finite()) {
        bail!("overlay: state q{i} is {}", q[i]);
    }
    let poses = match Poses::compute(model, q) {
        Ok(poses) => poses,
        Err(e) => bail!("overlay: unusable state: {e}"),
    };
    let view_frame = match FrameView::packed(
        frame.as_raw(),
        frame.width() as usize,
        frame.height() as usize,
    ) {
        Ok(v) => v,
        Err(e) => bail!("overlay: {e}"),
    };
    let mut projected = ProjectedModel::new();
    projected.update(model, &poses, camera, config.min_link_px);

    let mut canvas = Canvas::dimmed(frame);
    let mut found = Vec::with_capacity(projected.links.len());
    let mut features = LinkFeatures::default();
    for index in 0..projected.links.len() {
        find_link_features(
            &projected,
            camera,
            &view_frame,
            index,
            config,
            &mut features,
        );
        found.push(features.clone());
    }
    for link in &projected.links {
        let d = link.b - link.a;
        let len = d.norm();
        if len < 1e-3 {
            continue;
        }
        let normal = Vector2::new(-d.y, d.x) / len;
        for (k, sign) in [(0, 1.0), (1, -1.0)] {
            let a = link.a + normal * (sign * link.r0[k]);
            let b = link.b + normal * (sign * link.r1[k]);
            canvas.line(a, b, colours::SILHOUETTE);
        }
        canvas.line(link.a, link.b, colours::AXIS);
    }
    for features in &found {
        for edge in &features.edges {
            canvas.square(edge.position, 1, colours::EDGE);
        }
    }
    for features in &found {
        if let Some(tip) = features.tip {
            canvas.cross(tip, 3, colours::TIP);
        }
    }
    Ok(canvas.image)
}

/// An RGB image with a clipped line and point painter. Coordinates are px with (0, 0) the
/// centre of the top-left pixel; a point paints the pixel it falls in.
struct Canvas {
    image: RgbImage,
}

impl Canvas {
    /// `frame` as grey RGB at half brightness.
    fn dimmed(frame: &GrayImage) -> Self {
        let mut image = RgbImage::new(frame.width(), frame.height());
        for (o, p) in image.pixels_mut().zip(frame.pixels()) {
            let g = p.0[0] / 2;
            *o = Rgb([g, g, g]);
        }
        Canvas { image }
    }

    /// The pixel containing `(x, y)`, when inside the image.
    fn plot(&mut self, x: f32, y: f32, colour: Rgb<u8>) {
        let (x, y) = (x + 0.5, y + 0.5);
        if !(x >= 0.0 && y >= 0.0) {
            return;
        }
        let (x, y) = (x as u32, y as u32);
        if x < self.image.width() && y < self.image.height() {
            self.image.put_pixel(x, y, colour);
        }
    }

    /// A line from `a` to `b` (px), clipped to the image first, then one sample per pixel
    /// step, so far-off or huge lines cost no more than one across the image.
    fn line(&mut self, a: Vector2<f32>, b: Vector2<f32>, colour: Rgb<u8>) {
        let Some((a, b)) = self.clip(a, b) else {
            return;
        };
        let d = b - a;
        let steps = d.x.abs().max(d.y.abs()).ceil() as usize + 1;
        for i in 0..=steps {
            let p = a + d * (i as f32 / steps as f32);
            self.plot(p.x, p.y, colour);
        }
    }

    /// Liang–Barsky: the part of segment `a`–`b` inside the image's pixel area
    /// `[−0.5, w − 0.5] × [−0.5, h − 0.5]`, or `None` when none is (or a coordinate is not
    /// finite).
    fn clip(&self, a: Vector2<f32>, b: Vector2<f32>) -> Option<(Vector2<f32>, Vector2<f32>)> {
        if !(a.x.is_finite() && a.y.is_finite() && b.x.is_finite() && b.y.is_finite()) {
            return None;
        }
        let (lo, hi_x, hi_y) = (
            -0.5,
            self.image.width() as f32 - 0.5,
            self.image.height() as f32 - 0.5,
        );
        let d = b - a;
        let (mut t0, mut t1) = (0.0f32, 1.0f32);
        for (p, q) in [
            (-d.x, a.x - lo),
            (d.x, hi_x - a.x),
            (-d.y, a.y - lo),
            (d.y, hi_y - a.y),
        ] {
            if p == 0.0 {
                if q < 0.0 {
                    return None;
                }
            } else {
                let r = q / p;
                if p < 0.0 {
                    t0 = t0.max(r);
                } else {
                    t1 = t1.min(r);
                }
            }
        }
        (t0 <= t1).then(|| (a + d * t0, a + d * t1))
    }

    /// A filled square of half-side `half` px centred on the pixel containing `p`.
    fn square(&mut self, p: Vector2<f32>, half: i32, colour: Rgb<u8>) {
        for dy in -half..=half {
            for dx in -half..=half {
                self.plot(p.x + dx as f32, p.y + dy as f32, colour);
            }
        }
    }

    /// A `+` of arm `arm` px centred on the pixel containing `p`.
    fn cross(&mut self, p: Vector2<f32>, arm: i32, colour: Rgb<u8>) {
        for k in -arm..=arm {
            self.plot(p.x + k as f32, p.y, colour);
            self.plot(p.x, p.y + k as f32, colour);
        }
    }
}
