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
//!
//! The server is hyper's HTTP/1 on a small tokio runtime of its own ([`WORKER_THREADS`]
//! threads, whatever the number of clients), with every resource a client can make it spend
//! capped: the request head ([`MAX_HEAD_BYTES`]), the body ([`MAX_BODY_BYTES`]; a bigger
//! `Content-Length` is answered 413 and never read), the time to send a request head
//! ([`HEAD_TIMEOUT`], which also closes idle keep-alive connections), a connection's life
//! ([`CONNECTION_LIFETIME`]) and the connections open at once ([`MAX_CONNECTIONS`]; more wait
//! in the listen backlog). When the process runs out of file descriptors, accepting backs
//! off and resumes: the listener never closes. Bound to anything but loopback, it warns on
//! stderr: it serves that network, with no authentication.

use std::convert::Infallible;
use std::io::Cursor;
use std::net::SocketAddr;
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use digiteyes_core::features::FeatureConfig;
use http_body_util::Full;
use hyper::body::{Bytes, Incoming};
use hyper::header::{CACHE_CONTROL, CONNECTION, CONTENT_LENGTH, CONTENT_TYPE};
use hyper::{Method, Request, Response, StatusCode};
use hyper_util::rt::{TokioIo, TokioTimer};
use image::ImageFormat;
use tokio::net::TcpListener;
use tokio::sync::{oneshot, Semaphore};

use super::hub::{CameraFrame, Hub};
use crate::overlay::draw_overlay;

const INDEX_HTML: &str = include_str!("assets/index.html");
const APP_JS: &str = include_str!("assets/app.js");
const STYLE_CSS: &str = include_str!("assets/style.css");

/// The address `digiteyes ui` serves on unless told otherwise: loopback only.
pub const DEFAULT_BIND: &str = "127.0.0.1:7878";

/// Threads of the server's runtime: they serve every connection.
pub const WORKER_THREADS: usize = 2;
/// Connections served at once; further ones wait in the listen backlog.
pub const MAX_CONNECTIONS: usize = 256;
/// The largest request line plus headers read (bytes); beyond, the answer is 431.
pub const MAX_HEAD_BYTES: usize = 16 * 1024;
/// The most header lines in a request.
pub const MAX_HEADERS: usize = 64;
/// The largest request body accepted (bytes): the UI only needs GET. A request announcing
/// more is answered 413 and its body is never read.
pub const MAX_BODY_BYTES: u64 = 1024;
/// Time a client has to send a request head, from connecting or from its last answer
/// (keep-alive); then the connection is closed.
pub const HEAD_TIMEOUT: Duration = Duration::from_secs(5);
/// The longest a connection stays open, however busy (the page reconnects).
pub const CONNECTION_LIFETIME: Duration = Duration::from_secs(120);
/// Pause before accepting again when the process is out of file descriptors.
pub const ACCEPT_BACKOFF: Duration = Duration::from_millis(50);

/// A running UI server. Stops (and joins its thread) when dropped.
pub struct UiServer {
    addr: SocketAddr,
    stop: Option<oneshot::Sender<()>>,
    thread: Option<JoinHandle<()>>,
}

impl UiServer {
    /// Serves `hub` on `bind` (port 0 picks a free port; see [`UiServer::url`]). Warns on
    /// stderr when `bind` is not a loopback address.
    pub fn start(bind: SocketAddr, hub: Arc<Hub>) -> Result<UiServer> {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(WORKER_THREADS)
            .thread_name("ui-http")
            .enable_io()
            .enable_time()
            .build()
            .context("cannot start the UI server's runtime")?;
        let listener = runtime
            .block_on(TcpListener::bind(bind))
            .with_context(|| format!("cannot serve the UI on {bind}"))?;
        let addr = listener
            .local_addr()
            .context("the UI server has no address")?;
        if !addr.ip().is_loopback() {
            eprintln!("{}", exposure_warning(addr));
        }
        let (stop, stopped) = oneshot::channel();
        let thread = std::thread::Builder::new()
            .name("ui-server".into())
            .spawn(move || {
                runtime.block_on(accept_loop(listener, hub, stopped));
                // Connections still open are dropped with the runtime.
                runtime.shutdown_timeout(Duration::from_millis(100));
            })
            .context("cannot start the UI server's thread")?;
        Ok(UiServer {
            addr,
            stop: Some(stop),
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
        if let Some(stop) = self.stop.take() {
            let _ = stop.send(());
        }
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// What `start` prints when the page is served beyond this machine.
pub fn exposure_warning(addr: SocketAddr) -> String {
    format!(
        "digiteyes: WARNING: the UI is served on {addr}, not on loopback: anyone on that \
         network can open it (there is no authentication). Use --bind 127.0.0.1:PORT to keep \
         it on this machine."
    )
}

async fn accept_loop(listener: TcpListener, hub: Arc<Hub>, mut stop: oneshot::Receiver<()>) {
    let slots = Arc::new(Semaphore::new(MAX_CONNECTIONS));
    let cache = Arc::new(Mutex::new(FrameCache::default()));
    let mut last_complaint: Option<Instant> = None;
    loop {
        let permit = tokio::select! {
            _ = &mut stop => return,
            permit = Arc::clone(&slots).acquire_owned() => match permit {
                Ok(permit) => permit,
                Err(_) => return,
            },
        };
        let accepted = tokio::select! {
            _ = &mut stop => return,
            accepted = listener.accept() => accepted,
        };
        let stream = match accepted {
            Ok((stream, _)) => stream,
            Err(e) => {
                // Out of descriptors (EMFILE/ENFILE) or a connection reset before it was
                // accepted: say so now and then, wait a little, keep listening.
                let now = Instant::now();
                if last_complaint.is_none_or(|t| now - t > Duration::from_secs(10)) {
                    eprintln!("digiteyes: UI server: cannot accept a connection ({e}); retrying");
                    last_complaint = Some(now);
                }
                tokio::time::sleep(ACCEPT_BACKOFF).await;
                continue;
            }
        };
        let (hub, cache) = (Arc::clone(&hub), Arc::clone(&cache));
        tokio::spawn(async move {
            let _permit = permit;
            let service = hyper::service::service_fn(move |request| {
                let (hub, cache) = (Arc::clone(&hub), Arc::clone(&cache));
                async move { Ok::<_, Infallible>(answer(&request, &hub, &cache)) }
            });
            let connection = hyper::server::conn::http1::Builder::new()
                .timer(TokioTimer::new())
                .header_read_timeout(HEAD_TIMEOUT)
                .max_buf_size(MAX_HEAD_BYTES)
                .max_headers(MAX_HEADERS)
                .serve_connection(TokioIo::new(stream), service);
            // A client that hangs up or times out is its own business.
            let _ = tokio::time::timeout(CONNECTION_LIFETIME, connection).await;
        });
    }
}

/// The PNG of the newest camera frame, kept until a newer frame arrives.
#[derive(Default)]
struct FrameCache {
    frame: Option<u32>,
    png: Bytes,
}

fn answer(
    request: &Request<Incoming>,
    hub: &Hub,
    cache: &Mutex<FrameCache>,
) -> Response<Full<Bytes>> {
    if *request.method() != Method::GET && *request.method() != Method::HEAD {
        return text(StatusCode::METHOD_NOT_ALLOWED, "only GET");
    }
    let announced = request
        .headers()
        .get(CONTENT_LENGTH)
        .map(|v| v.to_str().ok().and_then(|s| s.trim().parse::<u64>().ok()));
    match announced {
        Some(Some(n)) if n <= MAX_BODY_BYTES => {}
        None => {}
        // Too big, or not a number: never read, and the connection closes after the answer.
        _ => {
            let mut response = text(StatusCode::PAYLOAD_TOO_LARGE, "request body too large");
            response
                .headers_mut()
                .insert(CONNECTION, hyper::header::HeaderValue::from_static("close"));
            return response;
        }
    }
    match request.uri().path() {
        "/" | "/index.html" => body(
            Bytes::from_static(INDEX_HTML.as_bytes()),
            "text/html; charset=utf-8",
        ),
        "/app.js" => body(
            Bytes::from_static(APP_JS.as_bytes()),
            "text/javascript; charset=utf-8",
        ),
        "/style.css" => body(
            Bytes::from_static(STYLE_CSS.as_bytes()),
            "text/css; charset=utf-8",
        ),
        "/api/model" => json(&hub.info()),
        "/api/state" => json(&hub.polled_snapshot()),
        "/frame.png" => match hub.camera_frame() {
            None => text(StatusCode::NOT_FOUND, "no camera frames from this source"),
            Some(frame) => {
                let Ok(mut cache) = cache.lock() else {
                    return text(StatusCode::INTERNAL_SERVER_ERROR, "frame cache unavailable");
                };
                if cache.frame != Some(frame.frame) {
                    match frame_png(hub, &frame) {
                        Ok(png) => {
                            cache.png = Bytes::from(png);
                            cache.frame = Some(frame.frame);
                        }
                        Err(e) => {
                            return text(StatusCode::INTERNAL_SERVER_ERROR, &format!("{e:#}"))
                        }
                    }
                }
                body(cache.png.clone(), "image/png")
            }
        },
        _ => text(StatusCode::NOT_FOUND, "not found"),
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

fn body(bytes: Bytes, content_type: &'static str) -> Response<Full<Bytes>> {
    let mut response = Response::new(Full::new(bytes));
    let headers = response.headers_mut();
    headers.insert(
        CONTENT_TYPE,
        hyper::header::HeaderValue::from_static(content_type),
    );
    headers.insert(
        CACHE_CONTROL,
        hyper::header::HeaderValue::from_static("no-store"),
    );
    response
}

fn json<T: serde::Serialize>(value: &T) -> Response<Full<Bytes>> {
    match serde_json::to_vec(value) {
        Ok(bytes) => body(Bytes::from(bytes), "application/json"),
        Err(e) => text(StatusCode::INTERNAL_SERVER_ERROR, &e.to_string()),
    }
}

fn text(status: StatusCode, message: &str) -> Response<Full<Bytes>> {
    let mut response = body(
        Bytes::from(message.to_string()),
        "text/plain; charset=utf-8",
    );
    *response.status_mut() = status;
    response
}
