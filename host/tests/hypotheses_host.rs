//! Several hypotheses on the host (issue 11, item 2): `track --hypotheses K` (K = 1 is today's
//! output byte for byte), `--hypotheses-out`'s CSV against the states CSV, the report's plot
//! of the count and the best's score, and the UI's state JSON carrying the other hypotheses as
//! ghosts.

use digiteyes_core::acquire::FinderConfig;
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use digiteyes_core::hypotheses::HypothesesConfig;
use digiteyes_host::report::{build_report, ReportOptions};
use digiteyes_host::scenarios::{render_scenario, RenderOptions};
use digiteyes_host::sequence::hypotheses::{parse_hypotheses, read_hypotheses};
use digiteyes_host::sequence::states::read_states;
use digiteyes_host::sequence::status::Status;
use digiteyes_host::track::{track_sequence_to, Init, TrackOptions, TrackOutputs};
use digiteyes_host::ui::{RunningUi, UiOptions, UiSource};
use digiteyes_host::TrackerConfig;

fn digiteyes(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_digiteyes"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap()
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// `scenario` rendered small into `dir/seq`.
fn render(dir: &Path, scenario: &str, frames: usize, size: (u32, u32)) -> PathBuf {
    let seq = dir.join("seq");
    let options = RenderOptions {
        frames: Some(frames),
        size: Some(size),
        supersample: 1,
        seed: 3,
        ..RenderOptions::default()
    };
    render_scenario(scenario, &seq, &options).unwrap();
    seq
}

#[test]
fn hypotheses_1_writes_todays_states_byte_for_byte_and_bad_counts_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    render(dir.path(), "mouse", 6, (160, 120));
    let plain = digiteyes(&["track", "seq", "-o", "plain.csv", "-q"], dir.path());
    assert!(plain.status.success(), "{}", text(&plain.stderr));
    let one = digiteyes(
        &["track", "seq", "-o", "one.csv", "-q", "--hypotheses", "1"],
        dir.path(),
    );
    assert!(one.status.success(), "{}", text(&one.stderr));
    let plain = std::fs::read(dir.path().join("plain.csv")).unwrap();
    assert!(plain.len() > 100);
    assert_eq!(
        plain,
        std::fs::read(dir.path().join("one.csv")).unwrap(),
        "--hypotheses 1 changed the states"
    );
    for bad in ["0", "9", "two", "-1"] {
        let option = format!("--hypotheses={bad}");
        let out = digiteyes(&["track", "seq", "-o", "bad.csv", &option], dir.path());
        let err = text(&out.stderr);
        assert!(!out.status.success(), "--hypotheses {bad} was taken");
        assert!(
            err.contains("--hypotheses") && err.contains("1 to 8") && err.contains(bad),
            "--hypotheses {bad}: {err}"
        );
    }
    assert!(!dir.path().join("bad.csv").exists());
}

/// `digiteyes track seq --hypotheses 2 EXTRA…` in `dir`, its hypotheses written to
/// `NAME-hypotheses.csv`: returns that file's text.
fn track_two(dir: &Path, name: &str, extra: &[&str]) -> String {
    let (csv, carried) = (format!("{name}.csv"), format!("{name}-hypotheses.csv"));
    let mut args = vec!["track", "seq", "-o", &csv, "-q", "--hypotheses", "2"];
    args.extend_from_slice(&["--hypotheses-out", &carried]);
    args.extend_from_slice(extra);
    let out = digiteyes(&args, dir);
    assert!(out.status.success(), "{}", text(&out.stderr));
    std::fs::read_to_string(dir.join(&carried)).unwrap()
}

/// `--score-every S` reaches the hypotheses: on a whole hand, K = 2 scored one frame in 3
/// carries other hypotheses (`--hypotheses-out`: scores, ages, states) than K = 2 scored
/// every frame, the same on a second run (deterministic), and the first frame's alike (it is
/// scored either way). Without several hypotheses, or at 0, it is refused, naming the option.
#[test]
fn score_every_reaches_the_hypotheses_and_is_refused_where_it_means_nothing() {
    let dir = tempfile::tempdir().unwrap();
    render(dir.path(), "fullhand-mono", 7, (160, 120));
    let track = |name: &str, extra: &[&str]| track_two(dir.path(), name, extra);
    let every = track("every", &[]);
    let one_in_three = track("three", &["--score-every", "3"]);
    let again = track("again", &["--score-every", "3"]);
    assert_eq!(one_in_three, again, "the same run twice");
    assert_ne!(every, one_in_three, "--score-every 3 changed nothing");
    let first_frame = |csv: &str| -> Vec<String> {
        csv.lines()
            .skip(1)
            .filter(|l| l.starts_with("0,"))
            .map(str::to_owned)
            .collect()
    };
    assert!(!first_frame(&every).is_empty());
    assert_eq!(
        first_frame(&every),
        first_frame(&one_in_three),
        "the first frame is scored either way"
    );
    for (args, why) in [
        (vec!["--score-every", "3"], "only several hypotheses"),
        (
            vec!["--hypotheses", "1", "--score-every", "2"],
            "only several hypotheses",
        ),
        (vec!["--hypotheses", "2", "--score-every", "0"], "0"),
    ] {
        let mut all = vec!["track", "seq", "-o", "bad.csv"];
        all.extend_from_slice(&args);
        let out = digiteyes(&all, dir.path());
        let err = text(&out.stderr);
        assert!(!out.status.success(), "{args:?} was taken");
        assert!(
            err.contains("--score-every") && err.contains(why),
            "{args:?}: {err}"
        );
    }
    assert!(!dir.path().join("bad.csv").exists());
}

/// The whole hand tracked with K = 4 from its given initial state, with the hypotheses CSV.
struct Tracked {
    _dir: tempfile::TempDir,
    seq: PathBuf,
    states: PathBuf,
    hypotheses: PathBuf,
    summary: digiteyes_host::TrackSummary,
}

fn track_fullhand_k4() -> Tracked {
    let dir = tempfile::tempdir().unwrap();
    let seq = render(dir.path(), "fullhand-mono", 8, (240, 180));
    let states = dir.path().join("states.csv");
    let hypotheses = dir.path().join("hypotheses.csv");
    let options = TrackOptions {
        init: Some(Init::Given),
        hypotheses: HypothesesConfig {
            count: 4,
            ..HypothesesConfig::default()
        },
        ..TrackOptions::default()
    };
    let outputs = TrackOutputs {
        hypotheses_out: Some(&hypotheses),
        ..TrackOutputs::default()
    };
    let summary = track_sequence_to(
        &seq,
        &states,
        TrackerConfig::default(),
        false,
        &outputs,
        &options,
    )
    .unwrap();
    Tracked {
        _dir: dir,
        seq,
        states,
        hypotheses,
        summary,
    }
}

#[test]
fn k4_writes_every_hypothesis_carried_and_the_best_is_the_output() {
    let run = track_fullhand_k4();
    let n = 28;
    // The states CSV is valid and whole.
    let states = read_states(&run.states, n).unwrap();
    assert_eq!(states.rows.len(), 8);
    let table = read_hypotheses(&run.hypotheses, n).unwrap();
    let by_frame = table.by_frame(8);
    let carried = &run.summary.hypotheses.carried;
    assert_eq!(carried.len(), 8);
    let statuses = states.status.as_ref().unwrap();
    for (k, rows) in by_frame.iter().enumerate() {
        // One row per hypothesis carried, as the tracker reported the count.
        assert_eq!(rows.len(), usize::from(carried[k]), "frame {k}");
        assert!(rows.len() <= 4, "frame {k}: {} rows", rows.len());
        let searching = statuses[k] == Some(Status::Searching);
        assert_eq!(rows.is_empty(), searching, "frame {k}");
        if let Some(best) = rows.first() {
            // Rank 0 is the output.
            assert_eq!(best.rank, 0);
            assert_eq!(
                best.state, states.rows[k],
                "frame {k}: rank 0 is not the output"
            );
            // Best first.
            for w in rows.windows(2) {
                assert!(
                    w[0].score >= w[1].score - 0.011,
                    "frame {k}: not best first"
                );
            }
        }
    }
    assert!(
        carried.iter().any(|&c| c > 1),
        "K = 4 never carried more than one: {carried:?}"
    );
    let text = run.summary.to_string();
    assert!(
        text.contains("hypotheses: up to 4") && text.contains("carried on average"),
        "{text}"
    );
    assert!(text.contains("switched"), "{text}");
    // A parse round trip: the rows written again as text are the file.
    let written = std::fs::read_to_string(&run.hypotheses).unwrap();
    let mut again = written.lines().next().unwrap().to_string();
    again.push('\n');
    for r in &table.rows {
        again.push_str(&format!("{},{},{},{}", r.frame, r.rank, r.score, r.age));
        for v in &r.state {
            again.push_str(&format!(",{v}"));
        }
        again.push('\n');
    }
    assert_eq!(again, written);
    assert_eq!(parse_hypotheses(&again, n).unwrap(), table);

    // The report plots the count and the best's score only when asked.
    let mut options = ReportOptions::default();
    options.thumb_every = 0;
    let (without, summary) = build_report(&run.seq, &run.states, &options).unwrap();
    assert!(!without.contains("hypotheses-plot"));
    assert_eq!(summary.hypotheses_plots, 0);
    options.hypotheses = Some(run.hypotheses.clone());
    let (with, summary) = build_report(&run.seq, &run.states, &options).unwrap();
    assert_eq!(summary.hypotheses_plots, 2);
    assert!(with.contains(r#"class="hypotheses-plot" data-series="count""#));
    assert!(with.contains(r#"class="hypotheses-plot" data-series="best-score""#));
    assert!(with.contains("<h2>Hypotheses</h2>"));
    assert!(with.contains(r#"<polyline class="hyp-count""#));
}

#[test]
fn searching_frames_carry_no_hypotheses() {
    let dir = tempfile::tempdir().unwrap();
    render(dir.path(), "fullhand-mono", 12, (240, 180));
    let out = digiteyes(
        &[
            "track",
            "seq",
            "-q",
            "--init",
            "auto",
            "--hypotheses",
            "2",
            "--hypotheses-out",
            "hyp.csv",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let states = read_states(&dir.path().join("states.csv"), 28).unwrap();
    let table = read_hypotheses(&dir.path().join("hyp.csv"), 28).unwrap();
    let by_frame = table.by_frame(states.rows.len());
    let statuses = states.status.unwrap();
    let searching = |k: usize| statuses[k] == Some(Status::Searching);
    assert!(
        (0..statuses.len()).any(searching),
        "no searching frame to judge: {statuses:?}"
    );
    for (k, rows) in by_frame.iter().enumerate() {
        assert_eq!(
            rows.is_empty(),
            searching(k),
            "frame {k}: {} rows",
            rows.len()
        );
        // Up to K, or for the few frames that confirm an acquisition, up to the search's
        // confirming count (its other good leaves carried beside the accepted one, and one
        // camera's two depth variants).
        let confirming = usize::from(FinderConfig::default().confirm_capacity(1));
        assert!(
            rows.len() <= confirming.max(2),
            "frame {k}: {} rows",
            rows.len()
        );
    }
    assert!(text(&out.stdout).contains("hypotheses: up to 2"));
}

/// `GET path` on the UI; the body.
fn get(addr: SocketAddr, path: &str) -> String {
    let mut stream = TcpStream::connect_timeout(&addr, Duration::from_secs(2)).unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(2)))
        .unwrap();
    write!(
        stream,
        "GET {path} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut response = Vec::new();
    let _ = stream.read_to_end(&mut response);
    let text = String::from_utf8_lossy(&response).into_owned();
    assert!(text.starts_with("HTTP/1.1 200"), "{text}");
    text.split_once("\r\n\r\n").unwrap().1.to_string()
}

#[test]
fn the_ui_state_carries_the_other_hypotheses_as_ghosts() {
    let dir = tempfile::tempdir().unwrap();
    let seq = render(dir.path(), "mouse", 4, (160, 120));
    let states = dir.path().join("states.csv");
    digiteyes_host::track_sequence(&seq, &states, TrackerConfig::default(), false).unwrap();
    let table = read_states(&states, 28).unwrap();
    // Every frame: the output and one other, finger 1's MCP bent 0.5 rad further.
    let mut csv = digiteyes_host::sequence::hypotheses::hypotheses_header(28);
    csv.push('\n');
    for (k, row) in table.rows.iter().enumerate() {
        for (rank, bend) in [(0, 0.0), (1, 0.5)] {
            csv.push_str(&format!("{k},{rank},{},{k}", 0.9 - 0.1 * rank as f64));
            for (i, v) in row.iter().enumerate() {
                csv.push_str(&format!(",{}", if i == 8 { v + bend } else { *v }));
            }
            csv.push('\n');
        }
    }
    let hypotheses = dir.path().join("hypotheses.csv");
    std::fs::write(&hypotheses, &csv).unwrap();

    let start = |hypotheses: Option<PathBuf>| {
        RunningUi::start(
            &UiOptions {
                bind: "127.0.0.1:0".parse().unwrap(),
                source: UiSource::Replay {
                    seqdir: seq.clone(),
                    states: states.clone(),
                    hypotheses,
                    camera: 0,
                    fps: Some(50.0),
                },
                duration: None,
            },
            &mut std::io::sink(),
        )
    };
    let ui = start(Some(hypotheses.clone())).expect("the UI starts");
    let addr: SocketAddr = ui
        .url()
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .parse()
        .unwrap();
    let deadline = Instant::now() + Duration::from_secs(20);
    let json = loop {
        let json: serde_json::Value = serde_json::from_str(&get(addr, "/api/state")).unwrap();
        if json["state"].is_object() {
            break json;
        }
        assert!(Instant::now() < deadline, "the replay showed no state");
        // Polling for the replay's first state, not waiting out a guess.
        std::thread::sleep(Duration::from_millis(20));
    };
    ui.stop().unwrap();
    let frame = json["state"]["frame"].as_u64().unwrap() as usize;
    assert_eq!(json["hypotheses"], 2, "{json}");
    assert!((json["best_score"].as_f64().unwrap() - 0.9).abs() < 1e-6);
    let ghosts = json["ghosts"].as_array().unwrap();
    assert_eq!(ghosts.len(), 1, "{json}");
    assert_eq!(ghosts[0]["rank"], 1);
    assert_eq!(ghosts[0]["age"], frame as u64);
    let q8 = ghosts[0]["q"][8].as_f64().unwrap();
    assert!(
        (q8 - (table.rows[frame][8] + 0.5)).abs() < 1e-5,
        "{q8} vs {}",
        table.rows[frame][8]
    );
    assert_eq!(ghosts[0]["shapes"].as_array().unwrap().len(), 16);

    // Without the file: no ghost.
    let ui = start(None).expect("the UI starts");
    let deadline = Instant::now() + Duration::from_secs(20);
    while ui.hub().snapshot().state.is_none() {
        assert!(Instant::now() < deadline, "the replay showed no state");
        std::thread::sleep(Duration::from_millis(20));
    }
    let snapshot = ui.hub().snapshot();
    ui.stop().unwrap();
    assert!(snapshot.ghosts.is_empty() && snapshot.hypotheses == 0);

    // A file of another run (a frame past the states' last) is refused, naming it.
    std::fs::write(&hypotheses, format!("{csv}9,0,0.5,1{}\n", ",0".repeat(28))).unwrap();
    let err = format!("{:#}", start(Some(hypotheses.clone())).err().unwrap());
    assert!(
        err.contains("hypotheses.csv") && err.contains("frame 9"),
        "{err}"
    );
}

/// `--sample-iterations` and `--other-iterations` reach the hypotheses: on a whole hand, K = 2
/// with either cap at one iteration carries other hypotheses than by default, while a cap at the
/// tracker's own number (8) is no cap. Without several hypotheses (or a cap at 0) each, and
/// `--no-keep-fingers`, is refused, naming the option. (No finger-undo candidate is kept on
/// these frames, so `--no-keep-fingers` shows nothing in the output here; the option's mapping
/// is checked in `cli::hypothesis_budget`.)
#[test]
fn iteration_caps_reach_the_hypotheses_and_are_refused_where_they_mean_nothing() {
    let dir = tempfile::tempdir().unwrap();
    render(dir.path(), "fullhand-mono", 7, (160, 120));
    let track = |name: &str, extra: &[&str]| track_two(dir.path(), name, extra);
    let own = track("own", &[]);
    assert_ne!(
        own,
        track("samples", &["--sample-iterations", "1"]),
        "--sample-iterations 1 changed nothing"
    );
    assert_ne!(
        own,
        track("others", &["--other-iterations", "1"]),
        "--other-iterations 1 changed nothing"
    );
    assert_eq!(
        own,
        track(
            "at-own",
            &["--sample-iterations", "8", "--other-iterations", "8"]
        ),
        "a cap at the tracker's own number is no cap"
    );
    for option in ["--sample-iterations", "--other-iterations"] {
        for (args, why) in [
            (vec![option, "2"], "only several hypotheses"),
            (
                vec!["--hypotheses", "1", option, "2"],
                "only several hypotheses",
            ),
            (vec!["--hypotheses", "2", option, "0"], "0"),
        ] {
            let mut all = vec!["track", "seq", "-o", "bad.csv"];
            all.extend_from_slice(&args);
            let out = digiteyes(&all, dir.path());
            let err = text(&out.stderr);
            assert!(!out.status.success(), "{args:?} was taken");
            assert!(err.contains(option) && err.contains(why), "{args:?}: {err}");
        }
    }
    for args in [
        vec!["--no-keep-fingers"],
        vec!["--hypotheses", "1", "--no-keep-fingers"],
    ] {
        let mut all = vec!["track", "seq", "-o", "bad.csv"];
        all.extend_from_slice(&args);
        let out = digiteyes(&all, dir.path());
        let err = text(&out.stderr);
        assert!(!out.status.success(), "{args:?} was taken");
        assert!(
            err.contains("--no-keep-fingers") && err.contains("only several hypotheses"),
            "{args:?}: {err}"
        );
    }
    assert!(!dir.path().join("bad.csv").exists());
}
