//! `palpa serve` without a browser (issue 27): the real binary on a free port with the
//! committed default model, driven over its WebSocket and stdin.
//!
//! - bad messages (not JSON, not an object, unknown type or field, a negative force, a NaN, a
//!   message over the size limit, binary, a press off the plate, a pull) each get an error
//!   naming the fault on their own socket, and the server keeps serving; a message too big
//!   for the WebSocket layer closes that connection only;
//! - a press reaches every screen (broadcast), with the stress the model itself predicts;
//! - a plate reading lands where the calibration puts its hand-computed centre of pressure;
//! - the stdin stream reports bad lines with their numbers and goes on;
//! - `--replay` plays a log at its recorded speed, a bad row reported and skipped;
//! - `palpa calibrate` recovers a known affine map from synthetic presses.

mod support;

use serde_json::{json, Value};
use std::io::Write;
use std::time::{Duration, Instant};
use support::{default_model, Server};
use surrogate::sensor::{Affine2, Calibration, LogSample, SensorLog};
use surrogate::ServedModel;

/// The default calibration of the default model: the plate centred on the raster's centre.
const HOME: [f64; 2] = [-0.05, 0.195];

fn plate_msg(plate_point: [f64; 2], force: f64, t: f64) -> String {
    let loads = Calibration::centred_at(HOME)
        .plate
        .loads_for(plate_point, [0.0, 0.0, force]);
    json!({"type": "plate", "corners": loads.force, "t": t}).to_string()
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

#[test]
fn bad_messages_get_errors_and_every_screen_sees_the_press() {
    let server = Server::start(&default_model(), &[]);
    let mut a = server.connect();
    let mut b = server.connect();
    assert_eq!(a.next_of("frame")["lifted"], true, "the hand starts lifted");
    b.next_of("frame");

    let long = format!(
        r#"{{"type":"pointer","x":0,"y":0,"force":1,"pad":"{}"}}"#,
        "a".repeat(20_000)
    );
    let bad: Vec<(String, &str)> = vec![
        ("{\"type\": \"pointer\", \"x\": ".into(), "not JSON"),
        ("42".into(), "expected a JSON object"),
        (r#"{"type":"teleport"}"#.into(), "unknown type \"teleport\""),
        (
            r#"{"type":"pointer","x":-0.07,"y":0.18,"force":-5}"#.into(),
            "negative",
        ),
        (
            r#"{"type":"pointer","x":NaN,"y":0.18,"force":5}"#.into(),
            "not JSON",
        ),
        (
            r#"{"type":"pointer","x":-0.07,"y":0.18,"force":5,"speed":3}"#.into(),
            "unknown field `speed`",
        ),
        (long, "longer than the limit of 16384 bytes"),
        // a bolted plate pulled up at two cells and pressed beside its +x edge:
        // x_p = 0.2 (2 + 12 + 12 + 2) / 20 = 280 mm, off the 400 mm plate
        (
            r#"{"type":"plate","corners":[-2,12,12,-2]}"#.into(),
            "off the plate",
        ),
        (
            r#"{"type":"plate","corners":[-5,-5,-5,-5]}"#.into(),
            "negative",
        ),
        (r#"{"type":"phase","value":1.5}"#.into(), "outside 0"),
        (
            r#"{"type":"replay","action":"start"}"#.into(),
            "no replay log",
        ),
    ];
    for (text, expect) in &bad {
        a.send(text);
        let e = a.next_of("error");
        let msg = e["error"].as_str().unwrap();
        assert!(msg.contains(expect), "{text:.60}: {msg}");
    }
    a.ws.send(tungstenite::Message::binary(vec![1u8, 2, 3]))
        .unwrap();
    assert!(a.next_of("error")["error"]
        .as_str()
        .unwrap()
        .contains("binary"));
    // none of that reached the other screen
    assert!(
        b.drain(Duration::from_millis(200)).is_empty(),
        "errors go to their sender only"
    );

    // a press at A with 30 N: both screens get it, with the model's own prediction
    let (x, y, force) = (-0.0725, 0.1775, 30.0);
    a.send(&json!({"type":"pointer","x":x,"y":y,"force":force,"stamp":1.0}).to_string());
    let fa = a.next_of("frame");
    let fb = b.next_of("frame");
    assert_eq!(fa["seq"], fb["seq"]);
    assert_eq!(f(&fb["x"]), x);
    assert_eq!(f(&fb["force"]), force);
    assert_eq!(f(&fb["stamp"]), 1.0, "the sender's stamp comes back");
    let mut model = ServedModel::load(&default_model()).unwrap();
    let own = model.predict(x, y, force);
    let shown = fb["stress"].as_array().unwrap();
    assert_eq!(shown.len(), 377);
    for (s, o) in shown.iter().zip(&own.stress) {
        assert!((f(s) - o).abs() <= 0.05 + 1e-9, "{s} against {o}");
    }
    assert!((f(&fb["sd"]) - own.sd.unwrap()).abs() < 1e-9);
    assert!(fb["warnings"].as_array().unwrap().is_empty(), "A is inside");

    // a plate reading: centre of pressure (10, -20) mm on the plate, the plate centred at
    // HOME: body (-40, 175) mm
    b.send(&plate_msg([0.01, -0.02], 25.0, 0.0));
    let fp = a.next_of("frame");
    assert_eq!(b.next_of("frame")["seq"], fp["seq"]);
    assert_eq!(fp["source"], "plate");
    assert!((f(&fp["x"]) + 0.040).abs() < 1e-12 && (f(&fp["y"]) - 0.175).abs() < 1e-12);
    assert!((f(&fp["force"]) - 25.0).abs() < 1e-9);
    let p = fp["plate"].as_array().unwrap();
    assert!((f(&p[0]) - 0.01).abs() < 1e-12 && (f(&p[1]) + 0.02).abs() < 1e-12);

    // a press outside the body (x = -160 mm, the torso ends at -150 mm) is served, with its
    // warnings
    a.send(r#"{"type":"pointer","x":-0.16,"y":0.2,"force":20}"#);
    let fo = b.next_of("frame");
    let codes: Vec<&str> = fo["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w["code"].as_str().unwrap())
        .collect();
    assert!(codes.contains(&"outside_body"), "{codes:?}");
    assert!(codes.contains(&"outside_training_locations"), "{codes:?}");

    // deviation map: to the asker only
    a.send(r#"{"type":"deviation_map","force":30}"#);
    let d = a.next_of("deviation_map");
    let sd = d["sd"].as_array().unwrap();
    assert_eq!(sd.len(), 48 * 48);
    let prior = f(&d["prior"]);
    let max = sd.iter().map(f).fold(0.0, f64::max);
    // (the map is rounded to whole pascals)
    assert!(
        max <= prior + 0.5 && max > 0.5 * prior,
        "{max} vs prior {prior}"
    );

    // a message too big for the WebSocket layer (2 MiB) ends that connection only
    let huge = "x".repeat(2 << 20);
    let _ = a.ws.send(tungstenite::Message::text(huge));
    let gone = (0..20).all(|_| {
        a.recv(Duration::from_millis(100))
            .is_none_or(|m| m["type"] == "error")
    });
    assert!(gone, "the oversized sender's connection ends");
    b.send(r#"{"type":"pointer","x":-0.05,"y":0.19,"force":10}"#);
    assert_eq!(
        f(&b.next_of("frame")["force"]),
        10.0,
        "the server keeps serving"
    );
    let mut c = server.connect();
    assert_eq!(
        f(&c.next_of("frame")["force"]),
        10.0,
        "a new screen gets the current frame"
    );
    assert!(!server.stderr().contains("panicked"), "{}", server.stderr());
}

#[test]
fn stdin_reports_bad_lines_and_goes_on() {
    let mut server = Server::start(&default_model(), &["--stdin"]);
    let mut ws = server.connect();
    ws.next_of("frame");
    let mut stdin = server.stdin.take().unwrap();
    let lines = [
        r#"{"type":"pointer","x":-0.0725,"y":0.1775,"force":12}"#.to_string(),
        "this is not json".to_string(),
        r#"{"type":"pointer","x":-0.0725,"y":0.1775,"force":-1}"#.to_string(),
        String::new(),
        plate_msg([0.0, 0.0], 18.0, 0.5),
    ];
    for l in &lines {
        writeln!(stdin, "{l}").unwrap();
    }
    drop(stdin);
    let f1 = ws.next_of("frame");
    assert_eq!(
        (f1["source"].as_str(), f(&f1["force"])),
        (Some("stdin"), 12.0)
    );
    let f2 = ws.next_of("frame");
    assert_eq!(
        (f2["source"].as_str(), f(&f2["force"])),
        (Some("stdin"), 18.0)
    );
    assert!(
        (f(&f2["x"]) - HOME[0]).abs() < 1e-12,
        "plate centre -> HOME"
    );
    let end = Instant::now() + Duration::from_secs(5);
    while !server.stderr().contains("stdin closed") && Instant::now() < end {
        std::thread::sleep(Duration::from_millis(20));
    }
    let err = server.stderr();
    assert!(err.contains("stdin line 2: not JSON"), "{err}");
    assert!(
        err.contains("stdin line 3: force = -1 N is negative"),
        "{err}"
    );
    assert!(
        err.contains("after 2 input(s), 2 line(s) with errors; still serving"),
        "{err}"
    );
    ws.send(r#"{"type":"pointer","x":-0.05,"y":0.19,"force":7}"#);
    assert_eq!(f(&ws.next_of("frame")["force"]), 7.0);
}

#[test]
fn replay_plays_at_recorded_speed() {
    let dir = tempfile::tempdir().unwrap();
    let log_path = dir.path().join("log.csv");
    // 50 readings at 100 Hz: the press moves 20 mm along the plate's x while the force rises
    // from 10 to 34.5 N; row 26 is a press off the plate
    let cal = Calibration::centred_at(HOME);
    let mut samples = Vec::new();
    for k in 0..50 {
        let u = [-0.01 + 0.0004 * k as f64, 0.005];
        let mut loads = cal.plate.loads_for(u, [0.0, 0.0, 10.0 + 0.5 * k as f64]);
        if k == 25 {
            loads = cal.plate.loads_for([0.0, 0.0], [0.0, 0.0, 20.0]);
            for (cell, fz) in loads.force.iter_mut().zip([-2.0, 12.0, 12.0, -2.0]) {
                cell[2] = fz;
            }
        }
        samples.push(LogSample {
            time_s: 0.01 * k as f64,
            loads,
            point_m: None,
        });
    }
    SensorLog {
        samples,
        errors: vec![],
    }
    .write(&log_path)
    .unwrap();
    let server = Server::start(&default_model(), &["--replay", log_path.to_str().unwrap()]);
    let mut ws = server.connect();
    // let the replay that starts with the server finish, then play it again
    std::thread::sleep(Duration::from_millis(700));
    ws.drain(Duration::from_millis(100));
    ws.send(r#"{"type":"replay","action":"start"}"#);
    let mut frames = Vec::new();
    let mut errors = Vec::new();
    let end = Instant::now() + Duration::from_secs(5);
    while frames.len() < 49 && Instant::now() < end {
        if let Some(m) = ws.recv(Duration::from_millis(200)) {
            match m["type"].as_str() {
                Some("frame") if m["source"] == "replay" => frames.push(m),
                Some("error") => errors.push(m["error"].as_str().unwrap().to_string()),
                _ => {}
            }
        }
    }
    assert_eq!(frames.len(), 49, "every good row, once");
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert!(
        errors[0].contains("row 26") && errors[0].contains("off the plate"),
        "{errors:?}"
    );
    // recorded speed: the 49 frames span the log's 0.49 s
    let span = (f(&frames[48]["received"]) - f(&frames[0]["received"])) / 1e3;
    assert!(
        (span - 0.49).abs() < 0.06,
        "replay took {span} s for 0.49 s of log"
    );
    // the last row: plate (9.6, 5) mm -> body (-40.4, 200) mm, force 34.5 N (1 ms filter on
    // 10 ms samples: the sample itself)
    let last = &frames[48];
    assert!((f(&last["x"]) + 0.0404).abs() < 1e-12, "{}", last["x"]);
    assert!((f(&last["y"]) - 0.2).abs() < 1e-12);
    assert!((f(&last["force"]) - 34.5).abs() < 1e-9);
}

#[test]
fn calibrate_recovers_a_known_map() {
    let dir = tempfile::tempdir().unwrap();
    let plate = surrogate::sensor::Plate::default();
    // the plate turned by 90 degrees (its u along the body's -y), mirrored, shifted
    let truth = Affine2 {
        a: [[0.0, 1.0], [1.0, 0.0]],
        b: [-0.05, 0.19],
    };
    let inv = truth.inverse().unwrap();
    let mut rng = surrogate::rng::Rng::new(3);
    let mut samples = Vec::new();
    let mut t = 0.0;
    for bx in [-0.1, -0.05, 0.0] {
        for by in [0.16, 0.2, 0.24] {
            for k in 0..6 {
                let mut loads = plate.loads_for(inv.apply([bx, by]), [0.0, 0.0, 25.0]);
                for c in loads.force.iter_mut() {
                    c[2] += 0.05 * rng.normal();
                }
                if k == 0 {
                    // the finger not yet down: no press
                    loads = plate.loads_for(inv.apply([bx, by]), [0.0, 0.0, 0.3]);
                }
                samples.push(LogSample {
                    time_s: t,
                    loads,
                    point_m: Some([bx, by]),
                });
                t += 0.01;
            }
        }
    }
    // one reading off the plate (a faulty cell)
    let mut off = samples[1].clone();
    off.loads.force = [
        [0.0, 0.0, -2.0],
        [0.0, 0.0, 12.0],
        [0.0, 0.0, 12.0],
        [0.0, 0.0, -2.0],
    ];
    off.time_s = t;
    samples.push(off);
    let presses = dir.path().join("presses.csv");
    SensorLog {
        samples,
        errors: vec![],
    }
    .write(&presses)
    .unwrap();
    let out = dir.path().join("calibration.json");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_palpa"))
        .args([
            "calibrate",
            presses.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stdout}\n{stderr}");
    assert!(stdout.contains("45 presses at 9 known points"), "{stdout}");
    assert!(
        stdout.contains("9 rows without a press, 1 refused"),
        "{stdout}"
    );
    assert!(stdout.contains("mirrored"), "{stdout}");
    assert!(stderr.contains("off the plate"), "{stderr}");
    let cal = Calibration::read(&out).unwrap();
    for r in 0..2 {
        assert!(
            (cal.affine.b[r] - truth.b[r]).abs() < 1e-3,
            "{:?}",
            cal.affine
        );
        for k in 0..2 {
            assert!(
                (cal.affine.a[r][k] - truth.a[r][k]).abs() < 0.01,
                "{:?}",
                cal.affine
            );
        }
    }
    // residuals are the cells' noise: x_p = a (f2 + f3 - f1 - f4) / F has the deviation
    // 2 a sigma / F = 2 * 0.2 * 0.05 / 25 = 0.8 mm per axis, 1.13 mm radial RMS
    let fit = cal.fit.unwrap();
    assert!(fit.rms_m > 0.8e-3 && fit.rms_m < 1.5e-3, "{fit:?}");
    // and the server takes it
    let server = Server::start(&default_model(), &["--calibration", out.to_str().unwrap()]);
    let mut ws = server.connect();
    ws.next_of("frame");
    let loads = plate.loads_for(inv.apply([-0.07, 0.18]), [0.0, 0.0, 20.0]);
    ws.send(&json!({"type":"plate","corners":loads.force}).to_string());
    let fr = ws.next_of("frame");
    assert!(
        (f(&fr["x"]) + 0.07).abs() < 1e-3 && (f(&fr["y"]) - 0.18).abs() < 1e-3,
        "{fr}"
    );
}
