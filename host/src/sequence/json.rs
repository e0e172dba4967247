//! `sequence.json` as data: the serde form of the file, and its conversion to core types.
//!
//! Unknown keys are ignored (the format may be extended with optional keys); numbers are kept
//! as `f64` so a file round-trips exactly, and converted to the core's `f32` on use.

use digiteyes_core::camera::Camera;
use digiteyes_core::nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// The `model` value naming the whole-hand model shipped with the project.
pub const BUILTIN_HAND: &str = "builtin:hand";

/// The contents of `sequence.json`, exactly as stored.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SequenceFile {
    /// A model file path relative to the sequence folder, or [`BUILTIN_HAND`].
    pub model: String,
    /// Frame rate (frames/s), for reports only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fps: Option<f64>,
    /// The cameras; camera `i`'s frames are in folder `cam{i}`.
    pub cameras: Vec<CameraFile>,
    /// The state at frame 0: quaternion `w, x, y, z`, translation (mm), joint angles (rad).
    /// Optional (empty when absent): without it every state must be free, and the tracker
    /// finds the hand itself.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub initial_state: Vec<f64>,
    /// The states the tracker estimates; absent means all.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub free: Option<Vec<i64>>,
}

/// One pinhole camera of `sequence.json`: `p_c = R · p_w + t`, `u = fx · x_c / z_c + cx`,
/// `v = fy · y_c / z_c + cy` (mm, px).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CameraFile {
    /// A label for reports (optional; the frames are in `cam{index}` whatever the name).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Image width (px).
    pub width: u32,
    /// Image height (px).
    pub height: u32,
    /// Focal length along u (px).
    pub fx: f64,
    /// Focal length along v (px).
    pub fy: f64,
    /// Principal point u (px).
    pub cx: f64,
    /// Principal point v (px).
    pub cy: f64,
    /// World-to-camera rotation, rows.
    #[serde(rename = "R")]
    pub r: [[f64; 3]; 3],
    /// World-to-camera translation (mm).
    pub t: [f64; 3],
}

impl CameraFile {
    /// The core camera (converted to `f32`); not validated.
    pub fn to_camera(&self) -> Camera {
        let r = &self.r;
        Camera {
            width: self.width,
            height: self.height,
            fx: self.fx as f32,
            fy: self.fy as f32,
            cx: self.cx as f32,
            cy: self.cy as f32,
            r: Matrix3::new(
                r[0][0] as f32,
                r[0][1] as f32,
                r[0][2] as f32,
                r[1][0] as f32,
                r[1][1] as f32,
                r[1][2] as f32,
                r[2][0] as f32,
                r[2][1] as f32,
                r[2][2] as f32,
            ),
            t: Vector3::new(self.t[0] as f32, self.t[1] as f32, self.t[2] as f32),
        }
    }
}

impl SequenceFile {
    /// Parses the text of a `sequence.json`. The error names the key at fault
    /// (`cameras[0].fx: ...`) as well as the line and column, and says so when the value is a
    /// `NaN` or `Infinity`, which JSON does not have.
    pub fn from_json(text: &str) -> Result<Self, String> {
        let mut de = serde_json::Deserializer::from_str(text);
        let parsed: Result<Self, serde_path_to_error::Error<serde_json::Error>> =
            serde_path_to_error::deserialize(&mut de);
        let (path, inner) = match parsed {
            Ok(file) => match de.end() {
                Ok(()) => return Ok(file),
                Err(e) => (String::new(), e),
            },
            Err(e) => (e.path().to_string(), e.into_inner()),
        };
        let mut message = if path.is_empty() || path == "." {
            inner.to_string()
        } else {
            format!("`{path}`: {inner}")
        };
        if let Some(word) = non_number_at(text, inner.line(), inner.column()) {
            message.push_str(&format!(
                " (`{word}` is not a JSON number: every value must be a finite number)"
            ));
        }
        Err(message)
    }

    /// The file's text (pretty-printed JSON, trailing newline).
    pub fn to_json(&self) -> Result<String, serde_json::Error> {
        let mut text = serde_json::to_string_pretty(self)?;
        text.push('\n');
        Ok(text)
    }
}

/// The word at 1-based `line`, `column` (serde_json's error position) if it spells a number
/// JSON does not have (`NaN`, `Infinity`, `-Infinity`, `inf`).
fn non_number_at(text: &str, line: usize, column: usize) -> Option<&'static str> {
    let row = text.lines().nth(line.checked_sub(1)?)?;
    let from = column.saturating_sub(1).min(row.len());
    let rest = row
        .get(from..)
        .or_else(|| row.get(column.min(row.len())..))?;
    let rest = rest.trim_start().to_ascii_lowercase();
    ["-infinity", "infinity", "nan", "-inf", "inf"]
        .into_iter()
        .find(|w| rest.starts_with(w))
        .map(|w| match w {
            "nan" => "NaN",
            "infinity" | "inf" => "Infinity",
            _ => "-Infinity",
        })
}
