//! What the search's tests set up alike: the base "from nothing" (every state free, the
//! identity palm at the origin), an acquirer and an auto tracker on it, and edge-map buffers.

use digiteyes_core::acquire::{AcquireConfig, Acquirer, FinderConfig, WorkingVolume};
use digiteyes_core::auto_tracker::{AutoTracker, Status};
use digiteyes_core::camera::Camera;
use digiteyes_core::config::MAX_STATES;
use digiteyes_core::estimator::FreeMask;
use digiteyes_core::frame::FrameView;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::likelihood::{EdgeMap, LikelihoodConfig, Scene};
use digiteyes_core::model::{Model, Shape};
use digiteyes_core::nalgebra::Vector3;
use digiteyes_core::state::TRANSLATION;
use digiteyes_core::tracker::TrackerConfig;
use digiteyes_host::sequence::Sequence;

use super::frames;

/// Fingertip error (px, in these 320-wide frames) under which a frame counts as on the hand:
/// the acquisition target's 10 px, as `acquire_probe --limit-px 20` counts it.
pub const ON_HAND_PX: f32 = 10.0;
/// Frames in a row on the hand that make an acquisition.
pub const HELD_FRAMES: usize = 5;
/// Frames the acquisition must be held within.
pub const WITHIN_FRAMES: usize = 30;

/// The state searched from: the identity palm at the origin, joints at 0.
pub fn base(n_states: usize) -> Vec<f32> {
    let mut base = vec![0.0f32; n_states];
    base[0] = 1.0;
    base
}

/// An acquirer over every state of `sequence`, in the working volume its cameras see at
/// 600 mm.
pub fn acquirer(sequence: &Sequence, acquire: AcquireConfig) -> Acquirer {
    let free = FreeMask::all(sequence.n_states());
    let volume = WorkingVolume::from_cameras(&sequence.cameras, 600.0);
    Acquirer::new(
        &sequence.model,
        &base(sequence.n_states()),
        free,
        volume,
        acquire,
    )
}

/// The status machine of `track --init auto` on `sequence`, searching from the first frame,
/// with its edge-map buffers.
pub fn searching(sequence: &Sequence, acquire: AcquireConfig) -> (AutoTracker, Vec<Vec<u8>>) {
    searching_with(sequence, acquire, TrackerConfig::default())
}

/// [`searching`] with the tracker's parameters `tracker`.
pub fn searching_with(
    sequence: &Sequence,
    acquire: AcquireConfig,
    tracker: TrackerConfig,
) -> (AutoTracker, Vec<Vec<u8>>) {
    let auto = AutoTracker::new(
        sequence.model.clone(),
        &sequence.cameras,
        &base(sequence.n_states()),
        sequence.free_mask(),
        tracker,
        acquire,
    )
    .unwrap();
    (
        auto,
        buffers(&sequence.cameras, acquire.likelihood.stride_px),
    )
}

/// One edge-map buffer per camera at `stride_px`.
pub fn buffers(cameras: &[Camera], stride_px: u8) -> Vec<Vec<u8>> {
    cameras
        .iter()
        .map(|c| vec![0u8; EdgeMap::bytes_needed(c.width as usize, c.height as usize, stride_px)])
        .collect()
}

/// Each camera's edge map of `views` in its buffer of `buffers`.
pub fn edge_maps<'b>(
    buffers: &'b mut [Vec<u8>],
    views: &[FrameView<'_>],
    likelihood: &LikelihoodConfig,
) -> Vec<EdgeMap<'b>> {
    buffers
        .iter_mut()
        .zip(views)
        .map(|(b, v)| EdgeMap::build(b, v, likelihood).unwrap())
        .collect()
}

/// The distance (mm) between the palm positions of states `a` and `b`.
pub fn palm_error_mm(a: &[f32], b: &[f32]) -> f32 {
    TRANSLATION
        .map(|i| (a[i] - b[i]).powi(2))
        .sum::<f32>()
        .sqrt()
}

/// Mean fingertip distance (px) between states `a` and `b` over every camera.
pub fn tip_error_px(model: &Model, cameras: &[Camera], a: &[f32], b: &[f32]) -> f32 {
    let (pa, pb) = (
        Poses::compute(model, a).unwrap(),
        Poses::compute(model, b).unwrap(),
    );
    let tips =
        (0..model.links().len()).filter(|&i| matches!(model.links()[i].shape, Shape::Tip { .. }));
    let (mut sum, mut n) = (0.0f32, 0);
    for t in tips {
        for c in cameras {
            let (x, y) = (pa.origin(t).unwrap(), pb.origin(t).unwrap());
            sum += match (c.project(&x), c.project(&y)) {
                (Some(u), Some(v)) => (u - v).norm(),
                _ => 1e3,
            };
            n += 1;
        }
    }
    sum / n as f32
}

/// What [`acquire_mono`] saw.
pub struct MonoRun {
    /// The frame the first run of [`HELD_FRAMES`] claimed frames within [`ON_HAND_PX`]
    /// starts on, if within [`WITHIN_FRAMES`].
    pub held: Option<usize>,
    /// Every frame's tip error (px) while claimed.
    pub errors: Vec<Option<f32>>,
    /// Every frame's palm position error (mm) while claimed.
    pub palm_errors_mm: Vec<Option<f32>>,
    /// The first frame a leaf was accepted on (claimed then or later), if any.
    pub accepted: Option<usize>,
    /// Every frame's hypotheses carried, best first: each palm's distance from the first
    /// camera (mm) and its ranked score.
    pub carried: Vec<Vec<(f32, f32)>>,
    /// The most hypotheses carried on any frame.
    pub most_hypotheses: usize,
}

/// `finder` without one camera's bar on the reverse chamfer term (`AcceptConfig::
/// one_camera_max_reverse_px`, on by default since stop 53), for the tests that show another
/// mechanism on a seed whose acceptance that bar refuses, in both their arms.
pub fn without_reverse_bar(mut finder: FinderConfig) -> FinderConfig {
    finder.accept.one_camera_max_reverse_px = f32::INFINITY;
    finder
}

/// `random-mono` `seed` acquired from nothing under the search's `finder`, as
/// `acquire_probe --limit-px 20` counts it, by the tracker's defaults. Every frame also
/// checks that the tracker's own configuration stays that, whatever the status machine does
/// to it meanwhile.
pub fn acquire_mono(seed: u64, finder: FinderConfig) -> MonoRun {
    let dir = tempfile::tempdir().unwrap();
    let sequence = super::seeded(dir.path(), "random-mono", seed, WITHIN_FRAMES + HELD_FRAMES);
    let truth = frames::truth_states(&sequence);
    let own = TrackerConfig::default();
    let (mut auto, mut bufs) = searching_with(&sequence, AcquireConfig::default(), own);
    auto.set_finder(finder);
    let mut errors = Vec::new();
    let mut palm_errors_mm = Vec::new();
    let mut accepted = None;
    let mut carried = Vec::new();
    let mut most_hypotheses = 0;
    for (k, true_state) in truth.iter().enumerate() {
        let images = frames::images(&sequence, k);
        let mut b: Vec<&mut [u8]> = bufs.iter_mut().map(|b| b.as_mut_slice()).collect();
        let r = auto.step(&frames::views(&images), &mut b).unwrap();
        assert_eq!(
            *auto.tracker().config(),
            own,
            "seed {seed} frame {k}: the tracker's own configuration, prior and all"
        );
        most_hypotheses = most_hypotheses.max(auto.hypotheses().len());
        let eye = sequence.cameras[0].centre();
        carried.push(
            auto.hypotheses()
                .iter()
                .map(|h| {
                    let p = &h.memory.state[TRANSLATION];
                    let depth_mm = (Vector3::new(p[0], p[1], p[2]) - eye).norm();
                    (depth_mm, h.ranked_score.unwrap_or(h.score))
                })
                .collect(),
        );
        if r.accepted && accepted.is_none() {
            accepted = Some(k);
        }
        let claimed = r.status != Status::Searching && !r.report.lost;
        errors.push(
            claimed.then(|| {
                tip_error_px(&sequence.model, &sequence.cameras, auto.state(), true_state)
            }),
        );
        palm_errors_mm.push(claimed.then(|| palm_error_mm(auto.state(), true_state)));
    }
    let on_hand: Vec<bool> = errors
        .iter()
        .map(|e| e.is_some_and(|e| e < ON_HAND_PX))
        .collect();
    let held = (0..WITHIN_FRAMES).find(|&k| {
        on_hand
            .get(k..k + HELD_FRAMES)
            .is_some_and(|run| run.iter().all(|&b| b))
    });
    MonoRun {
        held,
        errors,
        palm_errors_mm,
        accepted,
        carried,
        most_hypotheses,
    }
}

/// Prints each labelled run's claimed frames' tip errors for a test's log, one line each.
pub fn print_runs(seed: u64, runs: &[(&str, &[Option<f32>])]) {
    for (label, errors) in runs {
        println!("seed {seed} {label}: {}", format_errors(errors));
    }
}

/// Claimed frames' tip errors (px, one decimal) and `-` for the others, for a test's log.
pub fn format_errors(errors: &[Option<f32>]) -> String {
    errors
        .iter()
        .map(|e| e.map_or("-".into(), |e| format!("{e:.1}")))
        .collect::<Vec<_>>()
        .join(" ")
}

/// What a test of the library's finger poses needs on `fullhand-stereo`'s first frame (a
/// relaxed, slightly spread hand): the sequence, its true state (every model state), an
/// acquirer with the default search, and the frame as the likelihood sees it.
pub struct TrueFrame<'a> {
    pub sequence: &'a Sequence,
    pub truth: [f32; MAX_STATES],
    pub acquirer: Acquirer,
    pub scene: Scene<'a>,
}

/// Runs `test` on [`TrueFrame`].
pub fn on_the_true_first_frame(test: impl FnOnce(TrueFrame<'_>)) {
    let dir = tempfile::tempdir().unwrap();
    let sequence = super::seeded(dir.path(), "fullhand-stereo", 0, 1);
    let mut truth = [0.0f32; MAX_STATES];
    for (t, v) in truth
        .iter_mut()
        .zip(&sequence.read_truth().unwrap().rows[0])
    {
        *t = *v as f32;
    }
    let acquire = AcquireConfig::default();
    let images = frames::images(&sequence, 0);
    let views = frames::views(&images);
    let mut bufs = buffers(&sequence.cameras, acquire.likelihood.stride_px);
    let maps = edge_maps(&mut bufs, &views, &acquire.likelihood);
    test(TrueFrame {
        sequence: &sequence,
        truth,
        acquirer: acquirer(&sequence, acquire),
        scene: Scene::new(&sequence.model, &sequence.cameras, &views, &maps),
    });
}
