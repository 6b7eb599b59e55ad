//! What a surrogate was trained on, and whether an input lies outside it.
//!
//! `palpa train` records the training domain in `model.json` (`domain`): the training
//! locations, their convex hull in plan, the largest training force, the range of the training
//! stress (the fixed colour scale of the live view) and the width of the force filter the
//! dataset's forces went through. [`TrainingDomain::assess`] names what is outside it:
//!
//! - the position lies outside the hull of the training locations by more than
//!   [`HULL_TOLERANCE`] (a model interpolates between its locations; beyond them it
//!   extrapolates);
//! - the force exceeds the largest training force;
//! - the respiratory phase (a model trained across phases) lies outside the trained phases'
//!   range (a phase model interpolates between its phases; beyond them it extrapolates);
//! - the GP's predictive deviation is large: more than [`DEVIATION_RATIO`] of its prior
//!   deviation, `sigma(x) > 0.5 sigma_prior`, where `sigma(x)^2 = s_y^2 (sigma_f^2 -
//!   k*^T K^-1 k*)` is the latent predictive variance and `sigma_prior = s_y sigma_f` what the
//!   GP would say with no data (Rasmussen & Williams, "Gaussian Processes for Machine
//!   Learning", 2006, eq. 2.26). The ratio is scale-free: about 0.03-0.08 at the default
//!   model's test locations A, B and C, 0.6-1.0 outside the raster or far above its forces.

use crate::dataset::Dataset;
use crate::view::{convex_hull, distance_to_polygon, point_in_polygon, Ring};
use serde::{Deserialize, Serialize};

/// How far outside the training hull (m) a position may lie before it is flagged: half a
/// voxel of the default campaign, so that the raster's own edge points are inside.
pub const HULL_TOLERANCE: f64 = 0.0015;

/// The predictive deviation, as a fraction of the GP's prior deviation, above which it is
/// flagged as large.
pub const DEVIATION_RATIO: f64 = 0.5;

/// The training domain of a model (SI).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrainingDomain {
    /// Distinct training locations (x, y) [m], in dataset order.
    pub locations: Vec<[f64; 2]>,
    /// Convex hull of the training locations, counter-clockwise [m].
    pub hull: Ring,
    /// Largest training force [N].
    pub force_max_n: f64,
    /// Smallest and largest training stress [Pa].
    pub stress_range_pa: [f64; 2],
    /// Width of the moving average the dataset's forces went through [s], if the dataset
    /// names one (`manifest.solver.force_filter_s`).
    #[serde(default)]
    pub force_filter_s: Option<f64>,
    /// Smallest and largest training respiratory phase (0 exhalation .. 1 inspiration), for a
    /// dataset with a `phase` column; absent otherwise (and in models saved before it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phase_range: Option<[f64; 2]>,
}

/// Why an input lies outside the training domain.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "code", rename_all = "snake_case")]
pub enum Outside {
    /// The position is outside the training locations' hull by `distance_m`.
    Position {
        /// Distance to the hull [m].
        distance_m: f64,
    },
    /// The force is above the largest training force.
    Force {
        /// The force [N].
        force_n: f64,
        /// The largest training force [N].
        max_n: f64,
    },
    /// The respiratory phase is outside the trained phases.
    Phase {
        /// The phase asked for.
        phase: f64,
        /// The smallest and largest trained phase.
        range: [f64; 2],
    },
    /// The GP's predictive deviation is large.
    Deviation {
        /// Predictive deviation [Pa].
        sd_pa: f64,
        /// The GP's prior deviation [Pa].
        prior_pa: f64,
    },
}

impl std::fmt::Display for Outside {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Outside::Position { distance_m } => write!(
                f,
                "position {:.0} mm outside the training locations",
                distance_m * 1e3
            ),
            Outside::Force { force_n, max_n } => write!(
                f,
                "force {force_n:.1} N above the largest trained force ({max_n:.1} N)"
            ),
            Outside::Phase { phase, range } => write!(
                f,
                "respiratory phase {phase:.2} outside the trained phases {:.2} .. {:.2}",
                range[0], range[1]
            ),
            Outside::Deviation { sd_pa, prior_pa } => write!(
                f,
                "large predictive deviation: {:.2} kPa ({:.0} % of the GP's prior {:.2} kPa)",
                sd_pa / 1e3,
                100.0 * sd_pa / prior_pa,
                prior_pa / 1e3
            ),
        }
    }
}

impl TrainingDomain {
    /// The domain of `data`'s training rows (split 0); `None` without training rows.
    pub fn of_training_rows(data: &Dataset) -> Option<TrainingDomain> {
        let rows = data.rows_with_split(crate::Split::Train);
        if rows.is_empty() {
            return None;
        }
        let mut locations: Vec<[f64; 2]> = Vec::new();
        let (mut fmax, mut lo, mut hi) = (0.0f64, f64::INFINITY, f64::NEG_INFINITY);
        let phase_col = data.manifest.x_columns.iter().position(|n| n == "phase");
        let mut phases = [f64::INFINITY, f64::NEG_INFINITY];
        for &i in &rows {
            if let Some(c) = phase_col {
                phases = [phases[0].min(data.x[(i, c)]), phases[1].max(data.x[(i, c)])];
            }
            let p = [data.x[(i, 0)], data.x[(i, 1)]];
            if !locations.contains(&p) {
                locations.push(p);
            }
            fmax = fmax.max(data.x[(i, 2)]);
            for &v in data.y.row(i) {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        Some(TrainingDomain {
            hull: convex_hull(&locations),
            locations,
            force_max_n: fmax,
            stress_range_pa: [lo, hi],
            force_filter_s: data.manifest.solver["force_filter_s"].as_f64(),
            phase_range: phase_col.map(|_| phases),
        })
    }

    /// Whether a respiratory `phase` lies outside the trained phases (never for a domain that
    /// records none).
    pub fn assess_phase(&self, phase: f64) -> Option<Outside> {
        let range = self.phase_range?;
        (!(range[0]..=range[1]).contains(&phase)).then_some(Outside::Phase { phase, range })
    }

    /// Distance [m] of (x, y) outside the training hull; 0 inside. A hull of fewer than three
    /// points (locations on a line) counts its points' nearest distance.
    pub fn distance_outside(&self, x: f64, y: f64) -> f64 {
        let p = [x, y];
        if self.hull.len() >= 3 {
            if point_in_polygon(p, &self.hull) {
                0.0
            } else {
                distance_to_polygon(p, &self.hull)
            }
        } else {
            self.locations
                .iter()
                .map(|q| (q[0] - x).hypot(q[1] - y))
                .fold(f64::INFINITY, f64::min)
        }
    }

    /// What is outside the domain for a press at (x, y) [m] with `force` [N], given the
    /// model's predictive deviation and prior deviation [Pa] when it has them (a GP).
    pub fn assess(
        &self,
        x: f64,
        y: f64,
        force: f64,
        deviation: Option<(f64, f64)>,
    ) -> Vec<Outside> {
        let mut out = Vec::new();
        let d = self.distance_outside(x, y);
        if d > HULL_TOLERANCE {
            out.push(Outside::Position { distance_m: d });
        }
        if force > self.force_max_n {
            out.push(Outside::Force {
                force_n: force,
                max_n: self.force_max_n,
            });
        }
        if let Some((sd, prior)) = deviation {
            if prior > 0.0 && sd > DEVIATION_RATIO * prior {
                out.push(Outside::Deviation {
                    sd_pa: sd,
                    prior_pa: prior,
                });
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::make_synthetic_dataset;

    /// The synthetic dataset's training raster is 5 x 5 points 22.5 mm apart from 5 mm: its
    /// hull is the square [5, 95] mm x [5, 95] mm.
    #[test]
    fn domain_of_the_synthetic_raster() {
        let data = make_synthetic_dataset(4);
        let d = TrainingDomain::of_training_rows(&data).unwrap();
        assert_eq!(d.locations.len(), 25);
        assert_eq!(d.hull.len(), 4, "{:?}", d.hull);
        let fmax = data
            .rows_with_split(crate::Split::Train)
            .iter()
            .map(|&i| data.x[(i, 2)])
            .fold(0.0, f64::max);
        assert_eq!(d.force_max_n, fmax);
        // inside, on the edge, 1 mm out (tolerated), 10 mm out
        assert_eq!(d.distance_outside(0.05, 0.05), 0.0);
        assert!(d.assess(0.095, 0.05, 1.0, None).is_empty());
        assert!(d.assess(0.096, 0.05, 1.0, None).is_empty());
        let far = d.assess(0.105, 0.05, 1.0, None);
        match far.as_slice() {
            [Outside::Position { distance_m }] => assert!((distance_m - 0.010).abs() < 1e-12),
            other => panic!("{other:?}"),
        }
        // a corner: the distance is to the corner point
        assert!((d.distance_outside(0.098, 0.099) - 0.005).abs() < 1e-12);
    }

    #[test]
    fn force_and_deviation_flags() {
        let data = make_synthetic_dataset(4);
        let d = TrainingDomain::of_training_rows(&data).unwrap();
        let f = d.force_max_n;
        let flags = d.assess(0.05, 0.05, f + 1.0, Some((600.0, 1000.0)));
        assert_eq!(flags.len(), 2, "{flags:?}");
        assert!(flags[0]
            .to_string()
            .contains("above the largest trained force"));
        assert!(flags[1].to_string().contains("60 %"), "{}", flags[1]);
        assert!(d.assess(0.05, 0.05, f, Some((400.0, 1000.0))).is_empty());
    }

    #[test]
    fn phase_range_of_a_respiratory_dataset() {
        // the synthetic dataset's time column read as trained phases 0.2 .. 0.6
        let mut data = make_synthetic_dataset(4);
        assert!(TrainingDomain::of_training_rows(&data)
            .unwrap()
            .phase_range
            .is_none());
        data.manifest.x_columns[3] = "phase".into();
        for i in 0..data.x.nrows() {
            data.x[(i, 3)] = 0.2 + 0.1 * (i % 5) as f64;
        }
        let d = TrainingDomain::of_training_rows(&data).unwrap();
        let [lo, hi] = d.phase_range.unwrap();
        assert!(
            (lo - 0.2).abs() < 1e-15 && (hi - 0.6).abs() < 1e-15,
            "{lo} {hi}"
        );
        assert_eq!(d.assess_phase(0.2), None);
        assert_eq!(d.assess_phase(0.45), None);
        let out = d.assess_phase(0.9).unwrap();
        assert_eq!(
            out.to_string(),
            "respiratory phase 0.90 outside the trained phases 0.20 .. 0.60"
        );
        // recorded in model.json and read back
        let js = serde_json::to_string(&d).unwrap();
        assert!(js.contains("\"phase_range\""), "{js}");
        assert_eq!(serde_json::from_str::<TrainingDomain>(&js).unwrap(), d);
    }
}
