//! The UI server (`digiteyes ui`, `digiteyes sim --ui`) against what a hostile client on
//! loopback can do: a huge announced body, a flood of headers, descriptor exhaustion, idle
//! and half-sent connections, and a bind beyond loopback. After each, the server process is
//! still running and answers `/api/state` within a second; memory and threads stay bounded.
//! Every client here talks to 127.0.0.1 only, and every loop is bounded.

mod common;

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use digiteyes_host::ui::server::HEAD_TIMEOUT;

/// One attack at a time: each test loads the machine on purpose, and a server's "within a
/// second" should not measure a neighbouring test's flood.
static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn one_at_a_time() -> std::sync::MutexGuard<'static, ()> {
    SERIAL
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// A server child process, killed when dropped.
struct Server {
    child: Child,
    addr: SocketAddr,
    stderr: std::sync::mpsc::Receiver<String>,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Server {
    /// Runs `digiteyes ARGS` with at most `nofile` open descriptors, and waits for its
    /// `UI: http://ADDR/` line.
    fn start(args: &[&str], nofile: u32) -> Server {
        let exe = env!("CARGO_BIN_EXE_digiteyes");
        let mut command = Command::new("sh");
        command
            .arg("-c")
            .arg(format!("ulimit -n {nofile} && exec \"$0\" \"$@\""))
            .arg(exe)
            .args(args)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        let mut child = command.spawn().unwrap();
        let stdout = child.stdout.take().unwrap();
        let stderr = child.stderr.take().unwrap();
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                let _ = tx.send(line);
            }
        });
        let (addr_tx, addr_rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                if let Some(url) = line.strip_prefix("UI: http://") {
                    let _ = addr_tx.send(url.trim_end_matches('/').to_string());
                }
            }
        });
        let addr = addr_rx
            .recv_timeout(Duration::from_secs(30))
            .expect("the server printed no UI address");
        let mut addr: SocketAddr = addr.parse().unwrap();
        if addr.ip().is_unspecified() {
            addr.set_ip([127, 0, 0, 1].into());
        }
        Server {
            child,
            addr,
            stderr: rx,
        }
    }

    fn pid(&self) -> u32 {
        self.child.id()
    }

    /// Still running, and `/api/state` answered 200 within a second.
    #[track_caller]
    fn assert_answers(&mut self) {
        assert!(
            self.child.try_wait().unwrap().is_none(),
            "the server exited"
        );
        let started = Instant::now();
        let (status, body) = get(self.addr, "/api/state");
        assert_eq!(status, 200, "{body}");
        assert!(body.starts_with('{'), "{body}");
        assert!(
            started.elapsed() < Duration::from_secs(1),
            "answered in {:?}",
            started.elapsed()
        );
    }

    fn stderr_text(&self) -> String {
        self.stderr.try_iter().collect::<Vec<_>>().join("\n")
    }

    /// Stderr lines until one contains `needle`, or all that came within `wait`.
    fn stderr_until(&self, needle: &str, wait: Duration) -> String {
        let deadline = Instant::now() + wait;
        let mut lines = Vec::new();
        while let Some(left) = deadline.checked_duration_since(Instant::now()) {
            match self.stderr.recv_timeout(left) {
                Ok(line) => {
                    let found = line.contains(needle);
                    lines.push(line);
                    if found {
                        break;
                    }
                }
                Err(_) => break,
            }
        }
        lines.join("\n")
    }
}

/// A field of `/proc/PID/status` (e.g. `VmRSS` in kB, `Threads`).
fn proc_status(pid: u32, field: &str) -> u64 {
    let text = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    let line = text.lines().find(|l| l.starts_with(field)).unwrap();
    line.split_whitespace().nth(1).unwrap().parse().unwrap()
}

/// `GET path` with a one-second deadline: the status and the body.
fn get(addr: SocketAddr, path: &str) -> (u16, String) {
    let mut stream = match TcpStream::connect_timeout(&addr, Duration::from_secs(1)) {
        Ok(stream) => stream,
        Err(e) => return (0, format!("cannot connect: {e}")),
    };
    stream
        .set_read_timeout(Some(Duration::from_secs(1)))
        .unwrap();
    if write!(
        stream,
        "GET {path} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"
    )
    .is_err()
    {
        return (0, "cannot send".into());
    }
    let mut response = Vec::new();
    let _ = stream.read_to_end(&mut response);
    status_and_body(&response)
}

fn status_and_body(response: &[u8]) -> (u16, String) {
    let text = String::from_utf8_lossy(response);
    let status = text
        .split_whitespace()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    let body = text
        .split_once("\r\n\r\n")
        .map_or("", |(_, b)| b)
        .to_string();
    (status, body)
}

/// A replayable tracked sequence in `dir` (its states in `dir/mouse/states.csv`).
fn replay_sequence(dir: &Path) -> String {
    let seq = common::small_sequence(dir, "mouse", 4);
    digiteyes_host::track_sequence(
        &seq,
        &seq.join("states.csv"),
        digiteyes_host::TrackerConfig::default(),
        false,
    )
    .unwrap();
    seq.to_str().unwrap().to_string()
}

/// `digiteyes ui --replay` and `digiteyes sim --ui`, each started fresh.
fn servers(dir: &Path, nofile: u32) -> Vec<Server> {
    let seq = replay_sequence(dir);
    vec![
        Server::start(
            &[
                "ui",
                "--replay",
                &seq,
                "--bind",
                "127.0.0.1:0",
                "--seconds",
                "120",
            ],
            nofile,
        ),
        Server::start(&["sim", "--ui", "127.0.0.1:0"], nofile),
    ]
}

#[test]
fn a_huge_content_length_is_refused_not_allocated() {
    let _serial = one_at_a_time();
    let dir = tempfile::tempdir().unwrap();
    for mut server in servers(dir.path(), 1024) {
        let mut stream = TcpStream::connect(server.addr).unwrap();
        stream
            .set_read_timeout(Some(Duration::from_secs(2)))
            .unwrap();
        write!(
            stream,
            "GET /api/state HTTP/1.1\r\nHost: x\r\nContent-Length: 100000000000\r\n\r\n"
        )
        .unwrap();
        let mut response = vec![0u8; 4096];
        let n = stream.read(&mut response).unwrap_or(0);
        assert_eq!(status_and_body(&response[..n]).0, 413);
        server.assert_answers();
        assert!(proc_status(server.pid(), "VmRSS") < 64 * 1024);
    }
}

#[test]
fn a_header_flood_is_cut_short_and_memory_stays_small() {
    let _serial = one_at_a_time();
    let dir = tempfile::tempdir().unwrap();
    for mut server in servers(dir.path(), 1024) {
        let mut stream = TcpStream::connect(server.addr).unwrap();
        stream
            .set_write_timeout(Some(Duration::from_secs(2)))
            .unwrap();
        stream
            .write_all(b"GET /api/state HTTP/1.1\r\nHost: x\r\n")
            .unwrap();
        let line = format!("X-Flood: {}\r\n", "a".repeat(1000));
        let mut sent = 0usize;
        // Up to 40 MB of headers; the server stops reading long before.
        while sent < 40_000_000 {
            if stream.write_all(line.as_bytes()).is_err() {
                break;
            }
            sent += line.len();
        }
        assert!(sent < 40_000_000, "the server read 40 MB of headers");
        let rss_kb = proc_status(server.pid(), "VmRSS");
        assert!(rss_kb < 64 * 1024, "RSS {rss_kb} kB under a header flood");
        drop(stream);
        server.assert_answers();
    }
}

#[test]
fn running_out_of_descriptors_never_closes_the_listener() {
    let _serial = one_at_a_time();
    let dir = tempfile::tempdir().unwrap();
    // 64 descriptors for the whole server: 200 clients sending one byte each exhaust them.
    for mut server in servers(dir.path(), 64) {
        let mut clients = Vec::new();
        for _ in 0..200 {
            let Ok(mut c) = TcpStream::connect_timeout(&server.addr, Duration::from_secs(1)) else {
                break;
            };
            let _ = c.write_all(b"G");
            clients.push(c);
        }
        assert!(
            clients.len() > 64,
            "only {} clients connected",
            clients.len()
        );
        std::thread::sleep(Duration::from_millis(300)); // let the server hit the limit
        drop(clients);
        // The server frees the descriptors as it sees the clients go; it listens still.
        let deadline = Instant::now() + Duration::from_secs(3);
        loop {
            if server.child.try_wait().unwrap().is_some() {
                panic!("the server exited:\n{}", server.stderr_text());
            }
            if Instant::now() > deadline {
                server.assert_answers();
                break;
            }
            if get(server.addr, "/api/state").0 == 200 {
                break;
            }
        }
        server.assert_answers();
    }
}

#[test]
fn idle_connections_cost_no_threads_and_are_closed() {
    let _serial = one_at_a_time();
    let dir = tempfile::tempdir().unwrap();
    for mut server in servers(dir.path(), 4096) {
        let threads_before = proc_status(server.pid(), "Threads");
        let clients: Vec<TcpStream> = (0..600)
            .filter_map(|_| TcpStream::connect_timeout(&server.addr, Duration::from_secs(1)).ok())
            .collect();
        assert!(clients.len() >= 500, "{} clients", clients.len());
        std::thread::sleep(Duration::from_millis(300));
        let threads = proc_status(server.pid(), "Threads");
        assert!(
            threads <= threads_before + 2,
            "{threads} threads with {} idle connections (was {threads_before})",
            clients.len()
        );
        drop(clients);
        std::thread::sleep(Duration::from_millis(200));
        server.assert_answers();
    }
}

#[test]
fn a_half_sent_request_line_is_closed_after_the_head_timeout() {
    let _serial = one_at_a_time();
    let dir = tempfile::tempdir().unwrap();
    let mut servers = servers(dir.path(), 1024);
    let server = &mut servers[0];
    let mut stream = TcpStream::connect(server.addr).unwrap();
    stream.write_all(b"GET /api/st").unwrap();
    let started = Instant::now();
    stream
        .set_read_timeout(Some(HEAD_TIMEOUT + Duration::from_secs(3)))
        .unwrap();
    let mut buf = [0u8; 256];
    // Closed (0 bytes, or a 408) by the server, not by our read timeout.
    let n = stream.read(&mut buf);
    let waited = started.elapsed();
    assert!(
        waited < HEAD_TIMEOUT + Duration::from_secs(2),
        "still open after {waited:?}: {n:?}"
    );
    assert!(
        waited >= HEAD_TIMEOUT - Duration::from_millis(500),
        "closed early: {waited:?}"
    );
    server.assert_answers();
}

#[test]
fn binding_beyond_loopback_warns() {
    let _serial = one_at_a_time();
    let dir = tempfile::tempdir().unwrap();
    let seq = replay_sequence(dir.path());
    let mut server = Server::start(
        &[
            "ui",
            "--replay",
            &seq,
            "--bind",
            "0.0.0.0:0",
            "--seconds",
            "30",
        ],
        1024,
    );
    server.assert_answers();
    let err = server.stderr_until("not on loopback", Duration::from_secs(5));
    assert!(
        err.contains("WARNING") && err.contains("not on loopback"),
        "{err}"
    );
    let mut quiet = Server::start(
        &[
            "ui",
            "--replay",
            &seq,
            "--bind",
            "127.0.0.1:0",
            "--seconds",
            "30",
        ],
        1024,
    );
    quiet.assert_answers();
    // Were there a warning, it would come before the address; a second is ample.
    let said = quiet.stderr_until("WARNING", Duration::from_secs(1));
    assert!(!said.contains("WARNING"), "{said}");
}
