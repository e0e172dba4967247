//! The board's status through the `digiteyes` command (protocol version 4): `listen` prints
//! each state's status and counts them; `stream --init auto` has a simulated board (the
//! firmware's loop) search for the hand, and its CSV says so in a `status` column.

mod common;

use std::process::Command;

use digiteyes_core::protocol::{BoardMessage, State, WireStatus};
use digiteyes_host::sim::{self, SimOptions};

fn state(frame: u32, status: WireStatus) -> BoardMessage {
    let tracking = status == WireStatus::Tracking;
    BoardMessage::State(State {
        frame,
        timestamp: 1000 * u64::from(frame),
        q: [1.0, 0.0, 0.0, 0.0, 1.5, -2.0, 600.0].into_iter().collect(),
        rms_px: 0.5,
        lost: !tracking,
        features_found: 20,
        features_expected: 24,
        iterations: 5,
        track_ticks: 1234,
        status,
        search_evaluations: if status == WireStatus::Searching {
            977
        } else {
            0
        },
    })
}

#[test]
fn listen_prints_each_states_status_and_counts_them() {
    let messages: Vec<BoardMessage> = [
        (7, WireStatus::Searching),
        (8, WireStatus::Tracking),
        (9, WireStatus::Lost),
        (10, WireStatus::Searching),
    ]
    .into_iter()
    .map(|(frame, status)| state(frame, status))
    .collect();
    let (printed, summary) = common::listen_to(&messages, 4);
    let lines: Vec<&str> = printed.lines().collect();
    assert_eq!(lines.len(), 4, "{printed}");
    assert!(
        lines[0].starts_with("state 7 searching (977 evaluations): "),
        "{}",
        lines[0]
    );
    assert!(lines[1].starts_with("state 8 tracking: "), "{}", lines[1]);
    assert!(lines[2].starts_with("state 9 lost: ") && lines[2].contains("LOST"));
    assert!(lines[3].starts_with("state 10 searching "), "{}", lines[3]);
    assert!(
        summary
            .iter()
            .any(|l| l.contains("4 states: 1 tracking, 1 lost, 2 searching")),
        "{summary:?}"
    );
}

#[test]
fn stream_init_auto_has_a_simulated_board_search_and_writes_the_status() {
    let dir = tempfile::tempdir().unwrap();
    common::small_sequence(dir.path(), "mouse", 3);
    let board = sim::start(SimOptions::default()).unwrap();
    let port = board.path().display().to_string();
    let out = Command::new(env!("CARGO_BIN_EXE_digiteyes"))
        .args([
            "stream", "--port", &port, "--seq", "mouse", "--init", "auto",
        ])
        .args(["--out", "s.csv", "--quiet"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    let report = board.stop().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && stdout.contains("3 tracked"),
        "every frame answered:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(report.board.frames, 3, "{report:?}");
    let csv = std::fs::read_to_string(dir.path().join("s.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        &header[header.len() - 4..],
        ["lost", "dropped", "status", "board_ticks"]
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 3);
    // lost, dropped, status and the board's ticks of each row.
    let tail = |row: &[&str]| -> [String; 4] {
        core::array::from_fn(|k| row[row.len() - 4 + k].to_string())
    };
    // The first frame of a search can only search; later ones may have found the hand.
    assert_eq!(&tail(&rows[0])[..3], ["1", "", "searching"]);
    for row in &rows {
        let [lost, _, status, ticks] = tail(row);
        assert_eq!(lost == "1", status != "tracking", "{row:?}");
        assert!(ticks.parse::<u32>().is_ok_and(|t| t > 0), "{row:?}");
    }
    let searching = rows.iter().filter(|r| tail(r)[2] == "searching").count();
    assert!(
        stdout.contains(&format!("{searching} searching")),
        "the summary counts the statuses: {stdout}"
    );

    // Without --init auto the same board tracks from the initial state.
    let board = sim::start(SimOptions::default()).unwrap();
    let port = board.path().display().to_string();
    let out = Command::new(env!("CARGO_BIN_EXE_digiteyes"))
        .args(["stream", "--port", &port, "--seq", "mouse"])
        .args(["--out", "given.csv", "--quiet"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    board.stop().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = std::fs::read_to_string(dir.path().join("given.csv")).unwrap();
    assert!(
        csv.lines().skip(1).all(|l| l
            .rsplit_once(',')
            .is_some_and(|(head, _)| head.ends_with(",0,,tracking"))),
        "{csv}"
    );
}

#[test]
fn init_auto_with_one_board_per_camera_is_refused_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let args = [
        &["stream"][..],
        &common::TWO_ABSENT_BOARDS,
        &["--seq", "stereo", "--init", "auto"],
    ]
    .concat();
    let stderr = common::refused(dir.path(), &args);
    assert!(
        stderr.contains("--init auto") && stderr.contains("accepted: --init given"),
        "{stderr}"
    );
}
