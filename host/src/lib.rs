//! The host side of digiteyes: sequence I/O, the synthetic renderer, tracking and evaluation
//! of recorded sequences. The `digiteyes` binary is a thin command-line layer over this crate.
//!
//! - [`sequence`]: the on-disk contract of `sequence-format.md` — `sequence.json`, the
//!   `camN/NNNNNN.pgm` frames, `truth.csv` and the tracker's output CSV.
//! - [`render`]: the project's synthetic renderer (ray-cast capsules and the palm box,
//!   Lambertian shading, supersampled, optional noise, blur and clutter).
//! - [`scenarios`]: named synthetic sequences (`mouse`, `rigid`, ...) written to disk.
//! - [`track`]: runs the core tracker over a sequence and writes the estimated states.
//! - [`eval`]: compares estimated states with the ground truth (px, deg, mm).
//! - [`demo`]: render, track and evaluate the `mouse` scenario in one go.
//!
//! Units everywhere: millimetres, radians (degrees only in reports), pixels (pixel (0, 0) is
//! the centre of the top-left pixel).
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod demo;
pub mod eval;
pub mod progress;
pub mod render;
pub mod scenarios;
pub mod sequence;
pub mod track;

pub use eval::{evaluate, CameraErrors, EvalReport};
pub use render::RenderSettings;
pub use scenarios::{render_scenario, RenderOptions};
pub use track::{track_sequence, TrackSummary};

/// Re-exported so callers can build a [`TrackerConfig`] without naming the core crate.
pub use digiteyes_core::tracker::TrackerConfig;
