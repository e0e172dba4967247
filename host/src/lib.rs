//! The host side of digiteyes: sequence I/O, the synthetic renderer, tracking and evaluation
//! of recorded sequences. The `digiteyes` binary is a thin command-line layer over this crate.
//!
//! - [`cli`]: the `digiteyes` command line, one module per command (its options, its `run`).
//! - [`sequence`]: the on-disk contract of `docs/sequence-format.md` — `sequence.json`, the
//!   `camN/NNNNNN.pgm` frames, `truth.csv` and the tracker's output CSV.
//! - [`render`]: the project's synthetic renderer (ray-cast capsules and the palm box,
//!   Lambertian shading, supersampled, optional noise, blur and clutter).
//! - [`scenarios`]: named synthetic sequences (`mouse`, `rigid`, ...) written to disk.
//! - [`track`]: runs the core tracker over a sequence and writes the estimated states.
//! - [`eval`]: compares estimated states with the ground truth (px, deg, mm).
//! - [`link`]: the host's side of the board link: serial port, set-up, frame uploads, reports.
//! - [`stream`]: frames to a board, states back as `track`'s CSV.
//! - [`listen`]: a board's messages printed and forwarded as JSON lines over UDP.
//! - [`forward`]: `listen --forward`: JSON lines or Open Sound Control over UDP, optionally
//!   smoothed by the one-euro filter.
//! - [`sim`]: the simulated board (the firmware loop on a pseudo-terminal, on the Linux
//!   platform), its line noise, frame tap, overlays and UI feed.
//! - [`overlay`]: the debug overlay (model, slices, edges, tips over a frame) as RGB images.
//! - [`state_names`]: what each state means, for labels.
//! - [`report`]: a run as one self-contained HTML page: each free state against time, the
//!   error over time, overlay thumbnails.
//! - [`ui`]: `digiteyes ui`, the local web page that shows the hand, the overlay, the 3D
//!   mouse and the link live.
//! - [`mouse_pole`]: the thesis' 3D mouse — the mouse sub-model's states as a pole on the
//!   table (base mm, height mm) with two buttons.
//! - [`demo`]: render the `mouse` scenario, stream it to a simulated board over a PTY, and
//!   evaluate what came back.
//!
//! Units everywhere: millimetres, radians (degrees only in reports), pixels (pixel (0, 0) is
//! the centre of the top-left pixel).
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod acquire;
pub mod atomic_file;
pub mod bench;
pub mod cli;
pub mod cli_values;
pub mod demo;
pub mod eval;
pub mod forward;
pub mod link;
pub mod listen;
pub mod mouse_pole;
pub mod overlay;
pub mod parallel;
pub mod progress;
pub mod render;
pub mod report;
pub mod scenarios;
pub mod sequence;
pub mod sim;
pub mod state_names;
pub mod stereo;
pub mod stream;
pub mod text;
pub mod track;
pub mod ui;

pub use eval::{evaluate, CameraErrors, EvalReport};
pub use render::RenderSettings;
pub use scenarios::{render_scenario, RenderOptions};
pub use stream::{stream_sequence, StreamOptions, StreamSummary};
pub use track::{sequence_tracker, track_sequence, track_sequence_with, TrackSummary};

/// Re-exported so callers can build a [`TrackerConfig`] without naming the core crate.
pub use digiteyes_core::tracker::TrackerConfig;
