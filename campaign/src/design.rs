//! Space-filling designs of palpation locations (`[[locations.design]]`): `n` points of the
//! body surface's (x, y) plane, seeded, inside a rectangle (by default the ROI's plan extent)
//! or a stated polygon.
//!
//! - **Sobol**: the first `n` points of an Owen-scrambled Sobol sequence in two dimensions
//!   (Burley 2020, "Practical hash-based Owen scrambling", JCGT 9(4); the `sobol_burley`
//!   crate), mapped onto the rectangle. The seed selects an independent scramble. A polygon
//!   keeps the sequence's points that fall inside it, in order, until it has `n`: the kept
//!   points are the Sobol points of the polygon's bounding box restricted to the polygon, and
//!   stay space-filling there.
//! - **Latin hypercube** (`lhs`; McKay, Beckman and Conover 1979): each axis cut into `n` equal
//!   strata, one point per stratum and axis, the strata paired by a seeded permutation, the
//!   point uniform within its cell. Its stratification is of a rectangle, so it takes no
//!   polygon.
//! - **Random** (`random`): independent uniform points, seeded (SplitMix64, as the surrogate's
//!   trainers), for held-out sets that no design rule chose; a polygon keeps the draws inside
//!   it.
//!
//! A design with a `phase = [lo, hi]` range is a design over (x, y, phase) for a respiratory
//! campaign: its third coordinate, mapped onto the range, is each point's respiratory phase.
//! For Sobol it is the sequence's third dimension (the (x, y) points are those of the
//! two-dimensional design with the same seed); for LHS a third stratified axis; for random a
//! uniform draw of its own stream. Either way the (x, y) points do not change.
//!
//! The same file and seed give the same points, bit for bit, on every machine (both are pure
//! integer arithmetic and one multiply-add per coordinate).

use crate::plan::{CampaignLocation, Split};
use material::quantity::{Length, Number};
use scene::palpation::Place;
use serde::Deserialize;

/// The design's region when the file names none: the ROI's plan extent as the default raster
/// spans it, x = -100..0 mm, y = 165..225 mm (corners `[x, y]`, m; see
/// [`phantom::GridParams`]).
pub fn default_extent() -> [[f64; 2]; 2] {
    let g = phantom::GridParams::default();
    let half = |a: usize| (g.n[a] as f64 - 1.0) / 2.0 * g.spacing[a];
    [
        [g.center[0] - half(0), g.center[1] - half(1)],
        [g.center[0] + half(0), g.center[1] + half(1)],
    ]
}

/// The most points a design may have: the Sobol sequence's length ([`sobol_burley`] stops at 2^16).
pub const MAX_DESIGN_POINTS: usize = 1 << 16;

/// How a design places its points.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DesignKind {
    /// Owen-scrambled Sobol sequence.
    Sobol,
    /// Latin hypercube.
    Lhs,
    /// Independent uniform points.
    Random,
}

/// `[[locations.design]]`: a space-filling design of locations (see the module doc).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DesignSpec {
    /// `sobol`, `lhs` or `random`.
    pub kind: DesignKind,
    /// Number of points.
    pub n: usize,
    /// Seed of the scramble (Sobol), of the permutations and jitter (LHS) or of the draws
    /// (random).
    pub seed: u32,
    /// `train` or `test`.
    pub split: Split,
    /// Label prefix (default "S" for Sobol, "L" for LHS, "U" for random): S01, S02, ...
    pub prefix: Option<String>,
    /// Opposite corners `[[x0, y0], [x1, y1]]` of the rectangle (default: [`default_extent`]).
    pub extent: Option<[[Length; 2]; 2]>,
    /// A polygon `[[x, y], ...]` (at least 3 corners, in either order) instead of a rectangle;
    /// Sobol and random only.
    pub polygon: Option<Vec<[Length; 2]>>,
    /// `[lo, hi]`: the respiratory phases the design spans (module doc); absent: the points
    /// have no phase of their own.
    pub phase: Option<[Number; 2]>,
}

impl DesignSpec {
    /// The design's locations, labelled `prefix` + index from 1 (two digits at least).
    pub fn locations(&self) -> Result<Vec<CampaignLocation>, String> {
        let prefix = self.prefix.clone().unwrap_or_else(|| match self.kind {
            DesignKind::Sobol => "S".into(),
            DesignKind::Lhs => "L".into(),
            DesignKind::Random => "U".into(),
        });
        crate::label::check_label(&prefix)?;
        let width = self.n.to_string().len().max(2);
        Ok(self
            .points_with_phase()?
            .into_iter()
            .enumerate()
            .map(|(k, ([x, y], phase))| CampaignLocation {
                label: format!("{prefix}{:0width$}", k + 1),
                split: self.split,
                place: Place::At(x, y),
                phase,
            })
            .collect())
    }

    /// The design's points (x, y) in m, each with its respiratory phase when the design has a
    /// `phase` range (module doc).
    pub fn points_with_phase(&self) -> Result<Vec<([f64; 2], Option<f64>)>, String> {
        let n = self.n;
        if n == 0 || n > MAX_DESIGN_POINTS {
            return Err(format!(
                "locations.design: n = {n}; a design has 1 to {MAX_DESIGN_POINTS} points"
            ));
        }
        let drawn = self.region()?.draw_indexed(self.kind, n, self.seed)?;
        let Some([lo, hi]) = self.phase.map(|p| [p[0].0, p[1].0]) else {
            return Ok(drawn.into_iter().map(|(_, p)| (p, None)).collect());
        };
        for p in [lo, hi] {
            crate::phase::check_phase(p, "locations.design.phase")?;
        }
        if lo > hi {
            return Err(format!(
                "locations.design.phase: [{lo}, {hi}] is not a range (low first)"
            ));
        }
        let idx: Vec<usize> = drawn.iter().map(|d| d.0).collect();
        let u = third_axis(self.kind, &idx, self.seed);
        Ok(drawn
            .into_iter()
            .zip(u)
            .map(|((_, p), u)| (p, Some(lo + (hi - lo) * u)))
            .collect())
    }

    /// The region the design fills.
    pub fn region(&self) -> Result<Region, String> {
        match (&self.extent, &self.polygon) {
            (Some(_), Some(_)) => {
                Err("locations.design: give `extent` or `polygon`, not both".into())
            }
            (_, Some(poly)) => Ok(Region::Polygon(
                poly.iter().map(|p| [p[0].0, p[1].0]).collect(),
            )),
            (Some(e), None) => Ok(Region::Rect(checked_extent([
                [e[0][0].0, e[0][1].0],
                [e[1][0].0, e[1][1].0],
            ])?)),
            (None, None) => Ok(Region::Rect(default_extent())),
        }
    }

    /// The design's points (x, y) in m.
    pub fn points(&self) -> Result<Vec<[f64; 2]>, String> {
        Ok(self.points_with_phase()?.into_iter().map(|p| p.0).collect())
    }
}

/// Where a design's points lie, in the (x, y) plane of the body surface (m).
#[derive(Clone, Debug, PartialEq)]
pub enum Region {
    /// A rectangle, corners low and high.
    Rect([[f64; 2]; 2]),
    /// A polygon (at least 3 corners).
    Polygon(Vec<[f64; 2]>),
}

impl Region {
    /// The first `n` Sobol points of `seed` that lie in the region.
    pub fn sobol(&self, n: usize, seed: u32) -> Result<Vec<[f64; 2]>, String> {
        self.draw(DesignKind::Sobol, n, seed)
    }

    /// `n` points of `kind` and `seed` in the region (module doc): a Latin hypercube of the
    /// rectangle, or the first `n` Sobol or random points of the bounding box that lie inside.
    pub fn draw(&self, kind: DesignKind, n: usize, seed: u32) -> Result<Vec<[f64; 2]>, String> {
        Ok(self
            .draw_indexed(kind, n, seed)?
            .into_iter()
            .map(|d| d.1)
            .collect())
    }

    /// [`Region::draw`] with each point's index in its sequence (for a third coordinate).
    fn draw_indexed(
        &self,
        kind: DesignKind,
        n: usize,
        seed: u32,
    ) -> Result<Vec<(usize, [f64; 2])>, String> {
        let (bbox, poly) = match self {
            Region::Rect(r) => (*r, None),
            Region::Polygon(p) => (polygon_bbox(p)?, Some(p)),
        };
        if kind == DesignKind::Lhs {
            if poly.is_some() {
                return Err("locations.design: a Latin hypercube stratifies a rectangle; use kind = \"sobol\" for a polygon, or `extent`".into());
            }
            return Ok(latin_hypercube(n, seed)
                .into_iter()
                .enumerate()
                .map(|(k, u)| (k, map_to(&bbox, u)))
                .collect());
        }
        let mut out = Vec::with_capacity(n.min(MAX_DESIGN_POINTS));
        let mut g = surrogate::rng::Rng::new(u64::from(seed));
        for i in 0..MAX_DESIGN_POINTS {
            if out.len() == n {
                return Ok(out);
            }
            let u = match kind {
                DesignKind::Random => [g.uniform(), g.uniform()],
                _ => sobol_point(i, seed),
            };
            let p = map_to(&bbox, u);
            if poly.is_none_or(|q| inside(q, p)) {
                out.push((i, p));
            }
        }
        if out.len() == n {
            return Ok(out);
        }
        Err(format!(
            "locations.design.polygon: only {} of {MAX_DESIGN_POINTS} points drawn lie inside the polygon, fewer than n = {n}",
            out.len()
        ))
    }
}

/// The seed of a design's third (phase) axis for random and LHS designs: a stream of its own,
/// so that the (x, y) points do not change.
const PHASE_STREAM: u64 = 0x5048_4153_4500_0000;

/// The third coordinate in [0, 1) of the design points with sequence indices `idx` (module
/// doc).
fn third_axis(kind: DesignKind, idx: &[usize], seed: u32) -> Vec<f64> {
    let mut rng = surrogate::rng::Rng::new(u64::from(seed) ^ PHASE_STREAM);
    match kind {
        DesignKind::Sobol => idx
            .iter()
            .map(|&i| f64::from(sobol_burley::sample(i as u32, 2, seed)))
            .collect(),
        DesignKind::Random => {
            let last = idx.iter().copied().max().unwrap_or(0);
            let u: Vec<f64> = (0..=last).map(|_| rng.uniform()).collect();
            idx.iter().map(|&i| u[i]).collect()
        }
        DesignKind::Lhs => {
            let n = idx.len();
            let mut perm: Vec<usize> = (0..n).collect();
            rng.shuffle(&mut perm);
            perm.iter()
                .map(|&p| (p as f64 + rng.uniform()) / n as f64)
                .collect()
        }
    }
}

/// Sobol point `i` in the unit square.
fn sobol_point(i: usize, seed: u32) -> [f64; 2] {
    let i = i as u32;
    [
        f64::from(sobol_burley::sample(i, 0, seed)),
        f64::from(sobol_burley::sample(i, 1, seed)),
    ]
}

/// A Latin hypercube of `n` points in the unit square (see the module doc).
fn latin_hypercube(n: usize, seed: u32) -> Vec<[f64; 2]> {
    let mut rng = surrogate::rng::Rng::new(u64::from(seed));
    let mut perms = [(0..n).collect::<Vec<_>>(), (0..n).collect::<Vec<_>>()];
    for p in &mut perms {
        rng.shuffle(p);
    }
    (0..n)
        .map(|k| {
            let mut u = [0.0; 2];
            for (a, p) in perms.iter().enumerate() {
                u[a] = (p[k] as f64 + rng.uniform()) / n as f64;
            }
            u
        })
        .collect()
}

/// `u` of the unit square onto the rectangle `r` (corners, ordered).
fn map_to(r: &[[f64; 2]; 2], u: [f64; 2]) -> [f64; 2] {
    [
        r[0][0] + (r[1][0] - r[0][0]) * u[0],
        r[0][1] + (r[1][1] - r[0][1]) * u[1],
    ]
}

/// Corners ordered low-high, finite, with positive area.
fn checked_extent(e: [[f64; 2]; 2]) -> Result<[[f64; 2]; 2], String> {
    let lo = [e[0][0].min(e[1][0]), e[0][1].min(e[1][1])];
    let hi = [e[0][0].max(e[1][0]), e[0][1].max(e[1][1])];
    if !(lo.iter().chain(&hi).all(|v| v.is_finite()) && hi[0] > lo[0] && hi[1] > lo[1]) {
        return Err(format!(
            "locations.design.extent: corners {:?} and {:?} m do not span a rectangle",
            e[0], e[1]
        ));
    }
    Ok([lo, hi])
}

/// The bounding box of a polygon of at least 3 corners that encloses some area.
fn polygon_bbox(poly: &[[f64; 2]]) -> Result<[[f64; 2]; 2], String> {
    if poly.len() < 3 {
        return Err(format!(
            "locations.design.polygon: {} corners; a polygon needs at least 3",
            poly.len()
        ));
    }
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in poly {
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    checked_extent([lo, hi])
        .map_err(|_| "locations.design.polygon: the corners enclose no area".to_string())
}

/// Whether `p` lies inside the polygon: the even-odd crossing rule (W. R. Franklin's PNPOLY;
/// Shimrat 1962, "Algorithm 112: position of point relative to polygon"); a point on an edge
/// may go either way.
fn inside(poly: &[[f64; 2]], p: [f64; 2]) -> bool {
    let mut c = false;
    let mut j = poly.len() - 1;
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[j]);
        if (a[1] > p[1]) != (b[1] > p[1])
            && p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0]
        {
            c = !c;
        }
        j = i;
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(kind: DesignKind, n: usize) -> DesignSpec {
        DesignSpec {
            kind,
            n,
            seed: 3,
            split: Split::Train,
            prefix: None,
            extent: None,
            polygon: None,
            phase: None,
        }
    }

    /// A Latin hypercube has exactly one point in each of the n strata of each axis.
    #[test]
    fn lhs_fills_every_stratum_once() {
        let n = 37;
        let pts = spec(DesignKind::Lhs, n).points().unwrap();
        let [lo, hi] = default_extent();
        for a in 0..2 {
            let mut count = vec![0; n];
            for p in &pts {
                let s = ((p[a] - lo[a]) / (hi[a] - lo[a]) * n as f64).floor() as usize;
                count[s] += 1;
            }
            assert!(count.iter().all(|&c| c == 1), "axis {a}: {count:?}");
        }
    }

    /// 64 Sobol points (a power of two) put exactly one point in each cell of an 8 x 8 grid of
    /// the rectangle: the (0, m, 2)-net property that scrambling keeps.
    #[test]
    fn sobol_is_a_net() {
        let pts = spec(DesignKind::Sobol, 64).points().unwrap();
        let [lo, hi] = default_extent();
        let mut cells = [0; 64];
        for p in &pts {
            let i = ((p[0] - lo[0]) / (hi[0] - lo[0]) * 8.0).floor() as usize;
            let j = ((p[1] - lo[1]) / (hi[1] - lo[1]) * 8.0).floor() as usize;
            cells[8 * j + i] += 1;
        }
        assert!(cells.iter().all(|&c| c == 1), "{cells:?}");
    }

    /// Seeds give different points; the same seed the same bits; labels are S01.. in order.
    #[test]
    fn seeded_and_labelled() {
        let a = spec(DesignKind::Sobol, 12).locations().unwrap();
        let b = spec(DesignKind::Sobol, 12).locations().unwrap();
        let mut s = spec(DesignKind::Sobol, 12);
        s.seed = 4;
        let c = s.locations().unwrap();
        assert_eq!(a, b);
        assert_ne!(a[0].place, c[0].place);
        assert_eq!(a[0].label, "S01");
        assert_eq!(a[11].label, "S12");
    }

    /// Every point of a triangle design lies inside the triangle.
    #[test]
    fn polygon_keeps_points_inside() {
        let mm = |v: f64| Length(v * 1e-3);
        let mut s = spec(DesignKind::Sobol, 40);
        s.polygon = Some(vec![
            [mm(-100.0), mm(165.0)],
            [mm(0.0), mm(165.0)],
            [mm(-100.0), mm(225.0)],
        ]);
        let pts = s.points().unwrap();
        assert_eq!(pts.len(), 40);
        for p in pts {
            let (u, v) = ((p[0] + 0.1) / 0.1, (p[1] - 0.165) / 0.06);
            assert!(u >= 0.0 && v >= 0.0 && u + v <= 1.0 + 1e-12, "{p:?}");
        }
        s.kind = DesignKind::Random;
        for p in s.points().unwrap() {
            let (u, v) = ((p[0] + 0.1) / 0.1, (p[1] - 0.165) / 0.06);
            assert!(u >= 0.0 && v >= 0.0 && u + v <= 1.0 + 1e-12, "{p:?}");
        }
        s.kind = DesignKind::Lhs;
        assert!(s.points().unwrap_err().contains("rectangle"));
    }

    #[test]
    fn bad_designs_are_refused() {
        assert!(spec(DesignKind::Sobol, 0)
            .points()
            .unwrap_err()
            .contains("n = 0"));
        let mut s = spec(DesignKind::Sobol, 4);
        s.extent = Some([[Length(0.0), Length(0.1)], [Length(0.0), Length(0.2)]]);
        assert!(s.points().unwrap_err().contains("rectangle"));
        s.extent = None;
        s.polygon = Some(vec![[Length(0.0), Length(0.0)], [Length(1.0), Length(1.0)]]);
        assert!(s.points().unwrap_err().contains("at least 3"));
        s.polygon = None;
        s.prefix = Some("../x".into());
        assert!(s.locations().unwrap_err().contains("directory"));
    }

    /// A phase range makes a design over (x, y, phase): the (x, y) points stay those of the
    /// plain design; every phase lies in the range; LHS stratifies the phase axis too; Sobol's
    /// third dimension fills it (every eighth of it holds points among the first 64); a bad
    /// range is refused.
    #[test]
    fn phase_range_adds_a_third_coordinate() {
        for kind in [DesignKind::Sobol, DesignKind::Lhs, DesignKind::Random] {
            let plain = spec(kind, 64).points().unwrap();
            let mut s = spec(kind, 64);
            s.phase = Some([Number(0.2), Number(0.6)]);
            let pts = s.points_with_phase().unwrap();
            let xy: Vec<[f64; 2]> = pts.iter().map(|p| p.0).collect();
            assert_eq!(xy, plain, "{kind:?}");
            let ph: Vec<f64> = pts.iter().map(|p| p.1.unwrap()).collect();
            assert!(ph.iter().all(|&p| (0.2..=0.6).contains(&p)), "{kind:?}");
            let mut count = [0usize; 64];
            for &p in &ph {
                count[(((p - 0.2) / 0.4 * 64.0) as usize).min(63)] += 1;
            }
            match kind {
                DesignKind::Lhs => assert!(count.iter().all(|&c| c == 1), "{count:?}"),
                DesignKind::Sobol => {
                    assert!(
                        count.chunks(8).all(|c| c.iter().sum::<usize>() == 8),
                        "{count:?}"
                    )
                }
                DesignKind::Random => {}
            }
            assert!(s.locations().unwrap().iter().all(|l| l.phase.is_some()));
        }
        let mut s = spec(DesignKind::Sobol, 4);
        s.phase = Some([Number(0.5), Number(1.5)]);
        assert!(s.points().unwrap_err().contains("outside 0"));
        s.phase = Some([Number(0.8), Number(0.2)]);
        assert!(s.points().unwrap_err().contains("not a range"));
    }
}
