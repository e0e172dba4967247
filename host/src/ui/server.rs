//! The UI's HTTP server: the page and its script (embedded in the binary), the hand's state
//! as JSON, and the newest camera frame with the model drawn over it as a PNG.
//!
//! | path | what |
//! |---|---|
//! | `/` | the page |
//! | `/app.js`, `/style.css` | its script and style |
//! | `/api/model` | the state labels, the free states and the source ([`ModelInfo`](super::hub::ModelInfo)) |
//! | `/api/state` | everything live ([`Snapshot`](super::hub::Snapshot)) |
//! | `/frame.png` | the newest camera frame with the back-projected model (404 without frames) |
//!
//! Nothing is fetched from anywhere else: the page draws the 3D hand itself on a canvas.

use std::io::Cursor;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::Duration;

use anyhow::{anyhow, Context, Result};
use digiteyes_core::features::FeatureConfig;
use image::ImageFormat;
use tiny_http::{Header, Method, Request, Response, Server};

use super::hub::{CameraFrame, Hub};
use crate::overlay::draw_overlay;

const INDEX_HTML: &str = include_str!("assets/index.html");
const APP_JS: &str = include_str!("assets/app.js");
const STYLE_CSS: &str = include_str!("assets/style.css");

/// The address `digiteyes ui` serves on unless told otherwise: loopback only.
pub const DEFAULT_BIND: &str = "127.0.0.1:7878";

/// A running UI server. Stops (and joins its thread) when dropped.
pub struct UiServer {
    addr: SocketAddr,
    server: Arc<Server>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl UiServer {
    /// Serves `hub` on `bind` (port 0 picks a free port; see [`UiServer::url`]).
    pub fn start(bind: SocketAddr, hub: Arc<Hub>) -> Result<UiServer> {
        let server =
            Server::http(bind).map_err(|e| anyhow!("cannot serve the UI on {bind}: {e}"))?;
        let addr = server
            .server_addr()
            .to_ip()
            .ok_or_else(|| anyhow!("the UI server has no IP address"))?;
        let server = Arc::new(server);
        let stop = Arc::new(AtomicBool::new(false));
        let thread = {
            let (server, stop) = (Arc::clone(&server), Arc::clone(&stop));
            std::thread::Builder::new()
                .name("ui-http".into())
                .spawn(move || serve(&server, &hub, &stop))
                .context("cannot start the UI server's thread")?
        };
        Ok(UiServer {
            addr,
            server,
            stop,
            thread: Some(thread),
        })
    }

    /// The address it listens on.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// The page's address, e.g. `http://127.0.0.1:7878/`.
    pub fn url(&self) -> String {
        format!("http://{}/", self.addr)
    }
}

impl Drop for UiServer {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        self.server.unblock();
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// The PNG of the newest camera frame, kept until a newer frame arrives.
struct FrameCache {
    frame: Option<u32>,
    png: Vec<u8>,
}

fn serve(server: &Server, hub: &Hub, stop: &AtomicBool) {
    let mut cache = FrameCache {
        frame: None,
        png: Vec::new(),
    };
    while !stop.load(Ordering::Relaxed) {
        match server.recv_timeout(Duration::from_millis(200)) {
            Ok(Some(request)) => {
                // A client that hung up is its own business; keep serving the others.
                let _ = answer(request, hub, &mut cache);
            }
            Ok(None) => {}
            Err(_) => break,
        }
    }
}

fn answer(request: Request, hub: &Hub, cache: &mut FrameCache) -> std::io::Result<()> {
    if *request.method() != Method::Get && *request.method() != Method::Head {
        return request.respond(text(405, "only GET"));
    }
    let path = request.url().split('?').next().unwrap_or("/").to_string();
    match path.as_str() {
        "/" | "/index.html" => {
            request.respond(body(INDEX_HTML.as_bytes(), "text/html; charset=utf-8"))
        }
        "/app.js" => request.respond(body(APP_JS.as_bytes(), "text/javascript; charset=utf-8")),
        "/style.css" => request.respond(body(STYLE_CSS.as_bytes(), "text/css; charset=utf-8")),
        "/api/model" => request.respond(json(&hub.info())),
        "/api/state" => request.respond(json(&hub.snapshot())),
        "/frame.png" => match hub.camera_frame() {
            None => request.respond(text(404, "no camera frames from this source")),
            Some(frame) => {
                if cache.frame != Some(frame.frame) {
                    match frame_png(hub, &frame) {
                        Ok(png) => {
                            cache.png = png;
                            cache.frame = Some(frame.frame);
                        }
                        Err(e) => return request.respond(text(500, &format!("{e:#}"))),
                    }
                }
                request.respond(body(&cache.png, "image/png"))
            }
        },
        _ => request.respond(text(404, "not found")),
    }
}

/// The frame with the model drawn at its state, as PNG bytes.
pub fn frame_png(hub: &Hub, frame: &CameraFrame) -> Result<Vec<u8>> {
    let image = draw_overlay(
        hub.model(),
        &frame.camera,
        &frame.q,
        &frame.image,
        &FeatureConfig::default(),
    )?;
    let mut png = Vec::new();
    image
        .write_to(&mut Cursor::new(&mut png), ImageFormat::Png)
        .context("cannot encode the frame as PNG")?;
    Ok(png)
}

fn header(name: &str, value: &str) -> Header {
    Header::from_bytes(name.as_bytes(), value.as_bytes()).expect("static header is valid")
}

fn body(bytes: &[u8], content_type: &str) -> Response<Cursor<Vec<u8>>> {
    Response::from_data(bytes.to_vec())
        .with_header(header("Content-Type", content_type))
        .with_header(header("Cache-Control", "no-store"))
}

fn json<T: serde::Serialize>(value: &T) -> Response<Cursor<Vec<u8>>> {
    match serde_json::to_vec(value) {
        Ok(bytes) => body(&bytes, "application/json"),
        Err(e) => text(500, &e.to_string()),
    }
}

fn text(status: u16, message: &str) -> Response<Cursor<Vec<u8>>> {
    body(message.as_bytes(), "text/plain; charset=utf-8").with_status_code(status)
}
