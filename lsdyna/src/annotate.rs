//! `$palpa:` comments: what a deck written by `palpa export --lsdyna` says about the palpa scene
//! it came from, where LS-DYNA's keywords can only approximate it.
//!
//! LS-DYNA and the OpenRadioss starter skip every line that starts with `$`. palpa reads the
//! lines that start with `$palpa:` as TOML (`key = value`, SI units), attached to the keyword
//! they stand in, and uses them only after checking that they describe the LS-DYNA data next to
//! them; a comment that does not (a deck edited after export, a comment copied to another part)
//! is ignored with a warning, and the LS-DYNA data is used. `palpa run --ignore-palpa-comments`
//! reads a deck as LS-DYNA does.
//!
//! | keyword | comment | LS-DYNA sees | palpa checks |
//! |---|---|---|---|
//! | `*PART` (rigid) | `indenter = [{ shape = "capsule", ... }]` | the meshed part | every node lies on or inside the shapes, and the mesh spans their bounding box |
//! | `*PART` | `element = { formulation, hourglass, hourglass_coefficient, hourglass_modulus }` | ELFORM, IHQ, QM | the same element and hourglass form; QM = coefficient x modulus ratio |
//! | `*MAT_...` | `card = { law = ..., ... }` (a scene's material card) | the LS-DYNA law | the same density, small-strain shear modulus and wave speed (1e-3) |
//! | `*DEFINE_CURVE` | `curve = { kind = "smooth_step", ... }` or `motion = { curve = ..., ... }` | the table | every point lies on the curve |
//! | `*CONTACT_...` | `contact = { penalty = "soft", ... }` (the `[contact]` table) | SOFT, SOFSCL, SFS, VDC, FS | the same soft scale |
//! | `*DATABASE_BINARY_D3PLOT` | `fields = [...]` | every field | - |
//! | (before the first keyword) | `run = {...}`, `relaxation = {...}` | nothing | - |

use crate::lex::Loc;
use serde::Deserialize;

/// The `$palpa:` lines of one keyword, parsed; `None` when there are none. A line that is not
/// TOML is reported (as a warning) and skipped.
pub fn table(lines: &[(Loc, String)], warnings: &mut Vec<String>) -> Option<toml::Table> {
    if lines.is_empty() {
        return None;
    }
    let mut t = toml::Table::new();
    for (at, l) in lines {
        match l.parse::<toml::Table>() {
            Ok(x) => t.extend(x),
            Err(e) => warnings.push(format!(
                "{at}: `$palpa:` comment ignored: not TOML ({})",
                e.to_string().lines().next().unwrap_or("")
            )),
        }
    }
    (!t.is_empty()).then_some(t)
}

/// Take `key` from a comment table as `T`; a value that does not parse is a warning.
pub fn take<T: for<'de> Deserialize<'de>>(
    t: &mut Option<toml::Table>,
    key: &str,
    at: &Loc,
    warnings: &mut Vec<String>,
) -> Option<T> {
    let v = t.as_mut()?.remove(key)?;
    match T::deserialize(v) {
        Ok(x) => Some(x),
        Err(e) => {
            warnings.push(format!(
                "{at}: `$palpa: {key}` ignored: {}",
                e.to_string().trim()
            ));
            None
        }
    }
}

/// A boundary curve of a scene ([`contact::Curve`]) in a comment.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum BcCurve {
    /// `from` at `t0` to `to` at `t1`, quintic smooth step.
    SmoothStep {
        /// Start (s).
        t0: f64,
        /// End (s).
        t1: f64,
        /// Value before `t0`.
        from: f64,
        /// Value after `t1`.
        to: f64,
    },
}

impl BcCurve {
    /// The solver's curve.
    pub fn to_curve(&self) -> contact::Curve {
        match *self {
            BcCurve::SmoothStep { t0, t1, from, to } => {
                contact::Curve::SmoothStepBetween { t0, t1, from, to }
            }
        }
    }
}

/// The element of a part in a comment (the scene's `[[part]]` keys).
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ElementNote {
    /// `one_point`, `full_fbar` or `full`.
    pub formulation: String,
    /// `viscous` or `stiffness`.
    pub hourglass: Option<String>,
    /// Q.
    pub hourglass_coefficient: Option<f64>,
    /// `p_wave` or `shear`.
    pub hourglass_modulus: Option<String>,
}

/// Settings without an LS-DYNA keyword, before the first keyword.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RunNote {
    /// Hourglass guard ratio.
    pub max_hourglass_ratio: Option<f64>,
    /// From when (s).
    pub hourglass_check_after: Option<f64>,
    /// Smallest step (s).
    pub dt_min: Option<f64>,
    /// The element kernels' number type (`"f32"`; absent: `f64`). LS-DYNA chooses its
    /// precision by executable, so palpa keeps it in the note.
    pub precision: Option<String>,
    /// Subcycling's largest macro ratio (absent: off). palpa's partition and clock are its
    /// own, so the deck keeps the setting in the note rather than in an LS-DYNA keyword.
    pub subcycling: Option<u32>,
    /// How the stable step is estimated (`"global"`; absent: element by element). LS-DYNA has
    /// no global estimator, so the deck keeps the setting in the note.
    pub step_estimate: Option<String>,
}

/// Dynamic relaxation (the scene's `[relaxation]`).
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RelaxationNote {
    /// Relative out-of-balance force tolerance.
    pub tolerance: f64,
}

/// Whether a table of points (SI) lies on `f` within `tol` of its largest magnitude.
pub fn points_on(points: &[(f64, f64)], f: impl Fn(f64) -> f64) -> bool {
    let scale = points
        .iter()
        .fold(0.0f64, |m, p| m.max(p.1.abs()))
        .max(1e-300);
    points
        .iter()
        .all(|&(t, v)| (f(t) - v).abs() <= 1e-9 * scale)
}
