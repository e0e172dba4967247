//! # digiteyes-core
//!
//! The tracking core of digiteyes: a `no_std`, allocation-free reproduction of the DigitEyes
//! model-based hand tracker (J. Rehg, CMU-CS-95-138, 1995).
//!
//! One frame flows one way through the modules, named after the thesis' stages (Sec. 4.3.2):
//!
//! ```text
//! model ─▶ kinematics ─▶ camera ─▶ features (slices on a frame) ─▶ estimator ─▶ tracker
//! ```
//!
//! - [`model`]: the kinematic tree parsed from the `hand.dh` format (built-in: [`model::HAND_DH`]).
//! - [`kinematics`]: link poses for a state vector and point derivatives (Eq. 2.16).
//! - [`camera`]: calibrated pinhole cameras and their projection derivative.
//! - [`frame`]: a borrowed 8-bit frame and bounds-checked sub-pixel sampling.
//! - [`features`]: the slice edge search of Sec. 4.3.1 with occlusion masking.
//! - [`palm_outline`]: the palm box's image outline, whose edges are searched as the links' are.
//! - [`estimator`]: residuals gathered per link into the normal equations, conditioned
//!   Gauss–Newton solved by `LDLᵀ` (Eq. 2.22); [`estimator::reference`] is the oracle.
//! - [`state`]: the state vector's layout (palm quaternion, translation, joints).
//! - [`motion`]: the prediction between frames, the prior toward it, what a lost frame keeps.
//! - [`silhouette`]: how well the projected silhouette agrees with the image (region evidence).
//! - [`likelihood`]: how well a hypothesised state explains a frame (oriented chamfer + silhouette).
//! - [`acquire`]: the anytime coarse-to-fine search that finds the hand without help.
//! - [`status`], [`auto_tracker`]: Searching → Tracking → Lost, around the search and the tracker.
//! - [`search`]: one camera's slice search across a frame's iterations (coarse to fine).
//! - [`measurer`]: where the loop's features come from: local frames, or one board per camera.
//! - [`remote`]: a board's answer to a stereo host's `Measure`, and its features on the wire.
//! - [`tracker`]: the per-frame loop and its report.
//! - [`hypotheses`]: several hypotheses through ambiguity, each refined by the loop.
//! - [`measurement`]: measured axis lines and fingertips at a state, for a stereo host.
//! - [`protocol`]: the board link's messages and their framing (`docs/protocol.md`).
//! - [`float`]: square root, sine and cosine that stay in single precision on the board's FPU.
//!
//! Units everywhere: millimetres, radians, pixels (pixel (0, 0) is the centre of the top-left
//! pixel). Numbers are `f32`. Every capacity is a named constant in [`config`]; exceeding one
//! is a typed error or a counted condition, never a panic.
#![no_std]
#![deny(unsafe_code)]
#![warn(missing_docs)]

pub mod acquire;
pub mod auto_tracker;
pub mod camera;
pub mod config;
pub mod estimator;
pub mod features;
pub mod fill;
pub mod float;
pub mod frame;
pub mod hypotheses;
pub mod kinematics;
pub mod likelihood;
pub mod measurement;
pub mod measurer;
pub mod model;
pub mod model_writer;
pub mod motion;
pub mod palm_outline;
pub mod projection;
pub mod protocol;
pub mod quaternion;
pub mod remote;
pub mod search;
pub mod silhouette;
pub mod state;
pub mod status;
pub mod tracker;
pub mod visibility;
pub mod watch;

pub use nalgebra;
