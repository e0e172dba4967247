//! `digiteyes demo`: the thesis' 3D-mouse trial rendered, streamed to a simulated board,
//! evaluated, reported and shown.

use std::io::IsTerminal;
use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

use crate::cli_values;
use crate::demo::{
    run_demo, run_stereo_demo, serve_demo_ui, DEFAULT_DEMO_DIR, DEMO_FRAMES, REPORT_HTML,
    STEREO_DEMO_FRAMES,
};
use crate::ui::DEFAULT_BIND;
use crate::TrackerConfig;

/// Render the thesis' 3D-mouse trial, stream it to a board, evaluate, report, show.
///
/// The trial is the `mouse-thesis` scenario (see `render --help`).
///
/// The rendered camera's frames go to a simulated Linux board (the firmware loop on a
/// pseudo-terminal, as `digiteyes sim` runs it) over a real serial link; the states it
/// sends back are evaluated against the ground truth. Prints the accuracy and the link's
/// figures, writes the HTML report (DIR/report.html), and ends by saying where to open it
/// and the UI. In a terminal it then serves the UI (a replay of the run: 3D hand, camera
/// overlay, 3D mouse, link figures) until Ctrl-C; otherwise it prints the
/// `digiteyes ui --replay` command that shows it.
///
/// With --stereo: the whole hand (`fullhand-stereo`) from two cameras, each camera's
/// frames on its own simulated board, the host solving once per iteration with what both
/// found (as `stream --port A --port B` does).
#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Number of frames (default 500, the thesis' pace: fewer play the same trial faster;
    /// with --stereo, default 120).
    #[arg(long, value_parser = cli_values::frame_count)]
    pub frames: Option<usize>,
    /// Track the whole hand from two cameras instead, one simulated board per camera as
    /// the thesis' stereo system ran (`stream --port A --port B`).
    #[arg(long)]
    pub stereo: bool,
    /// Folder for the run: the sequence, states.csv and report.html (created if
    /// missing; its files are overwritten).
    #[arg(long, visible_alias = "keep", value_name = "DIR", default_value = DEFAULT_DEMO_DIR)]
    pub out: PathBuf,
    /// Serve the UI for this many seconds after the run (0: not at all; at most a week).
    /// Default: until Ctrl-C when run in a terminal, not at all otherwise.
    #[arg(long, value_name = "S", value_parser = cli_values::seconds_or_zero)]
    pub ui_seconds: Option<f64>,
}

/// Runs the demo and prints its figures; then serves the UI or says how to.
pub fn run(args: DemoArgs, progress: bool) -> Result<()> {
    let sequence = if args.stereo {
        let frames = args.frames.unwrap_or(STEREO_DEMO_FRAMES);
        let result = run_stereo_demo(frames, &args.out, TrackerConfig::default(), progress)?;
        print!("{}", result.stream);
        for (i, board) in result.boards.iter().enumerate() {
            println!("camera {i}'s {board}");
        }
        print!("{}", result.eval);
        result.sequence
    } else {
        let frames = args.frames.unwrap_or(DEMO_FRAMES);
        let result = run_demo(frames, &args.out, TrackerConfig::default(), progress)?;
        println!("{}", result.stream);
        println!("{}", result.board);
        print!("{}", result.eval);
        println!("{}", result.mouse);
        result.sequence
    };
    let dir = std::path::absolute(&sequence).unwrap_or(sequence);
    println!("run kept in {}", dir.display());
    println!();
    println!("report: {}", dir.join(REPORT_HTML).display());
    let interactive = std::io::stdin().is_terminal() && std::io::stdout().is_terminal();
    let serve = match args.ui_seconds {
        Some(s) if s > 0.0 => Some(Some(cli_values::duration(s))),
        Some(_) => None,
        None if interactive => Some(None),
        None => None,
    };
    match serve {
        Some(duration) => {
            if duration.is_none() {
                println!("(serving the UI, a replay of this run; Ctrl-C stops it)");
            }
            serve_demo_ui(&dir, duration, &mut std::io::stdout())?;
        }
        None => {
            // The command as this very binary, so it runs from `cargo run` too.
            let exe = std::env::current_exe()
                .map_or_else(|_| "digiteyes".into(), |p| p.display().to_string());
            println!(
                "UI: {exe} ui --replay {}   then open http://{DEFAULT_BIND}/",
                dir.display()
            );
        }
    }
    Ok(())
}
