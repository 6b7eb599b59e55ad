//! Meshes of the analytic indenter shapes: their closed, outward-oriented quadrilateral
//! surface ([`surface`], which palpa's frames draw the fingers with), and that surface
//! extruded halfway towards the shape's core into one layer of hexahedra ([`mesh`], a hollow
//! solid, which the LS-DYNA export writes as a rigid part): the outer faces lie on the exact
//! surface, every hexahedron has a positive Jacobian, and the mesh stays small.
//!
//! - sphere: the cube-sphere (each face of a cube, `n x n` quadrilaterals, projected onto the
//!   sphere with the map `x sqrt(1 - y^2/2 - z^2/2 + y^2 z^2/3)` and its permutations, which
//!   spreads the nodes evenly); `4n` segments around a great circle;
//! - capsule: the cube-sphere cut at its equator, the two halves moved to the two ends, joined
//!   by `m` rings of the cylinder;
//! - cylinder (flat punch): the square-to-disc map `(x sqrt(1 - y^2/2), y sqrt(1 - x^2/2))` on
//!   both end faces, joined by rings;
//! - box: one hexahedron.
//!
//! Nodes lie exactly on the surface (up to rounding); the chord error of `4n` segments around
//! a circle of radius `r` is `r (1 - cos(pi / (4n)))` (0.12 % of `r` for `4n = 64`).

use crate::ShapeSpec;
use std::collections::HashMap;

/// A hexahedral mesh (nodes in m, VTK_HEXAHEDRON order).
#[derive(Clone, Debug, Default)]
pub struct HexMesh {
    /// Nodes (m).
    pub nodes: Vec<[f64; 3]>,
    /// Elements.
    pub elements: Vec<[u32; 8]>,
}

type V = [f64; 3];

fn add(a: V, b: V) -> V {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn mul(s: f64, a: V) -> V {
    [s * a[0], s * a[1], s * a[2]]
}
fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: V, b: V) -> V {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn unit(a: V) -> V {
    let n = dot(a, a).sqrt();
    mul(1.0 / n, a)
}

/// An orthonormal frame (u, v, w) with w along `axis`.
fn frame(axis: V) -> (V, V, V) {
    let w = unit(axis);
    let t = if w[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let u = unit(sub(t, mul(dot(t, w), w)));
    (u, cross(w, u), w)
}

/// Cube point (each coordinate in [-1, 1], one of them +-1) onto the unit sphere.
fn spherify(p: V) -> V {
    let (x, y, z) = (p[0], p[1], p[2]);
    let (x2, y2, z2) = (x * x, y * y, z * z);
    [
        x * (1.0 - y2 / 2.0 - z2 / 2.0 + y2 * z2 / 3.0).sqrt(),
        y * (1.0 - z2 / 2.0 - x2 / 2.0 + z2 * x2 / 3.0).sqrt(),
        z * (1.0 - x2 / 2.0 - y2 / 2.0 + x2 * y2 / 3.0).sqrt(),
    ]
}

/// A closed quadrilateral surface (outward by the right-hand rule) and, per vertex, the point
/// of the shape's core it is pulled towards to make the hollow mesh.
#[derive(Clone, Debug, Default)]
pub struct Surface {
    /// Vertices (m).
    pub verts: Vec<V>,
    /// Per vertex, its core point (m).
    pub core: Vec<V>,
    /// Quadrilaterals (vertex indices).
    pub quads: Vec<[u32; 4]>,
}

impl Surface {
    /// One layer of hexahedra from the surface halfway to the core.
    pub fn into_hollow(self) -> HexMesh {
        let n = self.verts.len() as u32;
        let mut nodes = self.verts.clone();
        for (v, c) in self.verts.iter().zip(&self.core) {
            nodes.push(add(*c, mul(0.5, sub(*v, *c))));
        }
        let elements = self
            .quads
            .iter()
            .map(|q| {
                [
                    q[0] + n,
                    q[1] + n,
                    q[2] + n,
                    q[3] + n,
                    q[0],
                    q[1],
                    q[2],
                    q[3],
                ]
            })
            .collect();
        HexMesh { nodes, elements }
    }

    /// Orient every quad outward: away from its vertices' core points.
    fn orient(&mut self) {
        for q in &mut self.quads {
            let p: Vec<V> = q.iter().map(|&i| self.verts[i as usize]).collect();
            let n = cross(sub(p[2], p[0]), sub(p[3], p[1]));
            let c = mul(
                0.25,
                q.iter().map(|&i| self.core[i as usize]).fold([0.0; 3], add),
            );
            let m = mul(0.25, p.iter().fold([0.0; 3], |a, b| add(a, *b)));
            if dot(n, sub(m, c)) < 0.0 {
                q.swap(1, 3);
            }
        }
    }
}

/// The cube-sphere's grid points and quads: `n` divisions per cube edge; integer keys on the
/// cube's surface (each in 0..=n).
fn cube_grid(n: usize) -> (Vec<[usize; 3]>, Vec<[usize; 4]>) {
    let mut index: HashMap<[usize; 3], usize> = HashMap::new();
    let mut keys = Vec::new();
    let mut quads = Vec::new();
    let mut id = |k: [usize; 3], keys: &mut Vec<[usize; 3]>| {
        *index.entry(k).or_insert_with(|| {
            keys.push(k);
            keys.len() - 1
        })
    };
    for axis in 0..3 {
        for side in [0, n] {
            for i in 0..n {
                for j in 0..n {
                    let pt = |a: usize, b: usize| {
                        let mut k = [0; 3];
                        k[axis] = side;
                        k[(axis + 1) % 3] = a;
                        k[(axis + 2) % 3] = b;
                        k
                    };
                    let q = [
                        id(pt(i, j), &mut keys),
                        id(pt(i + 1, j), &mut keys),
                        id(pt(i + 1, j + 1), &mut keys),
                        id(pt(i, j + 1), &mut keys),
                    ];
                    quads.push(q);
                }
            }
        }
    }
    (keys, quads)
}

fn cube_point(k: [usize; 3], n: usize) -> V {
    k.map(|c| 2.0 * c as f64 / n as f64 - 1.0)
}

/// A sphere.
pub fn sphere(center: V, radius: f64, segments: usize) -> Surface {
    capsule(center, [0.0, 0.0, 1.0], radius, 0.0, segments)
}

/// A capsule: tip hemisphere centred at `a`, axis `axis`, straight length `length`.
pub fn capsule(a: V, axis: V, radius: f64, length: f64, segments: usize) -> Surface {
    let n = (segments / 4).max(2) & !1; // even: the equator is a grid line
    let (u, v, w) = frame(axis);
    let (keys, cq) = cube_grid(n);
    let half = n / 2;
    let rings = if length > 0.0 {
        ((length / (radius * std::f64::consts::PI / (2.0 * n as f64))).ceil() as usize).clamp(1, 8)
    } else {
        0
    };
    let mut s = Surface {
        verts: Vec::new(),
        core: Vec::new(),
        quads: Vec::new(),
    };
    // Vertex of grid key `k` on ring `j` (only equator keys have rings; j = 0 at `a`).
    let mut ids: HashMap<(usize, usize), u32> = HashMap::new();
    let mut vid = |k: usize, j: usize, s: &mut Surface| {
        *ids.entry((k, j)).or_insert_with(|| {
            let p = spherify(cube_point(keys[k], n));
            let local = add(add(mul(p[0], u), mul(p[1], v)), mul(p[2], w));
            let centre = if rings == 0 {
                a
            } else {
                add(a, mul(length * j as f64 / rings as f64, w))
            };
            s.verts.push(add(centre, mul(radius, local)));
            s.core.push(centre);
            (s.verts.len() - 1) as u32
        })
    };
    for q in &cq {
        let zs: Vec<usize> = q.iter().map(|&k| keys[k][2]).collect();
        let upper = zs.iter().all(|&z| z >= half) && zs.iter().any(|&z| z > half);
        let ring = |_k: usize| if upper { rings } else { 0 };
        let quad = [
            vid(q[0], ring(q[0]), &mut s),
            vid(q[1], ring(q[1]), &mut s),
            vid(q[2], ring(q[2]), &mut s),
            vid(q[3], ring(q[3]), &mut s),
        ];
        s.quads.push(quad);
    }
    if rings > 0 {
        // The equator loop, in order around the axis.
        let mut eq: Vec<usize> = (0..keys.len()).filter(|&k| keys[k][2] == half).collect();
        eq.sort_by(|&x, &y| {
            let (px, py) = (cube_point(keys[x], n), cube_point(keys[y], n));
            px[1].atan2(px[0]).total_cmp(&py[1].atan2(py[0]))
        });
        for j in 0..rings {
            for i in 0..eq.len() {
                let (k0, k1) = (eq[i], eq[(i + 1) % eq.len()]);
                let quad = [
                    vid(k0, j, &mut s),
                    vid(k1, j, &mut s),
                    vid(k1, j + 1, &mut s),
                    vid(k0, j + 1, &mut s),
                ];
                s.quads.push(quad);
            }
        }
    }
    // The core of a capsule is its axis segment; of each vertex, the nearest point of it.
    for (p, c) in s.verts.iter().zip(s.core.iter_mut()) {
        let h = dot(sub(*p, a), w).clamp(0.0, length);
        *c = add(a, mul(h, w));
    }
    s.orient();
    s
}

/// A flat-ended cylinder: pressing face centred at `c`, extending `length` along `axis`.
pub fn cylinder(c: V, axis: V, radius: f64, length: f64, segments: usize) -> Surface {
    let n = (segments / 4).max(2);
    let (u, v, w) = frame(axis);
    let rings = ((length / (radius * std::f64::consts::PI * 2.0 / (4 * n) as f64)).ceil() as usize)
        .clamp(1, 16);
    let inset = 0.3 * radius.min(0.5 * length);
    let core_a = add(c, mul(inset, w));
    let core_b = add(c, mul(length - inset, w));
    let mut s = Surface {
        verts: Vec::new(),
        core: Vec::new(),
        quads: Vec::new(),
    };
    let disc = |i: usize, j: usize| {
        let (x, y) = (
            2.0 * i as f64 / n as f64 - 1.0,
            2.0 * j as f64 / n as f64 - 1.0,
        );
        (
            x * (1.0 - y * y / 2.0).sqrt(),
            y * (1.0 - x * x / 2.0).sqrt(),
        )
    };
    // Boundary of the square, in order: (i, j) keys.
    let mut boundary: Vec<(usize, usize)> = Vec::new();
    for i in 0..n {
        boundary.push((i, 0));
    }
    for j in 0..n {
        boundary.push((n, j));
    }
    for i in (1..=n).rev() {
        boundary.push((i, n));
    }
    for j in (1..=n).rev() {
        boundary.push((0, j));
    }
    let mut ids: HashMap<(usize, usize, usize), u32> = HashMap::new();
    // level: ring index 0..=rings for boundary points, 0 or rings for interior points.
    let mut vid = |i: usize, j: usize, level: usize, s: &mut Surface| {
        *ids.entry((i, j, level)).or_insert_with(|| {
            let (x, y) = disc(i, j);
            let h = length * level as f64 / rings as f64;
            s.verts.push(add(
                add(c, mul(h, w)),
                add(mul(radius * x, u), mul(radius * y, v)),
            ));
            s.core.push([0.0; 3]);
            (s.verts.len() - 1) as u32
        })
    };
    for level in [0, rings] {
        for i in 0..n {
            for j in 0..n {
                let q = [
                    vid(i, j, level, &mut s),
                    vid(i + 1, j, level, &mut s),
                    vid(i + 1, j + 1, level, &mut s),
                    vid(i, j + 1, level, &mut s),
                ];
                s.quads.push(q);
            }
        }
    }
    for r in 0..rings {
        for k in 0..boundary.len() {
            let (i0, j0) = boundary[k];
            let (i1, j1) = boundary[(k + 1) % boundary.len()];
            let q = [
                vid(i0, j0, r, &mut s),
                vid(i1, j1, r, &mut s),
                vid(i1, j1, r + 1, &mut s),
                vid(i0, j0, r + 1, &mut s),
            ];
            s.quads.push(q);
        }
    }
    let seg = sub(core_b, core_a);
    let l2 = dot(seg, seg);
    for (p, cc) in s.verts.iter().zip(s.core.iter_mut()) {
        let t = (dot(sub(*p, core_a), seg) / l2).clamp(0.0, 1.0);
        *cc = add(core_a, mul(t, seg));
    }
    s.orient();
    s
}

/// The corners of a box in VTK_HEXAHEDRON order.
fn box_corners(center: V, half: V, axes: Option<[[f64; 3]; 3]>) -> Vec<V> {
    let a = axes.unwrap_or([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    let e0 = unit(a[0]);
    let e1 = unit(sub(a[1], mul(dot(a[1], e0), e0)));
    let e2 = cross(e0, e1);
    let corner = |sx: f64, sy: f64, sz: f64| {
        add(
            center,
            add(
                add(mul(sx * half[0], e0), mul(sy * half[1], e1)),
                mul(sz * half[2], e2),
            ),
        )
    };
    const SIGNS: [[f64; 3]; 8] = [
        [-1.0, -1.0, -1.0],
        [1.0, -1.0, -1.0],
        [1.0, 1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
        [1.0, -1.0, 1.0],
        [1.0, 1.0, 1.0],
        [-1.0, 1.0, 1.0],
    ];
    SIGNS.iter().map(|c| corner(c[0], c[1], c[2])).collect()
}

/// A box: one hexahedron.
pub fn boxed(center: V, half: V, axes: Option<[[f64; 3]; 3]>) -> HexMesh {
    HexMesh {
        nodes: box_corners(center, half, axes),
        elements: vec![[0, 1, 2, 3, 4, 5, 6, 7]],
    }
}

/// The surface of a shape (outward quadrilaterals), or why it has none. `segments`: around a
/// great circle of a sphere, capsule or cylinder.
pub fn surface(shape: &ShapeSpec, segments: usize) -> Result<Surface, String> {
    Ok(match shape {
        ShapeSpec::Sphere { center, radius } => sphere(*center, *radius, segments),
        ShapeSpec::Capsule {
            center,
            axis,
            radius,
            length,
        } => capsule(*center, *axis, *radius, *length, segments),
        ShapeSpec::Cylinder {
            center,
            axis,
            radius,
            length,
        } => cylinder(*center, *axis, *radius, *length, segments),
        ShapeSpec::Box {
            center,
            half_extents,
            axes,
        } => {
            let verts = box_corners(*center, *half_extents, *axes);
            Surface {
                core: vec![*center; 8],
                verts,
                // The hexahedron's faces, outward.
                quads: vec![
                    [0, 3, 2, 1],
                    [4, 5, 6, 7],
                    [0, 1, 5, 4],
                    [2, 3, 7, 6],
                    [0, 4, 7, 3],
                    [1, 2, 6, 5],
                ],
            }
        }
        ShapeSpec::Plane { .. } => return Err("an infinite plane has no surface mesh".into()),
        ShapeSpec::Stl { .. } | ShapeSpec::Triangles { .. } => {
            return Err("a triangle mesh is its own surface".into())
        }
    })
}

/// The hollow hexahedral mesh of a shape (a box is one hexahedron), or why it has none.
pub fn mesh(shape: &ShapeSpec, segments: usize) -> Result<HexMesh, String> {
    match shape {
        ShapeSpec::Box {
            center,
            half_extents,
            axes,
        } => Ok(boxed(*center, *half_extents, *axes)),
        ShapeSpec::Plane { .. } => {
            Err("an infinite plane has no mesh; give the indenter a box shape".into())
        }
        ShapeSpec::Stl { .. } | ShapeSpec::Triangles { .. } => {
            Err("a triangle mesh is written as shells, not meshed".into())
        }
        other => surface(other, segments).map(Surface::into_hollow),
    }
}
