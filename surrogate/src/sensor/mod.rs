//! The live inputs of `palpa serve`: the force plate ([`plate`]: four corner load cells to a
//! normal force and a centre of pressure), its calibration to the body ([`calibration`]: an
//! affine map fitted by `palpa calibrate`), the force filter ([`filter`]) and recorded sensor
//! logs ([`log`]). [`Sensor`] chains them: a reading of the four cells in, the (x, y, force)
//! input of a model out.

pub mod calibration;
pub mod filter;
pub mod log;
pub mod plate;

pub use calibration::{Affine2, Calibration, FitStats};
pub use filter::TrailingAverage;
pub use log::{LogSample, SensorLog};
pub use plate::{CornerLoads, Plate, PlateReading};

use crate::error::Result;

/// What one plate reading asks the model for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SensorInput {
    /// Not pressed: the normal force [N] (filtered) is below the contact threshold.
    Lifted {
        /// Filtered normal force [N].
        force_n: f64,
    },
    /// A press at body position (x, y) [m] with the filtered normal force [N].
    Press {
        /// Body x [m].
        x: f64,
        /// Body y [m].
        y: f64,
        /// Filtered normal force [N].
        force_n: f64,
        /// Centre of pressure on the plate [m].
        plate_m: [f64; 2],
    },
}

/// A plate with its calibration and the force filter of the model's training data.
#[derive(Clone, Debug)]
pub struct Sensor {
    /// Plate and map.
    pub calibration: Calibration,
    filter: TrailingAverage,
}

impl Sensor {
    /// A sensor with `calibration` and a trailing force filter of `window_s` seconds.
    pub fn new(calibration: Calibration, window_s: f64) -> Sensor {
        Sensor {
            calibration,
            filter: TrailingAverage::new(window_s),
        }
    }

    /// The force filter's window [s].
    pub fn filter_window(&self) -> f64 {
        self.filter.window()
    }

    /// One reading at time `t` [s]: resolved on the plate, its normal force filtered, its
    /// centre of pressure mapped to the body. A bad reading is an error and leaves the filter
    /// as it was.
    pub fn read(&mut self, t: f64, loads: &CornerLoads) -> Result<SensorInput> {
        let reading = self.calibration.plate.resolve(loads)?;
        Ok(match reading {
            PlateReading::NoContact { normal_n } => SensorInput::Lifted {
                force_n: self.filter.push(t, normal_n.max(0.0)),
            },
            PlateReading::Press {
                normal_n, cop_m, ..
            } => {
                let [x, y] = self.calibration.affine.apply(cop_m);
                SensorInput::Press {
                    x,
                    y,
                    force_n: self.filter.push(t, normal_n),
                    plate_m: cop_m,
                }
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A calibration fitted from synthetic presses at known body points recovers the affine
    /// map they were made with: plate points from the map's inverse, cell loads from the
    /// plate's statics, 0.2 mm of noise on each centre of pressure (as from cell noise);
    /// the fitted entries of A within 0.01 and b within 1 mm, residuals about the noise.
    #[test]
    fn calibration_from_synthetic_presses_recovers_the_map() {
        let plate = Plate::default();
        // rotated by 3 degrees, mirrored in y, scaled by 1.02, shifted
        let (c, s) = (3f64.to_radians().cos(), 3f64.to_radians().sin());
        let truth = Affine2 {
            a: [[1.02 * c, 1.02 * s], [1.02 * s, -1.02 * c]],
            b: [-0.048, 0.197],
        };
        let inv = truth.inverse().unwrap();
        let mut rng = crate::rng::Rng::new(11);
        let mut pairs = Vec::new();
        for &bx in &[-0.12, -0.07, -0.02, 0.03] {
            for &by in &[0.15, 0.19, 0.23] {
                for _ in 0..5 {
                    let body = [bx, by];
                    let u = inv.apply(body);
                    let loads = plate.loads_for(u, [0.0, 0.0, 20.0 + 10.0 * rng.uniform()]);
                    let PlateReading::Press { cop_m, .. } = plate.resolve(&loads).unwrap() else {
                        panic!("a 20 N press is a press")
                    };
                    let noisy = [
                        cop_m[0] + 2e-4 * rng.normal(),
                        cop_m[1] + 2e-4 * rng.normal(),
                    ];
                    pairs.push((noisy, body));
                }
            }
        }
        let (fit, stats) = Affine2::fit(&pairs).unwrap();
        for r in 0..2 {
            assert!((fit.b[r] - truth.b[r]).abs() < 1e-3, "{fit:?}");
            for k in 0..2 {
                assert!((fit.a[r][k] - truth.a[r][k]).abs() < 0.01, "{fit:?}");
            }
        }
        assert_eq!((stats.samples, stats.points), (60, 12));
        assert!(stats.rms_m < 5e-4 && stats.rms_m > 1e-4, "{stats:?}");
    }

    /// The sensor maps a press through plate and calibration, and says lifted below 1 N.
    #[test]
    fn sensor_chain() {
        let cal = Calibration::centred_at([-0.05, 0.195]);
        let mut s = Sensor::new(cal.clone(), 1e-3);
        let loads = cal.plate.loads_for([0.01, -0.02], [0.0, 0.0, 30.0]);
        match s.read(0.0, &loads).unwrap() {
            SensorInput::Press { x, y, force_n, .. } => {
                assert!((x + 0.04).abs() < 1e-12 && (y - 0.175).abs() < 1e-12);
                assert!((force_n - 30.0).abs() < 1e-12);
            }
            other => panic!("{other:?}"),
        }
        let light = cal.plate.loads_for([0.0, 0.0], [0.0, 0.0, 0.4]);
        assert!(matches!(
            s.read(0.1, &light).unwrap(),
            SensorInput::Lifted { .. }
        ));
    }
}
