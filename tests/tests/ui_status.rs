//! The tracker's status in the UI, in a real browser (headless Chromium): a board's states
//! say searching, tracking or lost (protocol version 4), and the page shows it — a badge, and
//! the 3D hand solid while tracking, ghosted while lost (the last good state, held), not drawn
//! while searching. A replayed states CSV with a `status` column shows it the same way.
//!
//! Lock-stepped with the page: a keeper hands the UI a fresh state of the status under test
//! each time the page has polled, so the signal never goes stale however slowly the browser
//! starts, and nothing waits out a guessed time.
//!
//! Needs Debian's `chromium` (scripts/test installs it; `DIGITEYES_CHROMIUM` names another
//! binary). Without it each test prints `SKIPPED: ...` to stderr and passes (under `CI=true` it
//! fails).

mod common;

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use digiteyes_core::protocol::{BoardMessage, State, WireStatus};
use digiteyes_host::scenarios::{render_scenario, scenario, RenderOptions};
use digiteyes_host::ui::hub::Hub;
use digiteyes_host::ui::{RunningUi, UiOptions, UiSource};
use digiteyes_host::{track_sequence, TrackerConfig};

/// How long each page runs (ms of its own time).
const PAGE_BUDGET_MS: u32 = 4_000;
/// How long the keeper waits for the page's next poll before giving up.
const POLL_DEADLINE: Duration = Duration::from_secs(20);

fn chromium_or_skip(test: &str) -> Option<PathBuf> {
    match common::browser::chromium() {
        Ok(exe) => Some(exe),
        Err(reason) => {
            common::skip(
                &format!("UI status test `{test}` (tests/tests/ui_status.rs)"),
                &reason,
            );
            None
        }
    }
}

/// The value of `data-NAME` on the page's `<body>`.
fn body_data<'a>(dom: &'a str, name: &str) -> &'a str {
    let body = &dom[dom.find("<body").expect("a <body>")..];
    let tag = &body[..body.find('>').unwrap()];
    let key = format!(r#"data-{name}=""#);
    let start = tag
        .find(&key)
        .unwrap_or_else(|| panic!("no data-{name} on <body>: {tag}"))
        + key.len();
    &tag[start..start + tag[start..].find('"').unwrap()]
}

/// The status badge's text.
fn badge(dom: &str) -> &str {
    let at = dom.find(r#"id="status""#).expect("the status badge");
    let rest = &dom[at..];
    let text = &rest[rest.find('>').unwrap() + 1..];
    &text[..text.find('<').unwrap()]
}

fn mouse_rest() -> Vec<f32> {
    scenario("mouse")
        .unwrap()
        .base
        .iter()
        .map(|&v| v as f32)
        .collect()
}

/// A board's `State` with `status` (`lost` whenever it is not tracking, as boards send it).
fn state(frame: u32, q: &[f32], status: WireStatus) -> BoardMessage {
    let tracking = status == WireStatus::Tracking;
    BoardMessage::State(State {
        frame,
        timestamp: u64::from(frame) * 1000,
        q: heapless::Vec::from_slice(q).unwrap(),
        rms_px: if tracking { 0.75 } else { 0.0 },
        lost: !tracking,
        features_found: if tracking { 40 } else { 0 },
        features_expected: 42,
        iterations: 3,
        track_ticks: 5000,
        status,
        search_evaluations: if status == WireStatus::Searching {
            900
        } else {
            0
        },
    })
}

/// Hands the hub a new state of one status every time the page has polled (lock-stepped
/// with the page), until dropped.
struct Keeper {
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<u32>>,
}

impl Keeper {
    fn start(hub: Arc<Hub>, q: Vec<f32>, status: WireStatus) -> Keeper {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        hub.push_message(&state(0, &q, status));
        let thread = std::thread::spawn(move || {
            let mut frame = 0;
            let mut polls = hub.polls_served();
            while !flag.load(Ordering::Relaxed) {
                let deadline = Instant::now() + POLL_DEADLINE;
                while hub.polls_served() == polls {
                    if flag.load(Ordering::Relaxed) || Instant::now() > deadline {
                        return frame;
                    }
                    // Polling a condition the page makes true, not waiting out a guess.
                    std::thread::sleep(Duration::from_millis(2));
                }
                polls = hub.polls_served();
                frame += 1;
                hub.push_message(&state(frame, &q, status));
            }
            frame
        });
        Keeper {
            stop,
            thread: Some(thread),
        }
    }

    /// Stops; the states handed over after the first (one per poll of the page).
    fn finish(mut self) -> u32 {
        self.stop.store(true, Ordering::Relaxed);
        self.thread.take().map_or(0, |t| t.join().unwrap())
    }
}

impl Drop for Keeper {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The DOM of the page fed states of `status` throughout.
fn page_with(exe: &Path, status: WireStatus) -> String {
    let options = UiOptions {
        bind: "127.0.0.1:0".parse().unwrap(),
        source: UiSource::Udp("127.0.0.1:0".parse().unwrap()),
        duration: None,
    };
    let ui = RunningUi::start(&options, &mut std::io::sink()).expect("the UI starts");
    let keeper = Keeper::start(Arc::clone(ui.hub()), mouse_rest(), status);
    let dom = common::browser::dump_dom(exe, &ui.url(), PAGE_BUDGET_MS);
    let polls = keeper.finish();
    ui.stop().unwrap();
    assert!(polls > 0, "the page never polled the UI");
    dom
}

#[test]
fn the_page_shows_each_status_and_draws_the_hand_accordingly() {
    let Some(exe) = chromium_or_skip("each status") else {
        return;
    };
    for (status, word, text, hand, shapes) in [
        (WireStatus::Tracking, "tracking", "TRACKING", "solid", "16"),
        (WireStatus::Lost, "lost", "LOST TRACK", "ghost", "16"),
        (
            WireStatus::Searching,
            "searching",
            "SEARCHING",
            "hidden",
            "0",
        ),
    ] {
        let dom = page_with(&exe, status);
        assert_eq!(badge(&dom), text, "{word}:\n{dom}");
        assert_eq!(body_data(&dom, "status"), word);
        assert_eq!(body_data(&dom, "hand"), hand, "{word}");
        assert_eq!(body_data(&dom, "shapes-drawn"), shapes, "{word}");
        assert!(
            dom.contains(&format!(" · {word} · ")),
            "{word}: the frame line does not name the status"
        );
    }
}

#[test]
fn a_replayed_csv_with_a_status_column_shows_it() {
    let Some(exe) = chromium_or_skip("replay status") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("mouse");
    let render = RenderOptions {
        frames: Some(4),
        size: Some((160, 120)),
        supersample: 1,
        ..RenderOptions::default()
    };
    render_scenario("mouse", &seq, &render).unwrap();
    let tracked = seq.join("tracked.csv");
    track_sequence(&seq, &tracked, TrackerConfig::default(), false).unwrap();
    // The same rows, every one claimed by nobody: `searching`, with `lost` 1.
    let text = std::fs::read_to_string(&tracked).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let columns: Vec<&str> = header.split(',').collect();
    let lost = columns.iter().position(|&c| c == "lost").unwrap();
    let status = columns.iter().position(|&c| c == "status");
    let mut out = String::new();
    match status {
        Some(_) => out.push_str(header),
        None => out.push_str(&format!("{header},status")),
    }
    out.push('\n');
    for line in lines {
        let mut fields: Vec<String> = line.split(',').map(str::to_string).collect();
        fields[lost] = "1".into();
        match status {
            Some(i) => fields[i] = "searching".into(),
            None => fields.push("searching".into()),
        }
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    let states = seq.join("states.csv");
    std::fs::write(&states, out).unwrap();

    let ui = RunningUi::start(
        &UiOptions {
            bind: "127.0.0.1:0".parse().unwrap(),
            source: UiSource::Replay {
                seqdir: seq.clone(),
                states,
                hypotheses: None,
                camera: 0,
                fps: Some(20.0),
            },
            duration: None,
        },
        &mut std::io::sink(),
    )
    .expect("the UI starts");
    let dom = common::browser::dump_dom(&exe, &ui.url(), PAGE_BUDGET_MS);
    let shown = ui.hub().snapshot().state.map(|s| s.status.as_str());
    ui.stop().unwrap();
    assert_eq!(shown, Some("searching"), "the replay's states");
    assert_eq!(badge(&dom), "SEARCHING", "{dom}");
    assert_eq!(body_data(&dom, "hand"), "hidden");
}

/// The DOM of a replay of a tracked 4-frame mouse sequence at 160×120, with a hypotheses CSV
/// holding, for every frame, the output and one other (finger 1's MCP bent 0.5 rad further)
/// when `with_hypotheses`.
fn replay_page(exe: &Path, with_hypotheses: bool) -> String {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("mouse");
    let render = RenderOptions {
        frames: Some(4),
        size: Some((160, 120)),
        supersample: 1,
        ..RenderOptions::default()
    };
    render_scenario("mouse", &seq, &render).unwrap();
    let states = seq.join("states.csv");
    track_sequence(&seq, &states, TrackerConfig::default(), false).unwrap();
    let table = digiteyes_host::sequence::states::read_states(&states, 28).unwrap();
    let mut csv = digiteyes_host::sequence::hypotheses::hypotheses_header(28);
    csv.push('\n');
    for (k, row) in table.rows.iter().enumerate() {
        for (rank, bend) in [(0, 0.0), (1, 0.5)] {
            csv.push_str(&format!("{k},{rank},0.9,{k}"));
            for (i, v) in row.iter().enumerate() {
                csv.push_str(&format!(",{}", if i == 8 { v + bend } else { *v }));
            }
            csv.push('\n');
        }
    }
    let hypotheses = seq.join("hypotheses.csv");
    std::fs::write(&hypotheses, csv).unwrap();
    let ui = RunningUi::start(
        &UiOptions {
            bind: "127.0.0.1:0".parse().unwrap(),
            source: UiSource::Replay {
                seqdir: seq.clone(),
                states,
                hypotheses: with_hypotheses.then_some(hypotheses),
                camera: 0,
                fps: Some(20.0),
            },
            duration: None,
        },
        &mut std::io::sink(),
    )
    .expect("the UI starts");
    let dom = common::browser::dump_dom(exe, &ui.url(), PAGE_BUDGET_MS);
    ui.stop().unwrap();
    dom
}

#[test]
fn a_replay_with_hypotheses_draws_the_others_ghosted_behind_the_hand() {
    let Some(exe) = chromium_or_skip("replay hypotheses") else {
        return;
    };
    let dom = replay_page(&exe, true);
    assert_eq!(body_data(&dom, "hand"), "solid", "{dom}");
    assert_eq!(body_data(&dom, "shapes-drawn"), "16");
    assert_eq!(body_data(&dom, "ghosts-drawn"), "1", "{dom}");
    assert!(
        dom.contains(" · 2 hypotheses, the best scoring 0.900"),
        "{dom}"
    );
    let dom = replay_page(&exe, false);
    assert_eq!(body_data(&dom, "hand"), "solid", "{dom}");
    assert_eq!(body_data(&dom, "ghosts-drawn"), "0", "{dom}");
}
