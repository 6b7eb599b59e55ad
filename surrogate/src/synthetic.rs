//! A synthetic dataset with a known smooth answer, for tests, benchmarks and demos.
//!
//! The paper's protocol in miniature: a 5 x 5 grid of finger locations over a 100 mm x 100 mm
//! window (training) plus 3 held-out interior locations A, B, C (test), each at 6 force levels
//! (the paper's 6 time stamps). R ROI elements sit on an arc through the window; element r at
//! distance `d` from the finger gets
//!
//! ```text
//! y_r = c F^1.2 ( exp(-d^2 / (2 w1^2)) - 0.35 exp(-d^2 / (2 w2^2)) ) (1 + 0.15 sin(20 x_r))
//! ```
//!
//! with `c = 60 Pa/N^1.2`, `w1 = 35 mm`, `w2 = 70 mm` (wider than the 22.5 mm grid spacing, so the grid resolves the field): tension under the finger, compression
//! around it, a few kPa at 37 N, as in the paper's range (-4.7 to +3.8 kPa).
//!
//! The stress tensor `S` of each element has principal stresses `y_r`, `y_r - 20 F^1.2` and
//! `y_r - 45 F^1.2` (Pa), the first two in the x-y plane turned by
//! `phi = 10 (p_x - x_r) + 5 (p_y - y_r)` radians about z, so its largest eigenvalue is `y_r`
//! exactly and its components turn as the finger moves.

use crate::dataset::{Dataset, Manifest};
use ndarray::{Array1, Array2, Array3};

/// Force levels [N] of every location (the paper's platform saw about 6, 27 and 37 N).
pub const FORCES: [f64; 6] = [0.0, 6.0, 14.0, 22.0, 29.0, 37.0];

/// Held-out locations A, B, C [m], inside the grid's hull and off its nodes.
pub const TEST_LOCATIONS: [(f64, f64); 3] = [(0.037, 0.062), (0.068, 0.031), (0.055, 0.08)];

/// The known stress [Pa] of an element at `(cx, cy)` [m] for a finger at `(px, py)` [m]
/// pressing with `force` [N].
pub fn compute_stress(cx: f64, cy: f64, px: f64, py: f64, force: f64) -> f64 {
    let d2 = (cx - px).powi(2) + (cy - py).powi(2);
    let (w1, w2) = (0.035f64, 0.07f64);
    60.0 * force.max(0.0).powf(1.2)
        * ((-d2 / (2.0 * w1 * w1)).exp() - 0.35 * (-d2 / (2.0 * w2 * w2)).exp())
        * (1.0 + 0.15 * (20.0 * cx).sin())
}

/// The stress tensor `[xx, yy, zz, xy, yz, zx]` [Pa] of an element at `(cx, cy)` [m] for a
/// finger at `(px, py)` [m] pressing with `force` [N] (module doc); its largest eigenvalue is
/// [`compute_stress`].
pub fn compute_stress_tensor(cx: f64, cy: f64, px: f64, py: f64, force: f64) -> [f64; 6] {
    let y = compute_stress(cx, cy, px, py, force);
    let f = force.max(0.0).powf(1.2);
    let (a, b) = (20.0 * f, 45.0 * f);
    let (s, c) = (10.0 * (px - cx) + 5.0 * (py - cy)).sin_cos();
    [
        y * c * c + (y - a) * s * s,
        y * s * s + (y - a) * c * c,
        y - b,
        a * c * s,
        0.0,
        0.0,
    ]
}

/// The synthetic dataset with `r` ROI elements: 25 grid locations (split 0) then A, B, C
/// (split 1), 6 force levels each; 168 samples. Columns of X: x, y, force, time.
pub fn make_synthetic_dataset(r: usize) -> Dataset {
    let mut locs: Vec<(f64, f64)> = Vec::new();
    for i in 0..5 {
        for j in 0..5 {
            locs.push((0.005 + 0.0225 * j as f64, 0.005 + 0.0225 * i as f64));
        }
    }
    locs.extend_from_slice(&TEST_LOCATIONS);
    let centroids = Array2::from_shape_fn((r, 3), |(k, c)| {
        let t = k as f64 / (r.max(2) - 1) as f64;
        let ang = std::f64::consts::PI * (0.15 + 0.7 * t);
        match c {
            0 => 0.05 + 0.045 * ang.cos(),
            1 => 0.01 + 0.08 * ang.sin(),
            _ => -0.02 - 0.005 * t,
        }
    });
    let n = locs.len() * FORCES.len();
    let mut x = Array2::zeros((n, 4));
    let mut y = Array2::zeros((n, r));
    let mut stress = Array3::zeros((n, r, 6));
    let mut location = Array1::zeros(n);
    let mut split = Array1::zeros(n);
    for (li, &(px, py)) in locs.iter().enumerate() {
        for (k, &f) in FORCES.iter().enumerate() {
            let i = li * FORCES.len() + k;
            x[(i, 0)] = px;
            x[(i, 1)] = py;
            x[(i, 2)] = f;
            x[(i, 3)] = 0.005 * k as f64;
            for e in 0..r {
                let (cx, cy) = (centroids[(e, 0)], centroids[(e, 1)]);
                y[(i, e)] = compute_stress(cx, cy, px, py, f);
                for (k, v) in compute_stress_tensor(cx, cy, px, py, f)
                    .into_iter()
                    .enumerate()
                {
                    stress[(i, e, k)] = v;
                }
            }
            location[i] = li as i64;
            split[i] = u8::from(li >= 25);
        }
    }
    let mut manifest = Manifest {
        x_columns: vec!["x".into(), "y".into(), "force".into(), "time".into()],
        ..Default::default()
    };
    manifest.location_labels = (0..25)
        .map(|i| format!("grid-{i:02}"))
        .chain(["A", "B", "C"].iter().map(|s| s.to_string()))
        .collect();
    manifest.solver = serde_json::json!({ "name": "synthetic", "function": "surrogate::synthetic::compute_stress" });
    Dataset {
        x,
        y,
        stress: Some(stress),
        roi_ids: (0..r as i64).map(|i| 1000 + i).collect(),
        roi_centroids: centroids,
        location,
        split,
        manifest,
    }
}
