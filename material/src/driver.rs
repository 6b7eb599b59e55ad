//! Material-point driver: one law, one homogeneous deformation path, a CSV table out
//! (`palpa material FILE.toml [--out FILE.csv]`). Test a law here before putting it in a model.
//!
//! ```toml
//! material = "paper:liver"        # a library name, or an inline card:
//! # [material]
//! # law = "ogden"  ...
//! mode = "uniaxial_stress"        # uniaxial_stress | uniaxial_strain | simple_shear | equibiaxial
//! steps_per_segment = 100         # default 100; a segment may override with `steps`
//! max_dt = "1 ms"                 # optional: more steps where a segment would exceed it
//! output_every = 1                # write every k-th step (segment ends are always written)
//! max_steps = 1e6                 # default; a path of more steps is refused before it runs
//!
//! [[segment]]                     # ramp to a stretch (shear for simple_shear) ...
//! ramp_to = 1.3
//! rate = "0.1 1/s"                # ... at a rate, or over `duration = "3 s"` (0 s: a jump)
//! [[segment]]
//! hold = "10 s"                   # hold the current stretch
//! [[segment]]
//! cycles = 3                      # each cycle: ramp to between[1], then to between[0]
//! between = [0.9, 1.1]
//! rate = "0.1 1/s"
//! ```
//!
//! Paths (x is the loading direction; all deformation gradients are diagonal except shear):
//! - `uniaxial_stress`: `F = diag(l, l_y, l_z)`, with `l_y`, `l_z` found by a Newton iteration
//!   (finite-difference Jacobian, from the start-of-step history each iteration) so that the
//!   lateral stresses vanish.
//! - `uniaxial_strain`: `F = diag(l, 1, 1)`.
//! - `simple_shear`: `F = I + gamma e_x (x) e_y`; the control column is the shear `gamma`.
//! - `equibiaxial`: `F = diag(l, l, l_z)` with `sigma_zz = 0` by Newton.
//!
//! Columns (SI: s, Pa, m/s, J/m^3): `time`, `stretch` (or `shear`), `nominal_stress` (`P_xx`
//! of `P = F S`, or `P_xy` in shear), the Cauchy stress `sigma_xx, sigma_yy, sigma_zz,
//! sigma_xy, sigma_yz, sigma_zx`, the lateral stretches `stretch_y, stretch_z`, `wave_speed`,
//! the cumulative `dissipated` energy, `failed` (0/1), then the law's history values by name
//! (e.g. `eps_p` for plasticity). The first row is the undeformed state at t = 0.

use crate::law::{cauchy_from_pk2, Law, LawError, Response};
use crate::quantity::{Number, Rate, Time};
use crate::tensor::Mat3;
use crate::{with_law, MaterialSpec};
use serde::Deserialize;
use std::path::Path;

/// Deformation path of the driver.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// Axial stretch, lateral faces stress-free.
    UniaxialStress,
    /// Axial stretch, lateral stretches fixed at 1.
    UniaxialStrain,
    /// `F = I + gamma e_x (x) e_y`.
    SimpleShear,
    /// Equal stretch in x and y, z stress-free.
    Equibiaxial,
}

/// One segment of the path.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SegmentSpec {
    /// Ramp the control (stretch, or shear) to this value.
    pub ramp_to: Option<Number>,
    /// Rate of the control (1/s), for ramps and cycles.
    pub rate: Option<Rate>,
    /// Duration of a ramp (instead of `rate`; 0 for a jump).
    pub duration: Option<Time>,
    /// Hold the control for this long.
    pub hold: Option<Time>,
    /// Number of cycles between `between[1]` and `between[0]`.
    pub cycles: Option<usize>,
    /// Lower and upper control values of the cycles.
    pub between: Option<[Number; 2]>,
    /// Sub-steps of this segment (of each half-cycle for cycles).
    pub steps: Option<usize>,
}

/// A driver file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriverSpec {
    /// The material card, or a library name such as `"paper:liver"`.
    pub material: MaterialSpec,
    /// The deformation path.
    pub mode: Mode,
    /// Sub-steps per segment (default 100).
    pub steps_per_segment: Option<usize>,
    /// Largest step (s).
    pub max_dt: Option<Time>,
    /// Write every k-th step (default 1).
    pub output_every: Option<usize>,
    /// The most steps the whole path may take (default [`DEFAULT_MAX_STEPS`]); a longer path
    /// is refused before it runs.
    pub max_steps: Option<Number>,
    /// Path segments, in order.
    pub segment: Vec<SegmentSpec>,
}

/// The driver's table.
#[derive(Clone, Debug)]
pub struct DriverOutput {
    /// Column names.
    pub header: Vec<String>,
    /// Rows of values (SI).
    pub rows: Vec<Vec<f64>>,
}

impl DriverOutput {
    /// The table as CSV text.
    pub fn to_csv(&self) -> String {
        let mut s = self.header.join(",");
        s.push('\n');
        for r in &self.rows {
            let line: Vec<String> = r.iter().map(|v| format!("{v:.10e}")).collect();
            s.push_str(&line.join(","));
            s.push('\n');
        }
        s
    }

    /// One column by name.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let k = self.header.iter().position(|h| h == name)?;
        Some(self.rows.iter().map(|r| r[k]).collect())
    }
}

/// The most steps a driver path may take unless `max_steps` raises the limit: a million rows
/// of the table, seconds of work.
pub const DEFAULT_MAX_STEPS: f64 = 1e6;

/// A straight piece of the control history.
struct Leg {
    duration: f64,
    target: f64,
    steps: usize,
}

fn legs(spec: &DriverSpec, start: f64) -> Result<Vec<Leg>, String> {
    let default_steps = spec.steps_per_segment.unwrap_or(100);
    let max_dt = spec.max_dt.map(|t| t.0);
    if default_steps == 0 || matches!(max_dt, Some(t) if !(t > 0.0)) {
        return Err("`steps_per_segment` and `max_dt` must be positive".into());
    }
    if spec.segment.is_empty() {
        return Err("the path has no `[[segment]]`".into());
    }
    let max_steps = spec.max_steps.map_or(DEFAULT_MAX_STEPS, |n| n.0);
    if !(max_steps >= 1.0) {
        return Err(format!("`max_steps` must be at least 1, got {max_steps}"));
    }
    let mut out = Vec::new();
    let mut c = start;
    let steps_for = |dur: f64, s: Option<usize>| -> Result<usize, String> {
        let mut n = s.unwrap_or(default_steps);
        if n == 0 {
            return Err("`steps` must be positive".into());
        }
        if let Some(m) = max_dt {
            n = n.max((dur / m).ceil() as usize);
        }
        Ok(n)
    };
    let mut total = 0.0;
    // every leg goes through here: its steps are counted and the path is refused as soon as it
    // exceeds `max_steps`
    let mut push = |duration: f64, target: f64, steps: Option<usize>, k: usize| {
        let steps = steps_for(duration, steps)?;
        total += steps as f64;
        if total > max_steps {
            return Err(format!(
                "segment {}: the path takes more than {max_steps:.0} steps; use fewer `steps` or `steps_per_segment`, a larger `max_dt` or fewer `cycles`, or raise `max_steps` if you mean it",
                k + 1
            ));
        }
        out.push(Leg {
            duration,
            target,
            steps,
        });
        Ok(())
    };
    let ramp_duration = |k: usize,
                         from: f64,
                         to: f64,
                         rate: Option<Rate>,
                         dur: Option<Time>|
     -> Result<f64, String> {
        match (rate, dur) {
            (Some(r), None) if r.0 > 0.0 => Ok((to - from).abs() / r.0),
            (None, Some(d)) if d.0 >= 0.0 => Ok(d.0),
            _ => Err(format!(
                "segment {}: give a positive `rate` or a `duration` (not both)",
                k + 1
            )),
        }
    };
    for (k, s) in spec.segment.iter().enumerate() {
        let kind = (s.ramp_to.is_some(), s.hold.is_some(), s.cycles.is_some());
        match kind {
            (true, false, false) => {
                if s.between.is_some() {
                    return Err(format!("segment {}: `between` belongs to cycles", k + 1));
                }
                let to = s.ramp_to.unwrap().0;
                let d = ramp_duration(k, c, to, s.rate, s.duration)?;
                push(d, to, s.steps, k)?;
                c = to;
            }
            (false, true, false) => {
                if s.rate.is_some() || s.duration.is_some() || s.between.is_some() {
                    return Err(format!(
                        "segment {}: a hold takes only `hold` (and `steps`)",
                        k + 1
                    ));
                }
                let d = s.hold.unwrap().0;
                if !(d >= 0.0) {
                    return Err(format!("segment {}: `hold` must be >= 0", k + 1));
                }
                push(d, c, s.steps, k)?;
            }
            (false, false, true) => {
                let [lo, hi] = s.between.ok_or_else(|| {
                    format!("segment {}: cycles need `between = [low, high]`", k + 1)
                })?;
                if s.duration.is_some() {
                    return Err(format!(
                        "segment {}: cycles take a `rate`, not a `duration`",
                        k + 1
                    ));
                }
                for _ in 0..s.cycles.unwrap() {
                    for to in [hi.0, lo.0] {
                        let d = ramp_duration(k, c, to, s.rate, None)?;
                        push(d, to, s.steps, k)?;
                        c = to;
                    }
                }
            }
            _ => {
                return Err(format!(
                    "segment {}: give exactly one of `ramp_to`, `hold` or `cycles`",
                    k + 1
                ))
            }
        }
    }
    Ok(out)
}

/// Deformation gradient of the path for control `c` and unknown lateral stretches `y`.
fn deformation(mode: Mode, c: f64, y: &[f64; 2]) -> Mat3 {
    match mode {
        Mode::UniaxialStress => Mat3::new(c, 0.0, 0.0, 0.0, y[0], 0.0, 0.0, 0.0, y[1]),
        Mode::UniaxialStrain => Mat3::new(c, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
        Mode::SimpleShear => Mat3::new(1.0, c, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
        Mode::Equibiaxial => Mat3::new(c, 0.0, 0.0, 0.0, c, 0.0, 0.0, 0.0, y[1]),
    }
}

/// Unknowns of the lateral Newton iteration: indices into `y`.
fn unknowns(mode: Mode) -> &'static [usize] {
    match mode {
        Mode::UniaxialStress => &[0, 1],
        Mode::Equibiaxial => &[1],
        _ => &[],
    }
}

fn lateral_residual(s: &Mat3, idx: usize) -> f64 {
    if idx == 0 {
        s[(1, 1)]
    } else {
        s[(2, 2)]
    }
}

fn law_err(t: f64, e: LawError) -> String {
    format!("at t = {t:.6e} s: {e}")
}

/// Solve one step: lateral stretches `y` (updated in place) and the response; `hist` holds the
/// start-of-step history on entry and the end-of-step history on return.
fn solve_step<L: Law>(
    law: &L,
    mode: Mode,
    c: f64,
    dt: f64,
    t: f64,
    y: &mut [f64; 2],
    hist: &mut [f64],
    scratch: &mut [f64],
    modulus: f64,
) -> Result<(Mat3, Response), String> {
    let unk = unknowns(mode);
    let eval = |y: &[f64; 2], out: &mut [f64]| -> Result<Response, String> {
        out.copy_from_slice(hist);
        law.evaluate(&deformation(mode, c, y), dt, out)
            .map_err(|e| law_err(t, e))
    };
    if !unk.is_empty() {
        let mut converged = false;
        for _ in 0..100 {
            let r0 = eval(y, scratch)?;
            let axial = r0.pk2[(0, 0)].abs();
            let tol = 1e-10 * axial + 1e-14 * modulus;
            let res: Vec<f64> = unk.iter().map(|&i| lateral_residual(&r0.pk2, i)).collect();
            if res.iter().all(|r| r.abs() <= tol) {
                converged = true;
                break;
            }
            // Finite-difference Jacobian d(residual)/d(y).
            let n = unk.len();
            let mut jac = [[0.0; 2]; 2];
            for (b, &j) in unk.iter().enumerate() {
                let d = 1e-7 * y[j];
                let mut yp = *y;
                yp[j] += d;
                let rp = eval(&yp, scratch)?;
                for (a, &i) in unk.iter().enumerate() {
                    jac[a][b] = (lateral_residual(&rp.pk2, i) - res[a]) / d;
                }
            }
            let dy: [f64; 2] = if n == 1 {
                [-res[0] / jac[0][0], 0.0]
            } else {
                let det = jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0];
                [
                    -(jac[1][1] * res[0] - jac[0][1] * res[1]) / det,
                    -(-jac[1][0] * res[0] + jac[0][0] * res[1]) / det,
                ]
            };
            for (b, &j) in unk.iter().enumerate() {
                let step = dy[b];
                if !step.is_finite() {
                    return Err(format!("at t = {t:.6e} s: the lateral Newton iteration broke down (singular tangent)"));
                }
                // Limit each update to 10 % of the stretch.
                y[j] += step.clamp(-0.1 * y[j], 0.1 * y[j]);
            }
        }
        if !converged {
            return Err(format!(
                "at t = {t:.6e} s: the lateral stresses did not converge to zero"
            ));
        }
    }
    let f = deformation(mode, c, y);
    let r = law.evaluate(&f, dt, hist).map_err(|e| law_err(t, e))?;
    Ok((f, r))
}

fn drive<L: Law>(law: &L, spec: &DriverSpec) -> Result<DriverOutput, String> {
    let mode = spec.mode;
    let start = if mode == Mode::SimpleShear { 0.0 } else { 1.0 };
    let legs = legs(spec, start)?;
    let every = spec.output_every.unwrap_or(1).max(1);
    let control = if mode == Mode::SimpleShear {
        "shear"
    } else {
        "stretch"
    };
    let mut header: Vec<String> = [
        "time",
        control,
        "nominal_stress",
        "sigma_xx",
        "sigma_yy",
        "sigma_zz",
        "sigma_xy",
        "sigma_yz",
        "sigma_zx",
        "stretch_y",
        "stretch_z",
        "wave_speed",
        "dissipated",
        "failed",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    header.extend(law.history_names());
    let nh = law.history_len();
    let mut hist = vec![0.0; nh];
    law.init_history(&mut hist);
    let mut scratch = vec![0.0; nh];
    let modulus = law.density() * law.initial_wave_speed().powi(2);
    let mut y = [1.0, 1.0];
    let mut t = 0.0;
    let mut c = start;
    let mut dissipated = 0.0;
    let mut rows = Vec::new();
    let mut row = |t: f64, c: f64, f: &Mat3, r: &Response, dissipated: f64, hist: &[f64]| {
        let p = f * r.pk2;
        let s = cauchy_from_pk2(f, &r.pk2);
        let nominal = if mode == Mode::SimpleShear {
            p[(0, 1)]
        } else {
            p[(0, 0)]
        };
        let mut v = vec![
            t,
            c,
            nominal,
            s[(0, 0)],
            s[(1, 1)],
            s[(2, 2)],
            s[(0, 1)],
            s[(1, 2)],
            s[(2, 0)],
            f[(1, 1)],
            f[(2, 2)],
            r.wave_speed,
            dissipated,
            if r.failed { 1.0 } else { 0.0 },
        ];
        v.extend_from_slice(hist);
        rows.push(v);
    };
    let (f0, r0) = solve_step(
        law,
        mode,
        c,
        0.0,
        0.0,
        &mut y,
        &mut hist,
        &mut scratch,
        modulus,
    )?;
    row(0.0, c, &f0, &r0, 0.0, &hist);
    for leg in &legs {
        let c0 = c;
        let dt = leg.duration / leg.steps as f64;
        for k in 1..=leg.steps {
            t += dt;
            c = c0 + (leg.target - c0) * (k as f64 / leg.steps as f64);
            let (f, r) = solve_step(
                law,
                mode,
                c,
                dt,
                t,
                &mut y,
                &mut hist,
                &mut scratch,
                modulus,
            )?;
            dissipated += r.dissipation;
            if k % every == 0 || k == leg.steps {
                row(t, c, &f, &r, dissipated, &hist);
            }
        }
    }
    Ok(DriverOutput { header, rows })
}

/// Run a parsed driver file; a relative `curve_file` in the material is read from `base_dir`.
pub fn run_driver(spec: &DriverSpec, base_dir: Option<&Path>) -> Result<DriverOutput, String> {
    let mat = spec.material.build_in("material", base_dir)?;
    with_law!(&mat, l => drive(l, spec))
}

/// Parse driver TOML text and run it.
pub fn run_driver_str(text: &str, base_dir: Option<&Path>) -> Result<DriverOutput, String> {
    let spec: DriverSpec = toml::from_str(text).map_err(|e| e.to_string())?;
    run_driver(&spec, base_dir)
}

/// Read a driver file, run it and return the CSV text (what `palpa material FILE.toml` prints).
pub fn run_driver_file(path: &Path) -> Result<String, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read `{}`: {e}", path.display()))?;
    let spec: DriverSpec =
        toml::from_str(&text).map_err(|e| crate::toml_error::describe(path, &text, &e))?;
    let out = run_driver(&spec, path.parent()).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(out.to_csv())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_keys_are_errors() {
        let e = run_driver_str(
            "material = \"paper:ribs\"\nmode = \"uniaxial_stress\"\nspeed = 3\n[[segment]]\nramp_to = 1.01\nduration = 1\n",
            None,
        )
        .unwrap_err();
        assert!(e.contains("speed"), "{e}");
        let e = run_driver_str(
            "material = \"paper:ribs\"\nmode = \"uniaxial_stress\"\n[[segment]]\nramp_to = 1.01\nduraton = 1\n",
            None,
        )
        .unwrap_err();
        assert!(e.contains("duraton"), "{e}");
        let e = run_driver_str(
            "material = \"paper:ribs\"\nmode = \"twist\"\n[[segment]]\nhold = 1\n",
            None,
        )
        .unwrap_err();
        assert!(e.contains("twist"), "{e}");
    }

    #[test]
    fn segments_expand_to_legs() {
        let spec: DriverSpec = toml::from_str(
            "material = \"paper:ribs\"\nmode = \"uniaxial_strain\"\n[[segment]]\nramp_to = 1.2\nrate = \"0.1 1/s\"\n\
             [[segment]]\nhold = \"5 s\"\n[[segment]]\ncycles = 2\nbetween = [0.9, 1.1]\nrate = \"0.2 1/s\"\n",
        )
        .unwrap();
        let l = legs(&spec, 1.0).unwrap();
        let d: Vec<f64> = l.iter().map(|l| l.duration).collect();
        let want = [2.0, 5.0, 0.5, 1.0, 1.0, 1.0];
        assert_eq!(d.len(), want.len());
        for (a, b) in d.iter().zip(want) {
            assert!((a - b).abs() < 1e-12, "{d:?}");
        }
    }

    /// Found while writing the material fuzz harness (docs/fuzzing.md), confirmed through it:
    /// nothing bounded the path's steps, so a huge `steps_per_segment`, `cycles` count or a
    /// tiny `max_dt` ran (and grew the table) for hours.
    #[test]
    fn a_driver_path_of_too_many_steps_is_an_error_not_a_hang() {
        let head = "material = \"paper:ribs\"\nmode = \"uniaxial_strain\"\n";
        for (keys, segment) in [
            (
                "steps_per_segment = 4000000000\n",
                "ramp_to = 1.01\nduration = 1\n",
            ),
            (
                "",
                "cycles = 1000000000000000\nbetween = [0.9, 1.1]\nrate = 1\n",
            ),
            ("max_dt = \"1 ns\"\n", "hold = \"1000 s\"\n"),
        ] {
            let t = std::time::Instant::now();
            let e =
                run_driver_str(&format!("{head}{keys}[[segment]]\n{segment}"), None).unwrap_err();
            assert!(t.elapsed().as_secs_f64() < 1.0, "{keys}{segment}");
            assert!(
                e.contains("segment 1: the path takes more than 1000000 steps"),
                "{keys}{segment}: {e}"
            );
        }
        // `max_steps` raises the limit, and must be at least 1
        let spec: DriverSpec = toml::from_str(&format!(
            "{head}max_steps = 3e6\nsteps_per_segment = 2000000\n[[segment]]\nhold = 1\n"
        ))
        .unwrap();
        assert_eq!(legs(&spec, 1.0).unwrap()[0].steps, 2_000_000);
        let e = run_driver_str(
            &format!("{head}max_steps = 0\n[[segment]]\nhold = 1\n"),
            None,
        )
        .unwrap_err();
        assert!(e.contains("`max_steps` must be at least 1"), "{e}");
    }
}
