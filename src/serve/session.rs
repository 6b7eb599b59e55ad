//! The live session: one hand on one model, shared by every screen. Each input (pointer,
//! plate reading, replayed or piped line) updates the hand and yields a frame, the JSON text the
//! server broadcasts to every WebSocket:
//!
//! ```json
//! {"type": "frame", "seq": 12, "source": "plate", "x": -0.0725, "y": 0.1775, "force": 30.0,
//!  "lifted": false, "phase": 0.0, "liver_shift": 0.0, "plate": [0.01, -0.02], "stress": [Pa, ...],
//!  "sd": 41.4, "max": {"index": 17, "value": 5241.3},
//!  "warnings": [{"code": "force_above_training", "text": "..."}],
//!  "stamp": 1732530000123.4, "received": 1732530000123.9, "predict_us": 21.0}
//! ```
//!
//! `x`, `y` [m] and `force` [N] are what the model was asked (the force filtered like the
//! training data's for plate readings); `stress` the maximum principal stress of each ROI
//! element [Pa, 0.1 Pa steps]; `sd` the GP's predictive deviation [Pa] (null for an MLP);
//! `plate` the centre of pressure on the plate [m] for plate readings; `stamp` the input's
//! wall-clock time [ms since the Unix epoch] (the sender's, else `received`, the server's).
//! A hand that is lifted (force below the plate's contact threshold, or a pointer force of
//! 0) is predicted at zero force where it last was.

use serde_json::{json, Value};
use std::time::{Instant, SystemTime, UNIX_EPOCH};
use surrogate::sensor::{CornerLoads, Sensor, SensorInput};
use surrogate::ServedModel;

/// Where an input came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// The page's pointer.
    Pointer,
    /// A plate reading over the WebSocket.
    Plate,
    /// The `--replay` log.
    Replay,
    /// A line on stdin.
    Stdin,
}

impl Source {
    fn name(self) -> &'static str {
        match self {
            Source::Pointer => "pointer",
            Source::Plate => "plate",
            Source::Replay => "replay",
            Source::Stdin => "stdin",
        }
    }
}

/// Wall-clock time [ms since the Unix epoch].
pub fn now_ms() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_secs_f64() * 1e3)
        .unwrap_or(0.0)
}

/// The hand and the model.
pub struct Session {
    model: ServedModel,
    sensor: Sensor,
    x: f64,
    y: f64,
    force: f64,
    lifted: bool,
    plate: Option<[f64; 2]>,
    source: Source,
    seq: u64,
    start: Instant,
}

impl Session {
    /// A session on `model` reading the plate through `sensor`; the hand starts lifted at
    /// `home` [m].
    pub fn new(model: ServedModel, sensor: Sensor, home: [f64; 2]) -> Session {
        Session {
            model,
            sensor,
            x: home[0],
            y: home[1],
            force: 0.0,
            lifted: true,
            plate: None,
            source: Source::Pointer,
            seq: 0,
            start: Instant::now(),
        }
    }

    /// The current force [N].
    pub fn force(&self) -> f64 {
        if self.lifted {
            0.0
        } else {
            self.force
        }
    }

    /// A press at (x, y) [m] with `force` [N] (checked by the protocol: finite, >= 0).
    pub fn pointer(
        &mut self,
        x: f64,
        y: f64,
        force: f64,
        stamp: Option<f64>,
        src: Source,
    ) -> String {
        self.x = x;
        self.y = y;
        self.force = force;
        self.lifted = force <= 0.0;
        self.plate = None;
        self.source = src;
        self.frame(stamp)
    }

    /// A plate reading at sensor time `t` [s] (the session's clock when `None`); an error
    /// (a negative normal force, a press off the plate, ...) leaves the hand as it was.
    pub fn plate(
        &mut self,
        loads: &CornerLoads,
        t: Option<f64>,
        stamp: Option<f64>,
        src: Source,
    ) -> Result<String, String> {
        let t = t.unwrap_or_else(|| self.start.elapsed().as_secs_f64());
        match self.sensor.read(t, loads).map_err(|e| e.to_string())? {
            SensorInput::Lifted { force_n } => {
                self.force = force_n;
                self.lifted = true;
            }
            SensorInput::Press {
                x,
                y,
                force_n,
                plate_m,
            } => {
                self.x = x;
                self.y = y;
                self.force = force_n;
                self.lifted = false;
                self.plate = Some(plate_m);
            }
        }
        self.source = src;
        Ok(self.frame(stamp))
    }

    /// The respiratory phase (0 exhalation .. 1 inspiration): a model trained on a respiratory
    /// campaign predicts at it; one that takes x, y and force only ignores it.
    pub fn phase(&mut self, value: f64) -> String {
        self.model.predictor.set_phase(value);
        self.frame(None)
    }

    /// How far [m] the liver and its ROI are drawn caudally of the view's outlines: the phase's
    /// shift for a model with a phase input and a `view.json`, else 0.
    fn liver_shift(&self) -> f64 {
        match &self.model.view {
            Some(v) if self.model.predictor.takes_phase() => {
                (self.phase_value() - v.respiratory_phase) * v.max_liver_shift_m
            }
            _ => 0.0,
        }
    }

    /// The current respiratory phase (held by the model's predictor).
    pub fn phase_value(&self) -> f64 {
        self.model.predictor.phase()
    }

    /// The frame of the current state (for a screen that has just connected).
    pub fn current(&mut self) -> String {
        self.frame(None)
    }

    fn frame(&mut self, stamp: Option<f64>) -> String {
        let received = now_ms();
        let t0 = Instant::now();
        let force = self.force();
        let served = self.model.predict(self.x, self.y, force);
        let predict_us = t0.elapsed().as_secs_f64() * 1e6;
        self.seq += 1;
        let (imax, vmax) =
            served
                .stress
                .iter()
                .enumerate()
                .fold(
                    (0, f64::NEG_INFINITY),
                    |a, (i, &v)| if v > a.1 { (i, v) } else { a },
                );
        let stress: Vec<Value> = served
            .stress
            .iter()
            .map(|v| json!((v * 10.0).round() / 10.0))
            .collect();
        let warnings: Vec<Value> = served
            .warnings
            .iter()
            .map(|w| json!({"code": w.code(), "text": w.to_string()}))
            .collect();
        json!({
            "type": "frame",
            "seq": self.seq,
            "source": self.source.name(),
            "x": self.x,
            "y": self.y,
            "force": force,
            "lifted": self.lifted,
            "phase": self.phase_value(),
            "liver_shift": self.liver_shift(),
            "plate": self.plate,
            "stress": stress,
            "sd": served.sd,
            "max": {"index": imax, "value": vmax},
            "warnings": warnings,
            "stamp": stamp.unwrap_or(received),
            "received": received,
            "predict_us": predict_us,
        })
        .to_string()
    }
}

/// The GP's predictive deviation [Pa] on an `n` x `n` grid over the picture's extent
/// (`lo`, `hi` [m]) at `force` [N], as JSON for the page's deviation view.
pub fn deviation_map(
    predictor: &mut surrogate::Predictor,
    lo: [f64; 2],
    hi: [f64; 2],
    force: f64,
    n: usize,
) -> String {
    let (dx, dy) = (
        (hi[0] - lo[0]) / (n - 1) as f64,
        (hi[1] - lo[1]) / (n - 1) as f64,
    );
    let mut sd = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (lo[0] + i as f64 * dx, lo[1] + j as f64 * dy);
            let v = predictor.predict_with_variance(x, y, force).1;
            sd.push(json!(v.map(|v| v.max(0.0).sqrt().round())));
        }
    }
    json!({
        "type": "deviation_map",
        "force": force,
        "phase": predictor.phase(),
        "grid": {"x0": lo[0], "y0": lo[1], "dx": dx, "dy": dy, "nx": n, "ny": n},
        "sd": sd,
        "prior": predictor.prior_deviation(),
    })
    .to_string()
}
