//! Rigid triangle-mesh indenter: STL reading and a signed distance accelerated by a BVH.
//!
//! The distance is the exact Euclidean distance to the closest triangle (closest-point algorithm
//! of Ericson, *Real-Time Collision Detection*, 5.1.5). The sign comes from the angle-weighted
//! pseudo-normal of the closest feature (face, edge or vertex), which is correct for any closed,
//! consistently oriented (outward) manifold mesh:
//! J. A. Baerentzen, H. Aanaes, "Signed distance computation using the angle weighted
//! pseudonormal", IEEE TVCG 11(3), 2005.
//! - face: its normal; edge: the sum of the two adjacent face normals; vertex: the sum of the
//!   incident face normals weighted by the incident angles.
//!
//! The outward normal returned with `phi` is `sign * (x - p) / |x - p|` for the closest point
//! `p`, i.e. the gradient of the signed distance; at the surface itself it falls back to the
//! pseudo-normal. The bounding-volume hierarchy is a median-split AABB tree (leaves of at most
//! four triangles), queried depth-first with a fixed-size stack: no allocation per query.
//!
//! STL carries no unit: the caller gives `scale`, the length of one file unit in metres. Both the
//! ASCII (`solid ... facet normal ... vertex x y z ...`) and the binary form (80-byte header,
//! `u32` count, 50 bytes per triangle) are read; the file's facet normals are ignored and the
//! winding order (counter-clockwise seen from outside) defines the outside. Coincident vertices
//! are merged by exact coordinate match.

use std::collections::HashMap;
use std::path::Path;

use crate::aabb::Aabb;
use crate::vec3::*;
use crate::ContactError;

/// Feature of a triangle closest to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Feature {
    Face,
    /// Edge `k` runs from vertex `k` to vertex `(k + 1) % 3`.
    Edge(u8),
    Vertex(u8),
}

#[derive(Clone, Debug)]
struct Node {
    bb: Aabb,
    /// Leaf: first triangle index in `order`; inner: index of the left child (right = left + 1).
    start: u32,
    /// Leaf: triangle count (>0); inner: 0.
    count: u32,
}

/// A closed triangle mesh with pseudo-normals and a BVH, ready for signed-distance queries.
#[derive(Clone, Debug)]
pub struct TriMesh {
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    face_normals: Vec<[f64; 3]>,
    /// Per triangle, pseudo-normal of edge k (vertex k -> k+1); not normalised (sign only).
    edge_normals: Vec<[[f64; 3]; 3]>,
    vertex_normals: Vec<[f64; 3]>,
    nodes: Vec<Node>,
    /// Triangle indices in BVH leaf order.
    order: Vec<u32>,
    mean_edge: f64,
}

const STACK: usize = 64;

impl TriMesh {
    /// Build from vertices (m) and triangles (counter-clockwise seen from outside).
    pub fn new(vertices: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> Result<TriMesh, ContactError> {
        if triangles.is_empty() {
            return Err(ContactError::Invalid(
                "triangle mesh has no triangles".into(),
            ));
        }
        let nv = vertices.len();
        if triangles.iter().flatten().any(|&i| i as usize >= nv) {
            return Err(ContactError::Invalid(
                "triangle refers to a missing vertex".into(),
            ));
        }
        let mut face_normals = Vec::with_capacity(triangles.len());
        let mut vertex_normals = vec![[0.0; 3]; nv];
        let mut edge_map: HashMap<(u32, u32), [f64; 3]> = HashMap::new();
        let mut edge_sum = 0.0;
        for t in &triangles {
            let p = [
                vertices[t[0] as usize],
                vertices[t[1] as usize],
                vertices[t[2] as usize],
            ];
            let n = normalize(cross(sub(p[1], p[0]), sub(p[2], p[0])))
                .ok_or_else(|| ContactError::Invalid("degenerate triangle in mesh".into()))?;
            face_normals.push(n);
            for k in 0..3 {
                let e1 = sub(p[(k + 1) % 3], p[k]);
                let e2 = sub(p[(k + 2) % 3], p[k]);
                let c = (dot(e1, e2) / (norm(e1) * norm(e2))).clamp(-1.0, 1.0);
                let angle = c.acos();
                let vn = &mut vertex_normals[t[k] as usize];
                *vn = axpy(angle, n, *vn);
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let key = (a.min(b), a.max(b));
                let en = edge_map.entry(key).or_insert([0.0; 3]);
                *en = add(*en, n);
                edge_sum += norm(e1);
            }
        }
        let edge_normals = triangles
            .iter()
            .map(|t| {
                let mut e = [[0.0; 3]; 3];
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    e[k] = edge_map[&(a.min(b), a.max(b))];
                }
                e
            })
            .collect();
        let mean_edge = edge_sum / (3 * triangles.len()) as f64;
        let mut m = TriMesh {
            vertices,
            triangles,
            face_normals,
            edge_normals,
            vertex_normals,
            nodes: Vec::new(),
            order: Vec::new(),
            mean_edge,
        };
        m.build_bvh();
        Ok(m)
    }

    /// Read an STL file (ASCII or binary), mapping `x = scale * x_file + translate` (m).
    pub fn from_stl_file(
        path: &Path,
        scale_: f64,
        translate: [f64; 3],
    ) -> Result<TriMesh, ContactError> {
        let bytes = std::fs::read(path)
            .map_err(|e| ContactError::Io(format!("{}: {e}", path.display())))?;
        Self::from_stl_bytes(&bytes, scale_, translate)
            .map_err(|e| ContactError::Invalid(format!("{}: {e}", path.display())))
    }

    /// Parse STL from memory (ASCII or binary), mapping `x = scale * x_file + translate` (m).
    pub fn from_stl_bytes(
        bytes: &[u8],
        scale_: f64,
        translate: [f64; 3],
    ) -> Result<TriMesh, ContactError> {
        let soup = parse_stl(bytes)?;
        // Weld coincident vertices (exact match of the file's coordinates).
        let mut index: HashMap<[u64; 3], u32> = HashMap::new();
        let mut vertices = Vec::new();
        let mut triangles = Vec::with_capacity(soup.len());
        for tri in &soup {
            let mut t = [0u32; 3];
            for k in 0..3 {
                let p = tri[k];
                let key = [p[0].to_bits(), p[1].to_bits(), p[2].to_bits()];
                t[k] = *index.entry(key).or_insert_with(|| {
                    vertices.push(axpy(scale_, p, translate));
                    (vertices.len() - 1) as u32
                });
            }
            if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                triangles.push(t);
            }
        }
        TriMesh::new(vertices, triangles)
    }

    /// Bounding box (m).
    pub fn aabb(&self) -> Aabb {
        self.nodes[0].bb
    }

    /// Vertices (m).
    pub fn vertices(&self) -> &[[f64; 3]] {
        &self.vertices
    }

    /// Triangles (vertex indices, counter-clockwise seen from outside).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Mean edge length (m).
    pub fn mean_edge_length(&self) -> f64 {
        self.mean_edge
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    fn tri_bb(&self, t: u32) -> Aabb {
        let mut b = Aabb::EMPTY;
        for &i in &self.triangles[t as usize] {
            b.include(self.vertices[i as usize]);
        }
        b
    }

    fn build_bvh(&mut self) {
        let n = self.triangles.len();
        let centroids: Vec<[f64; 3]> = self
            .triangles
            .iter()
            .map(|t| {
                let mut c = [0.0; 3];
                for &i in t {
                    c = add(c, self.vertices[i as usize]);
                }
                scale(c, 1.0 / 3.0)
            })
            .collect();
        self.order = (0..n as u32).collect();
        self.nodes.clear();
        self.nodes.push(Node {
            bb: Aabb::EMPTY,
            start: 0,
            count: 0,
        });
        // (node index, start, end) work list.
        let mut work = vec![(0usize, 0usize, n)];
        while let Some((ni, s, e)) = work.pop() {
            let mut bb = Aabb::EMPTY;
            let mut cb = Aabb::EMPTY;
            for &t in &self.order[s..e] {
                let tb = self.tri_bb(t);
                bb.include(tb.min);
                bb.include(tb.max);
                cb.include(centroids[t as usize]);
            }
            self.nodes[ni].bb = bb;
            if e - s <= 4 {
                self.nodes[ni].start = s as u32;
                self.nodes[ni].count = (e - s) as u32;
                continue;
            }
            let ext = sub(cb.max, cb.min);
            let mut axis = 0;
            if ext[1] > ext[axis] {
                axis = 1;
            }
            if ext[2] > ext[axis] {
                axis = 2;
            }
            let mid = (s + e) / 2;
            self.order[s..e].select_nth_unstable_by(mid - s, |&a, &b| {
                centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
            });
            let left = self.nodes.len();
            self.nodes.push(Node {
                bb: Aabb::EMPTY,
                start: 0,
                count: 0,
            });
            self.nodes.push(Node {
                bb: Aabb::EMPTY,
                start: 0,
                count: 0,
            });
            self.nodes[ni].start = left as u32;
            self.nodes[ni].count = 0;
            work.push((left, s, mid));
            work.push((left + 1, mid, e));
        }
    }

    /// Signed distance (m, negative inside) and outward unit normal at `x` (m).
    pub fn signed_distance(&self, x: [f64; 3]) -> (f64, [f64; 3]) {
        let mut best_d2 = f64::INFINITY;
        let mut best = (0u32, [0.0; 3], Feature::Face);
        let mut stack = [0u32; STACK];
        let mut sp = 1;
        stack[0] = 0;
        while sp > 0 {
            sp -= 1;
            let node = &self.nodes[stack[sp] as usize];
            if node.bb.distance2(x) >= best_d2 {
                continue;
            }
            if node.count > 0 {
                for &t in &self.order[node.start as usize..(node.start + node.count) as usize] {
                    let tri = self.triangles[t as usize];
                    let (p, f) = closest_point_triangle(
                        x,
                        self.vertices[tri[0] as usize],
                        self.vertices[tri[1] as usize],
                        self.vertices[tri[2] as usize],
                    );
                    let d2 = norm2(sub(x, p));
                    if d2 < best_d2 {
                        best_d2 = d2;
                        best = (t, p, f);
                    }
                }
            } else {
                let l = node.start as usize;
                // Visit the nearer child first (push it last).
                let dl = self.nodes[l].bb.distance2(x);
                let dr = self.nodes[l + 1].bb.distance2(x);
                debug_assert!(sp + 2 <= STACK);
                if dl <= dr {
                    stack[sp] = (l + 1) as u32;
                    stack[sp + 1] = l as u32;
                } else {
                    stack[sp] = l as u32;
                    stack[sp + 1] = (l + 1) as u32;
                }
                sp += 2;
            }
        }
        let (t, p, f) = best;
        let pseudo = match f {
            Feature::Face => self.face_normals[t as usize],
            Feature::Edge(k) => self.edge_normals[t as usize][k as usize],
            Feature::Vertex(k) => {
                self.vertex_normals[self.triangles[t as usize][k as usize] as usize]
            }
        };
        let d = sub(x, p);
        let s = if dot(d, pseudo) < 0.0 { -1.0 } else { 1.0 };
        let dist = best_d2.sqrt();
        let n = if dist > 1e-12 * self.mean_edge {
            scale(d, s / dist)
        } else {
            normalize(pseudo).unwrap_or(self.face_normals[t as usize])
        };
        (s * dist, n)
    }
}

/// Closest point on triangle (a, b, c) to p, and the feature it lies on (Ericson 5.1.5).
fn closest_point_triangle(p: V3, a: V3, b: V3, c: V3) -> (V3, Feature) {
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, Feature::Vertex(0));
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, Feature::Vertex(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (axpy(v, ab, a), Feature::Edge(0));
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, Feature::Vertex(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (axpy(w, ac, a), Feature::Edge(2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (axpy(w, sub(c, b), b), Feature::Edge(1));
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    (add(a, add(scale(ab, v), scale(ac, w))), Feature::Face)
}

/// Parse STL bytes into a triangle soup (file units).
fn parse_stl(bytes: &[u8]) -> Result<Vec<[[f64; 3]; 3]>, ContactError> {
    let is_binary = if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        bytes.len() == 84 + 50 * n
    } else {
        false
    };
    if is_binary {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        let mut out = Vec::with_capacity(n);
        for i in 0..n {
            let rec = &bytes[84 + 50 * i..84 + 50 * (i + 1)];
            let f = |k: usize| {
                let o = 12 + 4 * k;
                f32::from_le_bytes([rec[o], rec[o + 1], rec[o + 2], rec[o + 3]]) as f64
            };
            out.push([[f(0), f(1), f(2)], [f(3), f(4), f(5)], [f(6), f(7), f(8)]]);
        }
        return Ok(out);
    }
    let text = std::str::from_utf8(bytes)
        .map_err(|_| ContactError::Invalid("STL is neither valid binary nor ASCII".into()))?;
    if !text.trim_start().starts_with("solid") {
        return Err(ContactError::Invalid(
            "STL is neither binary (size mismatch) nor ASCII (no 'solid')".into(),
        ));
    }
    let mut out = Vec::new();
    let mut cur: Vec<[f64; 3]> = Vec::with_capacity(3);
    let mut tok = text.split_ascii_whitespace();
    while let Some(t) = tok.next() {
        if t == "vertex" {
            let mut p = [0.0; 3];
            for c in p.iter_mut() {
                *c = tok
                    .next()
                    .and_then(|s| s.parse::<f64>().ok())
                    .ok_or_else(|| {
                        ContactError::Invalid("bad 'vertex' line in ASCII STL".into())
                    })?;
            }
            cur.push(p);
        } else if t == "endfacet" {
            if cur.len() != 3 {
                return Err(ContactError::Invalid(format!(
                    "ASCII STL facet with {} vertices",
                    cur.len()
                )));
            }
            out.push([cur[0], cur[1], cur[2]]);
            cur.clear();
        }
    }
    if out.is_empty() {
        return Err(ContactError::Invalid("ASCII STL has no facets".into()));
    }
    Ok(out)
}

/// Write a triangle soup as binary STL bytes (used by tests and tools).
pub fn write_binary_stl(triangles: &[[[f64; 3]; 3]]) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&(triangles.len() as u32).to_le_bytes());
    for t in triangles {
        let n = normalize(cross(sub(t[1], t[0]), sub(t[2], t[0]))).unwrap_or([0.0; 3]);
        for c in n {
            b.extend_from_slice(&(c as f32).to_le_bytes());
        }
        for p in t {
            for c in p {
                b.extend_from_slice(&(*c as f32).to_le_bytes());
            }
        }
        b.extend_from_slice(&0u16.to_le_bytes());
    }
    b
}
