//! `digiteyes ui`: the UI machine of DigitEyes as a local web page.
//!
//! DigitEyes sent its states to a workstation that rendered the hand, while its board
//! overlaid the back-projected model on the live video, and drove a 3D mouse with them. This
//! module serves one page (on loopback by default; every asset is embedded in the binary)
//! that shows, live:
//! - the 3D hand at the newest state, drawn from the model's shapes (drag to orbit, wheel to
//!   zoom), with the table and the 3D mouse's pole when the hand is above the table;
//! - the newest camera frame with the model drawn over it, when frames are available (a
//!   replay, the demo, a simulated board: [`crate::sim::ui_tap`]);
//! - the 3D mouse (thesis Sec. 4.3.4): the pole's base on the table, its height, two buttons;
//! - every state's value, and the link's figures: states/s, drops by reason, CRC and framing
//!   errors, and whether the track is lost or the signal gone.
//!
//! ```text
//! source thread (serial | UDP | replay | simulated board) ─▶ Hub ◀─ HTTP thread ◀─ browser
//! ```

pub mod hub;
pub mod server;
pub mod sources;

use std::io::Write;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use digiteyes_core::model::Model;

pub use hub::Hub;
pub use server::{UiServer, DEFAULT_BIND};

use crate::link::{set_up_board, Link};
use crate::mouse_pole::{MouseConfig, MouseMapper};
use crate::sequence::Sequence;

/// Where the UI's states come from.
#[derive(Debug, Clone)]
pub enum UiSource {
    /// A board on a serial port.
    Serial {
        /// The tty.
        port: String,
        /// Line speed (bits/s).
        baud: u32,
        /// Set the board up first from this `sequence.json` or sequence folder.
        setup: Option<PathBuf>,
        /// The camera of a multi-camera set-up description.
        camera_index: Option<usize>,
    },
    /// JSON lines of board messages over UDP (`digiteyes listen --forward udp://`).
    Udp(SocketAddr),
    /// A tracked sequence played back with its frames.
    Replay {
        /// The sequence folder.
        seqdir: PathBuf,
        /// The states tracked for it (`track` or `stream` output).
        states: PathBuf,
        /// The hypotheses tracked for it (`track --hypotheses-out`): the others drawn ghosted.
        hypotheses: Option<PathBuf>,
        /// The camera whose frames to show.
        camera: usize,
        /// Frames/s (default: the sequence's).
        fps: Option<f64>,
    },
}

/// How `digiteyes ui` runs.
#[derive(Debug, Clone)]
pub struct UiOptions {
    /// Where the page is served.
    pub bind: SocketAddr,
    /// Where the states come from.
    pub source: UiSource,
    /// Stop after this long (forever when `None`).
    pub duration: Option<Duration>,
}

/// A running UI: its source's thread and its server. Stops both when dropped.
pub struct RunningUi {
    hub: Arc<Hub>,
    server: UiServer,
    stop: Arc<AtomicBool>,
    source: Option<SourceThread>,
    udp: Option<SocketAddr>,
}

impl RunningUi {
    /// Starts the source and the server; says where to find them on `out`.
    pub fn start(options: &UiOptions, out: &mut dyn Write) -> Result<RunningUi> {
        let stop = Arc::new(AtomicBool::new(false));
        let (hub, source, udp) = start_source(&options.source, Arc::clone(&stop), out)?;
        let server = match UiServer::start(options.bind, Arc::clone(&hub)) {
            Ok(server) => server,
            Err(e) => {
                stop.store(true, Ordering::Relaxed);
                let _ = source.join();
                return Err(e);
            }
        };
        writeln!(out, "UI: {}", server.url())?;
        out.flush()?;
        Ok(RunningUi {
            hub,
            server,
            stop,
            source: Some(source),
            udp,
        })
    }

    /// The page's address, e.g. `http://127.0.0.1:7878/`.
    pub fn url(&self) -> String {
        self.server.url()
    }

    /// The UDP address a `--udp` source listens on (its port, if 0 was asked for).
    pub fn udp_addr(&self) -> Option<SocketAddr> {
        self.udp
    }

    /// The picture the page shows.
    pub fn hub(&self) -> &Arc<Hub> {
        &self.hub
    }

    /// True once the source has ended (a replay never does; a port that failed has).
    pub fn source_ended(&self) -> bool {
        self.source.as_ref().is_none_or(|s| s.is_finished())
    }

    /// Stops the source and the server; the source's error, if it failed.
    pub fn stop(mut self) -> Result<()> {
        self.stop_source()
    }

    fn stop_source(&mut self) -> Result<()> {
        self.stop.store(true, Ordering::Relaxed);
        match self.source.take() {
            Some(thread) => thread
                .join()
                .unwrap_or_else(|_| Err(anyhow::anyhow!("the UI's source thread panicked"))),
            None => Ok(()),
        }
    }
}

impl Drop for RunningUi {
    fn drop(&mut self) {
        let _ = self.stop_source();
    }
}

/// Runs the UI: starts the source and the server, prints where to find them to `out`, and
/// serves until `options.duration` passes (or forever), or the source fails.
pub fn run_ui(options: &UiOptions, out: &mut dyn Write) -> Result<()> {
    let ui = RunningUi::start(options, out)?;
    let until = options.duration.map(|d| Instant::now() + d);
    while !ui.source_ended() && until.is_none_or(|t| Instant::now() < t) {
        // Checking the source and the deadline a few times a second; nothing to wait on.
        std::thread::sleep(Duration::from_millis(100));
    }
    ui.stop()
}

type SourceThread = std::thread::JoinHandle<Result<()>>;

fn start_source(
    source: &UiSource,
    stop: Arc<AtomicBool>,
    out: &mut dyn Write,
) -> Result<(Arc<Hub>, SourceThread, Option<SocketAddr>)> {
    match source {
        UiSource::Serial {
            port,
            baud,
            setup,
            camera_index,
        } => {
            let link = Link::open(port, *baud)?;
            let (link, model, free, rest) = match setup {
                Some(path) => {
                    let board = set_up_board(link, path, *camera_index, out)?;
                    let rest = board.sequence.initial_state.iter().map(|&v| v as f32);
                    (
                        board.link,
                        board.sequence.model.clone(),
                        board.sequence.free_states(),
                        Some(rest.collect()),
                    )
                }
                None => (
                    link,
                    Model::hand().context("built-in model")?,
                    Vec::new(),
                    None,
                ),
            };
            let hub = Hub::new(model, free, format!("serial {port}"));
            attach_mouse(&hub, rest);
            writeln!(out, "states from serial {port}")?;
            let thread_hub = Arc::clone(&hub);
            let thread = sources::spawn("ui-serial", stop, move |stop| {
                sources::serial(link, &thread_hub, stop)
            })?;
            Ok((hub, thread, None))
        }
        UiSource::Udp(addr) => {
            let socket = sources::bind_udp(*addr)?;
            let local = socket.local_addr().context("UDP socket address")?;
            let hub = Hub::new(
                Model::hand().context("built-in model")?,
                Vec::new(),
                format!("udp://{local}"),
            );
            attach_mouse(&hub, None);
            writeln!(
                out,
                "states from udp://{local} (e.g. digiteyes listen --port TTY --forward udp://{local})"
            )?;
            let thread_hub = Arc::clone(&hub);
            let thread = sources::spawn("ui-udp", stop, move |stop| {
                sources::udp(&socket, &thread_hub, stop)
            })?;
            Ok((hub, thread, Some(local)))
        }
        UiSource::Replay {
            seqdir,
            states,
            hypotheses,
            camera,
            fps,
        } => {
            let replay =
                sources::Replay::open(seqdir, states, hypotheses.as_deref(), *camera, *fps)?;
            let sequence = Sequence::open(seqdir)?;
            let hub = Hub::new(
                sequence.model.clone(),
                replay.free(),
                format!("replay of {}", states.display()),
            );
            attach_mouse(&hub, Some(replay.initial_state()));
            writeln!(
                out,
                "replaying {} frames of {} (looping)",
                replay.len(),
                replay.dir().display()
            )?;
            let thread_hub = Arc::clone(&hub);
            let thread = sources::spawn("ui-replay", stop, move |stop| {
                replay.play(&thread_hub, stop)
            })?;
            Ok((hub, thread, None))
        }
    }
}

/// Reads the 3D mouse off the hub's states, its buttons at rest in `rest` (or in the first
/// state seen). A model without finger 1's tip or the button states shows no mouse.
pub fn attach_mouse(hub: &Hub, rest: Option<Vec<f32>>) {
    let model = hub.model().clone();
    let mut mapper = match &rest {
        Some(rest) => match MouseMapper::new(&model, rest, MouseConfig::default()) {
            Ok(m) => Some(m),
            Err(_) => return,
        },
        None => None,
    };
    hub.set_mouse(Box::new(move |q| {
        if mapper.is_none() {
            mapper = MouseMapper::new(&model, q, MouseConfig::default()).ok();
        }
        let pole = mapper.as_mut()?.update(q).ok()?;
        serde_json::to_value(pole).ok()
    }));
}
