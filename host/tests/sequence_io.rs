//! Reading and writing sequences: round trips, the fixture, and every way reading can fail.

mod common;

use std::fs;
use std::path::Path;

use common::{message, small_sequence, FIXTURE};
use digiteyes_host::sequence::{self, Sequence, SequenceFile};
use digiteyes_host::track_sequence;
use digiteyes_host::TrackerConfig;
use image::GrayImage;

#[test]
fn fixture_is_read_as_its_authors_wrote_it() {
    let seq = Sequence::open(Path::new(FIXTURE)).unwrap();
    assert_eq!(seq.frames, 12);
    assert_eq!(seq.n_states(), 28);
    assert_eq!(seq.cameras.len(), 1);
    assert_eq!(seq.free.as_deref(), Some(&[4u8, 5, 8, 9, 10, 19, 24][..]));
    assert_eq!(seq.free_states(), vec![4, 5, 8, 9, 10, 19, 24]);
    assert_eq!(seq.fps(), Some(30.0));
    assert_eq!(seq.camera_name(0), "cam0");
    let cam = &seq.cameras[0];
    assert_eq!((cam.width, cam.height), (640, 480));
    assert_eq!((cam.cx, cam.cy), (319.5, 239.5));
    assert!((cam.t.z - 520.0828).abs() < 1e-3);
    assert_eq!(seq.initial_state[2], 0.9975510002532796);
    assert_eq!(seq.initial_state[6], 45.0);
    seq.check_frames().unwrap();
    let frame = seq.read_frame(0, 11).unwrap();
    assert_eq!(frame.dimensions(), (640, 480));
    let truth = seq.read_truth().unwrap();
    assert_eq!(truth.rows.len(), 12);
    assert!(truth.rows.iter().all(|r| r.len() == 28));
    assert_eq!(truth.rows[0], seq.initial_state);
    assert!((truth.rows[1][4] - 2.1112350782328555).abs() < 1e-15);
}

#[test]
fn sequence_json_round_trips() {
    let text = fs::read_to_string(Path::new(FIXTURE).join("sequence.json")).unwrap();
    let file = SequenceFile::from_json(&text).unwrap();
    let again = SequenceFile::from_json(&file.to_json().unwrap()).unwrap();
    assert_eq!(file, again);
    // Through the disk, and back as a sequence.
    let dir = tempfile::tempdir().unwrap();
    sequence::write_sequence_json(dir.path(), &file).unwrap();
    let frame = GrayImage::from_pixel(640, 480, image::Luma([20]));
    sequence::write_frame(dir.path(), 0, 0, &frame).unwrap();
    let seq = Sequence::open(dir.path()).unwrap();
    assert_eq!(seq.file, file);
    assert_eq!(seq.frames, 1);
}

#[test]
fn optional_keys_may_be_absent_and_unknown_keys_are_ignored() {
    let text = r#"{ "model": "builtin:hand", "comment": "extra keys are allowed",
        "cameras": [ { "width": 64, "height": 48, "fx": 100, "fy": 100, "cx": 31.5, "cy": 23.5,
                       "R": [[1,0,0],[0,1,0],[0,0,1]], "t": [0, 0, 600], "lens": "none" } ],
        "initial_state": [1,0,0,0, 0,0,0, 0,0,0,0, 0,0,0,0, 0,0,0,0, 0,0,0,0, 0,0,0,0,0] }"#;
    let dir = tempfile::tempdir().unwrap();
    fs::write(dir.path().join("sequence.json"), text).unwrap();
    fs::create_dir(dir.path().join("cam0")).unwrap();
    sequence::write_frame(dir.path(), 0, 0, &GrayImage::new(64, 48)).unwrap();
    let seq = Sequence::open(dir.path()).unwrap();
    assert_eq!(seq.free, None);
    assert_eq!(seq.free_states(), (0..28).collect::<Vec<_>>());
    assert_eq!(seq.fps(), None);
    assert_eq!(seq.camera_name(0), "cam0");
}

#[test]
fn rendered_scenario_is_a_valid_sequence() {
    let dir = tempfile::tempdir().unwrap();
    let seq_dir = small_sequence(dir.path(), "fullhand-stereo", 3);
    let seq = Sequence::open(&seq_dir).unwrap();
    assert_eq!(seq.frames, 3);
    assert_eq!(seq.cameras.len(), 2);
    assert_eq!(seq.file.model, "builtin:hand");
    assert_eq!(seq.free_states(), (0..28).collect::<Vec<_>>());
    seq.check_frames().unwrap();
    let truth = seq.read_truth().unwrap();
    assert_eq!(truth.rows[0], seq.initial_state);
    // The hand is there, brighter than the background.
    let frame = seq.read_frame(1, 2).unwrap();
    let bright = frame.as_raw().iter().filter(|&&v| v > 60).count();
    assert!(bright > 200, "{bright} bright pixels");
}

/// A two-camera sequence of three frames to break.
fn broken(edit: impl FnOnce(&Path)) -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let seq = small_sequence(dir.path(), "fullhand-stereo", 3);
    edit(&seq);
    (dir, seq)
}

fn edit_json(seq: &Path, from: &str, to: &str) {
    let path = seq.join("sequence.json");
    let text = fs::read_to_string(&path).unwrap();
    assert!(text.contains(from), "{from} not in sequence.json");
    fs::write(&path, text.replacen(from, to, 1)).unwrap();
}

#[test]
fn missing_sequence_json() {
    let dir = tempfile::tempdir().unwrap();
    let err = message(Sequence::open(dir.path()));
    assert!(err.contains("sequence.json"), "{err}");
}

#[test]
fn missing_frame_in_the_middle() {
    let (_d, seq) = broken(|s| fs::remove_file(s.join("cam0/000001.pgm")).unwrap());
    let err = message(Sequence::open(&seq));
    assert!(
        err.contains("cam0/000001.pgm: missing") && err.contains("000002.pgm exists"),
        "{err}"
    );
}

#[test]
fn cameras_with_different_frame_counts() {
    let (_d, seq) = broken(|s| fs::remove_file(s.join("cam1/000002.pgm")).unwrap());
    let err = message(Sequence::open(&seq));
    assert!(
        err.contains("cam1/000002.pgm: missing") && err.contains("camera 0 has 3 frames"),
        "{err}"
    );
}

#[test]
fn no_frames_at_all() {
    let (_d, seq) = broken(|s| {
        for k in 0..3 {
            fs::remove_file(s.join(format!("cam0/{k:06}.pgm"))).unwrap();
        }
    });
    let err = message(Sequence::open(&seq));
    assert!(err.contains("cam0/000000.pgm: missing"), "{err}");
}

#[test]
fn missing_camera_folder() {
    let (_d, seq) = broken(|s| fs::remove_dir_all(s.join("cam1")).unwrap());
    let err = message(Sequence::open(&seq));
    assert!(
        err.contains("cam1") && err.contains("missing folder"),
        "{err}"
    );
}

#[test]
fn frame_of_the_wrong_size() {
    let (_d, seq) = broken(|s| {
        sequence::pgm::write_pgm(&s.join("cam1/000001.pgm"), &GrayImage::new(10, 12)).unwrap()
    });
    let opened = Sequence::open(&seq).unwrap();
    let err = message(opened.check_frames());
    assert!(
        err.contains("cam1/000001.pgm") && err.contains("10x12") && err.contains("160x120"),
        "{err}"
    );
    let err = message(opened.read_frame(1, 1));
    assert!(err.contains("cam1/000001.pgm"), "{err}");
    // Tracking refuses before it starts, naming the file.
    let out = seq.join("states.csv");
    let err = message(track_sequence(&seq, &out, TrackerConfig::default(), false));
    assert!(
        err.contains("cam1/000001.pgm") && err.contains("10x12"),
        "{err}"
    );
}

#[test]
fn frame_that_is_not_a_binary_pgm() {
    let (_d, seq) = broken(|s| fs::write(s.join("cam0/000002.pgm"), "P2\n1 1\n255\n7\n").unwrap());
    let err = message(Sequence::open(&seq).unwrap().check_frames());
    assert!(
        err.contains("cam0/000002.pgm") && err.contains("P5"),
        "{err}"
    );
    let (_d, seq) = broken(|s| fs::write(s.join("cam0/000002.pgm"), "hello").unwrap());
    let err = message(Sequence::open(&seq).unwrap().read_frame(0, 2));
    assert!(
        err.contains("cam0/000002.pgm") && err.contains("not a readable PGM"),
        "{err}"
    );
}

#[test]
fn bad_json() {
    let (_d, seq) = broken(|s| fs::write(s.join("sequence.json"), "{ \"model\": ").unwrap());
    let err = message(Sequence::open(&seq));
    assert!(
        err.contains("sequence.json") && err.contains("line 1"),
        "{err}"
    );
    let (_d, seq) = broken(|s| edit_json(s, "\"cameras\"", "\"kameras\""));
    let err = message(Sequence::open(&seq));
    assert!(
        err.contains("sequence.json") && err.contains("missing field `cameras`"),
        "{err}"
    );
}

#[test]
fn model_errors_name_the_file_and_line() {
    let (_d, seq) = broken(|s| {
        let text = digiteyes_core::model::HAND_DH.replacen("cyl 10", "cylinder 10", 1);
        fs::write(s.join("hand.dh"), text).unwrap();
        edit_json(s, "builtin:hand", "hand.dh");
    });
    let err = message(Sequence::open(&seq));
    let line = digiteyes_core::model::HAND_DH
        .lines()
        .position(|l| l.contains("cyl 10"))
        .unwrap()
        + 1;
    assert!(
        err.contains("hand.dh") && err.contains(&format!("line {line}:")) && err.contains("shape"),
        "{err}"
    );
    let (_d, seq) = broken(|s| edit_json(s, "builtin:hand", "missing.dh"));
    let err = message(Sequence::open(&seq));
    assert!(err.contains("missing.dh"), "{err}");
    let (_d, seq) = broken(|s| edit_json(s, "builtin:hand", "builtin:foot"));
    let err = message(Sequence::open(&seq));
    assert!(err.contains("builtin:foot"), "{err}");
}

#[test]
fn a_model_file_beside_the_sequence_is_used() {
    let (_d, seq) = broken(|s| {
        fs::write(s.join("hand.dh"), digiteyes_core::model::HAND_DH).unwrap();
        edit_json(s, "builtin:hand", "hand.dh");
    });
    assert_eq!(Sequence::open(&seq).unwrap().n_states(), 28);
}

#[test]
fn bad_cameras_initial_state_and_free_lists() {
    let (_d, seq) = broken(|s| edit_json(s, "\"fx\": 250.0", "\"fx\": -1.0"));
    let err = message(Sequence::open(&seq));
    assert!(
        err.contains("camera 0 (cam0)") && err.contains("focal"),
        "{err}"
    );
    let (_d, seq) =
        broken(|s| edit_json(s, "\"initial_state\": [\n    1.0,", "\"initial_state\": ["));
    let err = message(Sequence::open(&seq));
    assert!(
        err.contains("initial_state") && err.contains("27 values"),
        "{err}"
    );
    let (_d, seq) = broken(|s| edit_json(s, "\"free\": [\n    0,", "\"free\": [\n    40,"));
    let err = message(Sequence::open(&seq));
    assert!(err.contains("free") && err.contains("state 40"), "{err}");
    let (_d, seq) = broken(|s| edit_json(s, "\"free\": [\n    0,", "\"free\": ["));
    let err = message(Sequence::open(&seq));
    assert!(err.contains("quaternion"), "{err}");
}

#[test]
fn truth_with_the_wrong_number_of_rows() {
    let (_d, seq) = broken(|s| {
        let path = s.join("truth.csv");
        let text = fs::read_to_string(&path).unwrap();
        let kept: Vec<&str> = text.lines().take(3).collect();
        fs::write(&path, kept.join("\n")).unwrap();
    });
    let err = message(Sequence::open(&seq).unwrap().read_truth());
    assert!(err.contains("truth.csv") && err.contains("2 rows"), "{err}");
}
