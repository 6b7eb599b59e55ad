//! Rigid indenters: one or more rigid parts moving together along a direction, and the two-finger
//! hand preset.
//!
//! An indenter is the union of its parts: `phi(x) = min_k phi_k(x - u(t))`, with the normal of
//! the part that attains the minimum. The hand is one indenter with two capsule parts, so its
//! reported force is the total over both fingers (the quantity the reference study records) and
//! force control acts on that total.

use serde::Deserialize;

use crate::aabb::Aabb;
use crate::motion::{MotionSpec, MotionState};
use crate::shape::{Shape, ShapeSpec};
use crate::vec3::*;
use crate::ContactError;

/// A rigid indenter as plain SI data.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct IndenterSpec {
    /// Name, used for output columns (`<name>_force_x`, ...).
    pub name: String,
    /// Rigid parts (union), world coordinates at `t = 0` (m).
    pub parts: Vec<ShapeSpec>,
    /// Pressing direction (normalised internally).
    pub direction: [f64; 3],
    /// Motion along `direction`.
    pub motion: MotionSpec,
    /// Coulomb friction coefficient for this indenter; `None` takes
    /// [`crate::ContactParams::friction`].
    #[serde(default)]
    pub friction: Option<f64>,
}

/// The two-finger hand of the reference study: two parallel capsule fingers.
///
/// Geometry (all SI): the fingers' lowest points (along `direction`) sit at
/// `point +- spacing/2 * e_s - gap * direction` at `t = 0`, where `e_s` is `spacing_axis` made
/// perpendicular to `direction`. Each finger axis (tip towards knuckle) is `-direction` rotated by
/// `tilt` about `e_s` by the right-hand rule (positive tilt moves the knuckles towards
/// `direction x e_s`; the fingertips stay where they are). Finger length
/// counts from the tip to the far end, both hemispherical.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct HandSpec {
    /// Name of the resulting indenter.
    pub name: String,
    /// Point between the two fingertips, usually on the body surface (m).
    pub point: [f64; 3],
    /// Pressing direction, e.g. the inward surface normal at `point` (normalised internally).
    pub direction: [f64; 3],
    /// Direction from finger 1 to finger 2; default world x (or y when x is parallel to
    /// `direction`), made perpendicular to `direction`.
    #[serde(default)]
    pub spacing_axis: Option<[f64; 3]>,
    /// Finger diameter (m).
    pub diameter: f64,
    /// Centre-to-centre finger spacing (m).
    pub spacing: f64,
    /// Finger length, tip to far end (m).
    pub length: f64,
    /// Tilt of the finger axes from the pressing direction (rad). Default 0.
    #[serde(default)]
    pub tilt: f64,
    /// Initial stand-off of the fingertips from `point` along `-direction` (m). Default 0.
    #[serde(default)]
    pub gap: f64,
    /// Motion along `direction`.
    pub motion: MotionSpec,
    /// Coulomb friction coefficient; `None` takes [`crate::ContactParams::friction`].
    #[serde(default)]
    pub friction: Option<f64>,
}

impl HandSpec {
    /// The indenter this hand stands for: two capsule parts named by `name`.
    pub fn to_indenter_spec(&self) -> Result<IndenterSpec, ContactError> {
        let d = normalize(self.direction)
            .ok_or_else(|| ContactError::Invalid(format!("hand {}: zero direction", self.name)))?;
        let guess = self.spacing_axis.unwrap_or_else(|| {
            if d[0].abs() < 0.9 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 1.0, 0.0]
            }
        });
        let e_s = normalize(sub(guess, scale(d, dot(guess, d)))).ok_or_else(|| {
            ContactError::Invalid(format!(
                "hand {}: spacing axis parallel to the direction",
                self.name
            ))
        })?;
        if !(self.diameter > 0.0 && self.length >= self.diameter && self.spacing >= 0.0) {
            return Err(ContactError::Invalid(format!(
                "hand {}: needs diameter > 0, length >= diameter, spacing >= 0",
                self.name
            )));
        }
        if self.spacing < self.diameter {
            return Err(ContactError::Invalid(format!(
                "hand {}: fingers overlap (spacing < diameter)",
                self.name
            )));
        }
        let r = 0.5 * self.diameter;
        let axis = rotate(scale(d, -1.0), e_s, self.tilt);
        let parts = [-0.5, 0.5]
            .iter()
            .map(|&side| {
                let lowest = axpy(-self.gap, d, axpy(side * self.spacing, e_s, self.point));
                ShapeSpec::Capsule {
                    center: axpy(-r, d, lowest),
                    axis,
                    radius: r,
                    length: self.length - 2.0 * r,
                }
            })
            .collect();
        Ok(IndenterSpec {
            name: self.name.clone(),
            parts,
            direction: d,
            motion: self.motion.clone(),
            friction: self.friction,
        })
    }
}

/// What an indenter reports after each contact evaluation (SI).
#[derive(Clone, Debug, PartialEq)]
pub struct IndenterState {
    /// Indenter name.
    pub name: String,
    /// Current offset from the initial placement `u = s * direction` (m).
    pub offset: [f64; 3],
    /// Travel `s` along the direction since `t = 0` (m).
    pub travel: f64,
    /// Indentation depth: travel beyond the travel at first contact (m); 0 before contact.
    pub depth: f64,
    /// Travel speed `ds/dt` (m/s).
    pub speed: f64,
    /// Force the body exerts on the indenter (N).
    pub force: [f64; 3],
    /// Reaction along the pressing direction, `-force . direction` (N); positive when pressing.
    pub reaction: f64,
    /// Current area of the penetrating sample points (m^2).
    pub area: f64,
    /// Largest penetration over the sample points (m).
    pub max_penetration: f64,
    /// Stored penalty energy of this indenter's contact (J).
    pub penalty_energy: f64,
}

/// Run-time indenter: parts, direction, motion.
#[derive(Clone, Debug)]
pub struct Indenter {
    pub(crate) name: String,
    pub(crate) parts: Vec<Shape>,
    /// Bounding box of each part at t = 0 (`None`: unbounded).
    pub(crate) part_aabb: Vec<Option<Aabb>>,
    pub(crate) direction: [f64; 3],
    pub(crate) motion: MotionSpec,
    pub(crate) friction: Option<f64>,
    pub(crate) state: MotionState,
}

impl Indenter {
    /// Build from a spec (reads STL files).
    pub fn from_spec(spec: &IndenterSpec) -> Result<Indenter, ContactError> {
        let err = |m: String| ContactError::Invalid(format!("indenter {}: {m}", spec.name));
        if spec.parts.is_empty() {
            return Err(err("no parts".into()));
        }
        let direction = normalize(spec.direction).ok_or_else(|| err("zero direction".into()))?;
        spec.motion.validate().map_err(err)?;
        if let Some(mu) = spec.friction {
            if !(mu >= 0.0 && mu.is_finite()) {
                return Err(err("friction must be >= 0".into()));
            }
        }
        let parts = spec
            .parts
            .iter()
            .map(Shape::from_spec)
            .collect::<Result<Vec<_>, _>>()?;
        let part_aabb = parts.iter().map(|p| p.aabb()).collect();
        Ok(Indenter {
            name: spec.name.clone(),
            parts,
            part_aabb,
            direction,
            motion: spec.motion.clone(),
            friction: spec.friction,
            state: MotionState::default(),
        })
    }

    /// Indenter name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Rigid parts.
    pub fn parts(&self) -> &[Shape] {
        &self.parts
    }

    /// Unit pressing direction.
    pub fn direction(&self) -> [f64; 3] {
        self.direction
    }

    /// Current offset `u` (m).
    #[inline]
    pub fn offset(&self) -> [f64; 3] {
        scale(self.direction, self.state.s)
    }

    /// Signed distance (m) and outward normal of the union of the parts at offset `u`.
    #[inline]
    pub fn signed_distance(&self, x: [f64; 3], u: [f64; 3]) -> (f64, [f64; 3]) {
        let y = sub(x, u);
        let mut best = self.parts[0].signed_distance(y);
        for p in &self.parts[1..] {
            let r = p.signed_distance(y);
            if r.0 < best.0 {
                best = r;
            }
        }
        best
    }

    /// Like [`Indenter::signed_distance`], but parts whose bounding box lies farther than
    /// `cutoff` (m) from `x` are skipped; returns `+inf` when all are. Exact whenever the true
    /// distance is at most `cutoff` (a part's distance is at least the distance to its box).
    #[inline]
    pub fn signed_distance_within(&self, x: [f64; 3], u: [f64; 3], cutoff: f64) -> (f64, [f64; 3]) {
        let y = sub(x, u);
        let c2 = cutoff.max(0.0).powi(2);
        let mut best = (f64::INFINITY, [0.0; 3]);
        for (p, bb) in self.parts.iter().zip(&self.part_aabb) {
            if let Some(bb) = bb {
                if bb.distance2(y) > c2 {
                    continue;
                }
            }
            let r = p.signed_distance(y);
            if r.0 < best.0 {
                best = r;
            }
        }
        best
    }

    /// Whether any part, shifted by `u`, may come within `margin` of the box `b` (broad phase).
    #[inline]
    pub fn may_touch(&self, u: [f64; 3], b: &Aabb, margin: f64) -> bool {
        self.parts
            .iter()
            .zip(&self.part_aabb)
            .any(|(p, bb)| match bb {
                Some(bb) => bb.translated(u).inflated(margin).overlaps(b),
                None => p.may_touch(u, b, margin),
            })
    }

    /// Smallest feature size over the parts (m).
    pub fn feature_size(&self) -> f64 {
        self.parts
            .iter()
            .map(|p| p.feature_size())
            .fold(f64::INFINITY, f64::min)
    }
}
