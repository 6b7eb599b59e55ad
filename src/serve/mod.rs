//! `palpa serve MODEL`: the live training view. An HTTP server (axum on tokio) serves one page,
//! embedded in the binary (no network needed), and a WebSocket; the page draws the model's
//! liver stress under the trainee's fingers in plan view at the display's frame rate, and every
//! screen that opens it (a projector over the plate, an instructor's screen) sees the same
//! session. Docs: `docs/serve.md`.
//!
//! Inputs, all going through one [`session::Session`]:
//! - the page's pointer (drag for position; wheel, pen pressure or the slider for force);
//! - force-plate readings over the WebSocket ([`protocol`]) or, with `--stdin`, as JSON lines
//!   on stdin: four corner load cells to a normal force and a centre of pressure, through the
//!   calibration (`--calibration`, `palpa calibrate`) to the body, the force filtered as the
//!   training data's was ([`surrogate::sensor`]);
//! - `--replay LOG.csv`: a recorded sensor log at its recorded speed;
//! - the respiratory phase (a model trained on a respiratory campaign predicts at it; models
//!   without a phase input ignore it).
//!
//! It binds to 127.0.0.1 by default; another `--bind` address is the user's explicit choice
//! and is printed with a warning (there is no authentication). A bad message gets an error on
//! its socket (or a numbered line on stderr for stdin) and the server keeps serving.
//!
//! The server is a front like the command line: it calls the `surrogate` crate only.

mod assets;
pub mod protocol;
mod replay;
pub mod scene;
pub mod session;
mod socket;

use protocol::{ClientMessage, ReplayAction};
use session::{Session, Source};
use std::net::{IpAddr, SocketAddr};
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use surrogate::sensor::{Calibration, Sensor, SensorLog};
use surrogate::Predictor;
use tokio::sync::broadcast;

/// `palpa serve`'s arguments.
#[derive(clap::Args, Debug)]
pub struct ServeArgs {
    /// The model `palpa train --out` saved (a directory with model.safetensors, model.json and
    /// the view.json it wrote beside them).
    pub model: PathBuf,
    /// TCP port (0 picks a free one; the address is printed).
    #[arg(long, default_value_t = 8080)]
    pub port: u16,
    /// Address to listen on. The default, 127.0.0.1, serves this machine only; any other
    /// address opens the view and its inputs to the network, without authentication.
    #[arg(long, default_value = "127.0.0.1")]
    pub bind: IpAddr,
    /// Plate-to-body calibration (`palpa calibrate` writes it) [default: the reference
    /// study's 400 x 400 mm plate centred on the training locations, axes along the body's].
    #[arg(long)]
    pub calibration: Option<PathBuf>,
    /// A recorded sensor log (CSV, see `palpa calibrate --help` and docs/serve.md) to play at
    /// its recorded speed from the start; the page's replay button plays it again.
    #[arg(long)]
    pub replay: Option<PathBuf>,
    /// Play the --replay log over and over.
    #[arg(long, requires = "replay")]
    pub replay_loop: bool,
    /// Also read inputs from stdin, one JSON message per line (the WebSocket's messages);
    /// a bad line is reported on stderr with its number and the stream goes on.
    #[arg(long)]
    pub stdin: bool,
}

/// The state every connection shares.
pub struct Shared {
    session: Mutex<Session>,
    frames: broadcast::Sender<Arc<str>>,
    scene: String,
    /// A second copy of the model for deviation maps, so that they do not hold up the session.
    deviation: Option<Mutex<Predictor>>,
    extent: ([f64; 2], [f64; 2]),
    replay: Option<replay::Replay>,
}

/// What a message asks to send back to its sender alone.
pub type Reply = Option<String>;

impl Shared {
    fn broadcast(&self, frame: String) {
        // no receiver is no error: nobody is watching
        let _ = self.frames.send(Arc::from(frame));
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Session> {
        // a poisoned lock means a panic elsewhere; the session itself is still consistent
        self.session.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// The frame of the current state.
    pub fn current_frame(&self) -> String {
        self.lock().current()
    }

    /// Acts on one checked message from `src`.
    pub async fn handle(
        self: &Arc<Self>,
        msg: ClientMessage,
        src: Source,
    ) -> Result<Reply, String> {
        match msg {
            ClientMessage::Pointer { x, y, force, stamp } => {
                let f = self.lock().pointer(x, y, force, stamp, src);
                self.broadcast(f);
                Ok(None)
            }
            ClientMessage::Plate { loads, t, stamp } => {
                let src = if src == Source::Stdin {
                    src
                } else {
                    Source::Plate
                };
                let f = self.lock().plate(&loads, t, stamp, src)?;
                self.broadcast(f);
                Ok(None)
            }
            ClientMessage::Phase { value } => {
                let f = self.lock().phase(value);
                self.broadcast(f);
                Ok(None)
            }
            ClientMessage::Replay { action } => {
                let r = self
                    .replay
                    .as_ref()
                    .ok_or("no replay log: start palpa serve with --replay LOG.csv")?;
                match action {
                    ReplayAction::Start => r.start(self.clone()),
                    ReplayAction::Stop => r.stop(),
                }
                Ok(None)
            }
            ClientMessage::DeviationMap { force } => {
                if self.deviation.is_none() {
                    return Err("this model (an MLP) gives no predictive deviation".into());
                }
                let (f, phase) = {
                    let s = self.lock();
                    (s.force(), s.phase_value())
                };
                let force = force.unwrap_or(f);
                let me = self.clone();
                tokio::task::spawn_blocking(move || {
                    let Some(d) = &me.deviation else {
                        return String::new();
                    };
                    let mut p = d.lock().unwrap_or_else(|p| p.into_inner());
                    // the screen's phase, for a model that takes one
                    p.set_phase(phase);
                    let (lo, hi) = me.extent;
                    session::deviation_map(&mut p, lo, hi, force, 48)
                })
                .await
                .map(Some)
                .map_err(|e| format!("deviation map: {e}"))
            }
        }
    }
}

/// Run `palpa serve`.
pub fn serve(a: &ServeArgs) -> Result<(), String> {
    let model = surrogate::ServedModel::load(&a.model).map_err(|e| {
        format!(
            "model {}: {e} (expected a directory holding model.safetensors and model.json, as \
             `palpa train --out` writes)",
            a.model.display()
        )
    })?;
    if model.domain().is_none() {
        return Err(format!(
            "model {}: its model.json records no training domain (locations, force and stress \
             range), which the view needs for its fixed colour scale and its warnings; train it \
             again with this palpa (`palpa train`)",
            a.model.display()
        ));
    }
    let layout = scene::layout(&model);
    let home = scene::home(&model, &layout);
    let (calibration, cal_source) = match &a.calibration {
        Some(p) => (
            Calibration::read(p).map_err(|e| e.to_string())?,
            p.display().to_string(),
        ),
        None => (
            Calibration::centred_at(home),
            format!(
                "none given: the 400 x 400 mm plate centred at ({:.1}, {:.1}) mm, axes along \
                 the body's",
                home[0] * 1e3,
                home[1] * 1e3
            ),
        ),
    };
    let filter_s = model.domain().and_then(|d| d.force_filter_s).unwrap_or(0.0);
    let sensor = Sensor::new(calibration, filter_s);
    let log = match &a.replay {
        Some(p) => {
            let log = SensorLog::read(p).map_err(|e| e.to_string())?;
            for e in &log.errors {
                eprintln!("replay {}: {e} (row skipped)", p.display());
            }
            if log.samples.is_empty() {
                return Err(format!("replay {}: no usable rows", p.display()));
            }
            Some((p.display().to_string(), log))
        }
        None => None,
    };
    let scale = model
        .scale()
        .unwrap_or_else(|| surrogate::ColourScale::over(0.0, 1.0));
    let scene = scene::scene_json(
        &scene::SceneParts {
            model: &model,
            model_path: a.model.display().to_string(),
            scale,
            sensor: &sensor,
            calibration_source: cal_source.clone(),
            replay: log.as_ref().map(|(f, l)| {
                let d = l.samples.last().map_or(0.0, |s| s.time_s)
                    - l.samples.first().map_or(0.0, |s| s.time_s);
                (f.clone(), l.samples.len(), d)
            }),
        },
        &layout,
    );
    let deviation = model
        .predictor
        .prior_deviation()
        .map(|_| Mutex::new(model.predictor.clone()));
    let summary = format!(
        "{} model {} ({} ROI elements), {}; calibration: {cal_source}; force filter {:.1} ms",
        model.predictor.meta().kind,
        a.model.display(),
        model.predictor.n_outputs(),
        if model.view.is_some() {
            "plan geometry from view.json"
        } else {
            "no view.json: ROI cells only, no outlines"
        },
        filter_s * 1e3
    );
    let (frames, _) = broadcast::channel(64);
    let shared = Arc::new(Shared {
        session: Mutex::new(Session::new(model, sensor, home)),
        frames,
        scene,
        deviation,
        extent: layout.extent,
        replay: log.map(|(f, l)| replay::Replay::new(f, l.samples, a.replay_loop)),
    });
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .map_err(|e| format!("cannot start the server's runtime: {e}"))?;
    rt.block_on(run(shared, a, summary))
}

async fn run(shared: Arc<Shared>, a: &ServeArgs, summary: String) -> Result<(), String> {
    let addr = SocketAddr::new(a.bind, a.port);
    let listener = tokio::net::TcpListener::bind(addr)
        .await
        .map_err(|e| format!("cannot listen on {addr}: {e}"))?;
    let local = listener
        .local_addr()
        .map_err(|e| format!("listening socket: {e}"))?;
    if !a.bind.is_loopback() {
        eprintln!(
            "warning: listening on {local}, not on this machine only: every machine that can \
             reach this address can watch the view and send inputs (no authentication)"
        );
    }
    let host = if a.bind.is_unspecified() {
        format!("localhost:{}", local.port())
    } else {
        local.to_string()
    };
    {
        use std::io::Write;
        let mut out = std::io::stdout().lock();
        let _ = writeln!(out, "palpa serve: {summary}");
        let _ = writeln!(out, "listening on http://{host}/ (Ctrl-C stops)");
        let _ = out.flush();
    }
    if let Some(r) = &shared.replay {
        r.start(shared.clone());
    }
    if a.stdin {
        spawn_stdin(shared.clone());
    }
    let app = socket::router(shared);
    // frames are small and must leave at once: no Nagle delay
    let listener = axum::serve::ListenerExt::tap_io(listener, |tcp| {
        let _ = tcp.set_nodelay(true);
    });
    tokio::select! {
        r = axum::serve(listener, app) => {
            r.map_err(|e| format!("server: {e}"))
        }
        _ = tokio::signal::ctrl_c() => {
            println!("palpa serve: stopped");
            Ok(())
        }
    }
}

/// Reads stdin on its own thread (a blocking read must not hold the runtime at exit) and
/// hands each line to the session.
fn spawn_stdin(shared: Arc<Shared>) {
    let (tx, mut rx) = tokio::sync::mpsc::unbounded_channel::<(usize, String)>();
    std::thread::spawn(move || {
        use std::io::BufRead;
        for (k, line) in std::io::stdin().lock().lines().enumerate() {
            match line {
                Ok(l) => {
                    if tx.send((k + 1, l)).is_err() {
                        break;
                    }
                }
                Err(e) => {
                    eprintln!("stdin line {}: {e}", k + 1);
                    break;
                }
            }
        }
    });
    tokio::spawn(async move {
        let (mut ok, mut bad) = (0usize, 0usize);
        while let Some((n, line)) = rx.recv().await {
            if line.trim().is_empty() {
                continue;
            }
            let r = match protocol::parse(&line) {
                Ok(m) => shared.handle(m, Source::Stdin).await,
                Err(e) => Err(e),
            };
            match r {
                Ok(reply) => {
                    ok += 1;
                    if let Some(text) = reply {
                        println!("{text}");
                    }
                }
                Err(e) => {
                    bad += 1;
                    eprintln!("stdin line {n}: {e}");
                }
            }
        }
        eprintln!("palpa serve: stdin closed after {ok} input(s), {bad} line(s) with errors; still serving");
    });
}
