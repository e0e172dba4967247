//! Recorded sequences: the on-disk contract of `sequence-format.md`.
//!
//! ```text
//! <seq>/sequence.json      model, cameras, initial state, free states, fps
//! <seq>/cam0/000000.pgm    frame 0 of camera 0, then 000001.pgm, ... (no gaps)
//! <seq>/truth.csv          optional ground truth (`frame,q0,...`)
//! ```
//!
//! [`Sequence::open`] reads and checks everything but the pixels; frames are read one at a
//! time with [`Sequence::read_frame`]. Every error names the file and says what is wrong.

pub mod hypotheses;
pub mod json;
pub mod pgm;
pub mod states;
pub mod status;

use std::path::{Path, PathBuf};

use anyhow::{bail, ensure, Context, Result};
use digiteyes_core::camera::Camera;
use digiteyes_core::config::MAX_CAMERAS;
use digiteyes_core::estimator::FreeMask;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::model::Model;
use image::GrayImage;

pub use json::{CameraFile, SequenceFile, BUILTIN_HAND};
pub use states::{read_states, write_truth, StateTable, StatesWriter};

/// The name of the file describing a sequence.
pub const SEQUENCE_JSON: &str = "sequence.json";
/// The name of the optional ground-truth file.
pub const TRUTH_CSV: &str = "truth.csv";

/// A sequence folder, opened and checked.
#[derive(Debug, Clone)]
pub struct Sequence {
    /// The sequence folder.
    pub dir: PathBuf,
    /// `sequence.json` as stored.
    pub file: SequenceFile,
    /// The kinematic model named by `model`.
    pub model: Model,
    /// The cameras, validated; camera `i`'s frames are in `cam{i}/`.
    pub cameras: Vec<Camera>,
    /// The state at frame 0 (quaternion, mm, rad), one value per model state. When
    /// `sequence.json` gives none ([`Sequence::initial_given`] false), the search's base
    /// state ([`base_state`]): the tracker must then find the hand itself.
    pub initial_state: Vec<f64>,
    /// Whether `sequence.json` gives `initial_state`.
    pub initial_given: bool,
    /// The free states, sorted; `None` when `sequence.json` has no `free` (all are free).
    pub free: Option<Vec<u8>>,
    /// Frames per camera.
    pub frames: usize,
}

impl Sequence {
    /// Reads `dir/sequence.json` and its model, checks the cameras, the initial state and the
    /// free list, and counts the frames of every camera (which must agree). Frame headers are
    /// not read here: see [`Sequence::check_frames`].
    pub fn open(dir: &Path) -> Result<Sequence> {
        let mut sequence = Self::open_description(&dir.join(SEQUENCE_JSON))?;
        sequence.frames = count_all_frames(dir, sequence.cameras.len())?;
        Ok(sequence)
    }

    /// Reads and checks a `sequence.json` (at any path) like [`Sequence::open`], without
    /// looking for frames: `frames` is 0 and `dir` is the file's folder. For setting up a
    /// live camera from a calibration in the sequence format.
    pub fn open_description(json_path: &Path) -> Result<Sequence> {
        let dir = json_path.parent().unwrap_or(Path::new("."));
        let text = std::fs::read_to_string(json_path)
            .with_context(|| format!("cannot read {}", json_path.display()))?;
        let file = SequenceFile::from_json(&text).map_err(|e| {
            anyhow::anyhow!("{}: invalid sequence description: {e}", json_path.display())
        })?;
        let at = |what: String| format!("{}: {what}", json_path.display());
        let model = load_model(dir, &file.model).with_context(|| at("model".into()))?;
        let cameras = check_cameras(&file.cameras).with_context(|| at("cameras".into()))?;
        let initial_given = !file.initial_state.is_empty();
        let initial_state = if initial_given {
            check_initial_state(&file.initial_state, &model)
                .with_context(|| at("initial_state".into()))?
        } else {
            base_state(&model, &cameras)
        };
        let free = match &file.free {
            Some(list) => {
                Some(check_free(list, model.n_states()).with_context(|| at("free".into()))?)
            }
            None => None,
        };
        if let (false, Some(list)) = (initial_given, &free) {
            ensure!(
                list.len() == model.n_states(),
                "{}: `initial_state` is absent, so every state must be free, but `free` lists \
                 {} of the model's {} states (leave `free` out, list every state, or give \
                 `initial_state`)",
                json_path.display(),
                list.len(),
                model.n_states()
            );
        }
        Ok(Sequence {
            dir: dir.to_path_buf(),
            file,
            model,
            cameras,
            initial_state,
            initial_given,
            free,
            frames: 0,
        })
    }

    /// Number of model states.
    pub fn n_states(&self) -> usize {
        self.model.n_states()
    }

    /// The states the tracker estimates (all when `free` is absent), sorted.
    pub fn free_states(&self) -> Vec<usize> {
        match &self.free {
            Some(list) => list.iter().map(|&s| usize::from(s)).collect(),
            None => (0..self.n_states()).collect(),
        }
    }

    /// The states the tracker estimates as a mask (all when `free` is absent). `open` checked
    /// every listed state is one of the model's (fewer than 32).
    pub fn free_mask(&self) -> FreeMask {
        match &self.free {
            Some(list) => list
                .iter()
                .fold(FreeMask(0), |m, &s| FreeMask(m.0 | 1 << s)),
            None => FreeMask::all(self.n_states()),
        }
    }

    /// The state a search starts from for `track --init auto`: the fixed states at their
    /// `initial_state` values, the free ones at the [`base_state`]'s (what a free state's
    /// given value was is not used).
    pub fn search_base(&self) -> Vec<f64> {
        let base = base_state(&self.model, &self.cameras);
        let free = self.free_mask();
        (0..self.n_states())
            .map(|s| {
                let quaternion_free = s < 4 && free.contains(0);
                if free.contains(s) || quaternion_free {
                    base[s]
                } else {
                    self.initial_state[s]
                }
            })
            .collect()
    }

    /// The name of camera `cam` for reports: its `name`, or `cam{cam}`.
    pub fn camera_name(&self, cam: usize) -> String {
        self.file
            .cameras
            .get(cam)
            .and_then(|c| c.name.clone())
            .unwrap_or_else(|| format!("cam{cam}"))
    }

    /// The frame rate (frames/s), when `sequence.json` gives one.
    pub fn fps(&self) -> Option<f64> {
        self.file.fps
    }

    /// The path of frame `frame` of camera `cam`.
    pub fn frame_path(&self, cam: usize, frame: usize) -> PathBuf {
        frame_path(&self.dir, cam, frame)
    }

    /// Reads frame `frame` of camera `cam`, checking it is 8-bit `P5` of the camera's size.
    pub fn read_frame(&self, cam: usize, frame: usize) -> Result<GrayImage> {
        let path = self.frame_path(cam, frame);
        pgm::read_pgm_checked(&path, |size| self.check_size(cam, &path, size))
    }

    /// Reads the header of every frame: each must be 8-bit `P5` of its camera's size.
    pub fn check_frames(&self) -> Result<()> {
        for cam in 0..self.cameras.len() {
            for frame in 0..self.frames {
                let path = self.frame_path(cam, frame);
                let size = pgm::read_pgm_size(&path)?;
                self.check_size(cam, &path, size)?;
            }
        }
        Ok(())
    }

    /// The one check every reader of a states file (`eval`, `report`, `ui --replay`) makes:
    /// it has one row per frame of this sequence, so all of them judge a file alike.
    pub fn check_state_rows(&self, states_csv: &Path, rows: usize) -> Result<()> {
        ensure!(
            rows == self.frames,
            "{}: {rows} frames of states, the sequence {} has {} (one row per frame is needed)",
            states_csv.display(),
            self.dir.display(),
            self.frames
        );
        Ok(())
    }

    /// Refuses a camera that cannot see the hand at its initial state: every link behind it
    /// or projected outside its frame (a hand placed behind the camera, absurd intrinsics such
    /// as fx = 1e30). Tracking such a camera could only report every frame lost.
    /// Without `initial_state`, the hand is looked for at the base state (the working volume's
    /// centre).
    pub fn check_cameras_see_the_hand(&self, cameras: &[usize]) -> Result<()> {
        let q: Vec<f32> = self.initial_state.iter().map(|&v| v as f32).collect();
        let poses = Poses::compute(&self.model, &q)
            .map_err(|e| anyhow::anyhow!("{}: initial_state: {e}", self.json_path().display()))?;
        let at = if self.initial_given {
            "initial_state"
        } else {
            "the working volume's centre (no initial_state)"
        };
        for &c in cameras {
            let camera = &self.cameras[c];
            let (w, h) = (camera.width as f32, camera.height as f32);
            let (mut behind, mut inside) = (0, 0);
            for i in 0..self.model.links().len() {
                let Some(p) = poses.origin(i) else { continue };
                match camera.project(&p) {
                    None => behind += 1,
                    Some(uv)
                        if uv.x >= -0.5 && uv.y >= -0.5 && uv.x <= w - 0.5 && uv.y <= h - 0.5 =>
                    {
                        inside += 1
                    }
                    Some(_) => {}
                }
            }
            if inside == 0 {
                let why = if behind > 0 {
                    "the hand is behind it"
                } else {
                    "no joint of the hand projects into its frame"
                };
                bail!(
                    "{}: camera {c} ({}) cannot see the hand at {at}: {why} \
                     (check its R, t and fx, fy, cx, cy)",
                    self.json_path().display(),
                    self.camera_name(c)
                );
            }
        }
        Ok(())
    }

    fn json_path(&self) -> PathBuf {
        self.dir.join(SEQUENCE_JSON)
    }

    /// Reads `truth.csv`; an error if it is missing or does not have one row per frame.
    pub fn read_truth(&self) -> Result<StateTable> {
        let path = self.dir.join(TRUTH_CSV);
        ensure!(
            path.exists(),
            "{}: missing (ground truth is needed for evaluation)",
            path.display()
        );
        let table = read_states(&path, self.n_states())?;
        ensure!(
            table.rows.len() == self.frames,
            "{}: {} rows, the sequence has {} frames",
            path.display(),
            table.rows.len(),
            self.frames
        );
        Ok(table)
    }

    fn check_size(&self, cam: usize, path: &Path, (w, h): (u32, u32)) -> Result<()> {
        let c = &self.cameras[cam];
        ensure!(
            (w, h) == (c.width, c.height),
            "{}: frame is {w}x{h} px, camera {cam} is {}x{} px",
            path.display(),
            c.width,
            c.height
        );
        Ok(())
    }
}

/// Writes `dir/sequence.json`, creating `dir` and the `cam{i}` folders of its cameras.
pub fn write_sequence_json(dir: &Path, file: &SequenceFile) -> Result<()> {
    for cam in 0..file.cameras.len() {
        let folder = dir.join(camera_dir_name(cam));
        std::fs::create_dir_all(&folder)
            .with_context(|| format!("cannot create {}", folder.display()))?;
    }
    let path = dir.join(SEQUENCE_JSON);
    let text = file
        .to_json()
        .with_context(|| format!("cannot encode {}", path.display()))?;
    crate::atomic_file::write_atomic(&path, text.as_bytes())
}

/// Writes frame `frame` of camera `cam` into sequence folder `dir` (the folder must exist).
pub fn write_frame(dir: &Path, cam: usize, frame: usize, image: &GrayImage) -> Result<()> {
    pgm::write_pgm(&frame_path(dir, cam, frame), image)
}

/// The path of frame `frame` of camera `cam` in sequence folder `dir`.
pub fn frame_path(dir: &Path, cam: usize, frame: usize) -> PathBuf {
    dir.join(camera_dir_name(cam))
        .join(format!("{frame:06}.pgm"))
}

/// The folder name of camera `cam`'s frames: `cam{cam}`.
pub fn camera_dir_name(cam: usize) -> String {
    format!("cam{cam}")
}

/// Loads the model named by `sequence.json`'s `model` field.
pub fn load_model(dir: &Path, name: &str) -> Result<Model> {
    if name == BUILTIN_HAND {
        return Model::hand().map_err(|e| anyhow::anyhow!("built-in hand model: {e}"));
    }
    if let Some(other) = name.strip_prefix("builtin:") {
        bail!("unknown built-in model `builtin:{other}` (the only one is `{BUILTIN_HAND}`)");
    }
    let path = dir.join(name);
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("cannot read {}", path.display()))?;
    Model::parse(&text).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
}

/// Converts and validates the cameras.
pub fn check_cameras(cameras: &[CameraFile]) -> Result<Vec<Camera>> {
    ensure!(!cameras.is_empty(), "no cameras listed");
    ensure!(
        cameras.len() <= MAX_CAMERAS,
        "{} cameras listed, at most {MAX_CAMERAS} are supported",
        cameras.len()
    );
    cameras
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let camera = c.to_camera();
            camera.validate().map_err(|e| {
                anyhow::anyhow!(
                    "camera {i}{}: {e}",
                    c.name
                        .as_deref()
                        .map(|n| format!(" ({n})"))
                        .unwrap_or_default()
                )
            })?;
            Ok(camera)
        })
        .collect()
}

/// The state a search starts from when nothing is known of the hand: the palm unrotated at
/// the centre of the rig's default working volume
/// ([`WorkingVolume::from_cameras`](digiteyes_core::acquire::WorkingVolume::from_cameras)),
/// every joint at 0 rad (or the nearest end of its range).
pub fn base_state(model: &Model, cameras: &[Camera]) -> Vec<f64> {
    let volume = digiteyes_core::acquire::WorkingVolume::from_cameras(
        cameras,
        digiteyes_core::auto_tracker::FALLBACK_DEPTH_MM,
    );
    let mut q = vec![0.0; model.n_states()];
    if let Some(w) = q.first_mut() {
        *w = 1.0;
    }
    for (d, c) in q.iter_mut().skip(4).take(3).zip(volume.centre_mm) {
        *d = f64::from(c);
    }
    for (s, v) in q
        .iter_mut()
        .enumerate()
        .skip(digiteyes_core::model::BASE_STATES)
    {
        if let Some(l) = model.limit(s) {
            *v = f64::from(0.0f32.clamp(l.lo, l.hi));
        }
    }
    q
}

fn check_initial_state(state: &[f64], model: &Model) -> Result<Vec<f64>> {
    ensure!(
        state.len() == model.n_states(),
        "{} values, the model has {} states",
        state.len(),
        model.n_states()
    );
    if let Some(i) = state.iter().position(|v| !v.is_finite()) {
        bail!("q{i} is not a finite number");
    }
    let norm = state[..4].iter().map(|v| v * v).sum::<f64>().sqrt();
    ensure!(norm > 1e-6, "the palm quaternion q0..q3 is zero");
    Ok(state.to_vec())
}

fn check_free(list: &[i64], n_states: usize) -> Result<Vec<u8>> {
    let mut free = Vec::with_capacity(list.len());
    for &s in list {
        ensure!(
            s >= 0 && (s as usize) < n_states,
            "state {s} is not a state of the model (0..{})",
            n_states.saturating_sub(1)
        );
        ensure!(!free.contains(&(s as u8)), "state {s} is listed twice");
        free.push(s as u8);
    }
    free.sort_unstable();
    let quaternion_free = (0..4u8).filter(|s| free.contains(s)).count();
    ensure!(
        quaternion_free == 0 || quaternion_free == 4,
        "the quaternion states 0, 1, 2, 3 must be free or fixed together"
    );
    Ok(free)
}

/// Counts the frames of every camera; they must be numbered from 000000 without gaps and
/// every camera must have the same number.
fn count_all_frames(dir: &Path, cameras: usize) -> Result<usize> {
    let mut counts = Vec::with_capacity(cameras);
    for cam in 0..cameras {
        counts.push(count_frames(dir, cam)?);
    }
    let first = counts[0];
    for (cam, &n) in counts.iter().enumerate().skip(1) {
        if n != first {
            let (short, long) = if n < first { (cam, 0) } else { (0, cam) };
            bail!(
                "{}: missing; camera {long} has {} frames, camera {short} has {}",
                frame_path(dir, short, n.min(first)).display(),
                n.max(first),
                n.min(first)
            );
        }
    }
    Ok(first)
}

fn count_frames(dir: &Path, cam: usize) -> Result<usize> {
    let folder = dir.join(camera_dir_name(cam));
    ensure!(
        folder.is_dir(),
        "{}: missing folder of camera {cam}'s frames",
        folder.display()
    );
    let mut n = 0;
    loop {
        let path = frame_path(dir, cam, n);
        match std::fs::metadata(&path) {
            Ok(meta) if meta.is_file() => n += 1,
            Ok(meta) => bail!(
                "{}: {}, not a PGM frame",
                path.display(),
                if meta.is_dir() {
                    "is a folder"
                } else {
                    "is not a regular file (a pipe, socket or device)"
                }
            ),
            Err(_) => break,
        }
    }
    ensure!(
        n > 0,
        "{}: missing (frames are numbered from 000000)",
        frame_path(dir, cam, 0).display()
    );
    // Frames past a gap would be silently ignored: the format allows no gaps.
    let entries =
        std::fs::read_dir(&folder).with_context(|| format!("cannot list {}", folder.display()))?;
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(stem) = name.to_str().and_then(|s| s.strip_suffix(".pgm")) else {
            continue;
        };
        if stem.len() == 6 && stem.bytes().all(|b| b.is_ascii_digit()) {
            if let Ok(k) = stem.parse::<usize>() {
                if k > n {
                    bail!(
                        "{}: missing, but {} exists (frames must be numbered without gaps)",
                        frame_path(dir, cam, n).display(),
                        entry.path().display()
                    );
                }
            }
        }
    }
    Ok(n)
}
