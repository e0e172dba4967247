//! `track --overlay`: one PNG per frame per camera, named like the frames, of the cameras'
//! sizes, drawn at the tracked states; and a clear failure when the folder cannot be written.

use digiteyes_host::overlay::{colours, overlay_path};
use digiteyes_host::sequence::Sequence;
use digiteyes_host::track::track_sequence_with;
use digiteyes_host::{render_scenario, RenderOptions, TrackerConfig};

fn render(name: &str, frames: usize, dir: &std::path::Path) {
    let opts = RenderOptions {
        frames: Some(frames),
        size: Some((160, 120)),
        supersample: 1,
        ..RenderOptions::default()
    };
    render_scenario(name, dir, &opts).unwrap();
}

#[test]
fn track_writes_one_overlay_per_frame_and_camera() {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("seq");
    render("fullhand-stereo", 4, &seq);
    let overlays = dir.path().join("overlay");
    let summary = track_sequence_with(
        &seq,
        &dir.path().join("states.csv"),
        TrackerConfig::default(),
        false,
        Some(&overlays),
    )
    .unwrap();
    let sequence = Sequence::open(&seq).unwrap();
    assert_eq!(sequence.cameras.len(), 2);
    let (written_to, png) = summary.overlays.clone().expect("overlay figures");
    assert_eq!(written_to, overlays);
    assert_eq!(png.files, 4 * 2);
    for cam in 0..2 {
        let mut files: Vec<_> = std::fs::read_dir(overlays.join(format!("cam{cam}")))
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        files.sort();
        assert_eq!(
            files,
            ["000000.png", "000001.png", "000002.png", "000003.png"]
        );
        for frame in 0..4 {
            let path = overlay_path(&overlays, cam, frame);
            let image = image::open(&path).unwrap().into_rgb8();
            let camera = &sequence.cameras[cam];
            assert_eq!(
                image.dimensions(),
                (camera.width, camera.height),
                "{path:?}"
            );
            // Drawn, not just the dimmed frame: the model's axes are there.
            let axis = image.pixels().filter(|p| **p == colours::AXIS).count();
            assert!(axis > 20, "{path:?}: {axis} axis pixels");
        }
    }
    assert!(summary.to_string().contains("8 PNG(s)"), "{summary}");
}

#[test]
fn an_unwritable_overlay_folder_is_an_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("seq");
    render("mouse", 2, &seq);
    // A file where the folder should be.
    let blocked = dir.path().join("blocked");
    std::fs::write(&blocked, "not a folder").unwrap();
    let err = track_sequence_with(
        &seq,
        &dir.path().join("states.csv"),
        TrackerConfig::default(),
        false,
        Some(&blocked),
    )
    .unwrap_err();
    let message = format!("{err:#}");
    assert!(message.contains("blocked"), "{message}");
}
