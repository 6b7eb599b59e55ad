//! The force plate: a rigid plate resting on a six-axis load cell at each corner, as in the
//! reference study (400 x 400 mm). From the four cells' forces (and moments, when given) it
//! gives the total normal force and the centre of pressure, where the hand presses.
//!
//! # Frame and conventions
//! Plate frame, SI: origin at the centre of the plate's top surface, x and y in its plane,
//! **z pointing into the plate** (the pressing direction), right-handed. Cell k sits at
//! `r_k = (s_x a, s_y b, h)` with `(s_x, s_y)` = (-,-), (+,-), (+,+), (-,+) for k = 1..4
//! (counter-clockwise from the (-x, -y) corner seen from above), `a`, `b` the half spans and
//! `h` the depth of the cells' measuring points below the surface. Each cell reports the load
//! the plate puts on it, `f_k = (f_x, f_y, f_z)` [N] (a press reads positive `f_z`), and
//! optionally its moment `m_k` [N m] about its measuring point.
//!
//! # Equations
//! A hand pressing at `p = (x_p, y_p, 0)` with force `F` (and a free moment `T` about z) is in
//! equilibrium with the cells: `F = sum_k f_k` and, about the origin,
//! `p x F + T e_z = M = sum_k (r_k x f_k + m_k)`. The x and y components give the centre of
//! pressure
//!
//! ```text
//! x_p = -M_y / F_z,   y_p = M_x / F_z,
//! M_x = sum_k (y_k f_zk - h f_yk + m_xk),   M_y = sum_k (h f_xk - x_k f_zk + m_yk),
//! ```
//!
//! i.e. without cell moments `x_p = (sum x_k f_zk - h F_x) / F_z`: the force-weighted mean of
//! the cells' positions, corrected for the shear acting `h` above the cells (the usual
//! force-plate relation, e.g. Kistler's `a_x = (F_x a_z0 - M_y) / F_z`). The normal force is
//! `F_z`.
//!
//! A normal force below the contact threshold (default 1 N) is no press: the centre of
//! pressure is undefined there (noise over a vanishing force). A clearly negative normal force
//! (a pull, or the cells' sign reversed) and a centre of pressure off the plate (a press beside
//! it, or a faulty cell: with four non-negative `f_z` and no shear the centre stays between the
//! cells, so only tension in a bolted cell, a moment or shear can move it out) are errors.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// Corner signs (s_x, s_y) of cells 1..4.
pub const CORNER_SIGNS: [[f64; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];

/// The plate's geometry (m) and contact threshold (N).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Plate {
    /// Plate size along x and y [m] (the reference study's: 0.4 x 0.4).
    pub size_m: [f64; 2],
    /// Half spans a, b of the cells' rectangle [m] (cells at the corners: half the size).
    pub cell_half_span_m: [f64; 2],
    /// Depth h of the cells' measuring points below the top surface [m].
    pub cell_depth_m: f64,
    /// Normal force below which the plate is not pressed [N].
    pub contact_threshold_n: f64,
}

impl Default for Plate {
    /// The reference study's plate: 400 x 400 mm, a cell at each corner, measuring in the
    /// surface plane, 1 N contact threshold.
    fn default() -> Self {
        Plate {
            size_m: [0.4, 0.4],
            cell_half_span_m: [0.2, 0.2],
            cell_depth_m: 0.0,
            contact_threshold_n: 1.0,
        }
    }
}

/// One reading of the four cells.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CornerLoads {
    /// Force on cell k (k = 1..4 at index 0..3) [N], plate frame.
    pub force: [[f64; 3]; 4],
    /// Moment of cell k about its measuring point [N m], if the cells report it.
    pub moment: Option<[[f64; 3]; 4]>,
}

/// What a reading means.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "state", rename_all = "snake_case")]
pub enum PlateReading {
    /// The plate is not pressed (normal force below the threshold).
    NoContact {
        /// Normal force [N].
        normal_n: f64,
    },
    /// A press.
    Press {
        /// Normal force F_z [N].
        normal_n: f64,
        /// Centre of pressure (x_p, y_p) [m], plate frame.
        cop_m: [f64; 2],
        /// Shear (F_x, F_y) [N].
        shear_n: [f64; 2],
    },
}

impl Plate {
    /// Checks that the sizes are positive and finite and the cells lie on the plate.
    pub fn validate(&self) -> Result<()> {
        let ok = |v: f64| v.is_finite() && v > 0.0;
        if !(ok(self.size_m[0]) && ok(self.size_m[1])) {
            return Err(Error::invalid("plate.size_m", "give two positive sizes"));
        }
        if !(ok(self.cell_half_span_m[0]) && ok(self.cell_half_span_m[1])) {
            return Err(Error::invalid(
                "plate.cell_half_span_m",
                "give two positive half spans",
            ));
        }
        if (0..2).any(|a| self.cell_half_span_m[a] > self.size_m[a] / 2.0 + 1e-12) {
            return Err(Error::invalid(
                "plate.cell_half_span_m",
                "the cells must lie under the plate (half span <= half size)",
            ));
        }
        if !(self.cell_depth_m.is_finite() && self.cell_depth_m >= 0.0) {
            return Err(Error::invalid("plate.cell_depth_m", "give a depth >= 0"));
        }
        if !(self.contact_threshold_n.is_finite() && self.contact_threshold_n > 0.0) {
            return Err(Error::invalid(
                "plate.contact_threshold_n",
                "give a positive force",
            ));
        }
        Ok(())
    }

    /// Position of cell k (0-based) [m].
    pub fn cell(&self, k: usize) -> [f64; 3] {
        let s = CORNER_SIGNS[k];
        [
            s[0] * self.cell_half_span_m[0],
            s[1] * self.cell_half_span_m[1],
            self.cell_depth_m,
        ]
    }

    /// Normal force and centre of pressure of a reading (see the module doc); an error for a
    /// non-finite value, a negative normal force or a centre of pressure off the plate.
    pub fn resolve(&self, loads: &CornerLoads) -> Result<PlateReading> {
        for (k, f) in loads.force.iter().enumerate() {
            for (c, v) in f.iter().enumerate() {
                if !v.is_finite() {
                    return Err(Error::invalid(
                        "corners",
                        format!("cell {} f{} = {v} is not a finite number", k + 1, AXES[c]),
                    ));
                }
            }
        }
        if let Some(m) = &loads.moment {
            for (k, mk) in m.iter().enumerate() {
                for (c, v) in mk.iter().enumerate() {
                    if !v.is_finite() {
                        return Err(Error::invalid(
                            "moments",
                            format!("cell {} m{} = {v} is not a finite number", k + 1, AXES[c]),
                        ));
                    }
                }
            }
        }
        let mut f = [0.0; 3];
        let mut m = [0.0; 3];
        for k in 0..4 {
            let (r, fk) = (self.cell(k), loads.force[k]);
            let rxf = [
                r[1] * fk[2] - r[2] * fk[1],
                r[2] * fk[0] - r[0] * fk[2],
                r[0] * fk[1] - r[1] * fk[0],
            ];
            let mk = loads.moment.map(|mm| mm[k]).unwrap_or([0.0; 3]);
            for c in 0..3 {
                f[c] += fk[c];
                m[c] += rxf[c] + mk[c];
            }
        }
        let fz = f[2];
        if fz < -self.contact_threshold_n {
            return Err(Error::invalid(
                "corners",
                format!(
                    "the normal force is {fz:.2} N: negative, a pull rather than a press \
                     (a press reads positive f_z on the cells)"
                ),
            ));
        }
        if fz < self.contact_threshold_n {
            return Ok(PlateReading::NoContact { normal_n: fz });
        }
        let cop = [-m[1] / fz, m[0] / fz];
        // on the edge counts as on the plate (1 um for rounding)
        let (hx, hy) = (self.size_m[0] / 2.0 + 1e-6, self.size_m[1] / 2.0 + 1e-6);
        if cop[0].abs() > hx || cop[1].abs() > hy {
            return Err(Error::invalid(
                "corners",
                format!(
                    "the centre of pressure ({:.1}, {:.1}) mm lies off the plate ({:.0} x {:.0} mm): \
                     a press beside the plate, or a faulty load cell",
                    cop[0] * 1e3,
                    cop[1] * 1e3,
                    self.size_m[0] * 1e3,
                    self.size_m[1] * 1e3
                ),
            ));
        }
        Ok(PlateReading::Press {
            normal_n: fz,
            cop_m: cop,
            shear_n: [f[0], f[1]],
        })
    }

    /// The cell loads of a press at `cop` [m] with force `force` = (F_x, F_y, F_z) [N]: the
    /// shear shared equally, the normal force by the bilinear weights
    /// `f_zk = F_z/4 (1 + s_x X/a)(1 + s_y Y/b)` with `(X, Y) = cop + h (F_x, F_y) / F_z`,
    /// which satisfy the equilibrium of the module doc (the fourth cell makes the plate
    /// statically indeterminate; this is the smooth solution). For synthetic presses: tests,
    /// calibration checks and demonstration logs.
    pub fn loads_for(&self, cop: [f64; 2], force: [f64; 3]) -> CornerLoads {
        let [a, b] = self.cell_half_span_m;
        let h = self.cell_depth_m;
        let (big_x, big_y) = if force[2] != 0.0 {
            (
                cop[0] + h * force[0] / force[2],
                cop[1] + h * force[1] / force[2],
            )
        } else {
            (cop[0], cop[1])
        };
        let mut out = CornerLoads::default();
        for (k, s) in CORNER_SIGNS.iter().enumerate() {
            out.force[k] = [
                force[0] / 4.0,
                force[1] / 4.0,
                force[2] / 4.0 * (1.0 + s[0] * big_x / a) * (1.0 + s[1] * big_y / b),
            ];
        }
        out
    }
}

const AXES: [&str; 3] = ["x", "y", "z"];

#[cfg(test)]
mod tests {
    use super::*;

    fn press(p: &Plate, fz: [f64; 4]) -> Result<PlateReading> {
        let mut l = CornerLoads::default();
        for k in 0..4 {
            l.force[k][2] = fz[k];
        }
        p.resolve(&l)
    }

    fn cop(r: PlateReading) -> ([f64; 2], f64) {
        match r {
            PlateReading::Press {
                cop_m, normal_n, ..
            } => (cop_m, normal_n),
            other => panic!("not a press: {other:?}"),
        }
    }

    /// Hand-computed centres of pressure on the 400 x 400 mm plate (cells at +-200 mm):
    /// x_p = sum x_k f_k / F, y_p = sum y_k f_k / F.
    #[test]
    fn centres_of_pressure_by_hand() {
        let p = Plate::default();
        // equal loads: the centre
        let (c, n) = cop(press(&p, [5.0, 5.0, 5.0, 5.0]).unwrap());
        assert_eq!(n, 20.0);
        assert!(c[0].abs() < 1e-15 && c[1].abs() < 1e-15);
        // 10, 30, 40, 20 N: F = 100 N,
        // x = 0.2 (-10 + 30 + 40 - 20) / 100 = 0.08 m, y = 0.2 (-10 - 30 + 40 + 20) / 100 = 0.04 m
        let (c, n) = cop(press(&p, [10.0, 30.0, 40.0, 20.0]).unwrap());
        assert_eq!(n, 100.0);
        assert!(
            (c[0] - 0.08).abs() < 1e-15 && (c[1] - 0.04).abs() < 1e-15,
            "{c:?}"
        );
        // all on cell 3: its corner (200, 200) mm, on the plate's edge
        let (c, _) = cop(press(&p, [0.0, 0.0, 12.0, 0.0]).unwrap());
        assert!((c[0] - 0.2).abs() < 1e-15 && (c[1] - 0.2).abs() < 1e-15);
    }

    /// Shear acting h above the cells moves the cells' centroid of f_z, not the press: a
    /// synthetic press with shear resolves back to its point; cell moments enter M.
    #[test]
    fn shear_and_moments() {
        let p = Plate {
            cell_depth_m: 0.03,
            ..Default::default()
        };
        let at = [-0.05, 0.12];
        let l = p.loads_for(at, [3.0, -2.0, 40.0]);
        let total: f64 = l.force.iter().map(|f| f[2]).sum();
        assert!((total - 40.0).abs() < 1e-12);
        match p.resolve(&l).unwrap() {
            PlateReading::Press {
                normal_n,
                cop_m,
                shear_n,
            } => {
                assert!((normal_n - 40.0).abs() < 1e-12);
                assert!((cop_m[0] - at[0]).abs() < 1e-12 && (cop_m[1] - at[1]).abs() < 1e-12);
                assert!((shear_n[0] - 3.0).abs() < 1e-12 && (shear_n[1] + 2.0).abs() < 1e-12);
            }
            other => panic!("{other:?}"),
        }
        // a moment of +0.4 N m about y on cell 1 shifts x_p by -0.4 / 40 = -10 mm
        let mut with_m = l.clone();
        let mut m = [[0.0; 3]; 4];
        m[0][1] = 0.4;
        with_m.moment = Some(m);
        let (c, _) = cop(p.resolve(&with_m).unwrap());
        assert!((c[0] - (at[0] - 0.01)).abs() < 1e-12, "{c:?}");
    }

    /// No press, a pull, a press off the plate, a NaN: each gets its answer or a clear error.
    #[test]
    fn bad_readings() {
        let p = Plate::default();
        assert!(matches!(
            press(&p, [0.2, 0.1, 0.3, 0.1]).unwrap(),
            PlateReading::NoContact { .. }
        ));
        let e = press(&p, [-5.0, -5.0, -5.0, -5.0]).unwrap_err().to_string();
        assert!(e.contains("negative"), "{e}");
        // a bolted plate pressed beside its +x edge: cells 2 and 3 carry more than the total,
        // cells 1 and 4 go into tension: x = 0.2 (2 + 12 + 12 + 2) / 20 = 0.28 m, off the plate
        let e = press(&p, [-2.0, 12.0, 12.0, -2.0]).unwrap_err().to_string();
        assert!(e.contains("off the plate") && e.contains("(280.0,"), "{e}");
        let e = press(&p, [1.0, f64::NAN, 1.0, 1.0])
            .unwrap_err()
            .to_string();
        assert!(e.contains("cell 2 fz") && e.contains("not a finite"), "{e}");
        assert!(Plate {
            cell_half_span_m: [0.3, 0.2],
            ..Default::default()
        }
        .validate()
        .is_err());
    }
}
