//! Palpation locations: the 5 x 5 raster over the liver and the test locations A, B, C.
//!
//! Each location is an (x, y) point of the body surface. Its surface point comes from a
//! vertical ray cast on the smoothed skin faces (the highest hit). Its inward normal, the
//! direction a hand placed there presses in, is the negated mean outward normal of the skin
//! over the hand's footprint: with `d_f` the plan distance of skin face `f`'s centroid from
//! (x, y), `R` = [`NORMAL_RADIUS`] and the smooth compact weight `w_f = (1 - d_f^2/R^2)^2` for
//! `d_f < R`, `n = sum_f w_f a_f n_f / |sum_f w_f a_f n_f|` (`a_f n_f` the face's area vector).
//! On a smooth surface this is the normal there; on a smoothed voxel surface it averages the
//! remaining steps out, and the weight lets faces enter and leave the footprint gradually, so
//! that the direction varies continuously with (x, y). The normal of the one face hit would not: a
//! riser of a step left by smoothing tilts it by up to 56 degrees, so that two locations
//! 2.5 mm apart were pressed in directions 40 degrees apart, and the 15 mm press gave
//! reaction forces of 31 and 43 N. What lies under a location is read
//! from the voxel column below it (walking down from the skin): the depth of the first liver
//! voxel below the skin, whether a rib voxel comes first, and how thick the liver is there.
//!
//! The raster is visited row by row from the cranial row to the caudal one, each row from
//! the patient's right (x min) to the left, like the paper's top-left-to-bottom-right order.
//! The test locations are searched over every voxel column in the raster's box widened by
//! 30 mm, among columns with at least 15 mm of liver:
//! - A: liver near the surface, not under the ribs: below the rib cage (no rib in the anterior
//!   half of this column or of any column caudal to it), smallest depth;
//! - B: liver deeper: below the rib cage, largest depth up to 80 mm;
//! - C: under the rib cage: a rib between skin and liver, smallest liver depth.

use serde::Serialize;

use super::anatomy::{LIVER, RIBS, TUMOUR};
use super::params::GridParams;
use crate::mesh::Mesh;
use crate::voxel::LabelVolume;

/// One palpation location.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Location {
    /// Name: "P01".."P25", or "A", "B", "C".
    pub name: String,
    /// Surface point (m): x, y of the location and z of the skin there.
    pub surface: [f64; 3],
    /// Unit normal pointing into the body at the surface point.
    pub inward_normal: [f64; 3],
    /// Skin-to-liver depth along the vertical (m), if there is liver below.
    pub liver_depth: Option<f64>,
    /// Whether a rib lies between the skin and the liver.
    pub under_ribs: bool,
}

/// The raster and the three test locations.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Locations {
    /// The raster, cranial row first, each row from the patient's right.
    pub grid: Vec<Location>,
    /// Liver near the surface, not under the ribs.
    pub a: Location,
    /// Liver deeper.
    pub b: Location,
    /// Liver under the rib cage.
    pub c: Location,
}

impl Locations {
    /// JSON text.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    /// Look a location up by name ("A", "B", "C", "P01".."P25"), case-insensitive.
    pub fn get(&self, name: &str) -> Option<&Location> {
        let n = name.to_ascii_uppercase();
        match n.as_str() {
            "A" => Some(&self.a),
            "B" => Some(&self.b),
            "C" => Some(&self.c),
            _ => self.grid.iter().find(|l| l.name == n),
        }
    }
}

/// What a voxel column holds under the skin.
#[derive(Clone, Copy, Debug)]
struct Column {
    depth: Option<f64>,
    under_ribs: bool,
    liver_thickness: f64,
}

fn is_liver(l: u8) -> bool {
    l == LIVER || l >= TUMOUR
}

fn column(vol: &LabelVolume, i: usize, j: usize) -> Column {
    let h = vol.spacing[2];
    let mut skin: Option<usize> = None;
    let mut rib = false;
    let mut out = Column {
        depth: None,
        under_ribs: false,
        liver_thickness: 0.0,
    };
    for k in (0..vol.dims[2]).rev() {
        let l = vol.get(i, j, k);
        if skin.is_none() {
            if l == 0 {
                continue;
            }
            skin = Some(k);
        }
        if l == RIBS {
            rib = true;
        }
        if is_liver(l) {
            let s = skin.unwrap_or(k);
            out.depth = Some((s - k) as f64 * h);
            out.under_ribs = rib;
            let mut n = 0;
            let mut kk = k as isize;
            while kk >= 0 && is_liver(vol.get(i, j, kk as usize)) {
                n += 1;
                kk -= 1;
            }
            out.liver_thickness = n as f64 * h;
            break;
        }
    }
    out
}

fn world_to_column(vol: &LabelVolume, x: f64, y: f64) -> Option<(usize, usize)> {
    let o = vol.origin();
    let i = ((x - o[0]) / vol.spacing[0]).round();
    let j = ((y - o[1]) / vol.spacing[1]).round();
    if i < 0.0 || j < 0.0 || i >= vol.dims[0] as f64 || j >= vol.dims[1] as f64 {
        None
    } else {
        Some((i as usize, j as usize))
    }
}

/// Plan radius (m) of the kernel over which a location's normal averages the skin. The
/// weight halves at 0.54 R = 16 mm, about the two-finger hand's half-footprint (fingers
/// 15 mm thick, 20 mm apart).
pub const NORMAL_RADIUS: f64 = 0.03;

/// Mean outward unit normal of the skin faces whose centroids lie within `radius` of (x, y)
/// in plan (weighted by area and a smooth kernel, see the module docs); `None` if no face is
/// that close.
pub fn mean_normal(
    mesh: &Mesh,
    skin: &[[u32; 4]],
    x: f64,
    y: f64,
    radius: f64,
) -> Option<[f64; 3]> {
    let mut sum = [0.0; 3];
    let mut any = false;
    for f in skin {
        let p = f.map(|n| mesh.nodes[n as usize]);
        let cx = 0.25 * (p[0][0] + p[1][0] + p[2][0] + p[3][0]);
        let cy = 0.25 * (p[0][1] + p[1][1] + p[2][1] + p[3][1]);
        let q = ((cx - x).powi(2) + (cy - y).powi(2)) / (radius * radius);
        if q >= 1.0 {
            continue;
        }
        let w = (1.0 - q) * (1.0 - q);
        // area vector of a bilinear quad: (x2 - x0) x (x3 - x1) / 2
        let d1 = [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]];
        let d2 = [p[3][0] - p[1][0], p[3][1] - p[1][1], p[3][2] - p[1][2]];
        let a = [
            0.5 * (d1[1] * d2[2] - d1[2] * d2[1]),
            0.5 * (d1[2] * d2[0] - d1[0] * d2[2]),
            0.5 * (d1[0] * d2[1] - d1[1] * d2[0]),
        ];
        // skin faces are outward by the right-hand rule; keep the upward sense regardless
        let s = if a[2] < 0.0 { -w } else { w };
        for k in 0..3 {
            sum[k] += s * a[k];
        }
        any = true;
    }
    let l = (sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]).sqrt();
    (any && l > 0.0).then(|| sum.map(|v| v / l))
}

/// Highest skin hit of the vertical line through (x, y): (z, outward unit normal of the face hit).
pub fn cast_down(mesh: &Mesh, skin: &[[u32; 4]], x: f64, y: f64) -> Option<(f64, [f64; 3])> {
    let mut best: Option<(f64, [f64; 3])> = None;
    for f in skin {
        let p: Vec<[f64; 3]> = f.iter().map(|&n| mesh.nodes[n as usize]).collect();
        for tri in [[0, 1, 2], [0, 2, 3]] {
            let (a, b, c) = (p[tri[0]], p[tri[1]], p[tri[2]]);
            let det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
            if det.abs() < 1e-18 {
                continue;
            }
            let l1 = ((x - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (y - a[1])) / det;
            let l2 = ((b[0] - a[0]) * (y - a[1]) - (x - a[0]) * (b[1] - a[1])) / det;
            let eps = 1e-9;
            if l1 < -eps || l2 < -eps || l1 + l2 > 1.0 + eps {
                continue;
            }
            let z = a[2] + l1 * (b[2] - a[2]) + l2 * (c[2] - a[2]);
            if best.is_none_or(|bz| z > bz.0) {
                let (u, v) = (
                    [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                    [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
                );
                let n = [
                    u[1] * v[2] - u[2] * v[1],
                    u[2] * v[0] - u[0] * v[2],
                    u[0] * v[1] - u[1] * v[0],
                ];
                let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                let s = if n[2] < 0.0 { -1.0 } else { 1.0 } / l;
                best = Some((z, [n[0] * s, n[1] * s, n[2] * s]));
            }
        }
    }
    best
}

fn make(
    mesh: &Mesh,
    skin: &[[u32; 4]],
    vol: &LabelVolume,
    name: &str,
    x: f64,
    y: f64,
) -> Result<Location, String> {
    let (z, n_face) = cast_down(mesh, skin, x, y)
        .ok_or_else(|| format!("location {name} ({x:.3}, {y:.3}) m is not over the skin"))?;
    let n = mean_normal(mesh, skin, x, y, NORMAL_RADIUS).unwrap_or(n_face);
    let col = world_to_column(vol, x, y).map(|(i, j)| column(vol, i, j));
    Ok(Location {
        name: name.to_string(),
        surface: [x, y, z],
        inward_normal: [-n[0], -n[1], -n[2]],
        liver_depth: col.and_then(|c| c.depth),
        under_ribs: col.map(|c| c.under_ribs).unwrap_or(false),
    })
}

/// A location at an arbitrary (x, y) (m).
pub fn location_at(
    mesh: &Mesh,
    skin: &[[u32; 4]],
    vol: &LabelVolume,
    name: &str,
    x: f64,
    y: f64,
) -> Result<Location, String> {
    make(mesh, skin, vol, name, x, y)
}

/// Build the raster and find A, B and C.
pub fn find_locations(
    mesh: &Mesh,
    skin: &[[u32; 4]],
    vol: &LabelVolume,
    g: &GridParams,
) -> Result<Locations, String> {
    let mut grid = Vec::new();
    let (nx, ny) = (g.n[0], g.n[1]);
    let x0 = g.center[0] - g.spacing[0] * (nx as f64 - 1.0) / 2.0;
    let y0 = g.center[1] + g.spacing[1] * (ny as f64 - 1.0) / 2.0;
    for r in 0..ny {
        for c in 0..nx {
            let name = format!("P{:02}", r * nx + c + 1);
            grid.push(make(
                mesh,
                skin,
                vol,
                &name,
                x0 + c as f64 * g.spacing[0],
                y0 - r as f64 * g.spacing[1],
            )?);
        }
    }
    let margin = 0.03;
    let lo = [x0 - margin, y0 - g.spacing[1] * (ny as f64 - 1.0) - margin];
    let hi = [x0 + g.spacing[0] * (nx as f64 - 1.0) + margin, y0 + margin];
    // a column is below the rib cage when no rib lies in it or in any column caudal to it
    let mut below_cage = vec![false; vol.dims[0] * vol.dims[1]];
    for i in 0..vol.dims[0] {
        let mut seen = false;
        for j in 0..vol.dims[1] {
            seen |= (0..vol.dims[2]).any(|k| {
                vol.get(i, j, k) == RIBS
                    && vol.voxel_center(i, j, k)[2]
                        > 0.5 * vol.voxel_center(i, j, vol.dims[2] - 1)[2]
            });
            below_cage[i + vol.dims[0] * j] = !seen;
        }
    }
    let (mut a, mut b, mut c): (
        Option<(f64, usize, usize)>,
        Option<(f64, usize, usize)>,
        Option<(f64, usize, usize)>,
    ) = (None, None, None);
    for j in 0..vol.dims[1] {
        for i in 0..vol.dims[0] {
            let p = vol.voxel_center(i, j, 0);
            if p[0] < lo[0] || p[0] > hi[0] || p[1] < lo[1] || p[1] > hi[1] {
                continue;
            }
            let col = column(vol, i, j);
            let Some(d) = col.depth else { continue };
            if col.liver_thickness < 0.015 {
                continue;
            }
            if col.under_ribs {
                if c.is_none_or(|q| d < q.0) {
                    c = Some((d, i, j));
                }
            } else if below_cage[i + vol.dims[0] * j] {
                if a.is_none_or(|q| d < q.0) {
                    a = Some((d, i, j));
                }
                if d <= 0.08 && b.is_none_or(|q| d > q.0) {
                    b = Some((d, i, j));
                }
            }
        }
    }
    let pick = |q: Option<(f64, usize, usize)>, name: &str| -> Result<Location, String> {
        let (_, i, j) = q.ok_or_else(|| format!("no column qualifies for test location {name}"))?;
        let p = vol.voxel_center(i, j, 0);
        make(mesh, skin, vol, name, p[0], p[1])
    };
    Ok(Locations {
        grid,
        a: pick(a, "A")?,
        b: pick(b, "B")?,
        c: pick(c, "C")?,
    })
}
