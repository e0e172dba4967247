//! What a host tells a board before frames: the camera, the tracker parameters, the initial
//! state and the free states — taken from a sequence's `sequence.json`.

use std::time::Duration;

use anyhow::{anyhow, bail, Result};
use digiteyes_core::protocol::{
    default_search_evaluations, model_digest, CameraParams, HypothesesParams, Start, TrackerParams,
};

use crate::sequence::Sequence;

/// How long the host waits for a board's answer by default.
pub const DEFAULT_REPLY_TIMEOUT: Duration = Duration::from_secs(2);

/// Everything a session needs to set a board up.
#[derive(Debug, Clone, PartialEq)]
pub struct SessionSetup {
    /// The board's camera (`Configure`); frames must be its size.
    pub camera: CameraParams,
    /// Tracker parameters (`Configure`).
    pub tracker: TrackerParams,
    /// `Features` every this many frames (0: never).
    pub features_every: u16,
    /// `Stats` every this many frames (0: only when pinged).
    pub stats_every: u16,
    /// The state at the first frame (`Reset`): quaternion, mm, rad.
    pub initial_state: Vec<f32>,
    /// What a search starts from (`Reset` with [`Start::Search`]): the fixed states'
    /// `initial_state` values and the free states' neutral base
    /// ([`Sequence::search_base`]), as `digiteyes track --init auto` starts: the free
    /// states' given values are ignored.
    pub search_base: Vec<f32>,
    /// Bit `i`: state `i` is estimated (`Reset`).
    pub free: u32,
    /// How the board starts (`Reset`): tracking from `initial_state`, or searching for the
    /// free states (the fixed ones keep `initial_state`'s values).
    pub start: Start,
    /// The board's search budget per frame, in evaluations (`Configure`).
    pub search_evaluations_per_frame: u16,
    /// The hypotheses the board's tracker carries and what they may cost (`Configure`;
    /// protocol versions 5, 9 and 10): more than one makes it send a `Hypotheses` message
    /// after every `State`.
    pub hypotheses: HypothesesParams,
    /// [`model_digest`] of the model the frames show; the board's must match.
    pub model_digest: u32,
    /// The model's name for messages (`sequence.json`'s `model`).
    pub model_name: String,
    /// How long to wait for each answer (an upload's `State`/`Dropped`, an `Ack`).
    pub reply_timeout: Duration,
}

impl SessionSetup {
    /// The setup for tracking camera `camera` of `sequence` (`None`: the only camera; a
    /// sequence with several cameras needs one picked — a board tracks one camera).
    pub fn from_sequence(sequence: &Sequence, camera: Option<usize>) -> Result<Self> {
        let n_cameras = sequence.cameras.len();
        let index = match camera {
            Some(i) if i < n_cameras => i,
            Some(i) => bail!(
                "{}: camera index {i} out of range: the sequence has {n_cameras} camera(s) \
                 (0..{})",
                sequence.dir.display(),
                n_cameras - 1
            ),
            None if n_cameras == 1 => 0,
            None => bail!(
                "{}: the sequence has {n_cameras} cameras; a board tracks one camera (as the \
                 IC40 ran one board per camera): pick one with --camera-index 0..{}, or give \
                 one --port per camera",
                sequence.dir.display(),
                n_cameras - 1
            ),
        };
        let camera = CameraParams::from_camera(&sequence.cameras[index]).ok_or_else(|| {
            anyhow!(
                "{}: camera {index} is larger than 65535 px on a side",
                sequence.dir.display()
            )
        })?;
        let n = sequence.n_states();
        if n > 32 {
            bail!("the model has {n} states; the link carries at most 32");
        }
        let free = sequence.free_mask().0;
        Ok(SessionSetup {
            camera,
            tracker: TrackerParams::default(),
            features_every: 0,
            stats_every: 0,
            initial_state: sequence.initial_state.iter().map(|&v| v as f32).collect(),
            search_base: sequence.search_base().iter().map(|&v| v as f32).collect(),
            free,
            // A sequence without an initial state can only be searched for.
            start: if sequence.initial_given {
                Start::Given
            } else {
                Start::Search
            },
            search_evaluations_per_frame: default_search_evaluations(),
            hypotheses: HypothesesParams::default(),
            model_digest: model_digest(&sequence.model),
            model_name: sequence.file.model.clone(),
            reply_timeout: DEFAULT_REPLY_TIMEOUT,
        })
    }
}
