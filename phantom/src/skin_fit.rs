//! A skin fitted to the body outline: the voxel grid's columns stretched so that the skin is
//! one layer of nodes on the analytic surface, with no voxel steps.
//!
//! On a voxel mesh the anterior skin is a staircase: where it slopes by theta the surface rises
//! one voxel h every h / tan(theta) (18 mm at 3 mm and 9.4 degrees), and Taubin smoothing
//! (`voxel/smooth.rs`), a low-pass filter with element-quality limits, leaves most of it: facets
//! 2 degrees and 60 degrees steep, nodes up to 1.3 mm off the outline. A finger sliding along
//! such a slope meets the riser faces one after another, and the liver's stress follows them
//! (the line study of `docs/surrogate.md`). A step is a change in the number of voxels in a column, so it
//! cannot be smoothed away without collapsing the element at its corner.
//!
//! With `skin = "fitted"` the phantom is labelled and meshed in a grid whose columns are
//! stretched vertically instead. With z0 the bottom face of the meshed box (the reduced
//! model's fixed bottom cut, the table for the full one), s(x) the analytic skin height
//! (`Anatomy::skin_z`) and S a grid face, a grid point (x, y, zeta) lies in the body at
//!
//! ```text
//! z = zeta                                  zeta <= z0
//! z = z0 + (zeta - z0) r(x),  r(x) = (s(x_c) - z0) / (S - z0),  x_c = clamp(x, -X, X)
//! ```
//!
//! so grid face S is the skin wherever |x| <= X, and every label is that of the point
//! of the body the grid point maps to ([`crate::full_volume`]); the mesh's nodes are mapped
//! the same way after meshing and smoothing. Columns keep their voxel counts, so inside
//! |x| <= X the skin is one node layer on s(x) and its facets are chords of the outline.
//! Beyond X, where the skin is steeper than [`MAX_SLOPE_DEG`], the columns keep the stretch
//! at X and the flank stays a (smoothed) staircase.
//!
//! - **Cut planes stay planar.** The map moves nodes only along z: the x and y cut faces
//!   stay planes, and the bottom face z0 does not move.
//! - **Cost.** Elements are stretched by r between r(X) and r(0). S is the grid face nearest
//!   the geometric mean of the skin heights above z0 at the midline and at X, so that the
//!   tallest and the flattest columns are stretched and squeezed by about the same factor
//!   (1.160 and 0.889 at 3 mm on the reduced model); a squeezed element has a shorter
//!   characteristic length and so a smaller stable time step. `palpa mesh phantom` prints
//!   the range.
//! - **Shear.** A column's top face tilts with the skin, at most [`MAX_SLOPE_DEG`].
//! - **Where it stops.** On the default torso X is 95.8 mm. The default design region
//!   reaches x = -100 mm and the fingers stand 20 mm apart along x, so a press left of about
//!   x = -86 mm puts the outer finger on the flank's steps.
//! - **Whole voxels.** The skin is one grid face, so the fit refuses voxel coarsening
//!   (`coarsen > 1` would mesh coarse faces that miss S).

use rayon::prelude::*;
use solver::mesh::Mesh;

use crate::anatomy::Anatomy;
use crate::voxel::jacobian::{corner_jacobians, element_coords};

/// The steepest skin the fit follows (degrees); beyond it the flank keeps its voxel steps.
pub const MAX_SLOPE_DEG: f64 = 30.0;

/// The column stretch of a fitted skin (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkinFit {
    /// Bottom face of the meshed box, where the map is the identity (m).
    pub z0: f64,
    /// The grid face that becomes the skin (m).
    pub face: f64,
    /// Half-width of the fitted band, |x| <= `half_width` (m).
    pub half_width: f64,
    /// s(0) and s(X): the skin's height at the midline and at the band's edge (m).
    skin_mid: f64,
    skin_edge: f64,
}

impl SkinFit {
    /// The fit for an anatomy, a meshed box whose bottom face is `z0` and voxels of edge `h`.
    pub fn new(an: &Anatomy, z0: f64, h: f64) -> Result<SkinFit, String> {
        let slope = |x: f64| {
            let d = 1e-6;
            ((an.skin_z(x + d) - an.skin_z(x - d)) / (2.0 * d)).abs()
        };
        let limit = MAX_SLOPE_DEG.to_radians().tan();
        let (mut lo, mut hi) = (0.0, an.half_width() * (1.0 - 1e-6));
        for _ in 0..60 {
            let m = 0.5 * (lo + hi);
            if slope(m) <= limit {
                lo = m;
            } else {
                hi = m;
            }
        }
        let (skin_mid, skin_edge) = (an.skin_z(0.0), an.skin_z(lo));
        if skin_edge - z0 < 4.0 * h {
            return Err(format!(
                "skin = \"fitted\": the skin at the fitted band's edge ({:.1} mm) lies only {:.1} mm above the meshed box's bottom",
                skin_edge * 1e3,
                (skin_edge - z0) * 1e3
            ));
        }
        let mean = z0 + ((skin_mid - z0) * (skin_edge - z0)).sqrt();
        // S is a face of the grid: the grid's faces lie at whole multiples of h
        let face = (mean / h).round() * h;
        Ok(SkinFit {
            z0,
            face,
            half_width: lo,
            skin_mid,
            skin_edge,
        })
    }

    /// Stretch of the column at x: r(x) (module doc).
    pub fn ratio(&self, an: &Anatomy, x: f64) -> f64 {
        let xc = x.clamp(-self.half_width, self.half_width);
        (an.skin_z(xc) - self.z0) / (self.face - self.z0)
    }

    /// The smallest and largest stretch, at the band's edge and at the midline.
    pub fn ratio_range(&self) -> (f64, f64) {
        let r = |s: f64| (s - self.z0) / (self.face - self.z0);
        (r(self.skin_edge), r(self.skin_mid))
    }

    /// Move the nodes of a mesh of the stretched grid to the body, and check that every
    /// element kept positive corner Jacobians (the map's own Jacobian is r(x) > 0, so only a
    /// smoothed element already close to its limit could fail).
    pub fn map_mesh(&self, an: &Anatomy, mesh: &mut Mesh) -> Result<(), String> {
        mesh.nodes
            .par_iter_mut()
            .for_each(|x| x[2] = self.body_z(an, x[0], x[2]));
        let bad = (0..mesh.elements.len()).into_par_iter().find_first(|&e| {
            corner_jacobians(&element_coords(&mesh.nodes, &mesh.elements[e]))
                .iter()
                .any(|&j| j <= 0.0)
        });
        match bad {
            None => Ok(()),
            Some(e) => {
                let c = mesh.nodes[mesh.elements[e][0] as usize];
                Err(format!(
                    "skin = \"fitted\": element {e} (corner at ({:.1}, {:.1}, {:.1}) mm) has a non-positive corner Jacobian after the column stretch",
                    c[0] * 1e3,
                    c[1] * 1e3,
                    c[2] * 1e3
                ))
            }
        }
    }

    /// Height in the body of grid point (x, zeta).
    pub fn body_z(&self, an: &Anatomy, x: f64, zeta: f64) -> f64 {
        if zeta <= self.z0 {
            zeta
        } else {
            self.z0 + (zeta - self.z0) * self.ratio(an, x)
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::voxel::jacobian::{centre_jacobian, element_coords};
    use crate::*;

    fn params(variant: Variant, skin: Skin) -> PhantomParams {
        PhantomParams {
            variant,
            voxel: 0.006,
            skin,
            ..Default::default()
        }
    }

    fn part_volume(ph: &Phantom, part: &str) -> f64 {
        let pid = ph.mesh.part_names.iter().position(|n| n == part).unwrap() as u32;
        (0..ph.mesh.n_elements())
            .filter(|&e| ph.mesh.element_part[e] == pid)
            .map(|e| 8.0 * centre_jacobian(&element_coords(&ph.mesh.nodes, &ph.mesh.elements[e])))
            .sum()
    }

    /// The largest height of an anterior skin node in the fitted band above or below the
    /// outline (m), and how many nodes were measured. (The full torso's skin set also holds
    /// upward faces of voxel steps near the table, which the fit leaves alone.)
    fn skin_offset(ph: &Phantom, band: f64) -> (f64, usize) {
        let an = Anatomy::new(&ph.params);
        let mut worst: (f64, usize) = (0.0, 0);
        for &v in &ph.mesh.node_sets["skin"] {
            let x = ph.mesh.nodes[v as usize];
            if x[0].abs() < band && x[2] > 0.5 * an.height() {
                worst.0 = worst.0.max((x[2] - an.skin_z(x[0])).abs());
                worst.1 += 1;
            }
        }
        worst
    }

    #[test]
    fn fitted_skin_lies_on_the_outline_and_keeps_the_body() {
        for variant in [Variant::Reduced, Variant::Full] {
            let (voxel, fitted) = (
                build(&params(variant, Skin::Voxel)).unwrap(),
                build(&params(variant, Skin::Fitted)).unwrap(),
            );
            let h = fitted.params.voxel;
            let an = Anatomy::new(&fitted.params);
            let (_, _, fit) = full_volume(&fitted.params).unwrap();
            let fit = fit.unwrap();
            // the band stops where the skin is 30 degrees steep: 95.8 mm from the midline on
            // the default torso (the superellipse's slope), short of the design region's
            // x = -100 mm
            assert!((0.09..0.10).contains(&fit.half_width), "{fit:?}");
            // every skin node inside the band lies on s(x), but for the smoothing of the
            // flank's steps, which reaches a few voxels into the band; the voxel skin misses
            // it by a good part of a voxel
            let band = fit.half_width - h;
            let (off, n) = skin_offset(&fitted, band);
            assert!(n > 200, "{n} skin nodes in the band");
            assert!(
                off < 0.05 * h,
                "{variant:?}: a fitted skin node is {off} m off the outline"
            );
            let (off, _) = skin_offset(&fitted, band - 8.0 * h);
            assert!(
                off < 1e-6,
                "{variant:?}: a fitted skin node is {off} m off the outline"
            );
            let (off_voxel, _) = skin_offset(&voxel, band);
            assert!(
                off_voxel > 0.25 * h,
                "{variant:?}: voxel skin off by {off_voxel} m"
            );
            // every element stays valid
            assert_eq!(fitted.quality.n_nonpositive, 0);
            assert!(fitted.quality.min_scaled_jacobian > 0.2);
            // the same body: the liver's volume within 3 %, the same locations and columns
            let (lv, lf) = (part_volume(&voxel, "liver"), part_volume(&fitted, "liver"));
            assert!(
                (lf / lv - 1.0).abs() < 0.03,
                "liver {lv} m^3 voxel, {lf} m^3 fitted"
            );
            for (a, b) in [
                (&voxel.locations.a, &fitted.locations.a),
                (&voxel.locations.b, &fitted.locations.b),
                (&voxel.locations.c, &fitted.locations.c),
            ] {
                assert_eq!(a.surface[..2], b.surface[..2]);
                // columns read from the body's plain labels, not the stretched grid's
                assert_eq!((a.liver_depth, a.under_ribs), (b.liver_depth, b.under_ribs));
                let s = an.skin_z(b.surface[0]);
                assert!(
                    (b.surface[2] - s).abs() < 0.05 * h,
                    "{}: {:?}",
                    b.name,
                    b.surface
                );
            }
            // the bottom face does not move
            if variant == Variant::Reduced {
                assert!(fitted.mesh.node_sets["back"]
                    .iter()
                    .all(|&v| (fitted.mesh.nodes[v as usize][2] - fit.z0).abs() < 1e-12));
            }
            // the stretch stays within 20 % either way
            let (rmin, rmax) = fit.ratio_range();
            assert!(rmin > 0.8 && rmax < 1.25, "{rmin} {rmax}");
        }
    }

    #[test]
    fn a_fitted_skin_refuses_coarsening() {
        let mut p = params(Variant::Reduced, Skin::Fitted);
        p.mesh.coarsen = 2;
        let e = build(&p).unwrap_err();
        assert!(e.contains("fitted") && e.contains("coarsen = 2"), "{e}");
    }

    #[test]
    fn unknown_skin_is_named() {
        let e = "fited".parse::<Skin>().unwrap_err();
        assert!(e.contains("fited") && e.contains("voxel | fitted"), "{e}");
        assert_eq!("fitted".parse::<Skin>(), Ok(Skin::Fitted));
    }
}
