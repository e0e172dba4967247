//! `digiteyes`: render, track and evaluate hand sequences. A thin layer over the library: it
//! parses the command line and hands each command to its module in `digiteyes_host::cli`.

use std::io::IsTerminal;
use std::process::ExitCode;

use anyhow::Result;
use clap::{Parser, Subcommand};
use digiteyes_host::cli::{bench, demo, eval, listen, render, report, sim, stream, track, ui};

/// Model-based 3D hand tracking after DigitEyes (Rehg 1995).
///
/// Sequences are folders in the format of `docs/sequence-format.md`: `sequence.json`, frames
/// `camN/NNNNNN.pgm` (8-bit P5) and optionally `truth.csv`. Units: mm, rad, px.
#[derive(Parser, Debug)]
#[command(name = "digiteyes", version, about, long_about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

// Each command's help is the doc comment of its arguments (`digiteyes_host::cli`).
#[derive(Subcommand, Debug)]
enum Command {
    Render(render::RenderArgs),
    Track(track::TrackArgs),
    Eval(eval::EvalArgs),
    Report(report::ReportArgs),
    Sim(sim::SimArgs),
    Stream(stream::StreamArgs),
    Listen(listen::ListenArgs),
    Ui(ui::UiArgs),
    /// Measure the tracker beyond what a test should: `bench robustness`.
    #[command(subcommand)]
    Bench(bench::BenchCommand),
    Demo(demo::DemoArgs),
}

fn main() -> ExitCode {
    quiet_on_closed_pipe();
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("digiteyes: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    let progress = std::io::stderr().is_terminal();
    match cli.command {
        Command::Render(args) => render::run(args, progress),
        Command::Track(args) => track::run(args, progress),
        Command::Eval(args) => eval::run(args),
        Command::Report(args) => report::run(args),
        Command::Sim(args) => sim::run(args),
        Command::Stream(args) => stream::run(args, progress),
        Command::Listen(args) => listen::run(args),
        Command::Ui(args) => ui::run(args),
        Command::Bench(command) => bench::run(command),
        Command::Demo(args) => demo::run(args, progress),
    }
}

/// `digiteyes eval ... | head` closes the pipe early; Rust ignores SIGPIPE, so the next
/// `println!` panics. Like any Unix tool, end quietly instead (exit status 141, as a process
/// killed by SIGPIPE reports in a shell); every other panic is reported as before.
fn quiet_on_closed_pipe() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let message = info
            .payload()
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| info.payload().downcast_ref::<&str>().copied())
            .unwrap_or("");
        if message.starts_with("failed printing to stdout") && message.contains("Broken pipe") {
            std::process::exit(141);
        }
        default(info);
    }));
}
