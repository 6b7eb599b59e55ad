//! A synthetic force-plate log for demonstrations and tests of `palpa serve --replay`:
//!
//! ```sh
//! cargo run --release --example sensor_log -- data/sensor-logs/demo-abc.csv
//! ```
//!
//! 100 readings per second of the four corner cells of the reference study's 400 x 400 mm
//! plate ([`surrogate::sensor::Plate`]), centred (without `--calibration`) on the default
//! campaign's raster centre, (-50, 195) mm: presses at the test locations A, B and C, each a
//! 1 s ramp to 30 N, a 1 s hold and a 0.5 s release, then a 2 s slide from A to B at 20 N.
//! The cell loads come from the plate's statics ([`Plate::loads_for`]), with 0.05 N of
//! Gaussian noise on each cell's normal load (seeded: the same file every time).

use surrogate::sensor::{Calibration, LogSample, SensorLog};

fn main() {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "demo-abc.csv".into());
    let cal = Calibration::centred_at([-0.05, 0.195]);
    let to_plate = cal.affine.inverse().expect("a translation is invertible");
    let (a, b, c) = ([-0.0725, 0.1775], [-0.0075, 0.2075], [-0.0875, 0.1725]);
    let rate = 100.0;
    let mut rng = surrogate::rng::Rng::new(27);
    let mut samples = Vec::new();
    let mut t = 0.0;
    let mut push = |t: f64, body: [f64; 2], force: f64, rng: &mut surrogate::rng::Rng| {
        let mut loads = cal.plate.loads_for(to_plate.apply(body), [0.0, 0.0, force]);
        for f in loads.force.iter_mut() {
            f[2] += 0.05 * rng.normal();
        }
        samples.push(LogSample {
            time_s: (t * 1e3_f64).round() / 1e3,
            loads,
            point_m: None,
        });
    };
    for at in [a, b, c] {
        for k in 0..250 {
            let s = k as f64 / rate;
            let f = if s < 1.0 {
                30.0 * s
            } else if s < 2.0 {
                30.0
            } else {
                30.0 * (1.0 - (s - 2.0) / 0.5)
            };
            push(t, at, f.max(0.0), &mut rng);
            t += 1.0 / rate;
        }
    }
    for k in 0..=200 {
        let s = k as f64 / 200.0;
        let p = [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])];
        push(t, p, 20.0, &mut rng);
        t += 1.0 / rate;
    }
    let log = SensorLog {
        samples,
        errors: vec![],
    };
    log.write(std::path::Path::new(&out))
        .unwrap_or_else(|e| panic!("{out}: {e}"));
    println!("{out}: {} readings, {:.2} s", log.samples.len(), t);
}
