//! Rigid indenter shapes: exact signed distance and outward normal.
//!
//! Every shape answers `phi(x)`, the signed distance from a point `x` to its boundary (m;
//! negative inside the solid), and `n(x) = grad phi`, the outward unit normal of the closest
//! boundary point. Penalty contact needs nothing else: a sample point of the deformable surface
//! penetrates by `g = -phi(x) > 0` and is pushed along `n(x)`.
//!
//! All the analytic distances are exact (so `phi` is 1-Lipschitz, which the contact stage uses
//! to cull whole faces from one evaluation at the face centre):
//! - sphere: `phi = |x - c| - r`;
//! - capsule (segment `a..a + L e` swept by radius `r`): `phi = |x - q| - r`, `q` the closest
//!   point of the segment;
//! - flat-ended cylinder: with axial coordinate `h` and radial distance `rho`,
//!   `d_r = rho - r`, `d_h = max(-h, h - L)`; outside `phi = |(max(d_r,0), max(d_h,0))|`,
//!   inside `phi = max(d_r, d_h)` (Quilez' exact box/cylinder distance);
//! - oriented box: the same construction per axis;
//! - plane (half-space): `phi = (x - p) . n`;
//! - triangle mesh: see [`crate::trimesh`].
//!
//! Shapes are given in world coordinates at `t = 0`; an indenter only translates, so the
//! contact stage queries `phi(x - u(t))` with the indenter's offset `u(t)`.

use serde::Deserialize;
use std::path::PathBuf;

use crate::aabb::Aabb;
use crate::trimesh::TriMesh;
use crate::vec3::*;
use crate::ContactError;

/// Geometry of one rigid part, as plain data, world coordinates at `t = 0`. Lengths are of
/// type `L`: `f64` in m (the default, what [`Shape::from_spec`] takes), or a type that carries a
/// unit, such as a scene file's lengths (`"7.5 mm"`); [`ShapeSpec::map`] turns one into the
/// other, so the file form and the SI form are one type.
///
/// Deserialises from a table with a `shape` tag, e.g.
/// `{ shape = "capsule", center = [0, 0, 0.0575], axis = [0, 0, 1], radius = 0.0075, length = 0.05 }`.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(
    tag = "shape",
    rename_all = "snake_case",
    deny_unknown_fields,
    bound(deserialize = "L: Deserialize<'de> + From<f64>")
)]
pub enum ShapeSpec<L = f64> {
    /// Sphere of `radius` (m) about `center` (m).
    Sphere {
        /// Centre (m).
        center: [L; 3],
        /// Radius (m).
        radius: L,
    },
    /// Capsule (a finger): the segment from `center` to `center + length * axis` swept by a ball of
    /// `radius`. `center` is the centre of the hemispherical fingertip; `axis` points from the tip
    /// towards the hand (normalised internally).
    Capsule {
        /// Centre of the hemispherical tip (m).
        center: [L; 3],
        /// Direction from the tip towards the other end (unit, normalised internally).
        axis: [f64; 3],
        /// Radius (m).
        radius: L,
        /// Length of the straight part between the two hemisphere centres (m).
        length: L,
    },
    /// Flat-ended circular cylinder (a flat punch): end face centred at `center`, extending
    /// `length` along `axis`.
    Cylinder {
        /// Centre of the pressing end face (m).
        center: [L; 3],
        /// Axis from the pressing face into the cylinder (unit, normalised internally).
        axis: [f64; 3],
        /// Radius (m).
        radius: L,
        /// Length (m).
        length: L,
    },
    /// Box with half extents along its axes; `axes` defaults to the world axes.
    Box {
        /// Centre (m).
        center: [L; 3],
        /// Half extents along the box axes (m).
        half_extents: [L; 3],
        /// Box axes (orthonormalised internally; default the world axes).
        #[serde(default)]
        axes: Option<[[f64; 3]; 3]>,
    },
    /// Rigid half-space: the solid lies on the side opposite to `normal`.
    Plane {
        /// A point of the plane (m).
        point: [L; 3],
        /// Outward normal (unit, normalised internally).
        normal: [f64; 3],
    },
    /// Closed triangle mesh read from an STL file (ASCII or binary); vertices are mapped by
    /// `x_world = scale * x_file + translate`.
    Stl {
        /// STL file path.
        path: PathBuf,
        /// Length of one file unit in metres (1e-3 for a file in mm). Default 1.
        /// (`unit` in a scene file: `"1 mm"`.)
        #[serde(default = "one", alias = "unit")]
        scale: L,
        /// Translation after scaling (m). Default zero.
        #[serde(default = "zero3")]
        translate: [L; 3],
    },
    /// Closed triangle mesh given in memory, e.g. the surface of a meshed rigid part of an
    /// LS-DYNA deck: vertices (m) and triangles, counter-clockwise seen from outside.
    Triangles {
        /// Vertices (m).
        vertices: Vec<[L; 3]>,
        /// Vertex indices of each triangle.
        triangles: Vec<[u32; 3]>,
    },
}

fn one<L: From<f64>>() -> L {
    L::from(1.0)
}

fn zero3<L: From<f64>>() -> [L; 3] {
    [0.0, 0.0, 0.0].map(L::from)
}

impl<L: Copy> ShapeSpec<L> {
    /// The same shape with every length mapped by `f` (e.g. from a unit-carrying type to m).
    pub fn map<M>(&self, f: impl Fn(L) -> M) -> ShapeSpec<M> {
        let v = |x: &[L; 3]| x.map(&f);
        match self {
            ShapeSpec::Sphere { center, radius } => ShapeSpec::Sphere {
                center: v(center),
                radius: f(*radius),
            },
            ShapeSpec::Capsule {
                center,
                axis,
                radius,
                length,
            } => ShapeSpec::Capsule {
                center: v(center),
                axis: *axis,
                radius: f(*radius),
                length: f(*length),
            },
            ShapeSpec::Cylinder {
                center,
                axis,
                radius,
                length,
            } => ShapeSpec::Cylinder {
                center: v(center),
                axis: *axis,
                radius: f(*radius),
                length: f(*length),
            },
            ShapeSpec::Box {
                center,
                half_extents,
                axes,
            } => ShapeSpec::Box {
                center: v(center),
                half_extents: v(half_extents),
                axes: *axes,
            },
            ShapeSpec::Plane { point, normal } => ShapeSpec::Plane {
                point: v(point),
                normal: *normal,
            },
            ShapeSpec::Stl {
                path,
                scale,
                translate,
            } => ShapeSpec::Stl {
                path: path.clone(),
                scale: f(*scale),
                translate: v(translate),
            },
            ShapeSpec::Triangles {
                vertices,
                triangles,
            } => ShapeSpec::Triangles {
                vertices: vertices.iter().map(v).collect(),
                triangles: triangles.clone(),
            },
        }
    }
}

/// A rigid part ready for queries (normalised axes, built acceleration structures).
#[derive(Clone, Debug)]
pub enum Shape {
    /// Sphere.
    Sphere {
        /// Centre (m).
        center: [f64; 3],
        /// Radius (m).
        radius: f64,
    },
    /// Capsule: segment `a .. a + length * axis` swept by `radius`.
    Capsule {
        /// Centre of the tip hemisphere (m).
        a: [f64; 3],
        /// Unit axis.
        axis: [f64; 3],
        /// Straight length (m).
        length: f64,
        /// Radius (m).
        radius: f64,
    },
    /// Flat-ended cylinder from the end face at `base` along `axis`.
    Cylinder {
        /// Centre of the pressing end face (m).
        base: [f64; 3],
        /// Unit axis.
        axis: [f64; 3],
        /// Length (m).
        length: f64,
        /// Radius (m).
        radius: f64,
    },
    /// Oriented box.
    Box {
        /// Centre (m).
        center: [f64; 3],
        /// Orthonormal axes (rows).
        axes: [[f64; 3]; 3],
        /// Half extents (m).
        half: [f64; 3],
    },
    /// Half-space.
    Plane {
        /// Point on the plane (m).
        point: [f64; 3],
        /// Unit outward normal.
        normal: [f64; 3],
    },
    /// Closed triangle mesh.
    Mesh(std::sync::Arc<TriMesh>),
}

fn unit(v: [f64; 3], what: &str) -> Result<[f64; 3], ContactError> {
    normalize(v).ok_or_else(|| ContactError::Invalid(format!("{what}: zero or non-finite vector")))
}

fn positive(x: f64, what: &str) -> Result<f64, ContactError> {
    if x > 0.0 && x.is_finite() {
        Ok(x)
    } else {
        Err(ContactError::Invalid(format!(
            "{what} must be positive and finite, got {x}"
        )))
    }
}

impl Shape {
    /// Build a shape from its spec (reads the STL file for [`ShapeSpec::Stl`]).
    pub fn from_spec(spec: &ShapeSpec) -> Result<Shape, ContactError> {
        Ok(match spec {
            ShapeSpec::Sphere { center, radius } => Shape::Sphere {
                center: *center,
                radius: positive(*radius, "sphere radius")?,
            },
            ShapeSpec::Capsule {
                center,
                axis,
                radius,
                length,
            } => Shape::Capsule {
                a: *center,
                axis: unit(*axis, "capsule axis")?,
                length: length.max(0.0),
                radius: positive(*radius, "capsule radius")?,
            },
            ShapeSpec::Cylinder {
                center,
                axis,
                radius,
                length,
            } => Shape::Cylinder {
                base: *center,
                axis: unit(*axis, "cylinder axis")?,
                length: positive(*length, "cylinder length")?,
                radius: positive(*radius, "cylinder radius")?,
            },
            ShapeSpec::Box {
                center,
                half_extents,
                axes,
            } => {
                let a = axes.unwrap_or([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
                // Gram-Schmidt.
                let e0 = unit(a[0], "box axis 0")?;
                let e1 = unit(sub(a[1], scale(e0, dot(a[1], e0))), "box axis 1")?;
                let e2 = cross(e0, e1);
                if dot(e2, a[2]) < 0.0 {
                    return Err(ContactError::Invalid("box axes are left-handed".into()));
                }
                Shape::Box {
                    center: *center,
                    axes: [e0, e1, e2],
                    half: [
                        positive(half_extents[0], "box half extent")?,
                        positive(half_extents[1], "box half extent")?,
                        positive(half_extents[2], "box half extent")?,
                    ],
                }
            }
            ShapeSpec::Plane { point, normal } => Shape::Plane {
                point: *point,
                normal: unit(*normal, "plane normal")?,
            },
            ShapeSpec::Stl {
                path,
                scale,
                translate,
            } => {
                let mesh = TriMesh::from_stl_file(path, *scale, *translate)?;
                Shape::Mesh(std::sync::Arc::new(mesh))
            }
            ShapeSpec::Triangles {
                vertices,
                triangles,
            } => Shape::Mesh(std::sync::Arc::new(TriMesh::new(
                vertices.clone(),
                triangles.clone(),
            )?)),
        })
    }

    /// Signed distance `phi` (m, negative inside) and outward unit normal at point `x` (m).
    #[inline]
    pub fn signed_distance(&self, x: [f64; 3]) -> (f64, [f64; 3]) {
        match self {
            Shape::Sphere { center, radius } => {
                let d = sub(x, *center);
                let r = norm(d);
                let n = if r > 0.0 {
                    scale(d, 1.0 / r)
                } else {
                    [0.0, 0.0, 1.0]
                };
                (r - radius, n)
            }
            Shape::Capsule {
                a,
                axis,
                length,
                radius,
            } => {
                let d = sub(x, *a);
                let h = dot(d, *axis).clamp(0.0, *length);
                let r = sub(d, scale(*axis, h));
                let rn = norm(r);
                let n = if rn > 0.0 {
                    scale(r, 1.0 / rn)
                } else {
                    any_perpendicular(*axis)
                };
                (rn - radius, n)
            }
            Shape::Cylinder {
                base,
                axis,
                length,
                radius,
            } => {
                let d = sub(x, *base);
                let h = dot(d, *axis);
                let rv = sub(d, scale(*axis, h));
                let rho = norm(rv);
                let e_r = if rho > 0.0 {
                    scale(rv, 1.0 / rho)
                } else {
                    any_perpendicular(*axis)
                };
                let (d_h, e_h) = if h < 0.5 * length {
                    (-h, scale(*axis, -1.0))
                } else {
                    (h - length, *axis)
                };
                let d_r = rho - radius;
                if d_r > 0.0 || d_h > 0.0 {
                    let pr = d_r.max(0.0);
                    let ph = d_h.max(0.0);
                    let phi = (pr * pr + ph * ph).sqrt();
                    let n = add(scale(e_r, pr / phi), scale(e_h, ph / phi));
                    (phi, n)
                } else if d_r > d_h {
                    (d_r, e_r)
                } else {
                    (d_h, e_h)
                }
            }
            Shape::Box { center, axes, half } => {
                let d = sub(x, *center);
                let q = [dot(d, axes[0]), dot(d, axes[1]), dot(d, axes[2])];
                let e = [
                    q[0].abs() - half[0],
                    q[1].abs() - half[1],
                    q[2].abs() - half[2],
                ];
                if e[0] > 0.0 || e[1] > 0.0 || e[2] > 0.0 {
                    let mut g = [0.0; 3];
                    for k in 0..3 {
                        g[k] = e[k].max(0.0) * q[k].signum();
                    }
                    let phi = norm(g);
                    let mut n = [0.0; 3];
                    for k in 0..3 {
                        n = axpy(g[k] / phi, axes[k], n);
                    }
                    (phi, n)
                } else {
                    let mut k = 0;
                    if e[1] > e[k] {
                        k = 1;
                    }
                    if e[2] > e[k] {
                        k = 2;
                    }
                    let s = if q[k] >= 0.0 { 1.0 } else { -1.0 };
                    (e[k], scale(axes[k], s))
                }
            }
            Shape::Plane { point, normal } => (dot(sub(x, *point), *normal), *normal),
            Shape::Mesh(m) => m.signed_distance(x),
        }
    }

    /// Bounding box of the solid at `t = 0` (m); `None` when unbounded (plane).
    pub fn aabb(&self) -> Option<Aabb> {
        let mut b = Aabb::EMPTY;
        match self {
            Shape::Sphere { center, radius } => {
                b.include(*center);
                Some(b.inflated(*radius))
            }
            Shape::Capsule {
                a,
                axis,
                length,
                radius,
            } => {
                b.include(*a);
                b.include(axpy(*length, *axis, *a));
                Some(b.inflated(*radius))
            }
            Shape::Cylinder {
                base,
                axis,
                length,
                radius,
            } => {
                b.include(*base);
                b.include(axpy(*length, *axis, *base));
                Some(b.inflated(*radius))
            }
            Shape::Box { center, axes, half } => {
                for k in 0..3 {
                    let ext = half[0] * axes[0][k].abs()
                        + half[1] * axes[1][k].abs()
                        + half[2] * axes[2][k].abs();
                    b.min[k] = center[k] - ext;
                    b.max[k] = center[k] + ext;
                }
                Some(b)
            }
            Shape::Plane { .. } => None,
            Shape::Mesh(m) => Some(m.aabb()),
        }
    }

    /// Whether the solid, shifted by `u`, may come within `margin` of the box `b`
    /// (conservative; used by the broad phase).
    pub fn may_touch(&self, u: [f64; 3], b: &Aabb, margin: f64) -> bool {
        match self {
            Shape::Plane { point, normal } => {
                // Lowest signed distance over the box corners.
                let p = add(*point, u);
                let mut lo = f64::INFINITY;
                for c in 0..8 {
                    let x = [
                        if c & 1 == 0 { b.min[0] } else { b.max[0] },
                        if c & 2 == 0 { b.min[1] } else { b.max[1] },
                        if c & 4 == 0 { b.min[2] } else { b.max[2] },
                    ];
                    lo = lo.min(dot(sub(x, p), *normal));
                }
                lo <= margin
            }
            _ => match self.aabb() {
                Some(a) => a.translated(u).inflated(margin).overlaps(b),
                None => true,
            },
        }
    }

    /// Smallest radius of curvature of the shape's contacting boundary (m); the contact stage
    /// chooses the sample spacing on each face from it. Infinite for a plane; for a box the
    /// smallest half extent; for a mesh its mean edge length.
    pub fn feature_size(&self) -> f64 {
        match self {
            Shape::Sphere { radius, .. } => *radius,
            Shape::Capsule { radius, .. } => *radius,
            Shape::Cylinder { radius, .. } => *radius,
            Shape::Box { half, .. } => half[0].min(half[1]).min(half[2]),
            Shape::Plane { .. } => f64::INFINITY,
            Shape::Mesh(m) => m.mean_edge_length(),
        }
    }
}
