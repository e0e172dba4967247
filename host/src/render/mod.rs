//! The project's synthetic renderer: the hand model seen by a calibrated camera.
//!
//! Every pixel is ray-cast against the capsules of the `cyl` links and the palm box (exact
//! occlusion: the nearest hit wins), shaded Lambertian with a light near the camera plus
//! ambient ([`Lighting`]) — one matte grey unless a [`Surface`] gives the parts their own
//! greys, a highlight and cast shadows — over a dark or cluttered background. Each pixel
//! averages `supersample × supersample` rays spread evenly over its square (pixel `(x, y)`
//! covers `u ∈ [x − ½, x + ½]`, `v ∈ [y − ½, y + ½]`), so silhouettes are sub-pixel accurate.
//! Optional Gaussian blur and noise follow. Rays are cast only inside each primitive's
//! projected bounding rectangle, and rows are shared among threads.

pub mod background;
pub mod filter;
pub mod hand_free;
pub mod intersect;
pub mod lighting;
pub mod scene;
pub mod shapes;
pub mod surface;

use std::sync::Mutex;

use intersect::Hit;

use anyhow::Result;
use digiteyes_core::camera::Camera;
use digiteyes_core::config::MAX_LINKS;
use digiteyes_core::model::Model;
use image::GrayImage;
use nalgebra::Vector3;

pub use background::{Background, PLAIN_GREY};
pub use lighting::{Lighting, ALBEDO, AMBIENT, LIGHT};
pub use scene::Scene;
pub use shapes::{world_shapes, WorldShape};
pub use surface::Surface;

/// How frames are rendered (besides the hand's state and the camera).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderSettings {
    /// Rays per pixel along each axis (`3` → 9 rays per pixel); at least 1.
    pub supersample: u32,
    /// Standard deviation of the additive Gaussian noise (grey levels); 0 for none.
    pub noise_sigma: f32,
    /// Standard deviation of the Gaussian blur (px); 0 for none.
    pub blur_sigma: f32,
    /// What lies behind the hand.
    pub background: Background,
    /// How the hand is lit.
    pub lighting: Lighting,
    /// What the hand's surface does with the light (matte and even by default).
    pub surface: Surface,
    /// Worker threads; 0 uses every available core.
    pub threads: usize,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            supersample: 3,
            noise_sigma: 0.0,
            blur_sigma: 0.0,
            background: Background::default(),
            lighting: Lighting::default(),
            surface: Surface::default(),
            threads: 0,
        }
    }
}

/// Renders frames of one camera; the background is drawn once and reused.
#[derive(Debug, Clone)]
pub struct Renderer {
    model: Model,
    camera: Camera,
    settings: RenderSettings,
    background: Vec<f32>,
}

/// What a ray contributes to its pixel.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Mode {
    /// Shaded hand over the background.
    Shaded,
    /// 1 on the hand, 0 elsewhere: the fraction of each pixel the hand covers.
    Coverage,
}

impl Renderer {
    /// A renderer of `model` seen by `camera`.
    pub fn new(model: &Model, camera: &Camera, settings: RenderSettings) -> Self {
        let background = background::background_image(
            camera.width as usize,
            camera.height as usize,
            settings.background,
        );
        Renderer {
            model: model.clone(),
            camera: *camera,
            settings,
            background,
        }
    }

    /// The camera rendered for.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// The frame at states `q` (quaternion, mm, rad); `noise_seed` draws the noise.
    pub fn render(&self, q: &[f32], noise_seed: u64) -> Result<GrayImage> {
        let (w, h) = self.size();
        let mut img = self.background.clone();
        self.cast(q, Mode::Shaded, &mut img)?;
        filter::gaussian_blur(&mut img, w, h, self.settings.blur_sigma);
        filter::add_noise(&mut img, self.settings.noise_sigma, noise_seed);
        Ok(filter::quantise(&img, w, h))
    }

    /// The frame without the hand: the background, blurred and with noise drawn from
    /// `noise_seed` exactly as [`Renderer::render`] draws it.
    pub fn render_empty(&self, noise_seed: u64) -> GrayImage {
        let (w, h) = self.size();
        let mut img = self.background.clone();
        filter::gaussian_blur(&mut img, w, h, self.settings.blur_sigma);
        filter::add_noise(&mut img, self.settings.noise_sigma, noise_seed);
        filter::quantise(&img, w, h)
    }

    /// The fraction (0–1) of each pixel covered by the hand at states `q`, row-major.
    pub fn coverage(&self, q: &[f32]) -> Result<Vec<f32>> {
        let (w, h) = self.size();
        let mut img = vec![0.0; w * h];
        self.cast(q, Mode::Coverage, &mut img)?;
        Ok(img)
    }

    fn size(&self) -> (usize, usize) {
        (self.camera.width as usize, self.camera.height as usize)
    }

    /// Ray-casts the hand into `img`, which holds what lies behind it.
    fn cast(&self, q: &[f32], mode: Mode, img: &mut [f32]) -> Result<()> {
        let scene = Scene::build(&self.model, &self.camera, q)?;
        if scene.placed.is_empty() {
            return Ok(());
        }
        let (w, h) = self.size();
        const ROWS_PER_JOB: usize = 8;
        let jobs = Mutex::new(img.chunks_mut(w * ROWS_PER_JOB).enumerate());
        let threads = match self.settings.threads {
            0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
            n => n,
        }
        .min(h.div_ceil(ROWS_PER_JOB));
        let raster = Raster::new(&self.camera, &self.settings, mode);
        std::thread::scope(|s| {
            for _ in 0..threads {
                s.spawn(|| {
                    let mut row_candidates = Vec::new();
                    let mut candidates = Vec::new();
                    loop {
                        let job = jobs.lock().map(|mut it| it.next());
                        let Ok(Some((index, chunk))) = job else { break };
                        for (r, row) in chunk.chunks_mut(w).enumerate() {
                            let y = index * ROWS_PER_JOB + r;
                            raster.row(&scene, y, row, &mut row_candidates, &mut candidates);
                        }
                    }
                });
            }
        });
        Ok(())
    }
}

/// Per-pixel ray casting.
struct Raster {
    cx: f64,
    cy: f64,
    fx: f64,
    fy: f64,
    /// Sub-pixel offsets of the rays along each axis (px).
    offsets: Vec<f64>,
    lighting: Lighting,
    surface: Surface,
    /// Each part's albedo factor ([`Surface::albedo_factor`]), by part.
    albedo_factors: Vec<f64>,
    /// Unit vector towards the light.
    light: Vector3<f64>,
    mode: Mode,
}

impl Raster {
    fn new(camera: &Camera, settings: &RenderSettings, mode: Mode) -> Self {
        let n = settings.supersample.max(1);
        Raster {
            cx: f64::from(camera.cx),
            cy: f64::from(camera.cy),
            fx: f64::from(camera.fx),
            fy: f64::from(camera.fy),
            offsets: (0..n)
                .map(|i| (f64::from(i) + 0.5) / f64::from(n) - 0.5)
                .collect(),
            lighting: settings.lighting,
            surface: settings.surface,
            albedo_factors: (0..=MAX_LINKS)
                .map(|part| settings.surface.albedo_factor(part))
                .collect(),
            light: settings.lighting.unit_toward_light(),
            mode,
        }
    }

    /// The grey level of the ray along unit `d` that hit part `part` of `scene` at `hit`.
    fn shade(&self, scene: &Scene, d: &Vector3<f64>, part: usize, hit: &Hit) -> f64 {
        let surface = &self.surface;
        let facing = hit.normal.dot(&self.light);
        let lit = facing > 0.0
            && !(surface.cast_shadows
                && scene.blocks(&Surface::shadow_origin(hit.t, d, &hit.normal), &self.light));
        let factor = self.albedo_factors.get(part).copied();
        let albedo = self.lighting.albedo * factor.unwrap_or_else(|| surface.albedo_factor(part));
        let ambient = self.lighting.ambient;
        if !lit {
            return albedo * ambient;
        }
        let highlight = surface.highlight(&hit.normal, d, &self.light);
        albedo * (ambient + (1.0 - ambient) * facing + highlight)
    }

    /// Renders row `y` into `row`, which holds the background.
    fn row(
        &self,
        scene: &Scene,
        y: usize,
        row: &mut [f32],
        row_candidates: &mut Vec<usize>,
        candidates: &mut Vec<usize>,
    ) {
        row_candidates.clear();
        row_candidates.extend(
            (0..scene.placed.len())
                .filter(|&i| (scene.placed[i].rect.y0..=scene.placed[i].rect.y1).contains(&y)),
        );
        if row_candidates.is_empty() {
            return;
        }
        let x_lo = row_candidates
            .iter()
            .map(|&i| scene.placed[i].rect.x0)
            .min()
            .unwrap_or(0);
        let x_hi = row_candidates
            .iter()
            .map(|&i| scene.placed[i].rect.x1)
            .max()
            .unwrap_or(0);
        let samples = (self.offsets.len() * self.offsets.len()) as f64;
        for (x, pixel) in row.iter_mut().enumerate().take(x_hi + 1).skip(x_lo) {
            candidates.clear();
            candidates.extend(row_candidates.iter().copied().filter(|&i| {
                let r = &scene.placed[i].rect;
                (r.x0..=r.x1).contains(&x)
            }));
            if candidates.is_empty() {
                continue;
            }
            let behind = f64::from(*pixel);
            let mut sum = 0.0;
            for oy in &self.offsets {
                let v = y as f64 + oy;
                for ox in &self.offsets {
                    let u = x as f64 + ox;
                    let d = Vector3::new((u - self.cx) / self.fx, (v - self.cy) / self.fy, 1.0)
                        .normalize();
                    sum += match (scene.nearest(&d, candidates), self.mode) {
                        (Some((part, hit)), Mode::Shaded) => self.shade(scene, &d, part, &hit),
                        (Some(_), Mode::Coverage) => 1.0,
                        (None, _) => behind,
                    };
                }
            }
            *pixel = (sum / samples) as f32;
        }
    }
}
