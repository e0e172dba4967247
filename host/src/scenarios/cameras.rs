//! Cameras for the scenarios: pinhole intrinsics and look-at extrinsics.

use nalgebra::{Matrix3, Vector3};

use crate::sequence::CameraFile;

/// Default image width (px).
pub const WIDTH: u32 = 640;
/// Default image height (px).
pub const HEIGHT: u32 = 480;
/// Default focal length (px).
pub const FOCAL: f64 = 1000.0;

/// A 640×480 camera with focal length [`FOCAL`] and the principal point at the image centre,
/// at `eye` (world, mm) looking at `target`, with world direction `up` pointing up the image.
pub fn look_at(name: &str, eye: [f64; 3], target: [f64; 3], up: [f64; 3]) -> CameraFile {
    let eye = Vector3::from(eye);
    let z = (Vector3::from(target) - eye).normalize();
    let x = z.cross(&Vector3::from(up)).normalize();
    let y = z.cross(&x);
    let r = Matrix3::from_rows(&[x.transpose(), y.transpose(), z.transpose()]);
    let t = -(r * eye);
    CameraFile {
        name: Some(name.to_string()),
        width: WIDTH,
        height: HEIGHT,
        fx: FOCAL,
        fy: FOCAL,
        cx: (f64::from(WIDTH) - 1.0) / 2.0,
        cy: (f64::from(HEIGHT) - 1.0) / 2.0,
        r: [0, 1, 2].map(|i| [r[(i, 0)], r[(i, 1)], r[(i, 2)]]),
        t: [t.x, t.y, t.z],
    }
}

/// The same view at another image size: intrinsics scale with the width and height, so the
/// hand covers the same part of the picture.
pub fn resized(camera: &CameraFile, width: u32, height: u32) -> CameraFile {
    let sx = f64::from(width) / f64::from(camera.width);
    let sy = f64::from(height) / f64::from(camera.height);
    CameraFile {
        width,
        height,
        fx: camera.fx * sx,
        fy: camera.fy * sy,
        cx: (camera.cx + 0.5) * sx - 0.5,
        cy: (camera.cy + 0.5) * sy - 0.5,
        ..camera.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use digiteyes_core::nalgebra::Vector3 as V3f;

    #[test]
    fn look_at_centres_the_target_with_up_upwards() {
        let cam = look_at(
            "c",
            [100.0, -400.0, 300.0],
            [0.0, 0.0, 50.0],
            [0.0, 0.0, 1.0],
        );
        let core = cam.to_camera();
        core.validate().unwrap();
        let centre = core.project(&V3f::new(0.0, 0.0, 50.0)).unwrap();
        assert!((centre.x - 319.5).abs() < 1e-3 && (centre.y - 239.5).abs() < 1e-3);
        let above = core.project(&V3f::new(0.0, 0.0, 80.0)).unwrap();
        assert!(above.y < centre.y - 10.0 && (above.x - centre.x).abs() < 1.0);
    }

    #[test]
    fn resizing_keeps_the_view() {
        let cam = look_at("c", [0.0, 0.0, 500.0], [10.0, 20.0, 0.0], [0.0, 1.0, 0.0]);
        let small = resized(&cam, 320, 240);
        let p = V3f::new(30.0, -20.0, 10.0);
        let a = cam.to_camera().project(&p).unwrap();
        let b = small.to_camera().project(&p).unwrap();
        assert!(((a.x + 0.5) / 2.0 - (b.x + 0.5)).abs() < 1e-3);
        assert!(((a.y + 0.5) / 2.0 - (b.y + 0.5)).abs() < 1e-3);
    }
}
