//! Evaluation against ground truth: zero for the truth itself, the expected figures for
//! known perturbations, and errors for files that do not fit the sequence.

mod common;

use std::path::Path;

use common::{message, small_sequence};
use digiteyes_core::kinematics::Poses;
use digiteyes_core::nalgebra::Vector3;
use digiteyes_host::eval::track_life;
use digiteyes_host::evaluate;
use digiteyes_host::sequence::{write_truth, Sequence};

/// Writes `rows` as a states CSV and evaluates it against `seq`.
fn eval_rows(seq: &Path, rows: &[Vec<f64>]) -> digiteyes_host::EvalReport {
    let path = seq.join("estimate.csv");
    write_truth(&path, rows).unwrap();
    evaluate(seq, &path).unwrap()
}

/// The mouse sequence's report of `frames` frames with the palm 150 mm off on the frames
/// `off` holds.
fn palm_moved_on(
    dir: &Path,
    frames: usize,
    off: impl Fn(usize) -> bool,
) -> digiteyes_host::EvalReport {
    let seq = small_sequence(dir, "mouse", frames);
    let truth = Sequence::open(&seq).unwrap().read_truth().unwrap().rows;
    let rows: Vec<Vec<f64>> = truth
        .iter()
        .enumerate()
        .map(|(k, q)| {
            let mut q = q.clone();
            if off(k) {
                q[4] += 150.0;
            }
            q
        })
        .collect();
    eval_rows(&seq, &rows)
}

#[test]
fn truth_against_itself_is_perfect() {
    let dir = tempfile::tempdir().unwrap();
    let seq = small_sequence(dir.path(), "fullhand-stereo", 4);
    let r = evaluate(&seq, &seq.join("truth.csv")).unwrap();
    assert_eq!(r.frames, 4);
    assert_eq!(r.cameras.len(), 2);
    for c in &r.cameras {
        assert_eq!(c.fingertip_mean_px, 0.0);
        assert_eq!(c.fingertip_p95_px, 0.0);
        assert_eq!(c.joint_mean_px, 0.0);
        assert_eq!(c.joint_p95_px, 0.0);
    }
    assert_eq!(r.free_joints, 21);
    assert_eq!(r.joint_rms_deg, 0.0);
    assert!(r.palm_rotation_deg < 0.03, "{}", r.palm_rotation_deg);
    assert_eq!(r.palm_translation_mm, 0.0);
    assert_eq!(r.track_life, 1.0);
    assert_eq!(r.lost_frames, None);
}

#[test]
fn a_palm_shift_gives_its_distance_and_its_image_displacement() {
    let dir = tempfile::tempdir().unwrap();
    let seq_dir = small_sequence(dir.path(), "mouse", 5);
    let seq = Sequence::open(&seq_dir).unwrap();
    let truth = seq.read_truth().unwrap().rows;
    let shift = Vector3::new(3.0f32, -4.0, 0.0);
    let moved: Vec<Vec<f64>> = truth
        .iter()
        .map(|q| {
            let mut q = q.clone();
            q[4] += f64::from(shift.x);
            q[5] += f64::from(shift.y);
            q
        })
        .collect();
    let r = eval_rows(&seq_dir, &moved);
    assert!((r.palm_translation_mm - 5.0).abs() < 1e-6);
    assert!((r.palm_translation_max_mm - 5.0).abs() < 1e-6);
    assert!(r.palm_rotation_deg < 0.03);
    assert_eq!(r.joint_rms_deg, 0.0);
    // Every point moves by the shift: its image displacement, computed here from the points.
    let cam = &seq.cameras[0];
    let tips = [
        "finger1.tip",
        "finger2.tip",
        "finger3.tip",
        "finger4.tip",
        "thumb.tip",
    ]
    .map(|n| seq.model.find(n).unwrap());
    let mut expected = Vec::new();
    for q in &truth {
        let q: Vec<f32> = q.iter().map(|&v| v as f32).collect();
        let poses = Poses::compute(&seq.model, &q).unwrap();
        for &t in &tips {
            let p = poses.origin(t).unwrap();
            let d = cam.project(&(p + shift)).unwrap() - cam.project(&p).unwrap();
            expected.push(f64::from(d.norm()));
        }
    }
    let mean = expected.iter().sum::<f64>() / expected.len() as f64;
    let got = r.cameras[0].fingertip_mean_px;
    println!("palm shift of 5 mm: fingertip error {got:.4} px (expected {mean:.4})");
    assert!(
        got > 0.5 && (got - mean).abs() < 1e-3 * mean,
        "{got} vs {mean}"
    );
    assert!(r.cameras[0].fingertip_p95_px >= got);
    assert!(r.cameras[0].joint_mean_px > 0.5);
}

#[test]
fn a_joint_offset_gives_its_rms_over_the_free_joints() {
    let dir = tempfile::tempdir().unwrap();
    let seq = small_sequence(dir.path(), "mouse", 4);
    let truth = Sequence::open(&seq).unwrap().read_truth().unwrap().rows;
    let bent: Vec<Vec<f64>> = truth
        .iter()
        .map(|q| {
            let mut q = q.clone();
            q[8] += 0.1;
            q
        })
        .collect();
    let r = eval_rows(&seq, &bent);
    // Mouse: free joints q8 q9 q10 q19 q24; one of five is off by 0.1 rad.
    assert_eq!(r.free_joints, 5);
    let expected = (0.1f64 * 0.1 / 5.0).sqrt().to_degrees();
    assert!(
        (r.joint_rms_deg - expected).abs() < 1e-9,
        "{}",
        r.joint_rms_deg
    );
    assert_eq!(r.palm_translation_mm, 0.0);
    assert!(r.cameras[0].fingertip_mean_px > 0.0);
}

#[test]
fn a_palm_turn_gives_its_angle() {
    let dir = tempfile::tempdir().unwrap();
    let seq = small_sequence(dir.path(), "rigid", 3);
    let truth = Sequence::open(&seq).unwrap().read_truth().unwrap().rows;
    let half = 2.0f64.to_radians() / 2.0;
    let turned: Vec<Vec<f64>> = truth
        .iter()
        .map(|q| {
            // q ⊗ (cos h, 0, 0, sin h): a further 2° about the palm's z axis.
            let (w, x, y, z) = (q[0], q[1], q[2], q[3]);
            let (c, s) = (half.cos(), half.sin());
            let mut out = q.clone();
            out[0] = w * c - z * s;
            out[1] = x * c + y * s;
            out[2] = y * c - x * s;
            out[3] = z * c + w * s;
            out
        })
        .collect();
    let r = eval_rows(&seq, &turned);
    assert!(
        (r.palm_rotation_deg - 2.0).abs() < 0.05,
        "{}",
        r.palm_rotation_deg
    );
    assert_eq!(r.free_joints, 0);
    assert_eq!(r.joint_rms_deg, 0.0);
}

#[test]
fn track_life_ends_where_the_error_stays_high() {
    assert_eq!(track_life(&[]), 1.0);
    assert_eq!(track_life(&[0.0; 10]), 1.0);
    // Four bad frames then recovery: not lost.
    assert_eq!(
        track_life(&[0.0, 11.0, 11.0, 11.0, 11.0, 1.0, 0.0, 0.0]),
        1.0
    );
    // Lost from frame 2 on.
    assert_eq!(
        track_life(&[0.0, 0.0, 11.0, 12.0, 30.0, 11.0, 11.0, 50.0]),
        2.0 / 8.0
    );
    // Exactly 10 px is not above the bar.
    assert_eq!(track_life(&[10.0; 8]), 1.0);
}

#[test]
fn a_lost_track_shows_in_the_report() {
    let dir = tempfile::tempdir().unwrap();
    let r = palm_moved_on(dir.path(), 8, |k| k >= 3);
    assert_eq!(r.track_life, 3.0 / 8.0);
    assert!(r.fingertip_mean_by_frame[3] > 10.0 && r.fingertip_mean_by_frame[2] == 0.0);
}

#[test]
fn a_hand_found_again_ends_the_life_but_counts_as_held_again() {
    let dir = tempfile::tempdir().unwrap();
    // The palm 150 mm off over frames 2..7, right before and after.
    let r = palm_moved_on(dir.path(), 10, |k| (2..7).contains(&k));
    assert_eq!(r.track_life, 2.0 / 10.0);
    assert_eq!(r.held_share, 5.0 / 10.0);
    let json: serde_json::Value = serde_json::to_value(&r).unwrap();
    assert_eq!(json["held_share"], 0.5);
}

#[test]
fn the_report_prints_as_a_table_and_as_json() {
    let dir = tempfile::tempdir().unwrap();
    let seq = small_sequence(dir.path(), "mouse", 3);
    let r = evaluate(&seq, &seq.join("truth.csv")).unwrap();
    let table = r.to_string();
    assert!(
        table.contains("fingertip mean")
            && table.contains("track life")
            && table.contains("frames held"),
        "{table}"
    );
    let json: serde_json::Value = serde_json::to_value(&r).unwrap();
    assert_eq!(json["cameras"][0]["fingertip_mean_px"], 0.0);
    assert_eq!(json["track_life"], 1.0);
}

#[test]
fn states_that_do_not_fit_the_sequence_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let seq = small_sequence(dir.path(), "mouse", 4);
    let truth = Sequence::open(&seq).unwrap().read_truth().unwrap().rows;
    // Too few frames.
    let path = seq.join("short.csv");
    write_truth(&path, &truth[..3]).unwrap();
    let err = message(evaluate(&seq, &path));
    assert!(
        err.contains("short.csv") && err.contains("3 frames"),
        "{err}"
    );
    // Too few states.
    let path = seq.join("narrow.csv");
    let narrow: Vec<Vec<f64>> = truth.iter().map(|q| q[..27].to_vec()).collect();
    write_truth(&path, &narrow).unwrap();
    let err = message(evaluate(&seq, &path));
    assert!(
        err.contains("narrow.csv") && err.contains("27 state columns"),
        "{err}"
    );
    // No ground truth.
    std::fs::remove_file(seq.join("truth.csv")).unwrap();
    let err = message(evaluate(&seq, &seq.join("short.csv")));
    assert!(
        err.contains("truth.csv") && err.contains("missing"),
        "{err}"
    );
}

/// `eval --lost-px`: the palm moved so the fingertips are a few px off on every frame is held
/// at the default 10 px and lost at a threshold under its error; the table and JSON say which
/// threshold; a threshold that is not a positive number is refused.
#[test]
fn the_lost_threshold_is_the_callers_to_choose() {
    let dir = tempfile::tempdir().unwrap();
    let seq = small_sequence(dir.path(), "mouse", 8);
    let truth = Sequence::open(&seq).unwrap().read_truth().unwrap().rows;
    let moved: Vec<Vec<f64>> = truth
        .iter()
        .map(|q| {
            let mut q = q.clone();
            q[4] += 6.0;
            q
        })
        .collect();
    let path = seq.join("moved.csv");
    write_truth(&path, &moved).unwrap();
    let at_default = evaluate(&seq, &path).unwrap();
    let error = at_default.fingertip_mean_by_frame[0];
    assert!(error > 1.0 && error < 10.0, "{error} px");
    assert_eq!(at_default.track_life, 1.0);
    assert_eq!(at_default.frames_to_acquire, Some(0));
    let strict = digiteyes_host::eval::evaluate_at(&seq, &path, error / 2.0).unwrap();
    assert_eq!(strict.track_life, 0.0);
    assert_eq!(strict.frames_to_acquire, None);
    let run = |px: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_digiteyes"))
            .args(["eval", &format!("--lost-px={px}")])
            .arg(&seq)
            .arg(&path)
            .output()
            .unwrap()
    };
    let out = run(&format!("{}", error / 2.0));
    assert!(out.status.success());
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        table.contains(&format!("stays > {} px", error / 2.0)) && table.contains("0.0 %"),
        "{table}"
    );
    for bad in ["0", "-3", "nan"] {
        let out = run(bad);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{bad}");
        assert!(stderr.contains("lost threshold"), "{bad}: {stderr}");
    }
}
