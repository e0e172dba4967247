//! The debug overlay of the IC40's video generator, in colour: a frame dimmed to half, with the
//! back-projected model at a state, the slices the tracker searches at that state, the edge
//! points and fingertips the search found (colours: [`colours`], `docs/overlay.md`).
//!
//! The search drawn is core's own
//! ([`find_link_features`](digiteyes_core::features::find_link_features) over every projected
//! link, as `core::measurement` runs it), so the overlay shows exactly what the tracker would
//! measure at `q` with `config`'s full window (the tracker's later iterations of a frame narrow
//! it).

use std::path::{Path, PathBuf};
use std::sync::mpsc::{sync_channel, SyncSender};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Context, Result};
use digiteyes_core::camera::Camera;
use digiteyes_core::features::{
    find_link_features_watched, FeatureConfig, LinkFeatures, SearchWindow, WindowOutcome,
};
use digiteyes_core::frame::FrameView;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::Model;
use digiteyes_core::nalgebra::Vector2;
use digiteyes_core::projection::ProjectedModel;
use image::{GrayImage, Rgb, RgbImage};

use crate::sequence::camera_dir_name;

/// The overlay's colours (RGB).
pub mod colours {
    use image::Rgb;

    /// A link's projected axis.
    pub const AXIS: Rgb<u8> = Rgb([255, 170, 0]);
    /// A link's two projected silhouette lines.
    pub const SILHOUETTE: Rgb<u8> = Rgb([0, 220, 255]);
    /// A search window along a slice (or beyond a tip) that was sampled.
    pub const SLICE: Rgb<u8> = Rgb([30, 55, 160]);
    /// A search window skipped because its predicted edge is hidden by a nearer part.
    pub const MASKED: Rgb<u8> = Rgb([120, 0, 120]);
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
    let mut windows: Vec<SearchWindow> = Vec::new();
    let mut features = LinkFeatures::default();
    for index in 0..projected.links.len() {
        find_link_features_watched(
            &projected,
            camera,
            &view_frame,
            index,
            config,
            &mut features,
            |w| windows.push(*w),
        );
        found.push(features.clone());
    }
    for w in &windows {
        let colour = match w.outcome {
            WindowOutcome::Masked => colours::MASKED,
            WindowOutcome::NoEdge | WindowOutcome::Found => colours::SLICE,
            WindowOutcome::OffFrame => continue,
        };
        let end = w.start + w.step * f32::from(w.samples.saturating_sub(1));
        canvas.line(w.start, end, colour);
    }
    for link in &projected.links {
        if link.length() < 1e-3 {
            continue;
        }
        for side in [1, -1] {
            let (a, b) = link.silhouette(side);
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

/// Where the overlay of frame `frame` of camera `cam` goes under `dir`:
/// `dir/cam{cam}/{frame:06}.png`, the sequence's frame naming with `.png`.
pub fn overlay_path(dir: &Path, cam: usize, frame: usize) -> PathBuf {
    dir.join(camera_dir_name(cam))
        .join(format!("{frame:06}.png"))
}

/// Overlay PNGs written on a thread of their own, so drawing and encoding overlap the
/// caller's work: the one background PNG writer (`track --overlay` hands it drawn images,
/// `sim --overlay` the board's tracked frames to draw, see [`crate::sim::overlay_tap`]).
/// Senders wait when `queue` jobs are pending; the first write failure stops the writer and is
/// returned by the next [`PngWriter::write`] or by [`PngWriter::finish`].
#[derive(Debug)]
pub struct PngWriter<J = (PathBuf, RgbImage)> {
    sender: Option<SyncSender<J>>,
    thread: Option<JoinHandle<Result<PngStats>>>,
}

/// What a [`PngWriter`] wrote.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PngStats {
    /// Files written.
    pub files: usize,
    /// Jobs that gave no image (each reported on stderr by whoever drew it).
    pub undrawable: usize,
    /// Time spent drawing, encoding and writing them, on the writer's thread (s).
    pub seconds: f64,
}

impl PngWriter {
    /// Starts the writer thread for images drawn by the caller, with room for `queue`
    /// pending images (at least 1).
    pub fn start(queue: usize) -> Result<Self> {
        Self::spawn(queue, None, Some)
    }
}

impl<J: Send + 'static> PngWriter<J> {
    /// Starts the writer thread with room for `queue` pending jobs (at least 1): `draw` turns
    /// each job into the image to write and its path, or `None` when it cannot (having said
    /// why on stderr). A write failure is also reported on stderr, after `failure` (for a
    /// writer fed by others, whose failure nobody may ask for until the end).
    pub fn drawing(
        queue: usize,
        failure: &'static str,
        draw: impl FnMut(J) -> Option<(PathBuf, RgbImage)> + Send + 'static,
    ) -> Result<Self> {
        Self::spawn(queue, Some(failure), draw)
    }

    fn spawn(
        queue: usize,
        failure: Option<&'static str>,
        mut draw: impl FnMut(J) -> Option<(PathBuf, RgbImage)> + Send + 'static,
    ) -> Result<Self> {
        let (sender, receiver) = sync_channel::<J>(queue.max(1));
        let thread = std::thread::Builder::new()
            .name("digiteyes-overlay-png".into())
            .spawn(move || {
                let mut stats = PngStats::default();
                let mut busy = Duration::ZERO;
                let mut made: Option<PathBuf> = None;
                for job in receiver {
                    let t0 = Instant::now();
                    match draw(job) {
                        Some((path, image)) => {
                            if let Err(e) = write_png(&path, &image, &mut made) {
                                if let Some(failure) = failure {
                                    eprintln!("{failure}: {e:#}");
                                }
                                return Err(e);
                            }
                            stats.files += 1;
                        }
                        None => stats.undrawable += 1,
                    }
                    busy += t0.elapsed();
                }
                stats.seconds = busy.as_secs_f64();
                Ok(stats)
            })
            .context("cannot start the overlay writer thread")?;
        Ok(PngWriter {
            sender: Some(sender),
            thread: Some(thread),
        })
    }

    /// Another way in for jobs (a frame tap's channel), while the writer runs.
    /// [`PngWriter::finish`] then also waits until every such sender is dropped.
    pub fn sender(&self) -> Option<SyncSender<J>> {
        self.sender.clone()
    }

    /// Queues `job` (its folder is created when written). Fails with the writer's error if
    /// an earlier write failed.
    pub fn write(&mut self, job: J) -> Result<()> {
        let sent = self.sender.as_ref().is_some_and(|s| s.send(job).is_ok());
        if sent {
            return Ok(());
        }
        // The writer stopped: its error says why.
        self.join()?;
        Err(anyhow!("the overlay writer stopped"))
    }

    /// Waits until every queued job is written (and every [`PngWriter::sender`] dropped);
    /// what was written, or the first failure.
    pub fn finish(mut self) -> Result<PngStats> {
        self.join()
    }

    fn join(&mut self) -> Result<PngStats> {
        self.sender = None;
        match self.thread.take() {
            Some(thread) => thread
                .join()
                .map_err(|_| anyhow!("the overlay writer panicked"))?,
            None => Err(anyhow!("the overlay writer has already stopped")),
        }
    }
}

/// Writes `image` to `path` as PNG, creating its folder unless it is `made` (the last one
/// created, updated).
pub(crate) fn write_png(path: &Path, image: &RgbImage, made: &mut Option<PathBuf>) -> Result<()> {
    if let Some(parent) = path.parent() {
        if made.as_deref() != Some(parent) {
            std::fs::create_dir_all(parent).with_context(|| {
                format!("cannot create the overlay folder {}", parent.display())
            })?;
            *made = Some(parent.to_path_buf());
        }
    }
    image
        .save_with_format(path, image::ImageFormat::Png)
        .with_context(|| format!("cannot write overlay {}", path.display()))
}

impl<J> Drop for PngWriter<J> {
    /// Waits for the queued jobs (so none is left half written) and for every
    /// [`PngWriter::sender`] to be dropped; errors are for `finish`.
    fn drop(&mut self) {
        self.sender = None;
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
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

    /// A line from `a` to `b` (px), clipped to the image first (in f64, so even a line from
    /// ±1e9 px is clipped to the pixel), then one sample per pixel step: far-off or huge lines
    /// cost no more than one across the image.
    fn line(&mut self, a: Vector2<f32>, b: Vector2<f32>, colour: Rgb<u8>) {
        let Some((a, b)) = self.clip(a.cast(), b.cast()) else {
            return;
        };
        let d = b - a;
        let steps = d.x.abs().max(d.y.abs()).ceil() as usize + 1;
        for i in 0..=steps {
            let p = a + d * (i as f64 / steps as f64);
            self.plot(p.x as f32, p.y as f32, colour);
        }
    }

    /// Liang–Barsky: the part of segment `a`–`b` inside the image's pixel area
    /// `[−0.5, w − 0.5] × [−0.5, h − 0.5]`, or `None` when none is (or a coordinate is not
    /// finite).
    fn clip(&self, a: Vector2<f64>, b: Vector2<f64>) -> Option<(Vector2<f64>, Vector2<f64>)> {
        if !(a.x.is_finite() && a.y.is_finite() && b.x.is_finite() && b.y.is_finite()) {
            return None;
        }
        let (lo, hi_x, hi_y) = (
            -0.5,
            f64::from(self.image.width()) - 0.5,
            f64::from(self.image.height()) - 0.5,
        );
        let d = b - a;
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::{RenderSettings, Renderer};
    use crate::sequence::Sequence;
    use crate::{render_scenario, RenderOptions};
    use digiteyes_core::features::find_link_features;

    /// Frame 0 of a small `fullhand-mono` render: the sequence, its true state and the frame.
    fn rendered() -> (tempfile::TempDir, Sequence, Vec<f32>, GrayImage) {
        let dir = tempfile::tempdir().unwrap();
        let opts = RenderOptions {
            frames: Some(1),
            size: Some((320, 240)),
            supersample: 2,
            ..RenderOptions::default()
        };
        render_scenario("fullhand-mono", dir.path(), &opts).unwrap();
        let sequence = Sequence::open(dir.path()).unwrap();
        let truth = sequence.read_truth().unwrap();
        let q: Vec<f32> = truth.rows[0].iter().map(|&v| v as f32).collect();
        let frame = sequence.read_frame(0, 0).unwrap();
        (dir, sequence, q, frame)
    }

    fn pixels_of(image: &RgbImage, colour: Rgb<u8>) -> Vec<Vector2<f32>> {
        image
            .enumerate_pixels()
            .filter(|(_, _, p)| **p == colour)
            .map(|(x, y, _)| Vector2::new(x as f32, y as f32))
            .collect()
    }

    fn projected(seq: &Sequence, q: &[f32], config: &FeatureConfig) -> ProjectedModel {
        let poses = Poses::compute(&seq.model, q).unwrap();
        let mut view = ProjectedModel::new();
        view.update(&seq.model, &poses, &seq.cameras[0], config.min_link_px);
        view
    }

    #[test]
    fn model_edges_and_tips_land_where_they_belong() {
        let (_dir, seq, q, frame) = rendered();
        let config = FeatureConfig::default();
        let camera = &seq.cameras[0];
        let image = draw_overlay(&seq.model, camera, &q, &frame, &config).unwrap();
        assert_eq!(image.dimensions(), frame.dimensions());
        let view = projected(&seq, &q, &config);

        // Every axis pixel lies on a projected link axis (within the pixel's half-diagonal).
        let axis = pixels_of(&image, colours::AXIS);
        assert!(axis.len() > 100, "{} axis pixels", axis.len());
        for p in &axis {
            let d = view
                .links
                .iter()
                .map(|l| l.closest(p).1)
                .fold(f32::INFINITY, f32::min);
            assert!(d <= 0.75, "axis pixel {p:?} is {d} px from every axis");
        }
        // And the axes are drawn: most points along each one are painted in the axis colour
        // (edge points and tips may cover a few).
        let (mut on, mut all) = (0, 0);
        for l in &view.links {
            for k in 0..=20 {
                let p = l.a + (l.b - l.a) * (k as f32 / 20.0);
                let (x, y) = ((p.x + 0.5) as u32, (p.y + 0.5) as u32);
                if p.x >= 0.0 && p.y >= 0.0 && x < image.width() && y < image.height() {
                    all += 1;
                    on += usize::from(*image.get_pixel(x, y) == colours::AXIS);
                }
            }
        }
        assert!(on * 10 >= all * 8, "{on} of {all} axis samples painted");

        // The edge points found at the true state lie within 2 px of the true silhouette: the
        // renderer's coverage boundary, or (where a finger lies over the hand, which the
        // coverage does not outline) the link's own projected outline.
        let coverage = Renderer::new(&seq.model, camera, RenderSettings::default())
            .coverage(&q)
            .unwrap();
        let (w, h) = (camera.width as i64, camera.height as i64);
        let inside = |x: i64, y: i64| {
            x >= 0 && y >= 0 && x < w && y < h && coverage[(y * w + x) as usize] >= 0.5
        };
        let mut boundary = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let c = coverage[(y * w + x) as usize];
                let change = inside(x, y) != inside(x + 1, y) || inside(x, y) != inside(x, y + 1);
                if (c > 0.02 && c < 0.98) || change {
                    boundary.push(Vector2::new(x as f32, y as f32));
                }
            }
        }
        let frame_view = FrameView::packed(frame.as_raw(), w as usize, h as usize).unwrap();
        let mut features = LinkFeatures::default();
        let (mut points, mut tips, mut outline_only) = (Vec::new(), Vec::new(), 0);
        for (index, link) in view.links.iter().enumerate() {
            find_link_features(&view, camera, &frame_view, index, &config, &mut features);
            for e in &features.edges {
                let to_coverage = boundary
                    .iter()
                    .map(|b| (b - e.position).norm())
                    .fold(f32::INFINITY, f32::min);
                let normal = link.normal();
                let axis_point = link.a + (link.b - link.a) * e.s;
                let across = (e.position - axis_point).dot(&normal) * f32::from(e.side);
                let to_outline = (across - link.side_radius_at(e.s, e.side)).abs();
                assert!(
                    to_coverage <= 2.0 || to_outline <= 2.0,
                    "edge {:?} of link {index}: {to_coverage} px from the silhouette, \
                     {to_outline} px from its outline",
                    e.position
                );
                outline_only += usize::from(to_coverage > 2.0);
                points.push(e.position);
            }
            tips.extend(features.tip);
        }
        assert!(points.len() > 20, "{} edge points", points.len());
        assert!(
            outline_only * 4 < points.len(),
            "{outline_only} edges inside the hand"
        );
        // Each is drawn as a 3×3 square of the edge colour (unless a tip cross covers it) and
        // every edge-coloured pixel belongs to one.
        let edge_pixels = pixels_of(&image, colours::EDGE);
        assert!(
            edge_pixels.len() > 5 * points.len(),
            "{}",
            edge_pixels.len()
        );
        let pixel = |p: &Vector2<f32>| ((p.x + 0.5).floor(), (p.y + 0.5).floor());
        for p in &edge_pixels {
            assert!(
                points.iter().any(|e| {
                    let (x, y) = pixel(e);
                    (x - p.x).abs() <= 1.0 && (y - p.y).abs() <= 1.0
                }),
                "edge-coloured pixel {p:?} is not at an edge point"
            );
        }

        // The slices searched are drawn, and the fingertips found are crosses centred on
        // them.
        assert!(pixels_of(&image, colours::SLICE).len() > 200);
        assert!(
            tips.len() >= 3,
            "{} fingertips found at the true state",
            tips.len()
        );
        for t in &tips {
            let (x, y) = pixel(t);
            if x >= 0.0 && y >= 0.0 && x < w as f32 && y < h as f32 {
                assert_eq!(
                    *image.get_pixel(x as u32, y as u32),
                    colours::TIP,
                    "tip {t:?}"
                );
            }
        }
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        let model = Model::hand().unwrap();
        let camera = Camera {
            width: 64,
            height: 48,
            fx: 100.0,
            fy: 100.0,
            cx: 31.5,
            cy: 23.5,
            r: digiteyes_core::nalgebra::Matrix3::identity(),
            t: digiteyes_core::nalgebra::Vector3::new(0.0, 0.0, 500.0),
        };
        let config = FeatureConfig::default();
        let mut q = vec![0.0f32; model.n_states()];
        q[0] = 1.0;
        let frame = GrayImage::new(64, 48);
        let image = draw_overlay(&model, &camera, &q, &frame, &config).unwrap();
        assert_eq!(image.dimensions(), (64, 48));

        let wrong = GrayImage::new(65, 48);
        let e = draw_overlay(&model, &camera, &q, &wrong, &config).unwrap_err();
        assert!(e.to_string().contains("65x48"), "{e}");
        let e = draw_overlay(&model, &camera, &q[..7], &frame, &config).unwrap_err();
        assert!(e.to_string().contains("7 values"), "{e}");
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            let mut q = q.clone();
            q[9] = bad;
            let e = draw_overlay(&model, &camera, &q, &frame, &config).unwrap_err();
            assert!(e.to_string().contains("q9"), "{e}");
        }
        let mut zero = q.clone();
        zero[..4].fill(0.0);
        assert!(draw_overlay(&model, &camera, &zero, &frame, &config).is_err());
    }

    #[test]
    fn lines_are_clipped_to_the_image() {
        let mut canvas = Canvas::dimmed(&GrayImage::from_pixel(10, 8, image::Luma([100])));
        assert_eq!(*canvas.image.get_pixel(0, 0), Rgb([50, 50, 50]));
        // A huge line across the image paints only its part inside, quickly.
        canvas.line(
            Vector2::new(-1e9, 3.0),
            Vector2::new(1e9, 3.0),
            colours::AXIS,
        );
        for x in 0..10 {
            assert_eq!(*canvas.image.get_pixel(x, 3), colours::AXIS);
        }
        assert_eq!(pixels_of(&canvas.image, colours::AXIS).len(), 10);
        // Lines wholly outside, or not finite, paint nothing.
        canvas.line(
            Vector2::new(-5.0, -5.0),
            Vector2::new(20.0, -3.0),
            colours::EDGE,
        );
        canvas.line(
            Vector2::new(f32::NAN, 1.0),
            Vector2::new(5.0, 1.0),
            colours::EDGE,
        );
        canvas.square(Vector2::new(-3.0, -3.0), 1, colours::EDGE);
        assert!(pixels_of(&canvas.image, colours::EDGE).is_empty());
        // A diagonal has no gaps.
        canvas.line(Vector2::new(0.0, 0.0), Vector2::new(7.0, 7.0), colours::TIP);
        for k in 0..8 {
            assert_eq!(*canvas.image.get_pixel(k, k), colours::TIP);
        }
    }
}
