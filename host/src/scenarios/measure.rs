//! Measurements on a trajectory seen by cameras: how fast the fingertips move in the images,
//! and whether the whole hand stays in view. Geometry through the core's kinematics and camera.

use anyhow::{anyhow, bail, Result};
use digiteyes_core::camera::Camera;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::{Model, Shape};
use digiteyes_core::nalgebra::Vector3;

/// Fingertips' image speed at every frame (px/frame): at frame `k ≥ 1`, the largest
/// displacement of a `tip` frame's origin from frame `k − 1` over all tips and cameras;
/// 0 at frame 0.
pub fn tip_speeds(model: &Model, cameras: &[Camera], states: &[Vec<f64>]) -> Result<Vec<f64>> {
    let tips: Vec<usize> = (0..model.links().len())
        .filter(|&i| matches!(model.links()[i].shape, Shape::Tip { .. }))
        .collect();
    let mut previous: Option<Vec<[f32; 2]>> = None;
    let mut speeds = Vec::with_capacity(states.len());
    for (k, q) in states.iter().enumerate() {
        let poses = poses(model, q, k)?;
        let mut now = Vec::with_capacity(tips.len() * cameras.len());
        for cam in cameras {
            for &t in &tips {
                let p = poses.origin(t).unwrap_or_default();
                let uv = cam
                    .project(&p)
                    .ok_or_else(|| anyhow!("frame {k}: a fingertip is behind a camera"))?;
                now.push([uv.x, uv.y]);
            }
        }
        let speed = previous.as_ref().map_or(0.0, |prev| {
            prev.iter()
                .zip(&now)
                .map(|(a, b)| f64::from((a[0] - b[0]).hypot(a[1] - b[1])))
                .fold(0.0, f64::max)
        });
        speeds.push(speed);
        previous = Some(now);
    }
    Ok(speeds)
}

/// The largest of [`tip_speeds`] (px/frame).
pub fn peak_tip_speed(model: &Model, cameras: &[Camera], states: &[Vec<f64>]) -> Result<f64> {
    Ok(tip_speeds(model, cameras, states)?
        .into_iter()
        .fold(0.0, f64::max))
}

/// Checks that every shape of the hand projects inside every image, at least `margin` px from
/// the border, at every frame: the ends of every capsule with its radius, and the palm box's
/// corners. The error names the first frame, camera and link that leave the view.
pub fn check_in_view(
    model: &Model,
    cameras: &[Camera],
    states: &[Vec<f64>],
    margin: f32,
) -> Result<()> {
    for (k, q) in states.iter().enumerate() {
        let poses = poses(model, q, k)?;
        for (c, cam) in cameras.iter().enumerate() {
            for (i, link) in model.links().iter().enumerate() {
                let Some(pose) = poses.frame(i) else { continue };
                let points: Vec<(Vector3<f32>, f32)> = match link.shape {
                    Shape::Cylinder { radius } => {
                        let end = link
                            .children
                            .first()
                            .and_then(|&ch| poses.origin(usize::from(ch)))
                            .unwrap_or(pose.t);
                        vec![(pose.t, radius), (end, radius)]
                    }
                    Shape::Box { size, centre } => box_corners(size, centre)
                        .iter()
                        .map(|p| (pose.apply(p), 0.0))
                        .collect(),
                    _ => Vec::new(),
                };
                for (p, radius) in points {
                    let depth = cam.to_camera(&p).z;
                    let inside = cam.project(&p).is_some_and(|uv| {
                        cam.contains(&uv, margin + cam.pixels_at_depth(radius, depth))
                    });
                    if !inside {
                        bail!(
                            "frame {k}: link {i} ({}) leaves the view of camera {c}",
                            link.name
                        );
                    }
                }
            }
        }
    }
    Ok(())
}

fn poses(model: &Model, q: &[f64], frame: usize) -> Result<Poses> {
    let q: Vec<f32> = q.iter().map(|&v| v as f32).collect();
    Poses::compute(model, &q).map_err(|e| anyhow!("frame {frame}: {e}"))
}

fn box_corners(size: [f32; 3], centre: [f32; 3]) -> [Vector3<f32>; 8] {
    let mut out = [Vector3::from(centre); 8];
    for (k, o) in out.iter_mut().enumerate() {
        for axis in 0..3 {
            let sign = if k & (1 << axis) == 0 { -0.5 } else { 0.5 };
            o[axis] += sign * size[axis];
        }
    }
    out
}
