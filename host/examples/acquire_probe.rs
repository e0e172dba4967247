//! How well the search finds the hand from nothing, over seeds of the random rigs.
//!
//! Each seed is rendered as `random-mono` and `random-stereo` (at `--width`, 320×240 by
//! default) and run from no initial state through the core's status machine
//! (`AutoTracker`, what `track` and the board run): Searching → Tracking → Lost → Searching.
//! A rig is *acquired* at frame k when frames k..k+5 are all tracked with a mean fingertip
//! error within 10 px at 640 px wide (scaled to the width), and k < `--within`.
//!
//! It prints one row per run and a summary per rig, and can write every refined leaf's
//! judgement and its true error (`--leaves-csv`), and the judgements of leaves refined on
//! hand-free frames (`--hand-free N`): the distributions the acceptance thresholds are set
//! from (docs/recovery.md).
//!
//! With `--blackout A..B` it runs the blackout sweep instead: each seed rendered with frames
//! A..B without the hand, tracked from its initial state; a seed is re-acquired when
//! `HELD_FRAMES` frames in a row are tracked within the limit, starting within `--within`
//! frames of the hand's return.
//!
//! ```text
//! cargo run --release -p digiteyes-host --example acquire_probe -- --seeds 401..=440
//! cargo run --release -p digiteyes-host --example acquire_probe -- --seeds 501..=520 \
//!     --frames 200 --blackout 80..110
//! ```

use std::io::Write;
use std::ops::RangeInclusive;

#[path = "common/kept.rs"]
mod kept;
#[path = "common/motions.rs"]
mod motions;
use motions::render_seed;
#[path = "common/overrides.rs"]
mod overrides;

use anyhow::{anyhow, Result};
use clap::Parser;
use digiteyes_core::acquire::{
    AcceptConfig, AcquireConfig, Acquirer, Finder, FinderConfig, WorkingVolume,
};
use digiteyes_core::auto_tracker::{AutoTracker, Status};
use digiteyes_core::camera::Camera;
use digiteyes_core::config::MAX_STATES;
use digiteyes_core::estimator::Robust;
use digiteyes_core::frame::FrameView;
use digiteyes_core::likelihood::{EdgeMap, LikelihoodConfig, Scene, StateScorer};
use digiteyes_core::state::TRANSLATION;
use digiteyes_core::tracker::Tracker;
use digiteyes_host::bench::robustness::FAR_PALM_MM;
use digiteyes_host::render::hand_free::{hand_free, hand_free_frame, KINDS};
use digiteyes_host::scenarios::RenderOptions;
use digiteyes_host::sequence::Sequence;
use digiteyes_host::TrackerConfig;

/// Frames a claimed hand must be held, right, to count as acquired.
const HELD_FRAMES: usize = 5;

#[derive(Parser)]
struct Args {
    #[arg(long, value_parser = parse_range, default_value = "101..=110")]
    seeds: RangeInclusive<u64>,
    /// Rigs to run each seed on: mono, stereo or both.
    #[arg(long, default_value = "mono,stereo", value_delimiter = ',')]
    rigs: Vec<String>,
    #[arg(long, default_value_t = 40)]
    frames: usize,
    /// Acquired only if the held run starts before this frame.
    #[arg(long, default_value_t = 30)]
    within: usize,
    #[arg(long, default_value_t = 320)]
    width: u32,
    #[arg(long)]
    budget: Option<u16>,
    #[arg(long)]
    normals: Option<u8>,
    #[arg(long)]
    spins: Option<u8>,
    #[arg(long)]
    coarse_poses: Option<u8>,
    #[arg(long)]
    tree_levels: Option<u8>,
    #[arg(long)]
    tree_pose_levels: Option<u8>,
    /// The tree's first steps: palm turn (rad), depth (share of the depth, one camera).
    #[arg(long, value_parser = parse_pair)]
    tree_steps: Option<[f32; 2]>,
    #[arg(long)]
    rounds: Option<u8>,
    #[arg(long)]
    refine_seeds: Option<u8>,
    /// The coarse level's points per line and silhouette grid, e.g. 3,10.
    #[arg(long, value_delimiter = ',')]
    coarse_sampling: Option<Vec<u8>>,
    #[arg(long)]
    leaves_per_frame: Option<u8>,
    #[arg(long)]
    leaves: Option<u8>,
    #[arg(long)]
    passes: Option<u8>,
    #[arg(long)]
    min_score: Option<f32>,
    /// The search's likelihood weighs the reverse chamfer term by this (and the watch's).
    #[arg(long)]
    reverse_weight: Option<f32>,
    /// The local re-acquisition also starts from the library's best finger pose (true/false).
    #[arg(long)]
    local_library: Option<bool>,
    /// Local frames with the hand's region found before the global search (0: all 60).
    #[arg(long)]
    local_in_view: Option<u8>,
    /// Starts refined per local re-acquisition frame, at most.
    #[arg(long)]
    local_starts: Option<u8>,
    /// Re-place leaves on the frame they are refined on (true/false).
    #[arg(long)]
    replace: Option<bool>,
    /// Frames the accepted leaf is carried with the other leaves as hypotheses.
    #[arg(long)]
    confirm_frames: Option<u8>,
    /// Hypotheses carried while confirming.
    #[arg(long)]
    confirm_k: Option<u8>,
    /// Mean score over the confirming frames needed to keep the hand.
    #[arg(long)]
    confirm_min_score: Option<f32>,
    /// How far the worst camera's score may fall on the frame after an acceptance before the
    /// hand is claimed (negative: claimed on the accepting frame).
    #[arg(long, allow_hyphen_values = true)]
    probation_drop: Option<f32>,
    /// While confirming, how much more another hypothesis must score to replace the best.
    #[arg(long)]
    confirm_switch: Option<f32>,
    /// While confirming, how much of each hypothesis' past scores its rank keeps.
    #[arg(long)]
    confirm_memory: Option<f32>,
    /// How far the local re-acquisition moves the palm in depth with one camera (a share).
    #[arg(long)]
    local_depth_mono: Option<f32>,
    /// The confirm phase's weight on the depth of the last claimed state (0: off).
    #[arg(long)]
    held_weight: Option<f32>,
    /// The band past which that weight's penalty grows no more (a share of the depth).
    #[arg(long)]
    held_band: Option<f32>,
    /// How far the local re-acquisition's variants turn the palm (rad).
    #[arg(long)]
    local_turn: Option<f32>,
    /// Score a leaf refined with the accepted one needs to join it.
    #[arg(long)]
    alternative_score: Option<f32>,
    #[arg(long)]
    min_camera_score: Option<f32>,
    /// The score a leaf needs with one camera.
    #[arg(long)]
    one_camera_score: Option<f32>,
    /// The acceptance's bar on the worst camera's reverse chamfer term with two cameras (px;
    /// a large finite value computes it for `--leaves-csv` without refusing anything).
    #[arg(long)]
    max_reverse_px: Option<f32>,
    /// The same with one camera (px).
    #[arg(long)]
    one_camera_max_reverse_px: Option<f32>,
    /// The robust weight leaves are refined under: `huber=K`, `tukey=C` (px) or `none`.
    #[arg(long)]
    leaf_robust: Option<String>,
    /// The edge-direction limit leaves are refined under (degrees; 90: off, the default).
    #[arg(long)]
    leaf_angle_deg: Option<f32>,
    /// The tracker's own edge-direction limit (degrees; 90: off; default: the tracker's).
    #[arg(long)]
    angle_deg: Option<f32>,
    /// The tracker's Gauss–Newton iterations per frame (default: the tracker's).
    #[arg(long)]
    tracker_iterations: Option<u8>,
    /// The tracker's region rows gathered afresh on this many of a frame's first iterations
    /// (default: the tracker's).
    #[arg(long)]
    fill_gather: Option<u8>,
    #[command(flatten)]
    tracker: overrides::TrackerOverrides,
    /// Whether the leaves' refinement does (default: the search's, the plain step).
    #[arg(long)]
    leaf_bounded_step: Option<bool>,
    /// The share of the tracker's prior toward the predicted state the leaves' refinement
    /// keeps (1: the tracker's own; 0: none; default: the search's, by the rig's cameras).
    #[arg(long)]
    leaf_prior_share: Option<f32>,
    /// The same for the local re-acquisition's starts (default: the search's).
    #[arg(long)]
    local_prior_share: Option<f32>,
    /// Frames the tracker runs without its prior on the palm's position after an
    /// acquisition (default: the search's).
    #[arg(long)]
    settle_frames: Option<u8>,
    /// The confirm phase's depth variants of the accepted state, as a share of its distance,
    /// with one camera (default: the search's; two cameras keep theirs).
    #[arg(long)]
    confirm_depth: Option<f32>,
    /// The margin within which a hypothesis at a rival depth leaves a confirm frame
    /// unclaimed (default: the search's; negative: every frame claimed; `inf`: none while
    /// rivals are carried).
    #[arg(long, allow_hyphen_values = true)]
    confirm_rival_margin: Option<f32>,
    /// The score a refused leaf needs to be pursued: two cameras, one camera (`A,B`; default:
    /// the search's)
    #[arg(long, value_delimiter = ',')]
    pursue_score: Option<Vec<f32>>,
    /// Searching frames a refused leaf is pursued for: two cameras, one camera (`A,B`; 0:
    /// never; default: the search's)
    #[arg(long, value_delimiter = ',')]
    pursue_frames: Option<Vec<u8>>,
    /// The margin a confirm phase's best with each finger polished must score by to be
    /// carried for another phase: two cameras, one camera (`A,B`; negative: never; default:
    /// the search's).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    polish_margin: Option<Vec<f32>>,
    /// Write every refined leaf's judgement and true error here (CSV).
    #[arg(long)]
    leaves_csv: Option<std::path::PathBuf>,
    /// Also run this many hand-free frames (plain, noisy, cluttered, in turn) through the
    /// search with acceptance off, and write their leaves' judgements to the CSV.
    #[arg(long, default_value_t = 0)]
    hand_free: usize,
    /// Also run this many hand-free frames (the same kinds, in turn, each frame a new one)
    /// through the status machine with its own acceptance, from searching, and count the
    /// frames that claim a hand.
    #[arg(long, default_value_t = 0)]
    hand_free_status: usize,
    /// With --hand-free-status: a still scene instead (one cluttered background per run,
    /// `hand_free_status_run`'s `still` seed, with fresh noise ±8 on every frame), as a fixed
    /// camera over a cluttered desk sees it.
    #[arg(long)]
    hand_free_still: Option<u64>,
    /// Also start the tracker at the truth of frame 10 and report whether it holds the hand
    /// (within the limit) for the next 5 frames: the most any search could give.
    #[arg(long)]
    oracle: bool,
    /// Print each run's frame-by-frame statuses.
    #[arg(long)]
    verbose: bool,
    /// The fingertip error (px at 640 wide, scaled to `--width`) a frame must be within to
    /// count as right.
    #[arg(long, default_value_t = 10.0)]
    limit_px: f32,
    /// Print the best hypothesis' score and tip error on frames with several hypotheses; on
    /// every claimed frame, and for every refined leaf, the claim against the truth (both
    /// scored, the palm's offset and turn, the turn from the truth's depth-flipped reading,
    /// each finger's joint RMS); and the truth's own score every 10th frame. With
    /// `--blackout`: each of the 30 frames after the return, its claim (or, unclaimed, the
    /// truth) against the truth.
    #[arg(long)]
    trace: bool,
    /// The fingers' motion: `sweep` (the sweep's own), `off-centre` (each joint swinging near
    /// either end of its range) or `straight=S` (the sweep's, flexions shifted down by S of
    /// their range and clipped at 0); the rigs, noise, blur and light are each seed's own.
    #[arg(long, default_value = "sweep")]
    motion: motions::Motion,
    /// The blackout sweep instead: render frames A..B without the hand, track from the
    /// initial state, and report whether each seed is re-acquired within `--within` frames
    /// of the hand's return (use with `--frames 200`).
    #[arg(long, value_parser = parse_span)]
    blackout: Option<std::ops::Range<usize>>,
}

fn parse_span(s: &str) -> Result<std::ops::Range<usize>, String> {
    let (a, b) = s.split_once("..").ok_or("A..B")?;
    Ok(a.parse().map_err(|_| "A")?..b.parse().map_err(|_| "B")?)
}

fn parse_range(s: &str) -> Result<RangeInclusive<u64>, String> {
    let (a, b) = s.split_once("..=").ok_or("A..=B")?;
    Ok(a.parse().map_err(|_| "A")?..=b.parse().map_err(|_| "B")?)
}

/// Two numbers, `A,B`.
fn parse_pair(s: &str) -> Result<[f32; 2], String> {
    let (a, b) = s.split_once(',').ok_or("expected two numbers, A,B")?;
    let number = |t: &str| t.trim().parse::<f32>().map_err(|e| format!("{t}: {e}"));
    Ok([number(a)?, number(b)?])
}

fn configs(args: &Args) -> (AcquireConfig, FinderConfig) {
    let d = AcquireConfig::default();
    let acquire = AcquireConfig {
        evaluations_per_frame: args.budget.unwrap_or(d.evaluations_per_frame),
        normals: args.normals.unwrap_or(d.normals),
        spins: args.spins.unwrap_or(d.spins),
        coarse_poses: args.coarse_poses.unwrap_or(d.coarse_poses),
        tree_levels: args.tree_levels.unwrap_or(d.tree_levels),
        tree_pose_levels: args.tree_pose_levels.unwrap_or(d.tree_pose_levels),
        tree_steps: args.tree_steps.unwrap_or(d.tree_steps),
        refine_rounds: args.rounds.unwrap_or(d.refine_rounds),
        refine_seeds: args.refine_seeds.unwrap_or(d.refine_seeds),
        coarse_sampling: match args.coarse_sampling.as_deref() {
            Some([a, b]) => [*a, *b],
            _ => d.coarse_sampling,
        },
        likelihood: LikelihoodConfig {
            reverse_weight: args.reverse_weight.unwrap_or(d.likelihood.reverse_weight),
            ..d.likelihood
        },
        ..d
    };
    let f = FinderConfig::default();
    let finder = FinderConfig {
        leaves_per_frame: args.leaves_per_frame.unwrap_or(f.leaves_per_frame),
        leaves: args.leaves.unwrap_or(f.leaves),
        passes_per_leaf: args.passes.unwrap_or(f.passes_per_leaf),
        refine_iterations: f.refine_iterations,
        accept: AcceptConfig {
            min_score: args.min_score.unwrap_or(f.accept.min_score),
            min_camera_score: args.min_camera_score.unwrap_or(f.accept.min_camera_score),
            one_camera_score: args.one_camera_score.unwrap_or(f.accept.one_camera_score),
            max_reverse_px: args.max_reverse_px.unwrap_or(f.accept.max_reverse_px),
            one_camera_max_reverse_px: args
                .one_camera_max_reverse_px
                .unwrap_or(f.accept.one_camera_max_reverse_px),
        },
        replace_leaves: args.replace.unwrap_or(f.replace_leaves),
        confirm_frames: args.confirm_frames.unwrap_or(f.confirm_frames),
        confirm_hypotheses: args.confirm_k.unwrap_or(f.confirm_hypotheses),
        alternative_score: args.alternative_score.unwrap_or(f.alternative_score),
        confirm_min_score: args.confirm_min_score.unwrap_or(f.confirm_min_score),
        leaf_robust: args
            .leaf_robust
            .as_deref()
            .map_or(f.leaf_robust, robust_weight),
        leaf_max_edge_angle_rad: args
            .leaf_angle_deg
            .map_or(f.leaf_max_edge_angle_rad, f32::to_radians),
        leaf_bounded_step: args.leaf_bounded_step.unwrap_or(f.leaf_bounded_step),
        leaf_prior_share: args.leaf_prior_share.map_or(f.leaf_prior_share, |v| [v, v]),
        local_prior_share: args.local_prior_share.unwrap_or(f.local_prior_share),
        local_library_pose: args.local_library.unwrap_or(f.local_library_pose),
        local_starts: args.local_starts.unwrap_or(f.local_starts),
        local_frames_in_view: args.local_in_view.unwrap_or(f.local_frames_in_view),
        probation_max_drop: match args.probation_drop {
            Some(d) if d < 0.0 => None,
            Some(d) => Some(d),
            None => f.probation_max_drop,
        },
        local_turn_rad: args.local_turn.unwrap_or(f.local_turn_rad),
        local_depth_share: [
            f.local_depth_share[0],
            args.local_depth_mono.unwrap_or(f.local_depth_share[1]),
        ],
        confirm_held_weight: args.held_weight.unwrap_or(f.confirm_held_weight),
        confirm_held_band: args.held_band.unwrap_or(f.confirm_held_band),
        confirm_switch_margin: args.confirm_switch.unwrap_or(f.confirm_switch_margin),
        confirm_score_memory: args.confirm_memory.unwrap_or(f.confirm_score_memory),
        settle_frames: args.settle_frames.unwrap_or(f.settle_frames),
        confirm_depth_share: [
            f.confirm_depth_share[0],
            args.confirm_depth.unwrap_or(f.confirm_depth_share[1]),
        ],
        confirm_rival_share: f.confirm_rival_share,
        confirm_rival_margin: args.confirm_rival_margin.unwrap_or(f.confirm_rival_margin),
        pursue_score: match args.pursue_score.as_deref() {
            Some([two, one]) => [*two, *one],
            _ => f.pursue_score,
        },
        pursue_frames: match args.pursue_frames.as_deref() {
            Some([two, one]) => [*two, *one],
            _ => f.pursue_frames,
        },
        polish_margin: match args.polish_margin.as_deref() {
            Some([two, one]) => [*two, *one],
            _ => f.polish_margin,
        },
    };
    (acquire, finder)
}

/// The tracker's configuration for every run, set once in `main` from the arguments.
static TRACKER: std::sync::OnceLock<TrackerConfig> = std::sync::OnceLock::new();

/// The tracker's defaults with `--angle-deg`, `--tracker-iterations`, `--fill-gather` and the
/// shared overrides (`common/overrides.rs`) where given.
fn tracker_config_from(args: &Args) -> TrackerConfig {
    let mut config = TrackerConfig::default();
    if let Some(degrees) = args.angle_deg {
        config.features.max_edge_angle_rad = degrees.to_radians();
    }
    config.iterations = args.tracker_iterations.unwrap_or(config.iterations);
    let fill = &mut config.fill;
    fill.gather_iterations = args.fill_gather.unwrap_or(fill.gather_iterations);
    args.tracker.apply(&mut config);
    config
}

/// The tracker's configuration for this run (the defaults until `main` sets it).
fn tracker_config() -> TrackerConfig {
    TRACKER.get().copied().unwrap_or_default()
}

/// `huber=K`, `tukey=C` or `none`; anything else is the default leaves' weight.
fn robust_weight(text: &str) -> Robust {
    let value = |s: &str| s.parse::<f32>().ok().filter(|v| *v > 0.0);
    match text.split_once('=') {
        Some(("huber", k)) => value(k).map_or(FinderConfig::default().leaf_robust, Robust::Huber),
        Some(("tukey", c)) => value(c).map_or(FinderConfig::default().leaf_robust, Robust::Tukey),
        _ if text == "none" => Robust::None,
        _ => FinderConfig::default().leaf_robust,
    }
}

/// One run's outcome.
struct Run {
    acquired: Option<usize>,
    /// Tip error (px) of the leaf accepted first, and its frame.
    first_claim: Option<(usize, f32)>,
    /// Frames claimed with a tip error over the limit.
    wrong_frames: usize,
    /// Frames claimed with the palm over [`FAR_PALM_MM`] from the truth.
    far_frames: usize,
    /// Frames claimed.
    claimed_frames: usize,
    evaluations: u64,
    refined: u32,
}

/// Other likelihoods than the search's, for the leaves CSV: (stride, cap, samples per line,
/// silhouette grid, reverse term's weight). The last is the search's with the reverse
/// chamfer term at weight 1.
const FINE: [(u8, f32, u8, u8, f32); 5] = [
    (2, 12.0, 12, 16, 0.0),
    (4, 24.0, 6, 48, 0.0),
    (1, 8.0, 12, 48, 0.0),
    (2, 8.0, 12, 48, 0.0),
    (4, 24.0, 6, 16, 1.0),
];

/// `q` scored under each of [`FINE`]: ",mean,worst" per config.
fn fine_columns(sequence: &Sequence, views: &[FrameView<'_>], q: &[f32]) -> Result<String> {
    let mut out = String::new();
    let mut scorer = StateScorer::new();
    for &(stride, cap, per_line, grid, reverse) in &FINE {
        let config = LikelihoodConfig {
            stride_px: stride,
            chamfer_cap_px: cap,
            samples_per_line: per_line,
            silhouette_grid: grid,
            reverse_weight: reverse,
            ..LikelihoodConfig::default()
        };
        let mut bufs: Vec<Vec<u8>> = sequence
            .cameras
            .iter()
            .map(|c| vec![0u8; EdgeMap::bytes_needed(c.width as usize, c.height as usize, stride)])
            .collect();
        let maps: Vec<EdgeMap<'_>> = bufs
            .iter_mut()
            .zip(views)
            .map(|(b, v)| EdgeMap::build(b, v, &config).map_err(|e| anyhow!("{e}")))
            .collect::<Result<_>>()?;
        let scene = Scene::new(&sequence.model, &sequence.cameras, views, &maps);
        let (mean, worst) = scorer.score_cameras(&scene, q, &config);
        out.push_str(&format!(",{mean:.4},{worst:.4}"));
    }
    Ok(out)
}

/// How a claimed state `q` differs from the truth: the search's likelihood of each (mean,
/// worst camera), the palm's offset (mm) and turn (deg), the joints' RMS (deg).
fn claim_against_truth(
    sequence: &Sequence,
    views: &[FrameView<'_>],
    q: &[f32],
    truth: &[f32],
    acquire: &AcquireConfig,
) -> Result<String> {
    let mut bufs = buffers(&sequence.cameras, acquire);
    let maps = kept::edge_maps(&mut bufs, views, &acquire.likelihood)?;
    let mut scorer = StateScorer::new();
    let scene = Scene::new(&sequence.model, &sequence.cameras, views, &maps);
    let mut score = |s: &[f32]| scorer.score_cameras(&scene, s, &acquire.likelihood);
    let (claim_mean, claim_worst) = score(q);
    let (truth_mean, truth_worst) = score(truth);
    let palm_mm = (4..7)
        .map(|i| (q[i] - truth[i]).powi(2))
        .sum::<f32>()
        .sqrt();
    let turn_deg = digiteyes_core::quaternion::angle_between(
        [q[0], q[1], q[2], q[3]],
        [truth[0], truth[1], truth[2], truth[3]],
    )
    .to_degrees();
    let joints = &q[7..q.len().min(truth.len())];
    let joint_rms_deg = (joints
        .iter()
        .zip(&truth[7..])
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f32>()
        / joints.len().max(1) as f32)
        .sqrt()
        .to_degrees();
    let relative = nalgebra::Rotation3::from_matrix_unchecked(
        digiteyes_core::quaternion::rotation(truth[0], truth[1], truth[2], truth[3]).transpose()
            * digiteyes_core::quaternion::rotation(q[0], q[1], q[2], q[3]),
    );
    let axis = match relative.axis() {
        Some(a) => format!("{:.2},{:.2},{:.2}", a.x, a.y, a.z),
        None => "-".to_string(),
    };
    let flip_deg = digiteyes_core::quaternion::angle_between(
        [q[0], q[1], q[2], q[3]],
        depth_flipped(&sequence.cameras[0], truth),
    )
    .to_degrees();
    let offset: Vec<String> = (4..7).map(|i| format!("{:.0}", q[i] - truth[i])).collect();
    let fingers: Vec<String> = [7..11, 11..15, 15..19, 19..23, 23..28]
        .into_iter()
        .filter(|r| r.end <= q.len().min(truth.len()))
        .map(|r| {
            let n = r.len() as f32;
            let rms = (r.map(|i| (q[i] - truth[i]).powi(2)).sum::<f32>() / n).sqrt();
            format!("{:.0}", rms.to_degrees())
        })
        .collect();
    Ok(format!(
        "claim {claim_mean:.3}/{claim_worst:.3} truth {truth_mean:.3}/{truth_worst:.3} \
         palm {palm_mm:.1} mm ({}) turn {turn_deg:.1} deg about ({axis}) in the palm (flip {flip_deg:.1}) joints {joint_rms_deg:.1} deg \
         fingers {}",
        offset.join(","),
        fingers.join("/")
    ))
}

/// The palm's rotation of `q` mirrored in depth as `camera` sees it: reflected through the
/// plane across the camera's ray to the palm, and through the palm's own plane (so it stays a
/// rotation) — the reading one view can hardly tell from `q`.
fn depth_flipped(camera: &Camera, q: &[f32]) -> [f32; 4] {
    use nalgebra::{Matrix3, Vector3};
    let world = digiteyes_core::quaternion::rotation(q[0], q[1], q[2], q[3]);
    let centre = camera.r * Vector3::new(q[4], q[5], q[6]) + camera.t;
    let ray = centre.normalize();
    let across_ray = Matrix3::identity() - 2.0 * ray * ray.transpose();
    let across_palm = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0));
    let flipped = camera.r.transpose() * across_ray * camera.r * world * across_palm;
    digiteyes_core::quaternion::from_rotation(&flipped)
}

fn buffers(cameras: &[Camera], acquire: &AcquireConfig) -> Vec<Vec<u8>> {
    cameras
        .iter()
        .map(|c| {
            vec![
                0u8;
                EdgeMap::bytes_needed(
                    c.width as usize,
                    c.height as usize,
                    acquire.likelihood.stride_px
                )
            ]
        })
        .collect()
}

fn new_finder(sequence: &Sequence, base: &[f32], args: &Args) -> Result<(Tracker, Finder)> {
    let (acquire, finder) = configs(args);
    let tracker = Tracker::new(
        sequence.model.clone(),
        &sequence.cameras,
        base,
        sequence.free_mask(),
        tracker_config(),
    )
    .map_err(|e| anyhow!("{e}"))?;
    let volume = WorkingVolume::from_cameras(&sequence.cameras, 600.0);
    let acquirer = Acquirer::new(tracker.model(), base, tracker.free(), volume, acquire);
    Ok((tracker, Finder::new(acquirer, finder)))
}

/// The core's status machine for `sequence`: searching from the identity palm at the origin,
/// or (`initial`) tracking from a known state.
fn auto_tracker(sequence: &Sequence, args: &Args, initial: Option<&[f32]>) -> Result<AutoTracker> {
    let (acquire, finder) = configs(args);
    let mut base = vec![0.0f32; sequence.n_states()];
    base[0] = 1.0;
    let mut auto = match initial {
        None => AutoTracker::new(
            sequence.model.clone(),
            &sequence.cameras,
            &base,
            sequence.free_mask(),
            tracker_config(),
            acquire,
        ),
        Some(q) => AutoTracker::tracking(
            sequence.model.clone(),
            &sequence.cameras,
            q,
            sequence.free_mask(),
            tracker_config(),
            acquire,
        ),
    }
    .map_err(|e| anyhow!("{e}"))?;
    auto.set_finder(finder);
    Ok(auto)
}

/// One frame through the status machine: its report, whether it claims the hand, and the
/// claimed state's tip error (infinite when not claimed).
fn step_frame(
    sequence: &Sequence,
    auto: &mut AutoTracker,
    bufs: &mut [Vec<u8>],
    k: usize,
    truth_k: &[f32],
) -> Result<(digiteyes_core::auto_tracker::AutoReport, bool, f32)> {
    let images = kept::read_instant(sequence, k)?;
    let views = kept::views(&images)?;
    let mut buffers: Vec<&mut [u8]> = bufs.iter_mut().map(|b| b.as_mut_slice()).collect();
    let report = auto
        .step(&views, &mut buffers)
        .map_err(|e| anyhow!("{e}"))?;
    let claimed = report.status != Status::Searching && !report.report.lost;
    let e = if claimed {
        kept::tip_error_px(&sequence.model, &sequence.cameras, auto.state(), truth_k)
    } else {
        f32::INFINITY
    };
    Ok((report, claimed, e))
}

/// The character a frame's status is drawn as (`--verbose`).
fn status_char(report: &digiteyes_core::auto_tracker::AutoReport, was: Status) -> char {
    match (was, report.status) {
        (Status::Searching, Status::Tracking) => 'F',
        (_, Status::Tracking) => 't',
        (_, Status::Lost) => 'l',
        (_, Status::Searching) if report.local => 'L',
        (_, Status::Searching) if report.leaf_score.is_some() => 'r',
        (_, Status::Searching) => '.',
    }
}

fn run(
    sequence: &Sequence,
    args: &Args,
    label: &str,
    csv: &mut Option<std::fs::File>,
) -> Result<Run> {
    let truth = sequence.read_truth()?;
    let (acquire, _) = configs(args);
    let mut auto = auto_tracker(sequence, args, None)?;
    let limit = args.limit_px * args.width as f32 / 640.0;
    let mut bufs = buffers(&sequence.cameras, &acquire);
    let mut good = Vec::new();
    let mut out = Run {
        acquired: None,
        first_claim: None,
        wrong_frames: 0,
        far_frames: 0,
        claimed_frames: 0,
        evaluations: 0,
        refined: 0,
    };
    let mut line = String::new();
    for k in 0..sequence.frames {
        let truth_k: Vec<f32> = truth.rows[k].iter().map(|&v| v as f32).collect();
        let was = auto.status();
        let (report, claimed, e) = step_frame(sequence, &mut auto, &mut bufs, k, &truth_k)?;
        if was == Status::Searching && !report.local {
            out.evaluations += u64::from(report.evaluated);
            if args.trace && report.accepted {
                let by_leaf = auto.finder().last_leaf().is_some_and(|(v, _)| v.accepted);
                let q = auto.tracker().state();
                let e = kept::tip_error_px(&sequence.model, &sequence.cameras, q, &truth_k);
                eprintln!(
                    "acceptance {label} {k} {} score {:.3} tip {e:.1} px",
                    if by_leaf { "leaf" } else { "pursued" },
                    report.leaf_score.unwrap_or(0.0)
                );
            }
            if report.leaf_score.is_some() {
                out.refined += 1;
            }
            if let (true, true, Some((verdict, q))) = (
                args.trace,
                report.leaf_score.is_some(),
                auto.finder().last_leaf(),
            ) {
                let n = sequence.n_states();
                let images = kept::read_instant(sequence, k)?;
                let views = kept::views(&images)?;
                let e = kept::tip_error_px(&sequence.model, &sequence.cameras, &q[..n], &truth_k);
                eprintln!(
                    "leaf {label} {k} accepted {} tip {e:.1} px {}",
                    u8::from(verdict.accepted),
                    claim_against_truth(sequence, &views, &q[..n], &truth_k, &acquire)?
                );
            }
            if let (Some((verdict, q)), Some(f)) = (auto.finder().last_leaf(), csv.as_mut()) {
                let n = sequence.n_states();
                let e = kept::tip_error_px(&sequence.model, &sequence.cameras, &q[..n], &truth_k);
                let images = kept::read_instant(sequence, k)?;
                let views = kept::views(&images)?;
                let fine = fine_columns(sequence, &views, &q[..n])?;
                writeln!(
                    f,
                    "{label},{k},{:.4},{:.4},{},{},{e:.2}{fine},{}",
                    verdict.score,
                    verdict.worst_camera,
                    u8::from(verdict.lost),
                    u8::from(verdict.accepted),
                    verdict
                        .reverse_px
                        .map_or(String::new(), |px| format!("{px:.2}"))
                )?;
            }
        }
        line.push(status_char(&report, was));
        if args.trace && (k % 10 == 0 || claimed) {
            let images = kept::read_instant(sequence, k)?;
            let views = kept::views(&images)?;
            if k % 10 == 0 {
                eprintln!(
                    "truth {label} {k} {}",
                    claim_against_truth(sequence, &views, &truth_k, &truth_k, &acquire)?
                );
            }
            if claimed {
                eprintln!(
                    "claim {label} {k} tip {e:.1} px {} hypotheses {}",
                    claim_against_truth(sequence, &views, auto.state(), &truth_k, &acquire)?,
                    report.hypotheses
                );
            }
        }
        if args.trace && report.hypotheses > 1 {
            let each: Vec<String> = auto
                .hypotheses()
                .iter()
                .map(|h| {
                    let tip = kept::tip_error_px(
                        &sequence.model,
                        &sequence.cameras,
                        &h.memory.state,
                        &truth_k,
                    );
                    format!("{:.3}:{tip:.1}", h.score)
                })
                .collect();
            eprintln!(
                "trace {label} {k} {} {:.4} {e:.2} [{}]",
                report.hypotheses,
                report.best_score,
                each.join(" ")
            );
        }
        if claimed && out.first_claim.is_none() {
            out.first_claim = Some((k, e));
        }
        out.claimed_frames += usize::from(claimed);
        if claimed && e > limit {
            out.wrong_frames += 1;
        }
        let palm_mm = TRANSLATION
            .map(|i| (auto.state()[i] - truth_k[i]).powi(2))
            .sum::<f32>()
            .sqrt();
        // A palm not a number counts as far.
        if claimed && (palm_mm.is_nan() || f64::from(palm_mm) > FAR_PALM_MM) {
            out.far_frames += 1;
        }
        good.push(claimed && e <= limit);
    }
    out.acquired = (0..good.len().saturating_sub(HELD_FRAMES - 1))
        .filter(|&k| k < args.within)
        .find(|&k| good[k..k + HELD_FRAMES].iter().all(|&g| g));
    if args.verbose {
        eprintln!("{label}: {line}");
    }
    Ok(out)
}

/// One blackout run's outcome.
struct BlackoutRun {
    /// Tracked up to the blackout: no [`HELD_FRAMES`] frames in a row over the limit before it.
    tracked_to_dark: bool,
    /// Frames after the hand's return until the first of [`HELD_FRAMES`] tracked frames in a
    /// row within the limit (when within `--within`).
    reacquired_after: Option<usize>,
    /// Frames without the hand that claimed it.
    dark_claimed: usize,
    /// Searching frames.
    searching: usize,
    /// Claimed frames after the return with the palm over 30 mm and over 100 mm from the truth.
    palm_off: (usize, usize),
}

/// Tracks `sequence` from its initial state through the blackout `dark`.
fn blackout_run(
    sequence: &Sequence,
    args: &Args,
    dark: &std::ops::Range<usize>,
    label: &str,
) -> Result<BlackoutRun> {
    let truth = sequence.read_truth()?;
    let (acquire, _) = configs(args);
    let initial: Vec<f32> = sequence.initial_state.iter().map(|&v| v as f32).collect();
    let mut auto = auto_tracker(sequence, args, Some(&initial))?;
    let limit = args.limit_px * args.width as f32 / 640.0;
    let mut bufs = buffers(&sequence.cameras, &acquire);
    let (mut good, mut over) = (Vec::new(), Vec::new());
    let mut out = BlackoutRun {
        tracked_to_dark: false,
        reacquired_after: None,
        dark_claimed: 0,
        searching: 0,
        palm_off: (0, 0),
    };
    let mut line = String::new();
    let mut errors = String::new();
    for k in 0..sequence.frames {
        let truth_k: Vec<f32> = truth.rows[k].iter().map(|&v| v as f32).collect();
        let was = auto.status();
        let (report, claimed, e) = step_frame(sequence, &mut auto, &mut bufs, k, &truth_k)?;
        line.push(status_char(&report, was));
        if args.trace && k == 0 {
            if let Some(reference) = report.watch_score {
                eprintln!("{label}: watch reference {reference:.3}");
            }
        }
        if args.verbose
            && (k + 4 >= dark.start && k < dark.start || k >= dark.end && k < dark.end + 12)
        {
            errors.push_str(&format!(" {k}:{e:.1}"));
        }
        if args.verbose && (k + 1 == dark.start || k == dark.end + 10) {
            let st = auto.state();
            let d: Vec<String> = (0..st.len())
                .map(|i| {
                    let x = st[i] - truth_k[i];
                    if (4..7).contains(&i) {
                        format!("{x:.0}")
                    } else {
                        format!("{x:.2}")
                    }
                })
                .collect();
            eprintln!("{label}: frame {k} state - truth: {}", d.join(" "));
            let turn = digiteyes_core::quaternion::angle_between(
                [st[0], st[1], st[2], st[3]],
                [truth_k[0], truth_k[1], truth_k[2], truth_k[3]],
            );
            eprintln!(
                "{label}: frame {k} palm turned {:.0} deg",
                turn.to_degrees()
            );
        }
        if args.trace && k >= dark.end && k < dark.end + 30 {
            let images = kept::read_instant(sequence, k)?;
            let views = kept::views(&images)?;
            let held: &[f32] = if claimed { auto.state() } else { &truth_k };
            let claim = claim_against_truth(sequence, &views, held, &truth_k, &acquire)?;
            eprintln!(
                "{label} {k} {} tip {e:.1} px {claim} hypotheses {}",
                status_char(&report, was),
                report.hypotheses
            );
        }
        if dark.contains(&k) && claimed {
            out.dark_claimed += 1;
        }
        if report.status == Status::Searching {
            out.searching += 1;
        }
        if claimed && k >= dark.end {
            let st = auto.state();
            let palm_mm = (4..7)
                .map(|i| (st[i] - truth_k[i]).powi(2))
                .sum::<f32>()
                .sqrt();
            out.palm_off.0 += usize::from(palm_mm > 30.0);
            out.palm_off.1 += usize::from(palm_mm > 100.0);
        }
        good.push(claimed && e <= limit);
        over.push(!(claimed && e <= limit));
    }
    let a = dark.start.min(over.len());
    out.tracked_to_dark = !(0..a.saturating_sub(HELD_FRAMES - 1))
        .any(|k| over[k..k + HELD_FRAMES].iter().all(|&o| o));
    out.reacquired_after = (dark.end..good.len().saturating_sub(HELD_FRAMES - 1))
        .filter(|&k| k < dark.end + args.within)
        .find(|&k| good[k..k + HELD_FRAMES].iter().all(|&g| g))
        .map(|k| k - dark.end);
    if args.verbose {
        eprintln!("{label}: {line}");
        eprintln!("{label}: tip px{errors}");
    }
    Ok(out)
}

/// The blackout sweep: `random-stereo` and `random-mono` seeds through `--blackout`.
fn blackout_sweep(args: &Args, dark: &std::ops::Range<usize>) -> Result<()> {
    let dir = tempfile::tempdir()?;
    let (w, h) = (args.width, args.width * 3 / 4);
    println!("| seed | rig | tracked to the blackout | re-acquired after (frames) | dark frames claimed | searching frames | claimed, palm > 30 / 100 mm |");
    println!("|---|---|---|---|---|---|---|");
    for rig in &args.rigs {
        let mut runs = Vec::new();
        for seed in args.seeds.clone() {
            let seq = dir.path().join(format!("{rig}{seed}"));
            let options = RenderOptions {
                seed,
                frames: Some(args.frames),
                size: Some((w, h)),
                blackout: Some(dark.clone()),
                ..RenderOptions::default()
            };
            render_seed(seed, rig == "stereo", args.motion, &options, &seq)?;
            let sequence = Sequence::open(&seq)?;
            let r = blackout_run(&sequence, args, dark, &format!("{rig}-{seed}"))?;
            println!(
                "| {seed} | {rig} | {} | {} | {} | {} | {} / {} |",
                r.tracked_to_dark,
                r.reacquired_after.map_or("never".into(), |k| k.to_string()),
                r.dark_claimed,
                r.searching,
                r.palm_off.0,
                r.palm_off.1
            );
            std::fs::remove_dir_all(&seq)?;
            runs.push(r);
        }
        let tracked: Vec<&BlackoutRun> = runs.iter().filter(|r| r.tracked_to_dark).collect();
        let mut after: Vec<usize> = tracked.iter().filter_map(|r| r.reacquired_after).collect();
        after.sort();
        let all: usize = runs.iter().filter(|r| r.reacquired_after.is_some()).count();
        let claimed: usize = runs.iter().map(|r| r.dark_claimed).sum();
        let off30: usize = runs.iter().map(|r| r.palm_off.0).sum();
        let off100: usize = runs.iter().map(|r| r.palm_off.1).sum();
        println!(
            "{rig}: tracked to the blackout {}/{}; of those re-acquired {}/{} (frames after the \
             return: {after:?}); re-acquired over all seeds {all}/{}; dark frames claimed \
             {claimed}; claimed after the return with the palm over 30 mm {off30}, over 100 mm \
             {off100}",
            tracked.len(),
            runs.len(),
            after.len(),
            tracked.len(),
            runs.len(),
        );
    }
    Ok(())
}

/// Whether the tracker started at the truth of frame `start` holds the hand within `limit`
/// for [`HELD_FRAMES`] frames (the first tracked on `start` itself).
fn oracle_holds(sequence: &Sequence, start: usize, limit: f32) -> Result<bool> {
    let truth = sequence.read_truth()?;
    let q: Vec<f32> = truth.rows[start].iter().map(|&v| v as f32).collect();
    let mut tracker = Tracker::new(
        sequence.model.clone(),
        &sequence.cameras,
        &q,
        sequence.free_mask(),
        tracker_config(),
    )
    .map_err(|e| anyhow!("{e}"))?;
    for k in start..start + HELD_FRAMES {
        let images: Vec<_> = (0..sequence.cameras.len())
            .map(|c| sequence.read_frame(c, k))
            .collect::<Result<_>>()?;
        let views = kept::views(&images)?;
        let report = tracker.track(&views).map_err(|e| anyhow!("{e}"))?;
        let t: Vec<f32> = truth.rows[k].iter().map(|&v| v as f32).collect();
        let e = kept::tip_error_px(&sequence.model, &sequence.cameras, tracker.state(), &t);
        if report.lost || e > limit {
            return Ok(false);
        }
    }
    Ok(true)
}

/// Frame `k` of a still hand-free scene for every camera of `sequence`: the cluttered
/// background `scene` (its grey and bars fixed), with noise ±8 drawn afresh for frame `k`.
fn still_frames(sequence: &Sequence, scene: u64, k: usize) -> Vec<Vec<u8>> {
    sequence
        .cameras
        .iter()
        .enumerate()
        .map(|(c, cam)| {
            let grey = 30 + (scene as usize * 7 % 40) as u8;
            let mut pixels = hand_free(
                cam.width as usize,
                cam.height as usize,
                grey,
                0,
                true,
                scene * 4 + c as u64,
            );
            let mut state = (k as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ c as u64;
            for p in &mut pixels {
                state = state
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                let n = ((state >> 33) % 17) as i32 - 8;
                *p = (i32::from(*p) + n).clamp(0, 255) as u8;
            }
            pixels
        })
        .collect()
}

/// Hand-free frame `k` of every camera of `sequence` ([`hand_free_frame`]: its kind, grey
/// and clutter set by `k` and the camera).
fn hand_free_frames(sequence: &Sequence, k: usize) -> Vec<Vec<u8>> {
    let sizes: Vec<(usize, usize)> = sequence
        .cameras
        .iter()
        .map(|c| (c.width as usize, c.height as usize))
        .collect();
    hand_free_frame(&sizes, k)
}

/// Views of one hand-free frame per camera.
fn hand_free_views<'a>(sequence: &Sequence, frames: &'a [Vec<u8>]) -> Result<Vec<FrameView<'a>>> {
    Ok(frames
        .iter()
        .zip(&sequence.cameras)
        .map(|(p, c)| FrameView::packed(p, c.width as usize, c.height as usize))
        .collect::<Result<_, _>>()?)
}

/// Hand-free frames through the search with acceptance off: every leaf's judgement.
fn hand_free_run(sequence: &Sequence, args: &Args, csv: &mut Option<std::fs::File>) -> Result<f32> {
    let mut base = vec![0.0f32; sequence.n_states()];
    base[0] = 1.0;
    let (acquire, _) = configs(args);
    let mut args_off = Args::parse_from(["probe"]);
    args_off.min_score = Some(2.0);
    args_off.budget = Some(u16::MAX);
    args_off.leaves_per_frame = Some(8);
    args_off.leaves = args.leaves;
    let (mut tracker, mut finder) = new_finder(sequence, &base, &args_off)?;
    let mut bufs = buffers(&sequence.cameras, &acquire);
    let mut worst = 0.0f32;
    // The names of hand_free::KINDS, in its order.
    let names = ["plain", "noisy", "cluttered", "clutter"];
    let mut k = 0;
    while k < args.hand_free {
        let kind = names[k % KINDS.len()];
        let frames = hand_free_frames(sequence, k);
        let views = hand_free_views(sequence, &frames)?;
        // The search to its end on this frame, then its leaves on the same frame.
        loop {
            let maps = kept::edge_maps(&mut bufs, &views, &acquire.likelihood)?;
            finder
                .step(&mut tracker, &views, &maps)
                .map_err(|e| anyhow!("{e}"))?;
            if let Some((verdict, q)) = finder.last_leaf() {
                worst = worst.max(verdict.score);
                if let Some(f) = csv.as_mut() {
                    let fine = fine_columns(sequence, &views, &q[..sequence.n_states()])?;
                    writeln!(
                        f,
                        "hand-free-{kind}-{},{k},{:.4},{:.4},{},0,inf{fine},{}",
                        sequence.cameras.len(),
                        verdict.score,
                        verdict.worst_camera,
                        u8::from(verdict.lost),
                        verdict
                            .reverse_px
                            .map_or(String::new(), |px| format!("{px:.2}"))
                    )?;
                }
                break;
            }
        }
        finder.restart();
        k += 1;
    }
    Ok(worst)
}

/// `frames` hand-free frames through the status machine, from searching, with its own
/// acceptance: the frames that claim a hand, and the best leaf score any frame refined.
fn hand_free_status_run(sequence: &Sequence, args: &Args, frames: usize) -> Result<(usize, f32)> {
    let (acquire, _) = configs(args);
    let mut auto = auto_tracker(sequence, args, None)?;
    let mut bufs = buffers(&sequence.cameras, &acquire);
    let (mut claimed, mut best) = (0, 0.0f32);
    for k in 0..frames {
        let (noise, clutter) = KINDS[k % KINDS.len()];
        let images = match args.hand_free_still {
            Some(scene) => still_frames(sequence, scene, k),
            None => hand_free_frames(sequence, k),
        };
        let views = hand_free_views(sequence, &images)?;
        let mut buffers: Vec<&mut [u8]> = bufs.iter_mut().map(|b| b.as_mut_slice()).collect();
        let report = auto
            .step(&views, &mut buffers)
            .map_err(|e| anyhow!("{e}"))?;
        if args.trace && report.accepted {
            eprintln!(
                "hand-free acceptance {k} score {:.3}",
                report.leaf_score.unwrap_or(0.0)
            );
        }
        if report.status != Status::Searching && !report.report.lost {
            claimed += 1;
            eprintln!(
                "  claimed hand-free frame {k} (noise {noise}, clutter {clutter}): best score {:.3}",
                report.best_score
            );
        }
        best = best.max(report.leaf_score.unwrap_or(0.0));
    }
    Ok((claimed, best))
}

fn main() -> Result<()> {
    let args = Args::parse();
    let _ = TRACKER.set(tracker_config_from(&args));
    if let Some(dark) = args.blackout.clone() {
        return blackout_sweep(&args, &dark);
    }
    let dir = tempfile::tempdir()?;
    let (w, h) = (args.width, args.width * 3 / 4);
    let mut csv = match &args.leaves_csv {
        Some(p) => {
            let mut f = std::fs::File::create(p)?;
            writeln!(f, "run,frame,score,worst_camera,lost,accepted,tip_error_px,f1,f1w,f2,f2w,f3,f3w,f4,f4w,rev,revw,reverse_px")?;
            Some(f)
        }
        None => None,
    };
    println!("| seed | rig | acquired at | first claim (frame: tip px) | wrong frames | evaluations | leaves refined |");
    println!("|---|---|---|---|---|---|---|");
    let mut summary: Vec<(String, Vec<Run>)> =
        args.rigs.iter().map(|r| (r.clone(), Vec::new())).collect();
    for seed in args.seeds.clone() {
        for (rig, runs) in summary.iter_mut() {
            let seq = dir.path().join(format!("{rig}{seed}"));
            let options = RenderOptions {
                seed,
                frames: Some(args.frames),
                size: Some((w, h)),
                ..RenderOptions::default()
            };
            render_seed(seed, rig == "stereo", args.motion, &options, &seq)?;
            let sequence = Sequence::open(&seq)?;
            let r = run(&sequence, &args, &format!("{rig}-{seed}"), &mut csv)?;
            if args.oracle {
                let held = oracle_holds(&sequence, 10, args.limit_px * args.width as f32 / 640.0)?;
                eprintln!("{rig}-{seed}: from the truth at frame 10, held: {held}");
            }
            println!(
                "| {seed} | {rig} | {} | {} | {} | {} | {} |",
                r.acquired.map_or("never".into(), |k| k.to_string()),
                r.first_claim
                    .map_or("-".into(), |(k, e)| format!("{k}: {e:.1}")),
                r.wrong_frames,
                r.evaluations,
                r.refined
            );
            if seed == *args.seeds.start() && args.hand_free > 0 {
                let worst = hand_free_run(&sequence, &args, &mut csv)?;
                eprintln!(
                    "{rig}: {} hand-free frames, best leaf score {worst:.3}",
                    args.hand_free
                );
            }
            if seed == *args.seeds.start() && args.hand_free_status > 0 {
                let (claimed, best) =
                    hand_free_status_run(&sequence, &args, args.hand_free_status)?;
                eprintln!(
                    "{rig}: {} hand-free frames through the status machine, {claimed} claimed; best leaf score {best:.3}",
                    args.hand_free_status
                );
            }
            std::fs::remove_dir_all(&seq)?;
            runs.push(r);
        }
    }
    for (rig, runs) in &summary {
        let n = runs.len();
        let mut frames: Vec<usize> = runs.iter().filter_map(|r| r.acquired).collect();
        frames.sort();
        let mut errors: Vec<f32> = runs
            .iter()
            .filter_map(|r| r.first_claim.map(|(_, e)| e))
            .collect();
        errors.sort_by(f32::total_cmp);
        let wrong: usize = runs.iter().map(|r| r.wrong_frames).sum();
        let far: usize = runs.iter().map(|r| r.far_frames).sum();
        let claimed: usize = runs.iter().map(|r| r.claimed_frames).sum();
        let pct = |v: &[usize], p: usize| v.get((v.len().max(1) - 1) * p / 100).copied();
        println!(
            "{rig}: acquired {}/{n} ({:.0} %); frames to acquire: min {:?}, median {:?}, max {:?}; \
             first claim's tip error (px at {w}): median {:?}, max {:?}; {} of {n} runs claimed; \
             of {claimed} claimed frames {wrong} wrong, {far} far (palm over {FAR_PALM_MM} mm)",
            frames.len(),
            100.0 * frames.len() as f32 / n.max(1) as f32,
            frames.first(),
            pct(&frames, 50),
            frames.last(),
            errors.get(errors.len() / 2),
            errors.last(),
            errors.len(),
        );
    }
    let _ = MAX_STATES;
    Ok(())
}
