//! `--replay LOG.csv`: a recorded sensor log played at its recorded speed, row k at
//! `start + (t_k - t_0)` on the server's clock, each row going through the session as a plate
//! reading (with the log's own time for the force filter). A row the plate refuses (a press
//! off the plate, a pull) is reported on stderr and to every screen, and the replay goes on.

use super::session::{now_ms, Source};
use super::Shared;
use std::sync::{Arc, Mutex};
use std::time::Duration;
use surrogate::sensor::LogSample;
use tokio::task::JoinHandle;
use tokio::time::Instant;

/// A log and the task playing it.
pub struct Replay {
    file: String,
    samples: Arc<Vec<LogSample>>,
    repeat: bool,
    task: Mutex<Option<JoinHandle<()>>>,
}

impl Replay {
    /// A replay of `samples` (non-empty, times non-decreasing) from `file`.
    pub fn new(file: String, samples: Vec<LogSample>, repeat: bool) -> Replay {
        Replay {
            file,
            samples: Arc::new(samples),
            repeat,
            task: Mutex::new(None),
        }
    }

    /// Plays the log from its start (stopping a replay under way).
    pub fn start(&self, shared: Arc<Shared>) {
        self.stop();
        let samples = self.samples.clone();
        let (file, repeat) = (self.file.clone(), self.repeat);
        let task = tokio::spawn(async move {
            loop {
                let t0 = Instant::now();
                let first = samples.first().map_or(0.0, |s| s.time_s);
                for (k, s) in samples.iter().enumerate() {
                    let at = t0 + Duration::from_secs_f64((s.time_s - first).max(0.0));
                    tokio::time::sleep_until(at).await;
                    let frame = shared.lock().plate(
                        &s.loads,
                        Some(s.time_s),
                        Some(now_ms()),
                        Source::Replay,
                    );
                    match frame {
                        Ok(f) => shared.broadcast(f),
                        Err(e) => {
                            let msg = format!("replay {file}, row {}: {e}", k + 1);
                            eprintln!("{msg}");
                            shared.broadcast(
                                serde_json::json!({"type": "error", "error": msg}).to_string(),
                            );
                        }
                    }
                }
                if !repeat {
                    break;
                }
            }
        });
        *self.task.lock().unwrap_or_else(|p| p.into_inner()) = Some(task);
    }

    /// Stops the replay, if one is under way.
    pub fn stop(&self) {
        if let Some(t) = self.task.lock().unwrap_or_else(|p| p.into_inner()).take() {
            t.abort();
        }
    }
}
