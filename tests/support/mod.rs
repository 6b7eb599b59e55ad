//! Test support for `palpa serve`: start the real binary on a free port, talk to its
//! WebSocket.
#![allow(dead_code)]

use serde_json::Value;
use std::io::{BufRead, BufReader, Read};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use tungstenite::stream::MaybeTlsStream;
use tungstenite::{Message, WebSocket};

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The committed default model (relative to the repository root when the tests run there, as
/// cargo runs them, so that the page names it as a user would).
pub fn default_model() -> PathBuf {
    let rel = PathBuf::from("data/default-model-gp");
    if rel.is_dir() {
        rel
    } else {
        root().join(rel)
    }
}

/// A running `palpa serve`.
pub struct Server {
    pub child: Child,
    /// host:port
    pub addr: String,
    pub stdin: Option<ChildStdin>,
    stderr: Arc<Mutex<String>>,
}

impl Server {
    /// `palpa serve MODEL --port 0 EXTRA...`.
    pub fn start(model: &Path, extra: &[&str]) -> Server {
        let mut child = Command::new(env!("CARGO_BIN_EXE_palpa"))
            .arg("serve")
            .arg(model)
            .args(["--port", "0"])
            .args(extra)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("palpa serve starts");
        let stderr = Arc::new(Mutex::new(String::new()));
        let mut err = child.stderr.take().unwrap();
        let sink = stderr.clone();
        std::thread::spawn(move || {
            let mut buf = [0u8; 4096];
            while let Ok(n) = err.read(&mut buf) {
                if n == 0 {
                    break;
                }
                sink.lock()
                    .unwrap()
                    .push_str(&String::from_utf8_lossy(&buf[..n]));
            }
        });
        let mut out = BufReader::new(child.stdout.take().unwrap());
        let mut addr = None;
        let mut seen = String::new();
        for _ in 0..10 {
            let mut line = String::new();
            if out.read_line(&mut line).unwrap_or(0) == 0 {
                break;
            }
            seen.push_str(&line);
            if let Some(rest) = line.strip_prefix("listening on http://") {
                addr = Some(rest.split('/').next().unwrap().to_string());
                break;
            }
        }
        // keep draining stdout so that the server never blocks on it
        std::thread::spawn(move || for _ in out.lines() {});
        let addr = addr.unwrap_or_else(|| {
            panic!(
                "palpa serve did not start:\n{seen}\n{}",
                stderr.lock().unwrap()
            )
        });
        let stdin = child.stdin.take();
        Server {
            child,
            addr,
            stdin,
            stderr,
        }
    }

    pub fn url(&self) -> String {
        format!("http://{}/", self.addr)
    }

    pub fn stderr(&self) -> String {
        self.stderr.lock().unwrap().clone()
    }

    /// A WebSocket client; its first message (the current frame) is left unread.
    pub fn connect(&self) -> Client {
        let (ws, _) = tungstenite::connect(format!("ws://{}/ws", self.addr)).expect("connects");
        if let MaybeTlsStream::Plain(s) = ws.get_ref() {
            s.set_nodelay(true).unwrap();
        }
        Client { ws }
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A WebSocket client of the server.
pub struct Client {
    pub ws: WebSocket<MaybeTlsStream<TcpStream>>,
}

impl Client {
    fn stream(&self) -> &TcpStream {
        match self.ws.get_ref() {
            MaybeTlsStream::Plain(s) => s,
            _ => unreachable!("plain ws://"),
        }
    }

    pub fn send(&mut self, text: &str) {
        self.ws.send(Message::text(text)).expect("send");
    }

    /// The next text message, parsed, within `timeout`; `None` on timeout or close.
    pub fn recv(&mut self, timeout: Duration) -> Option<Value> {
        let end = Instant::now() + timeout;
        loop {
            let left = end.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return None;
            }
            self.stream().set_read_timeout(Some(left)).unwrap();
            match self.ws.read() {
                Ok(Message::Text(t)) => return Some(serde_json::from_str(t.as_str()).unwrap()),
                Ok(Message::Close(_)) => return None,
                Ok(_) => continue,
                Err(tungstenite::Error::Io(e))
                    if matches!(
                        e.kind(),
                        std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                    ) =>
                {
                    return None
                }
                Err(_) => return None,
            }
        }
    }

    /// The next message of type `ty` (others skipped), within 5 s.
    pub fn next_of(&mut self, ty: &str) -> Value {
        let end = Instant::now() + Duration::from_secs(5);
        while Instant::now() < end {
            if let Some(m) = self.recv(Duration::from_millis(200)) {
                if m["type"] == ty {
                    return m;
                }
            }
        }
        panic!("no {ty} message within 5 s")
    }

    /// Reads everything that arrives within `quiet`.
    pub fn drain(&mut self, quiet: Duration) -> Vec<Value> {
        let mut v = Vec::new();
        while let Some(m) = self.recv(quiet) {
            v.push(m);
        }
        v
    }
}
