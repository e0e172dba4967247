//! Several hypotheses on a board through the `digiteyes` command (protocol version 5):
//! `stream --hypotheses K` has a simulated board (the firmware's loop) carry K hypotheses and
//! the summary count the `Hypotheses` messages that follow its states; `listen` prints each
//! one and counts them; a count out of 1 to 8, or with one board per camera, is refused clearly;
//! `--score-every S` (protocol version 9) and the caps on the hypotheses' iterations
//! (`--sample-iterations`, `--other-iterations`, protocol version 10) reach the board, and are
//! refused where they mean nothing; `--hypotheses-out` writes what the board carried, the same
//! file as `track`'s.

mod common;

use std::process::Command;

use digiteyes_core::protocol::{BoardMessage, Hypotheses, State, WireHypothesis, WireStatus};
use digiteyes_host::sim::{self, SimOptions};

/// `stream --hypotheses 3` on a whole-hand sequence: every tracked frame's state is followed
/// by its hypotheses (one message each, 1 to 3 carried), which the summary counts; without
/// the option (one hypothesis) no such message comes and the summary has no such line.
#[test]
fn stream_with_hypotheses_counts_what_the_board_carried() {
    let dir = tempfile::tempdir().unwrap();
    let frames = 8;
    common::small_sequence(dir.path(), "fullhand-mono", frames);
    let run = |extra: &[&str], csv: &str| {
        let board = sim::start(SimOptions::default()).unwrap();
        let port = board.path().display().to_string();
        let out = Command::new(env!("CARGO_BIN_EXE_digiteyes"))
            .args(["stream", "--port", &port, "--seq", "fullhand-mono"])
            .args(extra)
            .args(["--out", csv, "--quiet"])
            .current_dir(dir.path())
            .output()
            .unwrap();
        let report = board.stop().unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        assert!(
            out.status.success(),
            "{stdout}\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(report.board.frames, frames as u32, "{report:?}");
        stdout
    };
    let stdout = run(&["--hypotheses", "3"], "k3.csv");
    assert!(stdout.contains(&format!("{frames} tracked")), "{stdout}");
    let line = stdout
        .lines()
        .find(|l| l.trim_start().starts_with("hypotheses: "))
        .unwrap_or_else(|| panic!("a hypotheses line: {stdout}"));
    // "  hypotheses: 4 messages, 2.50 carried on average (best's mean score 0.850)"
    let words: Vec<&str> = line.split_whitespace().collect();
    assert_eq!(
        words[1],
        frames.to_string(),
        "one message per frame: {line}"
    );
    let mean: f64 = words[3].parse().unwrap();
    assert!((1.0..=3.0).contains(&mean), "{line}");
    assert!(
        mean > 1.0,
        "a whole hand carries more than one hypothesis: {line}"
    );
    assert!(line.contains("best's mean score 0."), "{line}");

    // Scored one frame in two (protocol version 9), the board still sends one message a
    // frame, and carries other hypotheses than when it scores every frame.
    let every_other = run(&["--hypotheses", "3", "--score-every", "2"], "k3s2.csv");
    assert!(
        every_other.contains(&format!("hypotheses: {frames} messages")),
        "{every_other}"
    );
    // What the board estimated, without its `board_ticks` (its time, which differs from run to
    // run): two runs alike compare equal.
    let read = |csv: &str| -> Vec<String> {
        let text = std::fs::read_to_string(dir.path().join(csv)).unwrap();
        let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
        let ticks = header.iter().position(|c| *c == "board_ticks").unwrap();
        text.lines()
            .map(|line| {
                let mut cells: Vec<&str> = line.split(',').collect();
                cells.remove(ticks);
                cells.join(",")
            })
            .collect()
    };
    run(&["--hypotheses", "3"], "k3-again.csv");
    assert_eq!(read("k3.csv"), read("k3-again.csv"), "the same run twice");
    assert_ne!(
        read("k3.csv"),
        read("k3s2.csv"),
        "--score-every 2 changed nothing"
    );

    // With the iterations of the samples and of the hypotheses other than the best capped at
    // one (protocol version 10), the board carries other hypotheses than uncapped.
    let capped = run(
        &[
            "--hypotheses",
            "3",
            "--sample-iterations",
            "1",
            "--other-iterations",
            "1",
        ],
        "k3i1.csv",
    );
    assert!(
        capped.contains(&format!("hypotheses: {frames} messages")),
        "{capped}"
    );
    assert_ne!(
        read("k3.csv"),
        read("k3i1.csv"),
        "--sample-iterations 1 --other-iterations 1 changed nothing"
    );

    let single = run(&["--hypotheses", "1"], "k1.csv");
    assert!(
        !single.contains("hypotheses:"),
        "one hypothesis, no such message: {single}"
    );
}

/// `stream --hypotheses-out` writes the hypotheses the board sent, and since the board's
/// tracker is the host's, the file is byte for byte the one `track --hypotheses-out` writes
/// on the same sequence.
#[test]
fn stream_writes_the_boards_hypotheses_as_track_writes_its_own() {
    let dir = tempfile::tempdir().unwrap();
    let frames = 8;
    common::small_sequence(dir.path(), "fullhand-mono", frames);
    let digiteyes = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_digiteyes"))
            .args(args)
            .current_dir(dir.path())
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        assert!(
            out.status.success(),
            "{args:?}: {stdout}\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        stdout
    };
    let board = sim::start(SimOptions::default()).unwrap();
    let port = board.path().display().to_string();
    let streamed = digiteyes(&[
        "stream",
        "--port",
        &port,
        "--seq",
        "fullhand-mono",
        "--hypotheses",
        "3",
        "--hypotheses-out",
        "board-hyp.csv",
        "--out",
        "board.csv",
        "--quiet",
    ]);
    board.stop().unwrap();
    digiteyes(&[
        "track",
        "fullhand-mono",
        "--hypotheses",
        "3",
        "--hypotheses-out",
        "host-hyp.csv",
        "--out",
        "host.csv",
        "--quiet",
    ]);
    let read = |name: &str| std::fs::read_to_string(dir.path().join(name)).unwrap();
    let (on_board, on_host) = (read("board-hyp.csv"), read("host-hyp.csv"));
    let rows = on_board.lines().count() - 1;
    assert!(
        rows > frames,
        "more than one hypothesis on some frame: {rows} rows"
    );
    assert!(
        streamed.contains(&format!(
            "hypotheses: {rows} row(s) written to board-hyp.csv"
        )),
        "{streamed}"
    );
    assert_eq!(on_board, on_host, "the board's hypotheses are the host's");
    let last = on_board.lines().last().unwrap();
    assert!(
        last.starts_with(&format!("{},", frames - 1)),
        "the last frame's hypotheses (they follow its state) are written: {last}"
    );
}

fn state(frame: u32) -> BoardMessage {
    BoardMessage::State(State {
        frame,
        timestamp: 1000 * u64::from(frame),
        q: [1.0, 0.0, 0.0, 0.0, 1.5, -2.0, 600.0].into_iter().collect(),
        rms_px: 0.5,
        lost: false,
        features_found: 20,
        features_expected: 24,
        iterations: 5,
        track_ticks: 1234,
        status: WireStatus::Tracking,
        search_evaluations: 0,
    })
}

fn hypotheses(frame: u32, scores: &[f32]) -> BoardMessage {
    BoardMessage::Hypotheses(Hypotheses {
        frame,
        hypotheses: scores
            .iter()
            .enumerate()
            .map(|(i, &score)| WireHypothesis {
                score,
                age: 10 - i as u32,
                q: [1.0, 0.0, 0.0, 0.0, 1.5, -2.0, 600.0 + i as f32]
                    .into_iter()
                    .collect(),
            })
            .collect(),
    })
}

#[test]
fn listen_prints_each_hypotheses_message_and_counts_them() {
    // Two frames with their hypotheses (3, then 1), then a third state: listen stops there.
    let messages = [
        state(7),
        hypotheses(7, &[0.9, 0.875, 0.5]),
        state(8),
        hypotheses(8, &[0.75]),
        state(9),
    ];
    let (printed, summary) = common::listen_to(&messages, 3);
    let lines: Vec<&str> = printed.lines().collect();
    assert_eq!(lines.len(), 5, "{printed}");
    assert_eq!(
        lines[1],
        "hypotheses 7: 3 carried, best first: 0.9000 (age 10), 0.8750 (age 9), 0.5000 (age 8)"
    );
    assert_eq!(
        lines[3],
        "hypotheses 8: 1 carried, best first: 0.7500 (age 10)"
    );
    assert!(
        summary
            .iter()
            .any(|l| l.contains("2 hypotheses messages, 2.00 carried on average")),
        "{summary:?}"
    );
}

#[test]
fn a_hypothesis_count_out_of_range_or_with_a_board_per_camera_is_refused_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let one_board = ["--port", "/nonexistent/a", "--seq", "mono"];
    let two_boards = [&common::TWO_ABSENT_BOARDS[..], &["--seq", "stereo"]].concat();
    // (the boards, the options, what the error must name)
    let cases: [(&[&str], &[&str], [&str; 2]); 10] = [
        (
            &one_board,
            &["--hypotheses", "0"],
            ["--hypotheses", "1 to 8"],
        ),
        (
            &one_board,
            &["--hypotheses", "9"],
            ["--hypotheses", "1 to 8"],
        ),
        (
            &two_boards,
            &["--hypotheses", "2"],
            ["--hypotheses", "one board per camera"],
        ),
        (
            &two_boards,
            &["--score-every", "2"],
            ["--score-every", "one board per camera"],
        ),
        (
            &one_board,
            &["--score-every", "2"],
            ["--score-every", "only several hypotheses"],
        ),
        (
            &two_boards,
            &["--other-iterations", "2"],
            ["--other-iterations", "one board per camera"],
        ),
        (
            &one_board,
            &["--sample-iterations", "2"],
            ["--sample-iterations", "only several hypotheses"],
        ),
        (
            &one_board,
            &["--no-keep-fingers"],
            ["--no-keep-fingers", "only several hypotheses"],
        ),
        (
            &one_board,
            &["--hypotheses-out", "one.csv"],
            ["--hypotheses-out one.csv", "only when it carries several"],
        ),
        (
            &two_boards,
            &["--hypotheses", "2", "--hypotheses-out", "two.csv"],
            ["--hypotheses-out", "one board per camera"],
        ),
    ];
    for (boards, options, named) in cases {
        let mut args = vec!["stream"];
        args.extend_from_slice(boards);
        args.extend_from_slice(options);
        let stderr = common::refused(dir.path(), &args);
        assert!(
            named.iter().all(|n| stderr.contains(n)),
            "{options:?}: {stderr}"
        );
    }
    assert!(!dir.path().join("one.csv").exists() && !dir.path().join("two.csv").exists());
}
