//! Voxel-to-hexahedron meshing: coarsen, clean up, one hexahedron per labelled voxel, smooth.
//!
//! Voxel (i, j, k) becomes the hexahedron whose corners are the grid vertices
//! (i + a, j + b, k + c), a, b, c in {0, 1}, placed at index coordinates
//! (i + a - 1/2, j + b - 1/2, k + c - 1/2) through the volume's affine, numbered in
//! VTK_HEXAHEDRON order (bottom face (c = 0) counter-clockwise about +k, then the top face).
//! Grid vertices are numbered once, in storage order, so neighbouring voxels share nodes
//! whatever their parts. A mirrored affine (negative determinant) swaps the i-direction of
//! the numbering so every element keeps a positive Jacobian in world space.
//!
//! The mesh carries element sets named after the parts and a node set `"surface"` with the
//! nodes of the outer boundary (faces against background or the volume's bounding box).

use std::time::Instant;

use rayon::prelude::*;

use super::cleanup::cleanup;
use super::quality::MeshQuality;
use super::smooth::{smooth_surfaces, SmoothOptions, SurfaceFace};
use super::{LabelMap, LabelVolume};
use solver::mesh::Mesh;

/// Meshing options.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshOptions {
    /// Merge `coarsen^3` voxels into one by majority label before meshing (1 = off).
    pub coarsen: usize,
    /// Single-label components and detached pieces smaller than this are removed (voxels).
    pub min_island_voxels: usize,
    /// Keep only the largest 6-connected foreground component.
    pub keep_largest_component: bool,
    /// Repair edge- and corner-only connections.
    pub fix_nonmanifold: bool,
    /// Surface smoothing.
    pub smoothing: SmoothOptions,
}

impl Default for MeshOptions {
    fn default() -> Self {
        MeshOptions {
            coarsen: 1,
            min_island_voxels: 8,
            keep_largest_component: true,
            fix_nonmanifold: true,
            smoothing: SmoothOptions::default(),
        }
    }
}

/// Per-direction face corner offsets (a, b, c) in cyclic order, for faces normal to i, j, k.
const FACE_CYCLES: [[[usize; 3]; 4]; 3] = [
    [[0, 0, 0], [0, 1, 0], [0, 1, 1], [0, 0, 1]],
    [[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1]],
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],
];

/// Clean a copy of `vol` and mesh it, with smoothing; see the module docs.
pub fn mesh_volume(
    vol: &LabelVolume,
    map: &LabelMap,
    opts: &MeshOptions,
) -> Result<(Mesh, MeshQuality), String> {
    let t0 = Instant::now();
    let mut v = if opts.coarsen > 1 {
        vol.coarsen(opts.coarsen)
    } else {
        vol.clone()
    };
    let (names, table) = map.parts();
    let counts = v.label_counts();
    let unmapped: Vec<usize> = (1..256)
        .filter(|&l| counts[l] > 0 && table[l] == u32::MAX)
        .collect();
    if !unmapped.is_empty() {
        return Err(format!(
            "labels {unmapped:?} are present in the volume but not in the label map"
        ));
    }
    let rep = cleanup(
        &mut v,
        opts.min_island_voxels,
        opts.keep_largest_component,
        opts.fix_nonmanifold,
    );
    let (mut mesh, faces, plane_bits) = build_hexes(&v, &names, &table, opts.smoothing.interfaces)?;
    let t1 = Instant::now();
    let normals = plane_normals(&v);
    let srep = smooth_surfaces(
        &mut mesh.nodes,
        &mesh.elements,
        &faces,
        &plane_bits,
        &normals,
        &opts.smoothing,
    );
    let t2 = Instant::now();
    let mut q = MeshQuality::measure(&mesh);
    q.cleanup = rep;
    q.smoothing = srep;
    q.seconds_mesh = (t1 - t0).as_secs_f64();
    q.seconds_smooth = (t2 - t1).as_secs_f64();
    if q.n_nonpositive > 0 {
        return Err(format!(
            "{} elements have a non-positive Jacobian after smoothing",
            q.n_nonpositive
        ));
    }
    Ok((mesh, q))
}

/// World unit normals of the i, j and k grid planes.
fn plane_normals(v: &LabelVolume) -> [[f64; 3]; 3] {
    let a = &v.affine;
    let col = |c: usize| [a[0][c], a[1][c], a[2][c]];
    let cross = |p: [f64; 3], q: [f64; 3]| {
        [
            p[1] * q[2] - p[2] * q[1],
            p[2] * q[0] - p[0] * q[2],
            p[0] * q[1] - p[1] * q[0],
        ]
    };
    let mut out = [[0.0; 3]; 3];
    for (ax, o) in out.iter_mut().enumerate() {
        let n = cross(col((ax + 1) % 3), col((ax + 2) % 3));
        let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        *o = [n[0] / l, n[1] / l, n[2] / l];
    }
    out
}

/// The raw voxel mesh of a cleaned volume, its surface faces (outer surface, cut planes and,
/// if `interfaces`, part interfaces) and, per node, the bounding planes it lies on (bit = axis).
pub fn build_hexes(
    v: &LabelVolume,
    names: &[String],
    table: &[u32; 256],
    interfaces: bool,
) -> Result<(Mesh, Vec<SurfaceFace>, Vec<u8>), String> {
    let [nx, ny, nz] = v.dims;
    let grid = Grid {
        gx: nx + 1,
        gy: ny + 1,
    };
    let n_grid = grid.gx * grid.gy * (nz + 1);
    if n_grid > u32::MAX as usize {
        return Err("volume too large for 32-bit node ids".into());
    }
    let part_of = |l: u8| table[l as usize];
    let (node_id, nodes, plane_bits) = grid_nodes(v, &grid, n_grid, &part_of);
    let order = corner_order(v.affine_det() < 0.0);
    let mut elements = Vec::new();
    let mut element_part = Vec::new();
    let mut faces = Vec::new();
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let p = part_of(v.get(i, j, k));
                if p == u32::MAX {
                    continue;
                }
                let mut conn = [0u32; 8];
                for (q, o) in order.iter().enumerate() {
                    conn[q] = node_id[grid.id(i + o[0], j + o[1], k + o[2])];
                }
                elements.push(conn);
                element_part.push(p);
                let faces_of = VoxelFaces {
                    v,
                    grid: &grid,
                    node_id: &node_id,
                    part_of: &part_of,
                    interfaces,
                };
                faces_of.push([i, j, k], p, &mut faces);
            }
        }
    }
    // outer surface node set
    let mut surf: Vec<u32> = faces
        .par_iter()
        .filter(|f| (f.patch & 0xFFFF_0000) == 0xFFFF_0000)
        .flat_map_iter(|f| f.nodes)
        .collect();
    surf.par_sort_unstable();
    surf.dedup();
    let mut mesh = Mesh {
        nodes,
        elements,
        element_part,
        part_names: names.to_vec(),
        ..Default::default()
    };
    for (pid, name) in names.iter().enumerate() {
        let set: Vec<u32> = (0..mesh.elements.len() as u32)
            .filter(|&e| mesh.element_part[e as usize] == pid as u32)
            .collect();
        mesh.element_sets.insert(name.clone(), set);
    }
    mesh.node_sets.insert("surface".into(), surf);
    Ok((mesh, faces, plane_bits))
}

/// The grid of voxel corners: `gx` x `gy` x (nz + 1) points, x fastest.
struct Grid {
    gx: usize,
    gy: usize,
}

impl Grid {
    fn id(&self, a: usize, b: usize, c: usize) -> usize {
        a + self.gx * (b + self.gy * c)
    }
}

/// The corners used by some element, numbered in grid order: the grid-to-node map, the node
/// positions (the voxel centres' world frame) and each node's bounding-plane bits.
fn grid_nodes(
    v: &LabelVolume,
    grid: &Grid,
    n_grid: usize,
    part_of: &impl Fn(u8) -> u32,
) -> (Vec<u32>, Vec<[f64; 3]>, Vec<u8>) {
    let [nx, ny, nz] = v.dims;
    // mark used vertices, k-slab by k-slab
    let mut used = vec![false; n_grid];
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                if part_of(v.get(i, j, k)) != u32::MAX {
                    for c in 0..2 {
                        for b in 0..2 {
                            for a in 0..2 {
                                used[grid.id(i + a, j + b, k + c)] = true;
                            }
                        }
                    }
                }
            }
        }
    }
    let mut node_id = vec![u32::MAX; n_grid];
    let mut nodes = Vec::new();
    let mut plane_bits = Vec::new();
    for c in 0..=nz {
        for b in 0..=ny {
            for a in 0..=nx {
                let g = grid.id(a, b, c);
                if used[g] {
                    node_id[g] = nodes.len() as u32;
                    nodes.push(v.index_to_world([a as f64 - 0.5, b as f64 - 0.5, c as f64 - 0.5]));
                    let bits = (a == 0 || a == nx) as u8
                        | (((b == 0 || b == ny) as u8) << 1)
                        | (((c == 0 || c == nz) as u8) << 2);
                    plane_bits.push(bits);
                }
            }
        }
    }
    (node_id, nodes, plane_bits)
}

/// A voxel's corners in VTK order: (0,0,0) (1,0,0) (1,1,0) (0,1,0) then c = 1; mirrored when
/// the volume's affine map reverses orientation, so that every element has positive volume.
fn corner_order(mirrored: bool) -> [[usize; 3]; 8] {
    if mirrored {
        [
            [1, 0, 0],
            [0, 0, 0],
            [0, 1, 0],
            [1, 1, 0],
            [1, 0, 1],
            [0, 0, 1],
            [0, 1, 1],
            [1, 1, 1],
        ]
    } else {
        [
            [0, 0, 0],
            [1, 0, 0],
            [1, 1, 0],
            [0, 1, 0],
            [0, 0, 1],
            [1, 0, 1],
            [1, 1, 1],
            [0, 1, 1],
        ]
    }
}

/// The surface faces of a voxel towards its six neighbours.
struct VoxelFaces<'a, P: Fn(u8) -> u32> {
    v: &'a LabelVolume,
    grid: &'a Grid,
    node_id: &'a [u32],
    part_of: &'a P,
    interfaces: bool,
}

impl<P: Fn(u8) -> u32> VoxelFaces<'_, P> {
    /// Push the faces of voxel `[i, j, k]` (part `p`) that lie on the outer surface, on a cut
    /// plane or (with `interfaces`) on an interface towards a part of higher index, each with
    /// its patch key.
    fn push(&self, [i, j, k]: [usize; 3], p: u32, faces: &mut Vec<SurfaceFace>) {
        let v = self.v;
        for ax in 0..3 {
            for side in 0..2usize {
                let mut nb = [i as isize, j as isize, k as isize];
                nb[ax] += if side == 0 { -1 } else { 1 };
                let outside = nb[ax] < 0 || nb[ax] >= v.dims[ax] as isize;
                let q = if outside {
                    u32::MAX
                } else {
                    (self.part_of)(v.get_or_bg(nb[0], nb[1], nb[2]))
                };
                let patch = if outside {
                    // cut plane: its own patch per (part, plane)
                    ((p as u64) << 32) | (0xFFFF_0000 + (ax * 2 + side) as u64)
                } else if q == u32::MAX {
                    ((p as u64) << 32) | 0xFFFF_FFFF
                } else if q != p && self.interfaces && p < q {
                    ((p as u64) << 32) | q as u64
                } else {
                    continue;
                };
                let mut base = [i, j, k];
                base[ax] += side;
                let mut fnodes = [0u32; 4];
                for (r, off) in FACE_CYCLES[ax].iter().enumerate() {
                    fnodes[r] = self.node_id[self.grid.id(
                        base[0] + off[0],
                        base[1] + off[1],
                        base[2] + off[2],
                    )];
                }
                faces.push(SurfaceFace {
                    nodes: fnodes,
                    patch,
                });
            }
        }
    }
}
