//! The plan-view geometry that travels with a model: `view.json` beside `model.json` (for a
//! model saved as `NAME.safetensors`, `NAME.view.json`), written by `palpa train` (and, for a
//! campaign, `DIR/view.json` by `palpa campaign`, which `palpa train` carries over). With it a
//! model can be drawn without the solver: `palpa predict --png` and `palpa serve`.
//!
//! All lengths are in m, in the phantom's plan frame (x towards the patient's left, y cranial),
//! the frame of the model's inputs. Polygons are closed (the last point is not a repeat of the
//! first).
//!
//! ```json
//! {
//!   "format": "palpa-view", "version": 1,
//!   "source": "phantom parameters of data/default-campaign-3mm (reduced, 3 mm voxels)",
//!   "torso": [[x, y], ...],            // the torso's plan outline
//!   "model_box": [[x, y], ...],        // the reduced model's extent, or null
//!   "liver": [[[x, y], ...], ...],     // liver outline(s)
//!   "ribs": [[[x, y], ...], ...],      // anterior ribs, costal cartilage, sternum
//!   "roi_ids": [...],                  // the model's ROI element ids, in its order
//!   "roi_cells": [[[x, y], ...], ...], // each ROI element's plan footprint, same order
//!   "fingers": {"spacing_m": 0.02, "diameter_m": 0.015, "axis": [1, 0]},
//!   "respiratory_phase": 0.0,
//!   "max_liver_shift_m": 0.02          // the liver's caudal shift at phase 1
//! }
//! ```
//!
//! The fingers of the two-finger hand lie at `(x, y) +- spacing/2 * axis`. The hand's spacing
//! axis is world x made perpendicular to the pressing direction (the inward skin normal); its
//! plan projection is shortened by the cosine of the skin's slope across x, which over the
//! raster is at most a few degrees: the plan view draws the fingers at the full spacing.

use crate::dataset::write_atomic;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Value of [`ViewGeometry::format`].
pub const VIEW_FORMAT: &str = "palpa-view";
/// Current value of [`ViewGeometry::version`].
pub const VIEW_VERSION: u32 = 1;

/// A polygon or polyline in the plan frame (m).
pub type Ring = Vec<[f64; 2]>;

/// The two-finger hand in plan view.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fingers {
    /// Centre-to-centre spacing (m).
    pub spacing_m: f64,
    /// Finger diameter (m).
    pub diameter_m: f64,
    /// Unit vector from the first finger to the second, in plan.
    pub axis: [f64; 2],
}

impl Default for Fingers {
    /// The reference study's hand, as `palpa palpate` and the campaigns use it.
    fn default() -> Self {
        Fingers {
            spacing_m: 0.020,
            diameter_m: 0.015,
            axis: [1.0, 0.0],
        }
    }
}

impl Fingers {
    /// The two finger centres for a hand at (x, y) (m).
    pub fn centres(&self, x: f64, y: f64) -> [[f64; 2]; 2] {
        let h = self.spacing_m / 2.0;
        [
            [x - h * self.axis[0], y - h * self.axis[1]],
            [x + h * self.axis[0], y + h * self.axis[1]],
        ]
    }
}

/// The plan-view geometry of a model (see the module doc).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ViewGeometry {
    /// Always `"palpa-view"`.
    pub format: String,
    /// Format version, currently 1.
    pub version: u32,
    /// Where the geometry came from, in words.
    pub source: String,
    /// The torso's plan outline.
    pub torso: Ring,
    /// The reduced model's plan extent, if the phantom was reduced.
    #[serde(default)]
    pub model_box: Option<Ring>,
    /// Liver outline(s).
    pub liver: Vec<Ring>,
    /// Outlines of the anterior ribs, costal cartilage and sternum.
    pub ribs: Vec<Ring>,
    /// ROI element ids, in the model's output order.
    pub roi_ids: Vec<i64>,
    /// Plan footprint of each ROI element, same order.
    pub roi_cells: Vec<Ring>,
    /// The hand.
    pub fingers: Fingers,
    /// Respiratory phase of the phantom the outlines were drawn at (0 exhalation, 1 inspiration).
    #[serde(default)]
    pub respiratory_phase: f64,
    /// The liver's caudal shift at phase 1 (m): a model with a phase input is drawn with the
    /// liver and its ROI moved by `(phase - respiratory_phase) * max_liver_shift_m`.
    #[serde(default = "default_liver_shift")]
    pub max_liver_shift_m: f64,
}

/// The phantom's default [`ViewGeometry::max_liver_shift_m`], for a `view.json` written before
/// it was recorded.
fn default_liver_shift() -> f64 {
    0.02
}

/// The `view.json` path of the model at `model` (see the module doc).
pub fn view_path(model: &Path) -> PathBuf {
    match model.extension().and_then(|e| e.to_str()) {
        Some("safetensors") | Some("json") => model.with_extension("view.json"),
        _ => model.join("view.json"),
    }
}

impl ViewGeometry {
    /// Checks the shapes: one cell per ROI id, finite coordinates, polygons of 3 points or more,
    /// a positive finger size and a unit axis.
    pub fn validate(&self) -> Result<()> {
        if self.format != VIEW_FORMAT || self.version > VIEW_VERSION {
            return Err(Error::invalid(
                "view",
                format!(
                    "format {:?} version {}, expected {VIEW_FORMAT:?} version <= {VIEW_VERSION}",
                    self.format, self.version
                ),
            ));
        }
        if self.roi_cells.len() != self.roi_ids.len() {
            return Err(Error::invalid(
                "roi_cells",
                format!(
                    "{} cells for {} ROI ids",
                    self.roi_cells.len(),
                    self.roi_ids.len()
                ),
            ));
        }
        let rings = std::iter::once(("torso", &self.torso))
            .chain(self.model_box.iter().map(|b| ("model_box", b)))
            .chain(self.liver.iter().map(|r| ("liver", r)))
            .chain(self.ribs.iter().map(|r| ("ribs", r)))
            .chain(self.roi_cells.iter().map(|r| ("roi_cells", r)));
        for (name, r) in rings {
            if r.len() < 3 {
                return Err(Error::invalid(
                    name,
                    format!("a polygon of {} points", r.len()),
                ));
            }
            if r.iter().flatten().any(|v| !v.is_finite()) {
                return Err(Error::invalid(name, "a non-finite coordinate"));
            }
        }
        let f = &self.fingers;
        let norm = f.axis[0].hypot(f.axis[1]);
        if !(f.spacing_m > 0.0 && f.diameter_m > 0.0 && (norm - 1.0).abs() < 1e-6) {
            return Err(Error::invalid(
                "fingers",
                "spacing and diameter must be positive and the axis a unit vector",
            ));
        }
        Ok(())
    }

    /// Checks that the geometry belongs to a model with these ROI ids.
    pub fn check_roi(&self, roi_ids: &[i64]) -> Result<()> {
        if self.roi_ids != roi_ids {
            return Err(Error::invalid(
                "roi_ids",
                format!(
                    "the view's {} ROI elements are not the model's {} (a view.json of another \
                     campaign?)",
                    self.roi_ids.len(),
                    roi_ids.len()
                ),
            ));
        }
        Ok(())
    }

    /// Reads and validates `path`.
    pub fn read(path: &Path) -> Result<ViewGeometry> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        let v: ViewGeometry =
            serde_json::from_str(&text).map_err(|e| Error::format(path, e.to_string()))?;
        v.validate()
            .map_err(|e| Error::format(path, e.to_string()))?;
        Ok(v)
    }

    /// Writes `path` atomically (a temporary file, then a rename).
    pub fn write(&self, path: &Path) -> Result<()> {
        self.validate()?;
        let text = serde_json::to_string(self).map_err(|e| Error::format(path, e.to_string()))?;
        write_atomic(path, |mut f| {
            f.write_all(text.as_bytes()).map_err(|e| Error::io(path, e))
        })
    }

    /// Bounding box `([x_min, y_min], [x_max, y_max])` of the liver, the ROI cells and `extra`
    /// points, widened by `margin` (m): the picture's extent.
    pub fn extent(&self, extra: &[[f64; 2]], margin: f64) -> ([f64; 2], [f64; 2]) {
        let pts = self
            .liver
            .iter()
            .chain(self.roi_cells.iter())
            .flatten()
            .chain(extra.iter());
        bounds(pts, margin)
    }
}

/// Bounding box of points, widened by `margin`; a unit box around the origin when empty.
pub fn bounds<'a>(
    pts: impl IntoIterator<Item = &'a [f64; 2]>,
    margin: f64,
) -> ([f64; 2], [f64; 2]) {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in pts {
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    if !(lo[0] <= hi[0] && lo[1] <= hi[1]) {
        return ([-0.5, -0.5], [0.5, 0.5]);
    }
    (
        [lo[0] - margin, lo[1] - margin],
        [hi[0] + margin, hi[1] + margin],
    )
}

/// Whether (x, y) lies inside the polygon (even-odd rule).
pub fn point_in_polygon(p: [f64; 2], ring: &[[f64; 2]]) -> bool {
    let mut inside = false;
    let n = ring.len();
    for k in 0..n {
        let (a, b) = (ring[k], ring[(k + n - 1) % n]);
        if (a[1] > p[1]) != (b[1] > p[1])
            && p[0] < a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1])
        {
            inside = !inside;
        }
    }
    inside
}

/// Convex hull of points, counter-clockwise, without repeating the first point (Andrew's
/// monotone chain, A. M. Andrew, Inf. Process. Lett. 9 (1979) 216). Fewer than three distinct
/// points come back sorted.
pub fn convex_hull(points: &[[f64; 2]]) -> Ring {
    let mut p = points.to_vec();
    p.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Ring = Vec::with_capacity(2 * p.len());
    let lower_then_upper = p.iter().chain(p.iter().rev().skip(1));
    let mut start = 0;
    for (k, &q) in lower_then_upper.enumerate() {
        if k == p.len() {
            // the upper chain starts from the last point of the lower one
            start = hull.len() - 1;
        }
        while hull.len() >= start + 2 && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
        {
            hull.pop();
        }
        hull.push(q);
    }
    hull.pop(); // the first point again
    hull
}

/// Distance (m) from p to the polygon's boundary.
pub fn distance_to_polygon(p: [f64; 2], ring: &[[f64; 2]]) -> f64 {
    let n = ring.len();
    (0..n)
        .map(|k| {
            let (a, b) = (ring[k], ring[(k + 1) % n]);
            let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
            let l2 = ex * ex + ey * ey;
            let t = if l2 > 0.0 {
                (((p[0] - a[0]) * ex + (p[1] - a[1]) * ey) / l2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (p[0] - a[0] - t * ex).hypot(p[1] - a[1] - t * ey)
        })
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(c: [f64; 2], h: f64) -> Ring {
        vec![
            [c[0] - h, c[1] - h],
            [c[0] + h, c[1] - h],
            [c[0] + h, c[1] + h],
            [c[0] - h, c[1] + h],
        ]
    }

    fn sample() -> ViewGeometry {
        ViewGeometry {
            format: VIEW_FORMAT.into(),
            version: VIEW_VERSION,
            source: "test".into(),
            torso: square([0.0, 0.15], 0.15),
            model_box: None,
            liver: vec![square([-0.05, 0.2], 0.05)],
            ribs: vec![],
            roi_ids: vec![3, 7],
            roi_cells: vec![square([-0.05, 0.2], 0.0015), square([-0.04, 0.2], 0.0015)],
            fingers: Fingers::default(),
            respiratory_phase: 0.0,
            max_liver_shift_m: 0.02,
        }
    }

    #[test]
    fn round_trip_and_checks() {
        let dir = tempfile::tempdir().unwrap();
        let path = view_path(dir.path());
        assert_eq!(path, dir.path().join("view.json"));
        assert_eq!(
            view_path(Path::new("m/a.safetensors")),
            Path::new("m/a.view.json")
        );
        let v = sample();
        v.write(&path).unwrap();
        assert_eq!(ViewGeometry::read(&path).unwrap(), v);
        assert!(v.check_roi(&[3, 7]).is_ok());
        assert!(v.check_roi(&[3, 8]).is_err());
        let mut bad = v.clone();
        bad.roi_cells.pop();
        assert!(bad.write(&path).is_err());
        // an unknown field is an error naming it
        let text = std::fs::read_to_string(&path)
            .unwrap()
            .replacen('{', "{\"colour\": 1,", 1);
        std::fs::write(&path, text).unwrap();
        let e = ViewGeometry::read(&path).unwrap_err().to_string();
        assert!(e.contains("colour"), "{e}");
    }

    /// Fingers at +-10 mm along x; the extent covers the liver and the extra point.
    #[test]
    fn fingers_and_extent() {
        let v = sample();
        let [a, b] = v.fingers.centres(-0.07, 0.18);
        assert!((a[0] + 0.08).abs() < 1e-12 && (b[0] + 0.06).abs() < 1e-12);
        assert_eq!(a[1], 0.18);
        let (lo, hi) = v.extent(&[[0.1, 0.1]], 0.01);
        assert!((lo[0] + 0.11).abs() < 1e-12 && (lo[1] - 0.09).abs() < 1e-12);
        assert!((hi[0] - 0.11).abs() < 1e-12 && (hi[1] - 0.26).abs() < 1e-12);
    }

    /// Signed area (shoelace), positive counter-clockwise.
    fn area(r: &[[f64; 2]]) -> f64 {
        (0..r.len())
            .map(|k| {
                let (a, b) = (r[k], r[(k + 1) % r.len()]);
                a[0] * b[1] - a[1] * b[0]
            })
            .sum::<f64>()
            / 2.0
    }

    /// The hull of a unit square's corners, edge and interior points is the square,
    /// counter-clockwise; the distance to it is measured to the nearest edge.
    #[test]
    fn hull_of_a_square() {
        let pts = [
            [0.0, 0.0],
            [1.0, 0.0],
            [0.5, 0.5],
            [1.0, 1.0],
            [0.0, 1.0],
            [0.2, 0.7],
            [1.0, 0.5],
            [0.0, 0.0],
        ];
        let h = convex_hull(&pts);
        assert_eq!(h.len(), 4, "{h:?}");
        assert!((area(&h) - 1.0).abs() < 1e-12, "ccw, area 1: {h:?}");
        assert!((distance_to_polygon([0.5, 0.4], &h) - 0.4).abs() < 1e-12);
        assert!((distance_to_polygon([2.0, 2.0], &h) - 2f64.sqrt()).abs() < 1e-12);
        assert_eq!(convex_hull(&[[1.0, 0.0], [0.0, 0.0]]).len(), 2);
    }

    #[test]
    fn polygon_test() {
        let sq = square([0.0, 0.0], 1.0);
        assert!(point_in_polygon([0.5, -0.5], &sq));
        assert!(!point_in_polygon([1.5, 0.0], &sq));
        let l = vec![
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
        ];
        assert!(point_in_polygon([0.5, 1.5], &l));
        assert!(!point_in_polygon([1.5, 1.5], &l));
    }
}
