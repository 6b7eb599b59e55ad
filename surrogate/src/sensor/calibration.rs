//! The plate-to-body calibration: an affine map from the plate's centre of pressure (u, v)
//! to the body's plan position (x, y), the frame of the model's inputs,
//!
//! ```text
//! [x]   [a11 a12] [u]   [b1]
//! [y] = [a21 a22] [v] + [b2]
//! ```
//!
//! six numbers that absorb where the phantom lies on the plate, its rotation, a mirror (the
//! plate's axes may run either way) and a scale. `palpa calibrate` fits them by least squares
//! to presses recorded at known body points: for N samples with centre of pressure `u_k` at
//! known point `x_k`, each row of `[A | b]` is the least-squares solution of
//! `[u_k v_k 1] theta = x_k` (the design matrix solved by SVD; three presses not on one line
//! determine it, more average the noise out). The fit's residuals `|A u_k + b - x_k|` are
//! reported (RMS and largest).
//!
//! The file (`calibration.json`, written atomically):
//!
//! ```json
//! {"format": "palpa-calibration", "version": 1,
//!  "plate": {"size_m": [0.4, 0.4], "cell_half_span_m": [0.2, 0.2], "cell_depth_m": 0.0,
//!            "contact_threshold_n": 1.0},
//!  "affine": {"a": [[1, 0], [0, 1]], "b": [-0.05, 0.195]},
//!  "fit": {"samples": 40, "points": 5, "rms_m": 0.0004, "max_m": 0.0011}}
//! ```

use super::plate::Plate;
use crate::dataset::write_atomic;
use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::Path;

/// Value of [`Calibration::format`].
pub const CALIBRATION_FORMAT: &str = "palpa-calibration";

/// An affine map of the plane, `x = A u + b`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Affine2 {
    /// The linear part, row-major.
    pub a: [[f64; 2]; 2],
    /// The offset [m].
    pub b: [f64; 2],
}

impl Affine2 {
    /// A shift by `b`.
    pub fn translation(b: [f64; 2]) -> Affine2 {
        Affine2 {
            a: [[1.0, 0.0], [0.0, 1.0]],
            b,
        }
    }

    /// The image of `u`.
    pub fn apply(&self, u: [f64; 2]) -> [f64; 2] {
        [
            self.a[0][0] * u[0] + self.a[0][1] * u[1] + self.b[0],
            self.a[1][0] * u[0] + self.a[1][1] * u[1] + self.b[1],
        ]
    }

    /// The inverse map, if the linear part is invertible.
    pub fn inverse(&self) -> Option<Affine2> {
        let [[p, q], [r, s]] = self.a;
        let det = p * s - q * r;
        if det.abs() < 1e-12 || !det.is_finite() {
            return None;
        }
        let ai = [[s / det, -q / det], [-r / det, p / det]];
        let b = [
            -(ai[0][0] * self.b[0] + ai[0][1] * self.b[1]),
            -(ai[1][0] * self.b[0] + ai[1][1] * self.b[1]),
        ];
        Some(Affine2 { a: ai, b })
    }

    /// Least-squares fit to pairs (plate point u, body point x) [m]; needs three points not on
    /// one line.
    pub fn fit(pairs: &[([f64; 2], [f64; 2])]) -> Result<(Affine2, FitStats)> {
        let n = pairs.len();
        if n < 3 {
            return Err(Error::invalid(
                "calibration",
                format!("{n} press(es): give three or more known points, not on one line"),
            ));
        }
        let design = DMatrix::from_fn(n, 3, |k, c| match c {
            0 => pairs[k].0[0],
            1 => pairs[k].0[1],
            _ => 1.0,
        });
        let svd = design.clone().svd(true, true);
        let (smax, smin) = (svd.singular_values.max(), svd.singular_values.min());
        if !(smin > 1e-9 * smax.max(1e-12)) {
            return Err(Error::invalid(
                "calibration",
                "the presses lie on one line (or on one point): the map is not determined; \
                 press at three or more points spread over the plate",
            ));
        }
        let mut theta = [[0.0; 3]; 2];
        for (out, t) in theta.iter_mut().enumerate() {
            let rhs = DVector::from_fn(n, |k, _| pairs[k].1[out]);
            let sol = svd
                .solve(&rhs, 1e-12)
                .map_err(|e| Error::numerical("calibration", e.to_string()))?;
            *t = [sol[0], sol[1], sol[2]];
        }
        let map = Affine2 {
            a: [[theta[0][0], theta[0][1]], [theta[1][0], theta[1][1]]],
            b: [theta[0][2], theta[1][2]],
        };
        let res: Vec<f64> = pairs
            .iter()
            .map(|(u, x)| {
                let y = map.apply(*u);
                (y[0] - x[0]).hypot(y[1] - x[1])
            })
            .collect();
        let mut points: Vec<[f64; 2]> = pairs.iter().map(|p| p.1).collect();
        points.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
        points.dedup();
        let stats = FitStats {
            samples: n,
            points: points.len(),
            rms_m: (res.iter().map(|r| r * r).sum::<f64>() / n as f64).sqrt(),
            max_m: res.iter().copied().fold(0.0, f64::max),
        };
        Ok((map, stats))
    }
}

/// How well a calibration fits its presses.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitStats {
    /// Samples used.
    pub samples: usize,
    /// Distinct known points.
    pub points: usize,
    /// RMS residual [m].
    pub rms_m: f64,
    /// Largest residual [m].
    pub max_m: f64,
}

/// A plate and its map to the body.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Calibration {
    /// Always `"palpa-calibration"`.
    pub format: String,
    /// Format version, 1.
    pub version: u32,
    /// The plate.
    pub plate: Plate,
    /// Plate centre of pressure to body plan position.
    pub affine: Affine2,
    /// The fit's figures, when fitted.
    #[serde(default)]
    pub fit: Option<FitStats>,
}

impl Calibration {
    /// The reference study's plate with its centre over the body point `centre` [m] and its
    /// axes along the body's: the calibration used when none is given.
    pub fn centred_at(centre: [f64; 2]) -> Calibration {
        Calibration {
            format: CALIBRATION_FORMAT.into(),
            version: 1,
            plate: Plate::default(),
            affine: Affine2::translation(centre),
            fit: None,
        }
    }

    /// Checks the plate and that the map is finite and invertible.
    pub fn validate(&self) -> Result<()> {
        if self.format != CALIBRATION_FORMAT || self.version != 1 {
            return Err(Error::invalid(
                "calibration",
                format!(
                    "format {:?} version {}, expected {CALIBRATION_FORMAT:?} version 1",
                    self.format, self.version
                ),
            ));
        }
        self.plate.validate()?;
        let a = &self.affine;
        if a.a
            .iter()
            .flatten()
            .chain(a.b.iter())
            .any(|v| !v.is_finite())
            || a.inverse().is_none()
        {
            return Err(Error::invalid(
                "affine",
                "the map must be finite and invertible",
            ));
        }
        Ok(())
    }

    /// Reads and checks `path`.
    pub fn read(path: &Path) -> Result<Calibration> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let c: Calibration =
            serde_json::from_str(&text).map_err(|e| Error::format(path, e.to_string()))?;
        c.validate()
            .map_err(|e| Error::format(path, e.to_string()))?;
        Ok(c)
    }

    /// Writes `path` atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        self.validate()?;
        let text =
            serde_json::to_string_pretty(self).map_err(|e| Error::format(path, e.to_string()))?;
        write_atomic(path, |mut f| {
            f.write_all(text.as_bytes()).map_err(|e| Error::io(path, e))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_round_trip() {
        let m = Affine2 {
            a: [[0.9, -0.2], [0.15, -1.1]],
            b: [-0.05, 0.2],
        };
        let i = m.inverse().unwrap();
        let u = [0.13, -0.07];
        let back = i.apply(m.apply(u));
        assert!((back[0] - u[0]).abs() < 1e-15 && (back[1] - u[1]).abs() < 1e-15);
        assert!(Affine2 {
            a: [[1.0, 2.0], [2.0, 4.0]],
            b: [0.0, 0.0]
        }
        .inverse()
        .is_none());
    }

    /// Exact pairs give the map back to rounding; collinear presses are refused.
    #[test]
    fn fit_exact_and_degenerate() {
        let m = Affine2 {
            a: [[0.0, 1.0], [-1.0, 0.0]],
            b: [0.01, 0.02],
        };
        let pairs: Vec<_> = [[0.0, 0.0], [0.1, 0.0], [0.0, 0.1], [0.1, 0.1]]
            .iter()
            .map(|&u| (u, m.apply(u)))
            .collect();
        let (f, s) = Affine2::fit(&pairs).unwrap();
        for r in 0..2 {
            assert!((f.b[r] - m.b[r]).abs() < 1e-14);
            for c in 0..2 {
                assert!((f.a[r][c] - m.a[r][c]).abs() < 1e-13);
            }
        }
        assert!(s.max_m < 1e-14 && s.points == 4);
        let line: Vec<_> = (0..5)
            .map(|k| {
                let u = [0.02 * k as f64, 0.01 * k as f64];
                (u, m.apply(u))
            })
            .collect();
        let e = Affine2::fit(&line).unwrap_err().to_string();
        assert!(e.contains("one line"), "{e}");
        assert!(Affine2::fit(&pairs[..2]).is_err());
    }

    #[test]
    fn file_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("cal.json");
        let c = Calibration::centred_at([-0.05, 0.195]);
        c.write(&p).unwrap();
        assert_eq!(Calibration::read(&p).unwrap(), c);
        std::fs::write(
            &p,
            std::fs::read_to_string(&p)
                .unwrap()
                .replacen('{', "{\"gain\": 2,", 1),
        )
        .unwrap();
        let e = Calibration::read(&p).unwrap_err().to_string();
        assert!(e.contains("gain"), "{e}");
    }
}
