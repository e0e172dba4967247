//! The host and the emulated Cortex-M7 board (`boards/qemu-m7`, the tracker firmware on
//! `qemu-system-arm`) over a real serial link: a socat PTY pair, one end on QEMU's UART0, the
//! other opened by `digiteyes stream`. Every frame must be tracked, and as accurately as the
//! host tracker tracks the same frames.
//!
//! Needs the release ELF (`cd boards/qemu-m7 && cargo build --release`; `scripts/test` builds
//! it first), `qemu-system-arm` and `socat` (`apt-get install -y qemu-system-arm socat`);
//! without them it prints `SKIPPED: ...` to stderr and passes (under `CI=true` it fails). QEMU's UART moves host → board
//! bytes at only ~10–25 KB/s, so the frames are QQVGA (19.2 KB, ~1 s each). Every wait is on
//! a condition with a deadline that fails the test; QEMU and socat are killed when the test
//! ends, however it ends.

mod common;

use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use digiteyes_core::frame::FrameView;
use digiteyes_host::link::FrameOutcome;
use digiteyes_host::sequence::Sequence;
use digiteyes_host::{
    evaluate, render_scenario, sequence_tracker, stream_sequence, track_sequence, RenderOptions,
    StreamOptions, TrackerConfig,
};

/// Frames streamed: enough for the tracker to move, few enough for the slow UART.
const FRAMES: usize = 6;
/// QQVGA: 19.2 KB a frame, about a second each on QEMU's UART.
const SIZE: (u32, u32) = (160, 120);
/// The board may be this much worse than the host (relative) ...
const RELATIVE_SLACK: f64 = 0.10;
/// ... plus this (px), so that near-zero errors do not flake.
const ABSOLUTE_SLACK_PX: f64 = 0.05;

/// A child process killed (and reaped) when dropped.
struct KillOnDrop {
    child: Child,
    what: &'static str,
}

impl KillOnDrop {
    fn spawn(command: &mut Command, what: &'static str) -> KillOnDrop {
        let child = command
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start {what}: {e}"));
        KillOnDrop { child, what }
    }

    /// Fails the test if the process has already exited.
    fn check_running(&mut self, log: &Path) {
        if let Ok(Some(status)) = self.child.try_wait() {
            panic!(
                "{} exited early ({status}):\n{}",
                self.what,
                std::fs::read_to_string(log).unwrap_or_default()
            );
        }
    }
}

impl Drop for KillOnDrop {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Waits until `ready()` holds, failing the test with `what` after `limit`. `alive` is
/// checked between tries (a process that died will never make it true).
fn wait_until(
    limit: Duration,
    what: &str,
    mut alive: impl FnMut(),
    mut ready: impl FnMut() -> bool,
) {
    let deadline = Instant::now() + limit;
    while !ready() {
        alive();
        assert!(Instant::now() < deadline, "{what}: not within {limit:?}");
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Whether `program` can be run (it is on the PATH).
fn installed(program: &str) -> bool {
    Command::new(program)
        .arg("-h")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok()
}

fn board_dir() -> PathBuf {
    let tests = Path::new(env!("CARGO_MANIFEST_DIR"));
    tests.parent().unwrap_or(tests).join("boards/qemu-m7")
}

/// What the test needs from outside cargo, or why it is skipped.
fn prerequisites() -> Result<PathBuf, String> {
    let elf = board_dir().join("target/thumbv7em-none-eabihf/release/digiteyes-board-qemu-m7");
    if !elf.is_file() {
        return Err(format!(
            "no firmware ELF at {} (build it: cd boards/qemu-m7 && cargo build --release; \
             needs `rustup target add thumbv7em-none-eabihf`)",
            elf.display()
        ));
    }
    for program in ["qemu-system-arm", "socat"] {
        if !installed(program) {
            return Err(format!(
                "{program} not found (apt-get install -y qemu-system-arm socat)"
            ));
        }
    }
    Ok(elf)
}

/// A socat PTY pair in `dir` (`board`, `host`) and QEMU running `elf` with UART0 on `board`.
/// Returns the host end and the two processes (QEMU first, so it goes before socat).
fn boot_board(dir: &Path, elf: &Path) -> (PathBuf, [KillOnDrop; 2]) {
    let (board_end, host_end) = (dir.join("board"), dir.join("host"));
    let socat_log = dir.join("socat.log");
    let mut socat = KillOnDrop::spawn(
        Command::new("socat")
            .arg(format!("pty,raw,echo=0,link={}", board_end.display()))
            .arg(format!("pty,raw,echo=0,link={}", host_end.display()))
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(File::create(&socat_log).unwrap()),
        "socat",
    );
    wait_until(
        Duration::from_secs(10),
        "socat's PTY pair",
        || socat.check_running(&socat_log),
        || board_end.exists() && host_end.exists(),
    );

    // run-qemu (the board's cargo runner) execs QEMU with UART0 on DIGITEYES_SERIAL, so the
    // child is QEMU itself. Its stdout is the firmware's semihosting log.
    let qemu_log = dir.join("qemu.log");
    let log = File::create(&qemu_log).unwrap();
    let mut qemu = KillOnDrop::spawn(
        Command::new(board_dir().join("run-qemu"))
            .arg(elf)
            .env("DIGITEYES_SERIAL", &board_end)
            .env_remove("DIGITEYES_ICOUNT")
            .stdin(Stdio::null())
            .stdout(log.try_clone().unwrap())
            .stderr(log),
        "qemu-system-arm",
    );
    wait_until(
        Duration::from_secs(20),
        "the firmware's boot banner",
        || qemu.check_running(&qemu_log),
        || std::fs::read_to_string(&qemu_log).is_ok_and(|log| log.contains("tracker board up")),
    );
    (host_end, [qemu, socat])
}

/// Fingertip reprojection error (px, mean over frames and tips) of the states in `csv`.
fn fingertip_mean_px(seq: &Path, csv: &Path) -> f64 {
    evaluate(seq, csv).unwrap().cameras[0].fingertip_mean_px
}

#[test]
fn the_emulated_m7_board_tracks_a_mouse_sequence_as_well_as_the_host() {
    let started = Instant::now();
    let elf = match prerequisites() {
        Ok(elf) => elf,
        Err(reason) => {
            common::skip(
                "host <-> emulated Cortex-M7 board test (tests/tests/qemu_board.rs)",
                &reason,
            );
            return;
        }
    };
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("mouse");
    let render = RenderOptions {
        frames: Some(FRAMES),
        size: Some(SIZE),
        supersample: 2,
        ..RenderOptions::default()
    };
    render_scenario("mouse", &seq, &render).unwrap();

    let (host_end, processes) = boot_board(dir.path(), &elf);
    let board_csv = dir.path().join("board.csv");
    // A frame's answer comes ~1 s after its last chunk leaves the host at worst (the PTYs
    // buffer most of a frame); 15 s is a hang, not a slow board.
    let options =
        StreamOptions::new(host_end.display().to_string()).reply_timeout(Duration::from_secs(15));
    let summary = stream_sequence(&seq, &board_csv, &options).unwrap();
    drop(processes);
    println!("{summary}");
    let qemu_log = std::fs::read_to_string(dir.path().join("qemu.log")).unwrap_or_default();
    println!("{qemu_log}");

    // Every frame tracked, nothing dropped, a clean link.
    let link = &summary.link;
    assert_eq!(link.board_name, "qemu-m7");
    assert_eq!(summary.board_clock_hz, 25_000_000);
    assert_eq!(summary.outcomes.len(), FRAMES);
    for (k, outcome) in summary.outcomes.iter().enumerate() {
        assert!(
            matches!(outcome, FrameOutcome::Tracked(s) if s.frame == k as u32),
            "frame {k} not tracked by the board: {outcome:?}"
        );
    }
    assert_eq!((link.tracked, link.dropped_total()), (FRAMES, 0));
    assert!(link.pong, "the final ping was answered");
    let board = link.board.expect("the board's counters");
    assert_eq!(board.frames as usize, FRAMES);
    assert_eq!(board.link.crc_errors + board.link.framing_errors, 0);
    assert_eq!(link.host_link.crc_errors + link.host_link.framing_errors, 0);

    // As accurate as the host tracker on the same frames.
    let host_csv = dir.path().join("host.csv");
    track_sequence(&seq, &host_csv, TrackerConfig::default(), false).unwrap();
    let board_px = fingertip_mean_px(&seq, &board_csv);
    let host_px = fingertip_mean_px(&seq, &host_csv);
    let bound = host_px * (1.0 + RELATIVE_SLACK) + ABSOLUTE_SLACK_PX;
    println!(
        "fingertip reprojection error, mean: board {board_px:.4} px, host {host_px:.4} px \
         (bound {bound:.4} px)"
    );
    assert!(
        board_px <= bound,
        "the board's fingertip error {board_px:.4} px exceeds the host's {host_px:.4} px by \
         more than 10 % + {ABSOLUTE_SLACK_PX} px"
    );

    // Report (not required): are the board's states the host's, bit for bit?
    let sequence = Sequence::open(&seq).unwrap();
    let mut tracker = sequence_tracker(&sequence, TrackerConfig::default()).unwrap();
    let mut equal = 0;
    for (k, outcome) in summary.outcomes.iter().enumerate() {
        let image = sequence.read_frame(0, k).unwrap();
        let (w, h) = (image.width() as usize, image.height() as usize);
        tracker
            .track(&[FrameView::packed(image.as_raw(), w, h).unwrap()])
            .unwrap();
        let FrameOutcome::Tracked(state) = outcome else {
            unreachable!("checked above")
        };
        let bits = |q: &[f32]| q.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        equal += usize::from(bits(&state.q) == bits(tracker.state()));
    }
    println!(
        "board states bit-equal to the in-process tracker's: {equal} of {FRAMES} frames; \
         test took {:.1} s",
        started.elapsed().as_secs_f64()
    );
}

/// Two emulated boards, one hand (issue 13): each holds one camera's frames and searches them
/// at the host's state; the host solves once per iteration. The states must be the
/// in-process stereo tracker's on the same frames (to 1e-4; printed: how many bit-equal).
#[test]
fn two_emulated_m7_boards_track_a_stereo_sequence_as_the_host_does() {
    let started = Instant::now();
    let elf = match prerequisites() {
        Ok(elf) => elf,
        Err(reason) => {
            common::skip(
                "two emulated Cortex-M7 boards, one stereo hand (tests/tests/qemu_board.rs)",
                &reason,
            );
            return;
        }
    };
    const STEREO_FRAMES: usize = 4;
    const ITERATIONS: u8 = 2;
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("stereo");
    let render = RenderOptions {
        frames: Some(STEREO_FRAMES),
        size: Some(SIZE),
        supersample: 2,
        ..RenderOptions::default()
    };
    render_scenario("fullhand-stereo", &seq, &render).unwrap();
    let (dir0, dir1) = (dir.path().join("board0"), dir.path().join("board1"));
    std::fs::create_dir_all(&dir0).unwrap();
    std::fs::create_dir_all(&dir1).unwrap();
    let (port0, board0) = boot_board(&dir0, &elf);
    let (port1, board1) = boot_board(&dir1, &elf);
    let mut config = TrackerConfig::default();
    config.iterations = ITERATIONS;
    let config = digiteyes_host::stereo::wire_config(&config).unwrap();
    let mut options = digiteyes_host::stereo::StereoOptions::new(vec![
        port0.display().to_string(),
        port1.display().to_string(),
    ]);
    options.tracker = digiteyes_core::protocol::TrackerParams::from_config(&config);
    // A frame's upload takes ~1 s on QEMU's UART; 15 s is a hang, not a slow board.
    options.reply_timeout = Duration::from_secs(15);
    let csv = dir.path().join("boards.csv");
    let summary = digiteyes_host::stereo::stream_stereo(&seq, &csv, &options).unwrap();
    drop((board0, board1));
    print!("{summary}");
    assert_eq!(summary.frames, STEREO_FRAMES);
    for b in &summary.boards {
        assert_eq!((b.unanswered, b.frames_without), (0, 0), "{b:?}");
    }

    let sequence = Sequence::open(&seq).unwrap();
    // The host's solve over boards has no region rows (the boards send features, not
    // frames): the in-process reference is the same tracker without them.
    let reference = digiteyes_host::stereo::boards_config(&options.tracker).unwrap();
    let mut tracker = sequence_tracker(&sequence, reference).unwrap();
    let got = digiteyes_host::sequence::read_states(&csv, sequence.n_states()).unwrap();
    let (mut worst, mut equal) = (0.0f64, 0);
    for (k, row) in got.rows.iter().enumerate() {
        let images: Vec<_> = (0..2).map(|c| sequence.read_frame(c, k).unwrap()).collect();
        let views: Vec<_> = images
            .iter()
            .map(|i| {
                FrameView::packed(i.as_raw(), i.width() as usize, i.height() as usize).unwrap()
            })
            .collect();
        tracker.track(&views).unwrap();
        let mut same = true;
        for (x, y) in row.iter().zip(tracker.state()) {
            let d = (x - f64::from(*y)).abs();
            worst = worst.max(d);
            same &= d == 0.0;
        }
        equal += usize::from(same);
    }
    println!(
        "two emulated boards vs in-process stereo: largest difference {worst:e}, {equal} of \
         {STEREO_FRAMES} frames equal as written; test took {:.1} s",
        started.elapsed().as_secs_f64()
    );
    assert!(worst <= 1e-4, "largest difference {worst:e}");
}
