//! Finding the hand without a given initial state: `track --init auto`, sequences without
//! `initial_state`, the states CSV's `status` and `lost` columns, and the malformed cases.
//! Sequences are short and small (320×240, a few frames): these check the plumbing, not how
//! well the search finds the hand (tests/tests/acquire.rs and docs/recovery.md do that).

use std::path::{Path, PathBuf};

use digiteyes_host::sequence::status::Status;
use digiteyes_host::sequence::{read_states, Sequence, SequenceFile};
use digiteyes_host::track::{track_sequence_opts, Init, TrackOptions};
use digiteyes_host::{render_scenario, RenderOptions, TrackerConfig};

fn render(dir: &Path, scenario: &str, frames: usize, no_initial_state: bool) -> PathBuf {
    let seq = dir.join(scenario);
    let options = RenderOptions {
        frames: Some(frames),
        size: Some((320, 240)),
        supersample: 1,
        no_initial_state,
        ..RenderOptions::default()
    };
    render_scenario(scenario, &seq, &options).unwrap();
    seq
}

fn track(seq: &Path, out: &Path, init: Option<Init>) -> digiteyes_host::TrackSummary {
    let options = TrackOptions {
        init,
        ..TrackOptions::default()
    };
    track_sequence_opts(seq, out, TrackerConfig::default(), false, None, &options).unwrap()
}

fn track_err(seq: &Path, out: &Path, init: Option<Init>) -> String {
    let options = TrackOptions {
        init,
        ..TrackOptions::default()
    };
    let err =
        track_sequence_opts(seq, out, TrackerConfig::default(), false, None, &options).unwrap_err();
    format!("{err:#}")
}

/// Copies sequence folder `from` (sequence.json, truth.csv, cam0 frames) to `to`.
fn copy_sequence(from: &Path, to: &Path) {
    std::fs::create_dir_all(to.join("cam0")).unwrap();
    for entry in std::fs::read_dir(from.join("cam0")).unwrap() {
        let entry = entry.unwrap();
        std::fs::copy(entry.path(), to.join("cam0").join(entry.file_name())).unwrap();
    }
    for file in ["sequence.json", "truth.csv"] {
        std::fs::copy(from.join(file), to.join(file)).unwrap();
    }
}

fn edit_json(seq: &Path, edit: impl FnOnce(&mut SequenceFile)) {
    let path = seq.join("sequence.json");
    let mut file = SequenceFile::from_json(&std::fs::read_to_string(&path).unwrap()).unwrap();
    edit(&mut file);
    std::fs::write(&path, file.to_json().unwrap()).unwrap();
}

#[test]
fn init_auto_ignores_the_given_free_states_and_starts_searching() {
    let dir = tempfile::tempdir().unwrap();
    let seq = render(dir.path(), "mouse", 4, false);
    // The same frames, with every free state's initial value moved.
    let moved = dir.path().join("moved");
    copy_sequence(&seq, &moved);
    let sequence = Sequence::open(&seq).unwrap();
    let free = sequence.free_states();
    edit_json(&moved, |file| {
        for &s in &free {
            file.initial_state[s] += if s < 7 { 15.0 } else { 0.2 };
        }
    });
    let (a, b) = (dir.path().join("a.csv"), dir.path().join("b.csv"));
    let summary = track(&seq, &a, Some(Init::Auto));
    track(&moved, &b, Some(Init::Auto));
    assert_eq!(summary.init, Init::Auto);
    assert_eq!(
        std::fs::read(&a).unwrap(),
        std::fs::read(&b).unwrap(),
        "--init auto used the given values of the free states"
    );
    let table = read_states(&a, sequence.n_states()).unwrap();
    let status = table.status.clone().expect("a status column");
    assert_eq!(
        status[0],
        Some(Status::Searching),
        "--init auto starts searching"
    );
    // While searching, the states are the search's base: the fixed states as given, the free
    // ones not the given values.
    let base = sequence.search_base();
    for (k, row) in table.rows.iter().enumerate() {
        if status[k] == Some(Status::Searching) {
            for (s, (v, b)) in row.iter().zip(&base).enumerate() {
                assert!(
                    (v - b).abs() < 1e-4,
                    "frame {k} q{s}: {v} is not the base {b}"
                );
            }
        }
    }
    for (s, (b, given)) in base.iter().zip(&sequence.initial_state).enumerate() {
        if !free.contains(&s) && s >= 4 {
            assert_eq!(b, given, "fixed q{s} keeps its value");
        }
    }
    // --init given does start from the given state: the two runs then differ.
    let (c, d) = (dir.path().join("c.csv"), dir.path().join("d.csv"));
    let given = track(&seq, &c, None);
    track(&moved, &d, Some(Init::Given));
    assert_eq!(given.init, Init::Given, "the default with an initial state");
    assert_ne!(std::fs::read(&c).unwrap(), std::fs::read(&d).unwrap());
    let first = read_states(&c, sequence.n_states()).unwrap();
    assert_eq!(first.status.unwrap()[0], Some(Status::Tracking));
}

#[test]
fn a_sequence_without_initial_state_is_searched_with_status_and_lost_right() {
    let dir = tempfile::tempdir().unwrap();
    let seq = render(dir.path(), "rigid", 3, true);
    let text = std::fs::read_to_string(seq.join("sequence.json")).unwrap();
    assert!(
        !text.contains("initial_state") && !text.contains("\"free\""),
        "{text}"
    );
    let sequence = Sequence::open(&seq).unwrap();
    assert!(!sequence.initial_given);
    assert_eq!(sequence.free_states().len(), sequence.n_states());
    let out = dir.path().join("states.csv");
    let summary = track(&seq, &out, None);
    assert_eq!(
        summary.init,
        Init::Auto,
        "the default without an initial state"
    );
    assert_eq!(summary.frames, 3);
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.lines().next().unwrap().ends_with(",lost,status"),
        "{text}"
    );
    let table = read_states(&out, sequence.n_states()).unwrap();
    let status = table.status.clone().unwrap();
    let lost = table.extra("lost").unwrap();
    assert_eq!(status[0], Some(Status::Searching));
    for k in 0..table.rows.len() {
        let claimed = status[k] == Some(Status::Tracking);
        assert_eq!(
            lost[k] == 0.0,
            claimed,
            "frame {k}: lost {} with status {:?}",
            lost[k],
            status[k]
        );
        assert!(
            table.rows[k].iter().all(|v| v.is_finite()),
            "frame {k}: NaN"
        );
    }
    assert_eq!(
        summary.lost_frames,
        status
            .iter()
            .filter(|s| **s != Some(Status::Tracking))
            .count()
    );
    assert_eq!(
        summary.status.searching + summary.status.tracking + summary.status.lost,
        3
    );
    // eval reads the file, with and without its status column.
    let report = digiteyes_host::evaluate(&seq, &out).unwrap();
    assert_eq!(
        report.status.as_ref().unwrap().searching,
        summary.status.searching
    );
    let stripped = dir.path().join("old.csv");
    let old: String = text
        .lines()
        .map(|l| format!("{}\n", &l[..l.rfind(',').unwrap()]))
        .collect();
    std::fs::write(&stripped, old).unwrap();
    let report = digiteyes_host::evaluate(&seq, &stripped).unwrap();
    assert!(report.status.is_none());
    assert_eq!(report.lost_frames, Some(summary.lost_frames));
}

#[test]
fn malformed_cases_are_refused_with_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let seq = render(dir.path(), "mouse", 2, false);
    // No initial state with a partial free list: both keys named.
    edit_json(&seq, |file| file.initial_state.clear());
    let err = format!("{:#}", Sequence::open(&seq).unwrap_err());
    assert!(
        err.contains("`initial_state` is absent")
            && err.contains("`free` lists 7 of the model's 28"),
        "{err}"
    );
    let out = dir.path().join("states.csv");
    assert!(track_err(&seq, &out, None).contains("`free`"));
    // With `free` left out it opens; --init given is then refused, pointing to --init auto.
    edit_json(&seq, |file| file.free = None);
    Sequence::open(&seq).unwrap();
    let err = track_err(&seq, &out, Some(Init::Given));
    assert!(
        err.contains("--init given needs `initial_state`") && err.contains("--init auto"),
        "{err}"
    );
    assert!(!out.exists(), "a refused run writes nothing");
    // A blackout outside the sequence is refused before anything is rendered.
    let options = RenderOptions {
        frames: Some(4),
        size: Some((320, 240)),
        blackout: Some(2..9),
        ..RenderOptions::default()
    };
    let bad = dir.path().join("bad");
    let err = format!(
        "{:#}",
        render_scenario("mouse", &bad, &options).unwrap_err()
    );
    assert!(
        err.contains("blackout 2..9") && err.contains("<= 4"),
        "{err}"
    );
}
