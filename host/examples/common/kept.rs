//! The sequences `bench robustness --keep DIR` kept, as the study examples read them.
#![allow(dead_code)] // each example uses part of it

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Result};
use digiteyes_core::camera::Camera;
use digiteyes_core::estimator::{ResidualKind, Robust};
use digiteyes_core::frame::FrameView;
use digiteyes_core::hypotheses::fingers::Fingers;
use digiteyes_core::kinematics::Poses;
use digiteyes_core::likelihood::{EdgeMap, LikelihoodConfig};
use digiteyes_core::model::{Model, Shape};
use digiteyes_host::bench::robustness::{judge_frame, TRULY_LOST_TIP_PX_AT_640};
use digiteyes_host::eval::{evaluate, EvalReport};
use digiteyes_host::sequence::states::StateTable;
use digiteyes_host::sequence::{read_states, Sequence};
use digiteyes_host::track::TrackOptions;
use digiteyes_host::TrackerConfig;
use image::GrayImage;

/// The kept seeds' folders in `dir` (each with a `sequence.json`), in name order.
pub fn seed_dirs(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(dir)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("sequence.json").exists())
        .collect();
    dirs.sort();
    Ok(dirs)
}

/// The seed of a kept seed's folder (`seedNNNN`; 0 when the name is not one).
pub fn seed_of(dir: &Path) -> u64 {
    dir.file_name()
        .and_then(|n| n.to_str())
        .and_then(|n| n.trim_start_matches("seed").parse().ok())
        .unwrap_or(0)
}

/// State rows as the tracker takes them (f32).
pub fn f32s(rows: &[Vec<f64>]) -> Vec<Vec<f32>> {
    rows.iter()
        .map(|r| r.iter().map(|&v| v as f32).collect())
        .collect()
}

/// Every camera's frame `k` of `sequence`.
pub fn read_instant(sequence: &Sequence, k: usize) -> Result<Vec<GrayImage>> {
    (0..sequence.cameras.len())
        .map(|c| sequence.read_frame(c, k))
        .collect()
}

/// The tracker's views of `images`.
pub fn views(images: &[GrayImage]) -> Result<Vec<FrameView<'_>>> {
    images
        .iter()
        .map(|img| {
            FrameView::packed(img.as_raw(), img.width() as usize, img.height() as usize)
                .map_err(|e| anyhow!("{e}"))
        })
        .collect()
}

/// A kept seed's run as the benchmark judges it.
pub struct Judged {
    /// The states the benchmark wrote (`states.csv`).
    pub table: StateTable,
    /// `eval`'s report of them.
    pub report: EvalReport,
    /// The `lost` column (nonzero: flagged).
    pub lost: Vec<f64>,
    /// The truly-lost fingertip limit at the sequence's width (px).
    pub limit_px: f64,
}

impl Judged {
    /// The run in `dir` (a kept seed's folder) of `sequence`.
    pub fn open(dir: &Path, sequence: &Sequence) -> Result<Judged> {
        let states = dir.join("states.csv");
        let table = read_states(&states, sequence.n_states())?;
        let report = evaluate(dir, &states)?;
        let lost = table.extra("lost").unwrap_or_default();
        let width = sequence.cameras.first().map_or(640, |c| c.width);
        Ok(Judged {
            table,
            report,
            lost,
            limit_px: TRULY_LOST_TIP_PX_AT_640 * f64::from(width) / 640.0,
        })
    }

    /// Whether frame `k` was flagged lost, and whether it is truly lost against `truth`.
    pub fn frame(&self, k: usize, truth: &[f64]) -> (bool, bool) {
        let flagged = self.lost.get(k).is_some_and(|&v| v != 0.0);
        let truly =
            self.table.rows.get(k).is_none_or(|estimate| {
                judge_frame(estimate, truth, &self.report, k, self.limit_px).1
            });
        (flagged, truly)
    }
}

/// One instant's edge-map buffers, one per camera of `frames`.
pub fn edge_buffers(frames: &[FrameView<'_>], likelihood: &LikelihoodConfig) -> Vec<Vec<u8>> {
    frames
        .iter()
        .map(|f| vec![0u8; EdgeMap::bytes_needed(f.width(), f.height(), likelihood.stride_px)])
        .collect()
}

/// Each camera's edge map of `frames`, built in `buffers` (from [`edge_buffers`], or sized
/// alike).
pub fn edge_maps<'a>(
    buffers: &'a mut [Vec<u8>],
    frames: &[FrameView<'_>],
    likelihood: &LikelihoodConfig,
) -> Result<Vec<EdgeMap<'a>>> {
    buffers
        .iter_mut()
        .zip(frames)
        .map(|(b, f)| EdgeMap::build(b, f, likelihood).map_err(|e| anyhow!("{e}")))
        .collect()
}

/// A tracker's parameters and options: `default`, or overrides joined by `+` such as
/// `pj=500+iters=12+tukey=5` (the keys are listed in the match below).
pub fn variant(text: &str) -> Result<(TrackerConfig, TrackOptions)> {
    let mut c = TrackerConfig::default();
    let mut o = TrackOptions::default();
    if text == "default" {
        return Ok((c, o));
    }
    for part in text.split('+') {
        let Some((k, v)) = part.split_once('=') else {
            bail!("bad override {part}")
        };
        let f: f32 = v.parse()?;
        match k {
            "pj" => c.motion.prior.joint = f,
            "pt" => c.motion.prior.translation = f,
            "pq" => c.motion.prior.quaternion = f,
            "iters" => c.iterations = f as u8,
            "liters" => o.finder.refine_iterations = f as u8,
            "predict" => c.predict = f != 0.0,
            "window" => c.features.window_px = f as u8,
            "margin" => c.features.refine_margin_px = f,
            "contrast" => c.features.min_contrast = f,
            "slices" => c.features.slices_per_link = f as u8,
            "palm" => c.features.palm_edges = f != 0.0,
            "angle" => c.features.max_edge_angle_rad = f.to_radians(),
            "outer" => c.features.outermost_share = f,
            "knuckle" => c.features.knuckle_tips = f != 0.0,
            "fvf" => c.motion.full_velocity_found = f,
            "palmw" => c.estimator.palm_edge_weight = f,
            "widthw" => c.estimator.width_weight = f,
            "widthw1" => c.estimator.one_camera_width_weight = f,
            "widthws" => c.estimator.single_view_width_weight = f,
            "residual" => {
                c.estimator.residual = match f as u8 {
                    0 => ResidualKind::EdgePoints,
                    1 => ResidualKind::AxisLines,
                    _ => ResidualKind::AxisPoints,
                }
            }
            "bounds" => c.estimator.bounded_step = f != 0.0,
            "sj" => c.estimator.conditioning.joint = f,
            "st" => c.estimator.conditioning.translation = f,
            "sq" => c.estimator.conditioning.quaternion = f,
            "tipw" => c.estimator.tip_weight = f,
            "fill" => c.fill.weight = f,
            "fillgrid" => c.fill.grid = f as u8,
            "fillreach" => c.fill.reach_px = f,
            "fillgather" => c.fill.gather_iterations = f as u8,
            "fillmargin" => c.fill.class_margin = f,
            "core" => c.fill.core_share = f,
            "corem" => c.fill.core_margin = f,
            "fillhidden" => c.fill.hidden_gap_share = f,
            "fillend" => c.fill.full_length_widths = f,
            "shade" => c.shading_refine.every_frames = f as u8,
            "shadegrid" => c.shading_refine.grid = f as u8,
            "shadefingers" => c.shading_refine.fingers_per_call = f as u8,
            "shadecurl" => c.shading_refine.curl = f != 0.0,
            "shadesingle" => c.shading_refine.single_flexions = f != 0.0,
            "shadestep" => c.shading_refine.region_step_px = f,
            "shaderad" => c.shading_refine.steps_rad = [f, f / 2.0, f / 4.0],
            "shadelevels" => {
                for step in c.shading_refine.steps_rad.iter_mut().skip(f as usize) {
                    *step = 0.0;
                }
            }
            "shademargin" => c.shading_refine.margin = f,
            "shadecap" => c.shading_refine.residual_cap_grey = f,
            "shadeclamp" => c.shading_refine.clamp_light = f != 0.0,
            "lostrms" => c.lost_rms_px = f,
            "sdrop" => c.lost_silhouette_drop = f,
            "shold" => c.motion.hold_on_silhouette_drop = f != 0.0,
            "minfound" => c.lost_min_found = f,
            "huber" => c.estimator.robust = Robust::Huber(f),
            "tukey" => c.estimator.robust = Robust::Tukey(f),
            "s" => o.hypotheses.score_every_frames = f as u8,
            "spawn" => o.hypotheses.spawn_per_frame = f as u8,
            "keepf" => o.hypotheses.keep_fingers = f != 0.0,
            "si" => o.hypotheses.sample_iterations = f as u8,
            "oi" => o.hypotheses.other_iterations = f as u8,
            "lo" => o.hypotheses.light_others = f != 0.0,
            "jumps" => o.hypotheses.jumps_per_frame = f as u8,
            "jturn" => o.hypotheses.jump_min_turn_rad = f,
            "jpx" => o.hypotheses.jump_max_moved_px = f,
            "mw" => o.hypotheses.motion_weight = f,
            "rev" => o.hypotheses.likelihood.reverse_weight = f,
            "arev" => o.acquire.likelihood.reverse_weight = f,
            "wrev" => o.watch.reverse_weight = f,
            "wrx" => o.watch.max_reverse_px = f,
            "wrd" => o.watch.reverse_min_drop = f,
            "accm" => {
                o.finder.accept.min_score = f;
                o.finder.accept.min_camera_score = f;
            }
            "acc1" => o.finder.accept.one_camera_score = f,
            "arx" => o.finder.accept.max_reverse_px = f,
            "arx1" => o.finder.accept.one_camera_max_reverse_px = f,
            "revcap" => {
                o.hypotheses.likelihood.reverse_cap_px = f;
                o.acquire.likelihood.reverse_cap_px = f;
            }
            "step" => o.hypotheses.spawn_step = f,
            "k" => o.hypotheses.count = f as u8,
            "smem" => o.hypotheses.score_memory = f,
            "switch" => o.hypotheses.switch_margin = f,
            "csmem" => o.finder.confirm_score_memory = f,
            "cswitch" => o.finder.confirm_switch_margin = f,
            "settle" => o.finder.settle_frames = f as u8,
            "cdepth1" => o.finder.confirm_depth_share[1] = f,
            "rival" => o.finder.confirm_rival_share = f,
            "rivalm" => o.finder.confirm_rival_margin = f,
            "held" => o.finder.confirm_held_weight = f,
            "heldband" => o.finder.confirm_held_band = f,
            "cframes" => o.finder.confirm_frames = f as u8,
            "polish1" => o.finder.polish_margin[1] = f,
            "polish2" => o.finder.polish_margin[0] = f,
            "watch" => o.watch.every_frames = f as u8,
            "drop" => o.watch.max_drop = f,
            "depth1" => o.finder.local_depth_share[1] = f,
            "turn" => o.finder.local_turn_rad = f,
            "pursue1" => o.finder.pursue_frames[1] = f as u8,
            "probation" => o.finder.probation_max_drop = (f >= 0.0).then_some(f),
            "budget" => o.acquire.evaluations_per_frame = f as u16,
            _ => bail!("unknown key {k}"),
        }
    }
    Ok((c, o))
}

/// The finger of model frame `frame` (by its chain's last joint state), `None` for none.
pub fn finger_of_frame(model: &Model, fingers: &Fingers, frame: usize) -> Option<usize> {
    let chain = model.chain(frame)?;
    let s = usize::from(*chain.last()?);
    (0..fingers.count()).find(|&f| fingers.contains(f, s))
}

/// Mean fingertip distance (px) between states `a` and `b` over every camera.
pub fn tip_error_px(model: &Model, cameras: &[Camera], a: &[f32], b: &[f32]) -> f32 {
    let (Ok(pa), Ok(pb)) = (Poses::compute(model, a), Poses::compute(model, b)) else {
        return f32::INFINITY;
    };
    let tips: Vec<usize> = (0..model.links().len())
        .filter(|&i| matches!(model.links()[i].shape, Shape::Tip { .. }))
        .collect();
    let (mut sum, mut n) = (0.0f32, 0u32);
    for c in cameras {
        for &t in &tips {
            let (Some(x), Some(y)) = (pa.origin(t), pb.origin(t)) else {
                continue;
            };
            match (c.project(&x), c.project(&y)) {
                (Some(u), Some(v)) => sum += (u - v).norm(),
                _ => sum += 1e3,
            }
            n += 1;
        }
    }
    if n == 0 {
        f32::INFINITY
    } else {
        sum / n as f32
    }
}

/// Shortest distance (mm) between the segments `a0–a1` and `b0–b1`, from 17 points along the
/// first: exact enough for a study, and free of the parallel and degenerate cases.
pub fn segment_distance_mm(
    a0: &nalgebra::Vector3<f32>,
    a1: &nalgebra::Vector3<f32>,
    b0: &nalgebra::Vector3<f32>,
    b1: &nalgebra::Vector3<f32>,
) -> f32 {
    let mut best = f32::INFINITY;
    for i in 0..=16 {
        let p = a0 + (a1 - a0) * (i as f32 / 16.0);
        let d = b1 - b0;
        let t = ((p - b0).dot(&d) / d.norm_squared().max(1e-9)).clamp(0.0, 1.0);
        best = best.min((p - (b0 + d * t)).norm());
    }
    best
}
