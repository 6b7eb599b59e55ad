//! The phantom in plan view: its outlines projected on the x-y plane, the plane of the force
//! plate and of the live picture (`palpa serve`, the PNG maps). Lengths in m, in the phantom's
//! frame (x towards the patient's left, y cranial; see the module doc of `phantom`).
//!
//! - **Torso**: the rectangle the torso covers in plan, x in [-w/2, w/2], y in [0, L].
//! - **Model box**: the reduced model's crop, the (x, y) extent of its label volume (none for the
//!   full variant).
//! - **Liver**: the zero contour of `g(x, y) = max_z m(x, y, z)`, where `m` is the anatomy's
//!   signed liver margin (m, positive inside; `Anatomy::liver_margin`) sampled every
//!   `step` in x and y and every [`Z_STEP`] in z. Since `m` is a smooth signed distance-like
//!   function, the contour follows the implicit liver rather than a voxel staircase.
//! - **Ribs**: the columns whose anterior half (above the torso outline's centre) holds a rib,
//!   costal cartilage or sternum point (`Anatomy::in_ribs`, every [`Z_STEP`] in z): the level
//!   1/2 contour of that 0/1 mask, sampled every `step / 2` (a mask has no sub-grid
//!   information, so it takes the finer grid), so the ribs a trainee's fingers meet from the
//!   front.
//!
//! Contours are traced by marching squares (the 2-D case of Lorensen & Cline, "Marching
//! cubes", SIGGRAPH 1987): each grid cell's corners above the level give one of 16 cases, the
//! crossing on each cut edge is placed by linear interpolation, `t = (level - f_a)/(f_b - f_a)`,
//! and the two ambiguous (saddle) cases are decided by the mean of the four corners. The grid
//! is padded with samples below the level, so every contour closes. The polygons are then
//! thinned by Douglas-Peucker (Cartographica 10 (1973) 112) with a tolerance of `step / 4`.

use rayon::prelude::*;

use super::anatomy::Anatomy;
use super::Phantom;

/// Sampling step along z of the column scans (m).
pub const Z_STEP: f64 = 0.001;

/// Default sampling step of the plan grid (m).
pub const PLAN_STEP: f64 = 0.002;

/// The phantom's outlines in plan view (m). Polygons are closed: the last point is not a
/// repeat of the first.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlanView {
    /// The torso's plan rectangle.
    pub torso: Vec<[f64; 2]>,
    /// The reduced model's crop box, if the phantom is the reduced variant.
    pub model_box: Option<Vec<[f64; 2]>>,
    /// Liver outline(s).
    pub liver: Vec<Vec<[f64; 2]>>,
    /// Outlines of the anterior ribs, costal cartilage and sternum.
    pub ribs: Vec<Vec<[f64; 2]>>,
}

/// The plan view of a built phantom, its grids sampled every `step` (m) in x and y.
pub fn plan_view(ph: &Phantom, step: f64) -> PlanView {
    let p = &ph.params;
    let an = Anatomy::new(p);
    let a = an.half_width();
    let len = an.length();
    let torso = vec![[-a, 0.0], [a, 0.0], [a, len], [-a, len]];
    let model_box = match p.variant {
        super::Variant::Full => None,
        super::Variant::Reduced => {
            let v = &ph.volume;
            let lo = v.index_to_world([-0.5, -0.5, -0.5]);
            let hi = v.index_to_world([
                v.dims[0] as f64 - 0.5,
                v.dims[1] as f64 - 0.5,
                v.dims[2] as f64 - 0.5,
            ]);
            Some(vec![
                [lo[0], lo[1]],
                [hi[0], lo[1]],
                [hi[0], hi[1]],
                [lo[0], hi[1]],
            ])
        }
    };
    let grid = Grid::over([-a, 0.0], [a, len], step);
    let height = an.height();
    let nz = (height / Z_STEP).ceil() as usize + 1;
    let liver_field = grid.sample(|x, y| {
        (0..nz)
            .map(|k| k as f64 * Z_STEP)
            .filter(|&z| an.inside(x, z))
            .map(|z| an.liver_margin(x, y, z, an.depth(x, z).max(0.0)))
            .fold(-1.0, f64::max)
    });
    let zc = an.centre_height();
    let rib_grid = Grid::over([-a, 0.0], [a, len], step / 2.0);
    let rib_field = rib_grid.sample(|x, y| {
        let hit = (0..nz)
            .map(|k| k as f64 * Z_STEP)
            .filter(|&z| z > zc && an.inside(x, z))
            .any(|z| an.in_ribs(x, y, z, an.depth(x, z).max(0.0)));
        if hit {
            1.0
        } else {
            0.0
        }
    });
    let tol = step / 4.0;
    let liver = grid.contours(&liver_field, 0.0, -1.0, tol);
    let ribs = rib_grid.contours(&rib_field, 0.5, 0.0, tol);
    PlanView {
        torso,
        model_box,
        liver,
        ribs,
    }
}

/// A regular plan grid: sample (i, j) at `origin + (i, j) * step`, padded by one sample on
/// every side (the padding holds the outside value, so that contours close).
struct Grid {
    origin: [f64; 2],
    step: f64,
    n: [usize; 2],
}

impl Grid {
    fn over(lo: [f64; 2], hi: [f64; 2], step: f64) -> Grid {
        let n = |a: usize| ((hi[a] - lo[a]) / step).ceil() as usize + 3;
        Grid {
            origin: [lo[0] - step, lo[1] - step],
            step,
            n: [n(0), n(1)],
        }
    }

    fn point(&self, i: f64, j: f64) -> [f64; 2] {
        [
            self.origin[0] + i * self.step,
            self.origin[1] + j * self.step,
        ]
    }

    /// `f` at every interior sample, row-major (`i + n_x j`); the padding ring is left NaN and
    /// set by [`Grid::contours`].
    fn sample(&self, f: impl Fn(f64, f64) -> f64 + Sync) -> Vec<f64> {
        let [nx, ny] = self.n;
        (0..ny)
            .into_par_iter()
            .flat_map_iter(|j| {
                let f = &f;
                (0..nx).map(move |i| {
                    if i == 0 || j == 0 || i == nx - 1 || j == ny - 1 {
                        f64::NAN
                    } else {
                        let [x, y] = self.point(i as f64, j as f64);
                        f(x, y)
                    }
                })
            })
            .collect()
    }

    /// Closed contours of `field` at `level` (NaN samples count as `outside`, a value below the
    /// level), thinned to `tol`.
    fn contours(&self, field: &[f64], level: f64, outside: f64, tol: f64) -> Vec<Vec<[f64; 2]>> {
        let f: Vec<f64> = field
            .iter()
            .map(|&v| {
                if v.is_nan() {
                    outside.min(level - 1.0)
                } else {
                    v
                }
            })
            .collect();
        marching_squares(&f, self.n, level)
            .into_iter()
            .map(|ring| {
                let pts: Vec<[f64; 2]> = ring.iter().map(|p| self.point(p[0], p[1])).collect();
                simplify_closed(&pts, tol)
            })
            .filter(|r| r.len() >= 3)
            .collect()
    }
}

/// Contours of the grid `f` (`n[0] x n[1]`, row-major) at `level`, in grid coordinates. Every
/// contour of a field whose border lies below the level is closed.
pub fn marching_squares(f: &[f64], n: [usize; 2], level: f64) -> Vec<Vec<[f64; 2]>> {
    let [nx, ny] = n;
    let at = |i: usize, j: usize| f[i + nx * j];
    let inside = |i: usize, j: usize| at(i, j) > level;
    // edge ids: 2 (i + nx j) for the edge (i, j)-(i+1, j), 2 (i + nx j) + 1 for (i, j)-(i, j+1)
    let h = |i: usize, j: usize| 2 * (i + nx * j);
    let v = |i: usize, j: usize| 2 * (i + nx * j) + 1;
    let mut segments: Vec<[usize; 2]> = Vec::new();
    for j in 0..ny.saturating_sub(1) {
        for i in 0..nx.saturating_sub(1) {
            let case = usize::from(inside(i, j))
                | usize::from(inside(i + 1, j)) << 1
                | usize::from(inside(i + 1, j + 1)) << 2
                | usize::from(inside(i, j + 1)) << 3;
            let (e0, e1, e2, e3) = (h(i, j), v(i + 1, j), h(i, j + 1), v(i, j));
            let centre_in =
                (at(i, j) + at(i + 1, j) + at(i + 1, j + 1) + at(i, j + 1)) / 4.0 > level;
            let pairs: &[[usize; 2]] = match case {
                1 | 14 => &[[e3, e0]],
                2 | 13 => &[[e0, e1]],
                3 | 12 => &[[e3, e1]],
                4 | 11 => &[[e1, e2]],
                6 | 9 => &[[e0, e2]],
                7 | 8 => &[[e3, e2]],
                5 if centre_in => &[[e0, e1], [e2, e3]],
                5 => &[[e3, e0], [e1, e2]],
                10 if centre_in => &[[e3, e0], [e1, e2]],
                10 => &[[e0, e1], [e2, e3]],
                _ => &[],
            };
            segments.extend_from_slice(pairs);
        }
    }
    // link the segments through their shared edges
    let mut by_edge: std::collections::HashMap<usize, Vec<usize>> = Default::default();
    for (s, pair) in segments.iter().enumerate() {
        for &e in pair {
            by_edge.entry(e).or_default().push(s);
        }
    }
    let mut used = vec![false; segments.len()];
    let mut rings = Vec::new();
    for start in 0..segments.len() {
        if used[start] {
            continue;
        }
        used[start] = true;
        let mut chain = vec![segments[start][0], segments[start][1]];
        loop {
            let last = chain[chain.len() - 1];
            let next = by_edge
                .get(&last)
                .and_then(|ss| ss.iter().copied().find(|&s| !used[s]));
            let Some(s) = next else { break };
            used[s] = true;
            let [a, b] = segments[s];
            chain.push(if a == last { b } else { a });
        }
        if chain.len() > 2 && chain[0] == chain[chain.len() - 1] {
            chain.pop();
        }
        let point = |e: usize| {
            let (cell, vertical) = (e / 2, e % 2 == 1);
            let (i, j) = (cell % nx, cell / nx);
            let (i2, j2) = if vertical { (i, j + 1) } else { (i + 1, j) };
            let (fa, fb) = (at(i, j), at(i2, j2));
            let t = if fb != fa {
                ((level - fa) / (fb - fa)).clamp(0.0, 1.0)
            } else {
                0.5
            };
            [
                i as f64 + t * (i2 as f64 - i as f64),
                j as f64 + t * (j2 as f64 - j as f64),
            ]
        };
        rings.push(chain.into_iter().map(point).collect());
    }
    rings
}

/// Douglas-Peucker thinning of a closed polygon to tolerance `tol`.
fn simplify_closed(ring: &[[f64; 2]], tol: f64) -> Vec<[f64; 2]> {
    if ring.len() < 4 {
        return ring.to_vec();
    }
    // split at the point farthest from the first, thin both halves as open paths
    let d2 = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2);
    let far = (1..ring.len())
        .max_by(|&p, &q| d2(ring[0], ring[p]).total_cmp(&d2(ring[0], ring[q])))
        .unwrap_or(1);
    let mut first: Vec<[f64; 2]> = ring[..=far].to_vec();
    let mut second: Vec<[f64; 2]> = ring[far..].to_vec();
    second.push(ring[0]);
    first = simplify_open(&first, tol);
    second = simplify_open(&second, tol);
    first.pop();
    second.pop();
    first.extend(second);
    first
}

fn simplify_open(path: &[[f64; 2]], tol: f64) -> Vec<[f64; 2]> {
    if path.len() < 3 {
        return path.to_vec();
    }
    let (a, b) = (path[0], path[path.len() - 1]);
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l = (dx * dx + dy * dy).sqrt();
    let dist = |p: [f64; 2]| {
        if l > 0.0 {
            ((p[0] - a[0]) * dy - (p[1] - a[1]) * dx).abs() / l
        } else {
            ((p[0] - a[0]).powi(2) + (p[1] - a[1]).powi(2)).sqrt()
        }
    };
    let (k, dmax) = (1..path.len() - 1)
        .map(|k| (k, dist(path[k])))
        .max_by(|x, y| x.1.total_cmp(&y.1))
        .unwrap_or((0, 0.0));
    if dmax <= tol {
        return vec![a, b];
    }
    let mut left = simplify_open(&path[..=k], tol);
    let right = simplify_open(&path[k..], tol);
    left.pop();
    left.extend(right);
    left
}

#[cfg(test)]
mod tests {
    use super::*;

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

    /// The zero contour of a circle's signed distance on a 1 mm grid is the circle: every
    /// contour point within 0.05 mm of radius 30 mm (linear interpolation of an exact distance
    /// is exact on straight crossings, and the chord error of a 30 mm circle over a 1 mm cell
    /// is about 1/(8 * 30) mm), and the enclosed area within 0.3 % of pi r^2.
    #[test]
    fn contour_of_a_circle() {
        let (r, c) = (0.030, [0.01, -0.02]);
        let grid = Grid::over([-0.05, -0.07], [0.07, 0.03], 0.001);
        let f = grid.sample(|x, y| r - ((x - c[0]).powi(2) + (y - c[1]).powi(2)).sqrt());
        let rings = grid.contours(&f, 0.0, -1.0, 0.0);
        assert_eq!(rings.len(), 1, "one closed contour");
        for p in &rings[0] {
            let d = ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt();
            assert!((d - r).abs() < 5e-5, "point {p:?} at {d} m from the centre");
        }
        let a = area(&rings[0]).abs();
        let exact = std::f64::consts::PI * r * r;
        assert!((a / exact - 1.0).abs() < 3e-3, "area {a} against {exact}");
    }

    /// Two separate squares of a 0/1 mask give two contours; the saddle between diagonal
    /// neighbours is decided by the centre (mean 1/2 is not above 1/2: they stay apart).
    #[test]
    fn mask_contours_and_saddles() {
        let n = [6, 6];
        let mut f = vec![0.0; 36];
        f[1 + 6] = 1.0; // (1, 1)
        f[2 + 2 * 6] = 1.0; // (2, 2): diagonal neighbour, a saddle cell between them
        f[4 + 4 * 6] = 1.0;
        let rings = marching_squares(&f, n, 0.5);
        assert_eq!(rings.len(), 3, "{rings:?}");
        for r in &rings {
            assert_eq!(r.len(), 4, "a diamond around one sample: {r:?}");
            assert!((area(r).abs() - 0.5).abs() < 1e-12);
        }
    }

    /// Douglas-Peucker keeps the corners of a densely sampled square and drops the rest.
    #[test]
    fn simplify_keeps_corners() {
        let mut ring = Vec::new();
        for k in 0..10 {
            ring.push([k as f64 / 10.0, 0.0]);
        }
        for k in 0..10 {
            ring.push([1.0, k as f64 / 10.0]);
        }
        for k in 0..10 {
            ring.push([1.0 - k as f64 / 10.0, 1.0]);
        }
        for k in 0..10 {
            ring.push([0.0, 1.0 - k as f64 / 10.0]);
        }
        let s = simplify_closed(&ring, 1e-6);
        assert_eq!(s.len(), 4, "{s:?}");
        assert!((area(&s) - 1.0).abs() < 1e-12);
    }
}
