//! Overlay snapshots every N frames (after the thesis' Fig. 4.5): the estimated model drawn
//! over the frame by [`crate::overlay::draw_overlay`], scaled down, as PNG `data:` URIs.

use std::fmt::Write;

use anyhow::{ensure, Result};
use base64::Engine;
use image::codecs::png::{CompressionType, FilterType as PngFilter, PngEncoder};
use image::imageops::FilterType;
use image::{ExtendedColorType, ImageEncoder, RgbImage};

use super::html::escape;
use super::input::Inputs;
use super::ReportOptions;
use crate::overlay::draw_overlay;

/// One snapshot.
#[derive(Debug, Clone)]
pub struct Thumbnail {
    /// The frame.
    pub frame: usize,
    /// The camera.
    pub camera: usize,
    /// The image as PNG.
    pub png: Vec<u8>,
    /// Its size (px).
    pub size: (u32, u32),
    /// Why there is no overlay on it (a state that is not a number, ...), if there is none.
    pub note: Option<String>,
}

/// The frames that get a thumbnail: 0, N, 2N, ... (ceil(frames / N) of them); none for N = 0.
pub fn thumbnail_frames(frames: usize, every: usize) -> Vec<usize> {
    if every == 0 {
        return Vec::new();
    }
    (0..frames).step_by(every).collect()
}

/// The cameras `options` asks for: its `camera`, or every camera of the sequence.
pub fn thumbnail_cameras(inputs: &Inputs, options: &ReportOptions) -> Result<Vec<usize>> {
    let n = inputs.sequence.cameras.len();
    match options.camera {
        Some(c) => {
            ensure!(
                c < n,
                "camera {c}: the sequence {} has {n} camera(s), numbered from 0",
                inputs.sequence.dir.display()
            );
            Ok(vec![c])
        }
        None => Ok((0..n).collect()),
    }
}

/// Draws the thumbnails of `frames` for `cameras`. A frame whose overlay cannot be drawn
/// (its state has a NaN) is shown without it, with a note; an unreadable frame is an error
/// naming its file.
pub fn thumbnails(
    inputs: &Inputs,
    options: &ReportOptions,
    frames: &[usize],
    cameras: &[usize],
) -> Result<Vec<Thumbnail>> {
    let sequence = &inputs.sequence;
    let mut out = Vec::with_capacity(frames.len() * cameras.len());
    for &k in frames {
        let q: Vec<f32> = inputs.estimate.table.rows[k]
            .iter()
            .map(|&v| v as f32)
            .collect();
        for &c in cameras {
            let frame = sequence.read_frame(c, k)?;
            let camera = &sequence.cameras[c];
            let (image, note) =
                match draw_overlay(&sequence.model, camera, &q, &frame, &options.features) {
                    Ok(image) => (image, None),
                    Err(e) => {
                        let why = format!("{e:#}");
                        let why = why.strip_prefix("overlay: ").unwrap_or(&why);
                        let bare = image::DynamicImage::ImageLuma8(frame).to_rgb8();
                        (bare, Some(format!("no overlay: {why}")))
                    }
                };
            let image = scale(image, options.thumb_width);
            out.push(Thumbnail {
                frame: k,
                camera: c,
                png: encode_png(&image)?,
                size: image.dimensions(),
                note,
            });
        }
    }
    Ok(out)
}

/// `image` scaled down to `width` px wide (aspect kept); as is when already that narrow.
fn scale(image: RgbImage, width: u32) -> RgbImage {
    let (w, h) = image.dimensions();
    if width == 0 || width >= w {
        return image;
    }
    let height = ((u64::from(h) * u64::from(width) + u64::from(w) / 2) / u64::from(w)).max(1);
    image::imageops::resize(&image, width, height as u32, FilterType::Triangle)
}

fn encode_png(image: &RgbImage) -> Result<Vec<u8>> {
    let mut png = Vec::new();
    PngEncoder::new_with_quality(&mut png, CompressionType::Default, PngFilter::Adaptive)
        .write_image(
            image.as_raw(),
            image.width(),
            image.height(),
            ExtendedColorType::Rgb8,
        )?;
    Ok(png)
}

/// The thumbnails as a flex row of `<figure class="thumb">`, each an `<img>` with a PNG
/// `data:` URI and a caption (frame, time, camera, lost/dropped, the fingertip error when
/// known).
pub fn thumbnails_html(
    inputs: &Inputs,
    thumbs: &[Thumbnail],
    fingertip_px: Option<&[f64]>,
) -> String {
    let mut s = String::from("<div class=\"thumbs\">");
    for t in thumbs {
        let k = t.frame;
        let mut caption = format!(
            "frame {k} · {} · {}",
            inputs.time_text(k),
            inputs.sequence.camera_name(t.camera)
        );
        if let Some(e) = fingertip_px
            .and_then(|e| e.get(k))
            .filter(|e| e.is_finite())
        {
            let _ = write!(caption, " · tips {e:.1} px");
        }
        if let Some(reason) = &inputs.dropped[k] {
            let _ = write!(caption, " · dropped: {reason}");
        } else if inputs.lost[k] {
            caption.push_str(" · lost");
        }
        if let Some(note) = &t.note {
            let _ = write!(caption, " · {note}");
        }
        let lost = if inputs.lost[k] || inputs.dropped[k].is_some() {
            " lost"
        } else {
            ""
        };
        let _ = write!(
            s,
            r#"<figure class="thumb{lost}" data-frame="{k}" data-camera="{c}"><img width="{w}" height="{h}" alt="{alt}" src="data:image/png;base64,{data}"><figcaption>{cap}</figcaption></figure>"#,
            c = t.camera,
            w = t.size.0,
            h = t.size.1,
            alt = escape(&format!("overlay at frame {k}")),
            data = base64::engine::general_purpose::STANDARD.encode(&t.png),
            cap = escape(&caption)
        );
    }
    s.push_str("</div>");
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_nth_frame_from_the_first() {
        assert_eq!(thumbnail_frames(12, 5), vec![0, 5, 10]);
        assert_eq!(thumbnail_frames(10, 5), vec![0, 5]);
        assert_eq!(thumbnail_frames(3, 10), vec![0]);
        assert!(thumbnail_frames(3, 0).is_empty());
    }

    #[test]
    fn scaling_keeps_the_aspect() {
        let image = RgbImage::new(640, 480);
        assert_eq!(scale(image.clone(), 160).dimensions(), (160, 120));
        assert_eq!(scale(image, 1000).dimensions(), (640, 480));
    }
}
