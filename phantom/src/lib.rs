//! Procedural abdomen phantom: a deterministic, parametric stand-in for the paper's CT-based
//! model (XCAT phantom, simplified to flesh, liver, ribs and lumped viscera).
//!
//! # Frame
//! Right-handed, in m, patient supine on a table:
//! - **x** towards the patient's **left**; x = 0 on the midline. The liver (right upper
//!   quadrant) lies mostly at **x < 0**.
//! - **y** **cranial** (towards the head); y = 0 at the caudal end of the torso, y = L
//!   (default 0.30 m) at its cranial end.
//! - **z** **anterior** (up); z = 0 is the flat back on the table, the skin on top is at
//!   about z = 0.22 m. Fingers press in **-z**.
//!
//! # Body plan
//! See `anatomy.rs`: a superellipse torso 300 x 220 mm, subcutaneous fat of given thickness
//! over a 12 mm muscle and rib layer, ribs 6-12 with costal cartilage and sternum, a liver
//! shaped as a rounded wedge with a sharp inferior edge reaching below the costal margin, a
//! spine column, lumped viscera, optional tumours. Labels: 1 flesh, 2 liver, 3 ribs,
//! 4 viscera, 5 spine, 6.. tumours; parts "flesh", "liver", "ribs", "viscera", "spine",
//! "tumour", "tumour2", ...
//!
//! # Variants and boundary conditions
//! - **Full**: the whole torso. Node sets: "back" (the flat back on z = 0 plus every spine
//!   node: fixed), "cut_ymin", "cut_ymax" (the torso's caudal and cranial cut faces; rollers
//!   if wanted), "cut_xmin", "cut_xmax" (empty), "skin".
//! - **Reduced**: the box x in [-(a + h), 40 mm], y from 195 mm below the top (minus the
//!   respiratory shift) to the top, z from 125 mm up: the anterior ("top") half of the liver
//!   and the tissue around it. "back" is the bottom cut face z = 125 mm (fixed); "cut_xmax",
//!   "cut_ymin", "cut_ymax" (and "cut_xmin", empty: the box reaches past the right flank)
//!   are roller faces (fix the normal displacement). Cut faces stay exactly planar through
//!   smoothing.
//! - "skin": nodes of the anterior skin, the faces of the outer surface (not on a cut
//!   plane) whose outward normal has z > 0.05 (every upward-facing face, so that a steep,
//!   smoothed voxel step on a coarse mesh leaves no hole under a palpation location); the faces themselves are in
//!   [`Phantom::skin_faces`] (outward normal by the right-hand rule), for finger contact.
//! - The skin is smoothed voxel steps ([`Skin::Voxel`], the default) or one node layer on the
//!   analytic outline where it is under 30 degrees steep ([`Skin::Fitted`]: the grid's
//!   columns stretched to meet it, `skin_fit.rs`).
//!
//! # Counts
//! Measured with the defaults (torso 300 x 220 x 300 mm, fat 15 mm, phase 0), release build:
//!
//! | variant | voxel | hexahedra | flesh | liver | ribs | viscera | spine |
//! |---|---|---|---|---|---|---|---|
//! | full | 5 mm (default) | 131,640 | 44,836 | 10,903 | 3,224 | 65,537 | 7,140 |
//! | reduced | 5 mm (default) | 22,971 | 8,174 | 5,048 | 640 | 9,109 | 0 |
//! | full | 3 mm (paper-like) | 611,800 | 211,958 | 50,518 | 14,192 | 301,282 | 33,850 |
//! | reduced | 3 mm (paper-like) | 104,455 | 37,626 | 22,871 | 2,869 | 41,089 | 0 |
//!
//! (paper: 547,250 full and 112,955 reduced). After smoothing the minimum scaled Jacobian is
//! 0.30 and the smallest characteristic length V / A_max is 0.6 voxel.

mod anatomy;
mod locations;
mod params;
pub mod plan;
mod roi;
mod skin_fit;
pub mod voxel;

pub use anatomy::{Anatomy, BACKGROUND, FLESH, LIVER, RIBS, SPINE, TUMOUR, VISCERA};
pub use locations::{
    cast_down, find_locations, location_at, skin_fit, Location, Locations, SKIN_FIT_RADIUS,
    TEST_SEARCH_VOXEL,
};
pub use params::{
    GridParams, PhantomParams, RoiParams, Skin, Tumour, Variant, DEFAULT_VOXEL, PAPER_VOXEL,
};
pub use plan::{plan_view, PlanView, PLAN_STEP};
pub use roi::{carry_roi, organ_parts, select_roi, surface_elements, Roi};
pub use skin_fit::{SkinFit, MAX_SLOPE_DEG};

use rayon::prelude::*;

use crate::voxel::{mesh_volume, write_preview_at, LabelMap, LabelVolume, MeshQuality};
use solver::mesh::Mesh;

/// A built phantom: labels, mesh, boundary sets, ROI and palpation locations.
#[derive(Clone, Debug)]
pub struct Phantom {
    /// The parameters it was built from.
    pub params: PhantomParams,
    /// The body's label volume (cropped for the reduced variant), before clean-up: the one
    /// that was meshed, or for a fitted skin the same grid unstretched (the mesh came from its
    /// stretched twin, [`full_volume`]). Locations read their columns from it.
    pub volume: LabelVolume,
    /// Label -> part map used for meshing.
    pub label_map: LabelMap,
    /// The smoothed hexahedral mesh, with node sets "back", "cut_xmin", "cut_xmax",
    /// "cut_ymin", "cut_ymax", "skin", "surface" and element sets per part and "roi".
    pub mesh: Mesh,
    /// Mesh quality figures.
    pub quality: MeshQuality,
    /// Anterior skin faces (global nodes, outward normal), for contact.
    pub skin_faces: Vec<[u32; 4]>,
    /// Region of interest.
    pub roi: Roi,
    /// Palpation raster and test locations.
    pub locations: Locations,
    /// (tumour part name, stiffness factor relative to liver).
    pub tumours: Vec<(String, f64)>,
    /// The column stretch of a fitted skin (`skin = "fitted"`), `None` for voxel steps.
    pub skin_fit: Option<SkinFit>,
}

/// The phantom's part names, labels 1..5 (tumours come after, see [`tumour_part_name`]).
pub const PART_NAMES: [&str; 5] = ["flesh", "liver", "ribs", "viscera", "spine"];

/// Part name of the phantom's n-th tumour (0-based): "tumour", "tumour2", "tumour3", ...
pub fn tumour_part_name(n: usize) -> String {
    if n == 0 {
        "tumour".to_string()
    } else {
        format!("tumour{}", n + 1)
    }
}

/// Whether `name` is a tumour part's name ([`tumour_part_name`] of some n).
pub fn is_tumour_part(name: &str) -> bool {
    name == "tumour"
        || name
            .strip_prefix("tumour")
            .is_some_and(|n| n.parse::<usize>().is_ok_and(|n| n >= 2))
}

/// Label map of the phantom.
pub fn label_map(p: &PhantomParams) -> LabelMap {
    let mut m = LabelMap::new();
    for (label, name) in [FLESH, LIVER, RIBS, VISCERA, SPINE]
        .into_iter()
        .zip(PART_NAMES)
    {
        m = m.with(label, name);
    }
    for n in 0..p.tumours.len() {
        m = m.with(TUMOUR + n as u8, &tumour_part_name(n));
    }
    m
}

/// Voxel box of the variant: (lo, hi) voxel indices into the full grid.
fn crop_box(p: &PhantomParams, an: &Anatomy, full: &LabelVolume) -> ([usize; 3], [usize; 3]) {
    match p.variant {
        Variant::Full => ([0; 3], full.dims),
        Variant::Reduced => {
            let h = p.voxel;
            let o = full.index_to_world([-0.5, -0.5, -0.5]); // lower faces of voxel 0
            let idx =
                |a: usize, v: f64| (((v - o[a]) / h).round().max(0.0) as usize).min(full.dims[a]);
            let top = p.torso_length;
            let lo = [0, idx(1, top - 0.195 - an.shift()), idx(2, 0.125)];
            let hi = [idx(0, 0.040), full.dims[1], full.dims[2]];
            (lo, hi)
        }
    }
}

/// The full-torso label volume, the anatomy it came from and, for a fitted skin, the column
/// stretch its grid was labelled through (a grid point (x, y, zeta) holds the label of body
/// point (x, y, [`SkinFit::body_z`])).
pub fn full_volume(p: &PhantomParams) -> Result<(LabelVolume, Anatomy, Option<SkinFit>), String> {
    p.validate()?;
    let an = Anatomy::new(p);
    let h = p.voxel;
    let nxh = (an.half_width() / h).ceil() as usize + 1;
    let dims = [
        2 * nxh,
        (p.torso_length / h + 1e-9).floor() as usize,
        (an.height() / h).ceil() as usize + 1,
    ];
    let mut vol = LabelVolume::new(
        dims,
        [h; 3],
        [-(nxh as f64) * h + h / 2.0, h / 2.0, h / 2.0],
    );
    let fit = match p.skin {
        Skin::Voxel => None,
        Skin::Fitted => {
            let (lo, _) = crop_box(p, &an, &vol);
            let z0 = vol.index_to_world([0.0, 0.0, lo[2] as f64 - 0.5])[2];
            Some(SkinFit::new(&an, z0, h)?)
        }
    };
    let [nx, ny, _] = dims;
    let slabs: Vec<Vec<u8>> = (0..dims[2])
        .into_par_iter()
        .map(|k| {
            let mut s = vec![0u8; nx * ny];
            for j in 0..ny {
                for i in 0..nx {
                    let c = vol.voxel_center(i, j, k);
                    let z = fit.map_or(c[2], |f| f.body_z(&an, c[0], c[2]));
                    s[i + nx * j] = an.label(c[0], c[1], z);
                }
            }
            s
        })
        .collect();
    vol.labels = slabs.concat();
    Ok((vol, an, fit))
}

/// The body's label volume of the chosen variant (cropped for the reduced model), unmeshed,
/// on the plain voxel grid whatever the skin (a fitted skin's stretched grid is
/// [`full_volume`]'s).
pub fn label_volume(p: &PhantomParams) -> Result<LabelVolume, String> {
    let plain = PhantomParams {
        skin: Skin::Voxel,
        ..p.clone()
    };
    let (full, an, _) = full_volume(&plain)?;
    let (lo, hi) = crop_box(p, &an, &full);
    Ok(full.crop(lo, hi))
}

fn face_normal(mesh: &Mesh, n: &[u32; 4]) -> [f64; 3] {
    let p = |q: usize| mesh.nodes[n[q] as usize];
    let (a, b) = (
        [p(2)[0] - p(0)[0], p(2)[1] - p(0)[1], p(2)[2] - p(0)[2]],
        [p(3)[0] - p(1)[0], p(3)[1] - p(1)[1], p(3)[2] - p(1)[2]],
    );
    let c = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    let l = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt().max(1e-300);
    [c[0] / l, c[1] / l, c[2] / l]
}

/// Build the phantom.
pub fn build(p: &PhantomParams) -> Result<Phantom, String> {
    let (full, an, fit) = full_volume(p)?;
    let (lo, hi) = crop_box(p, &an, &full);
    let volume = full.crop(lo, hi);
    drop(full);
    let map = label_map(p);
    let (mut mesh, mut quality) = mesh_volume(&volume, &map, &p.mesh)?;
    if let Some(f) = &fit {
        f.map_mesh(&an, &mut mesh)?;
    }

    // boundary node sets on the bounding planes of the meshed volume
    let plo = volume.index_to_world([-0.5, -0.5, -0.5]);
    let phi = volume.index_to_world([
        volume.dims[0] as f64 - 0.5,
        volume.dims[1] as f64 - 0.5,
        volume.dims[2] as f64 - 0.5,
    ]);
    let tol = 1e-9;
    let (part_names, _) = map.parts();
    let pid = |name: &str| part_names.iter().position(|n| n == name).map(|q| q as u32);
    let mut back = mesh.nodes_on_plane(2, plo[2], tol);
    if let Some(sp) = pid("spine") {
        for (e, c) in mesh.elements.iter().enumerate() {
            if mesh.element_part[e] == sp {
                back.extend_from_slice(c);
            }
        }
    }
    back.sort_unstable();
    back.dedup();
    let sets = [
        ("cut_xmin", mesh.nodes_on_plane(0, plo[0], tol)),
        ("cut_xmax", mesh.nodes_on_plane(0, phi[0], tol)),
        ("cut_ymin", mesh.nodes_on_plane(1, plo[1], tol)),
        ("cut_ymax", mesh.nodes_on_plane(1, phi[1], tol)),
    ];
    mesh.node_sets.insert("back".into(), back);
    for (n, s) in sets {
        mesh.node_sets.insert(n.into(), s);
    }

    // anterior skin faces: outer faces not on a bounding plane, facing up
    let on_plane =
        |x: [f64; 3]| (0..3).any(|a| (x[a] - plo[a]).abs() < tol || (x[a] - phi[a]).abs() < tol);
    let skin_faces: Vec<[u32; 4]> = mesh
        .boundary_faces()
        .into_iter()
        .filter(|f| !f.nodes.iter().all(|&n| on_plane(mesh.nodes[n as usize])))
        .filter(|f| face_normal(&mesh, &f.nodes)[2] > 0.05)
        .map(|f| f.nodes)
        .collect();
    let mut skin: Vec<u32> = skin_faces.iter().flatten().copied().collect();
    skin.sort_unstable();
    skin.dedup();
    mesh.node_sets.insert("skin".into(), skin);

    // ROI
    let organ = organ_parts(&part_names);
    let gx = p.grid.center[0];
    let center = p.roi.center.unwrap_or_else(|| an.liver_edge_point(gx));
    let roi = select_roi(&mesh, &organ, center, &p.roi);
    mesh.element_sets.insert("roi".into(), roi.element_set());

    // the locations' columns (liver depth, ribs above) and the test-location search read
    // labels by height: on the body's own grid, not a fitted skin's stretched one
    let plain = match p.skin {
        Skin::Voxel => None,
        Skin::Fitted => Some(label_volume(p)?),
    };
    let columns = plain.as_ref().unwrap_or(&volume);
    let search = if (p.voxel - TEST_SEARCH_VOXEL).abs() > 1e-12 {
        Some(label_volume(&PhantomParams {
            voxel: TEST_SEARCH_VOXEL,
            ..p.clone()
        })?)
    } else {
        None
    };
    let locations = find_locations(
        &mesh,
        &skin_faces,
        columns,
        search.as_ref().unwrap_or(columns),
        &p.grid,
    )?;
    let volume = plain.unwrap_or(volume);
    quality = {
        let mut q = MeshQuality::measure(&mesh);
        q.cleanup = quality.cleanup;
        q.smoothing = quality.smoothing;
        q.seconds_mesh = quality.seconds_mesh;
        q.seconds_smooth = quality.seconds_smooth;
        q
    };
    let tumours = p
        .tumours
        .iter()
        .enumerate()
        .map(|(n, t)| (tumour_part_name(n), t.stiffness_factor))
        .collect();
    Ok(Phantom {
        params: p.clone(),
        volume,
        label_map: map,
        mesh,
        quality,
        skin_faces,
        roi,
        locations,
        tumours,
        skin_fit: fit,
    })
}

impl Phantom {
    /// Replace the ROI by `reference` (the ROI of a phantom of the same body whose liver was
    /// shifted caudally by `reference_shift`, m) carried with the liver onto this phantom
    /// ([`carry_roi`]): column i of both ROIs is the same point of the liver. The element set
    /// `roi` follows.
    pub fn carry_roi_from(&mut self, reference: &Roi, reference_shift: f64) -> Result<(), String> {
        let d = [0.0, -(self.params.liver_shift() - reference_shift), 0.0];
        let organ = organ_parts(&self.mesh.part_names);
        let roi = carry_roi(&self.mesh, &organ, reference, d)
            .ok_or("the phantom has no liver surface to carry the ROI onto")?;
        self.mesh
            .element_sets
            .insert("roi".into(), roi.element_set());
        self.roi = roi;
        Ok(())
    }

    /// PNG slices (axial, sagittal, coronal) through the liver's centre into `dir`.
    pub fn write_preview(&self, dir: &std::path::Path) -> Result<Vec<std::path::PathBuf>, String> {
        let v = &self.volume;
        let (mut s, mut n) = ([0usize; 3], 0usize);
        for k in 0..v.dims[2] {
            for j in 0..v.dims[1] {
                for i in 0..v.dims[0] {
                    if v.get(i, j, k) == LIVER {
                        s[0] += i;
                        s[1] += j;
                        s[2] += k;
                        n += 1;
                    }
                }
            }
        }
        let at = if n > 0 {
            Some([s[0] / n, s[1] / n, s[2] / n])
        } else {
            None
        };
        write_preview_at(v, dir, at)
    }

    /// Counts per part, quality, ROI size and locations, as text.
    pub fn summary(&self) -> String {
        let l = &self.locations;
        let loc = |x: &Location| {
            format!(
                "{}: ({:.1}, {:.1}, {:.1}) mm, liver depth {}, {}",
                x.name,
                x.surface[0] * 1e3,
                x.surface[1] * 1e3,
                x.surface[2] * 1e3,
                x.liver_depth
                    .map(|d| format!("{:.1} mm", d * 1e3))
                    .unwrap_or("-".into()),
                if x.under_ribs {
                    "under ribs"
                } else {
                    "not under ribs"
                }
            )
        };
        let skin = match &self.skin_fit {
            None => "skin: voxel steps, smoothed".to_string(),
            Some(f) => {
                let (lo, hi) = f.ratio_range();
                format!(
                    "skin: fitted to the outline for |x| <= {:.1} mm (steeper flanks keep their voxel steps); columns stretched {:.3}..{:.3}",
                    f.half_width * 1e3,
                    lo,
                    hi
                )
            }
        };
        format!(
            "phantom {:?}, voxel {:.2} mm, phase {:.2}\n{}\n{}\nROI: {} liver surface elements\n{}\n{}\n{}",
            self.params.variant,
            self.params.voxel * 1e3,
            self.params.respiratory_phase,
            skin,
            self.quality.summary(),
            self.roi.elements.len(),
            loc(&l.a),
            loc(&l.b),
            loc(&l.c)
        )
    }
}

#[cfg(test)]
mod tests;
