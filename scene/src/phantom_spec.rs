//! The scene table `[mesh.phantom]`: the built-in abdomen phantom as a scene's mesh, and the
//! palpation locations that a `[[hand]]` can name instead of a point.
//!
//! ```toml
//! [mesh]
//! generator = "phantom"
//! [mesh.phantom]
//! variant = "reduced"          # or "full"
//! voxel = "5 mm"               # "3 mm" is close to the paper's CT resolution
//! fat_thickness = "15 mm"
//! respiratory_phase = 0.0      # 0 exhalation .. 1 inspiration (liver moves up to 20 mm)
//! skin = "voxel"               # or "fitted": one node layer on the outline, no voxel steps
//! coarsen = 1                  # merge coarsen^3 voxels before meshing
//! roi_radius = "60 mm"         # region of interest: liver-surface elements near the edge
//! roi_count = 377              # at most this many (the paper's 377)
//! tumours = [{ center = ["-60 mm", "180 mm", "150 mm"], radius = "10 mm", stiffness = 5.0 }]
//!
//! [[hand]]
//! name = "hand"
//! location = "A"               # "A", "B", "C" or "P01".."P25"; or at = ["-50 mm", "195 mm"]
//! ...
//! ```
//!
//! The mesh carries the parts `flesh`, `liver`, `ribs`, `viscera` (and `spine`, `tumour`, ...
//! where present), the node sets `back`, `cut_xmin`, `cut_xmax`, `cut_ymin`, `cut_ymax`,
//! `skin`, `surface`, and the element set `roi`. A hand placed at a location gets the skin point
//! there as `point` and the inward skin normal as `direction` (see
//! [`phantom::Locations`]).

use material::quantity::{Length, Number};
use serde::Deserialize;

use phantom::{PhantomParams, Skin, Tumour, Variant};

/// `[mesh.phantom]`.
#[derive(Debug, Deserialize, Default, Clone)]
#[serde(deny_unknown_fields)]
pub struct PhantomScene {
    /// `reduced` (default) or `full`.
    pub variant: Option<String>,
    /// Voxel edge (default 5 mm).
    pub voxel: Option<Length>,
    /// Subcutaneous fat thickness (default 15 mm).
    pub fat_thickness: Option<Length>,
    /// Respiratory phase 0..1 (default 0).
    pub respiratory_phase: Option<Number>,
    /// `voxel` (default: smoothed voxel steps) or `fitted` (the grid's columns stretched so
    /// that the skin is one node layer on the body's outline; `phantom::SkinFit`).
    pub skin: Option<String>,
    /// Voxel coarsening factor (default 1).
    pub coarsen: Option<usize>,
    /// ROI radius (default 60 mm).
    pub roi_radius: Option<Length>,
    /// ROI element count cap (default 377).
    pub roi_count: Option<usize>,
    /// Liver tumours.
    #[serde(default)]
    pub tumours: Vec<TumourScene>,
}

/// One tumour.
#[derive(Debug, Deserialize, Clone)]
#[serde(deny_unknown_fields)]
pub struct TumourScene {
    /// Centre at respiratory phase 0.
    pub center: [Length; 3],
    /// Radius.
    pub radius: Length,
    /// Stiffness relative to healthy liver.
    pub stiffness: Number,
}

impl PhantomScene {
    /// The phantom parameters (SI), defaults where a key is absent.
    pub fn to_params(&self) -> Result<PhantomParams, String> {
        let mut p = PhantomParams::default();
        if let Some(v) = &self.variant {
            p.variant = v.parse::<Variant>()?;
        }
        if let Some(v) = self.voxel {
            p.voxel = v.0;
        }
        if let Some(v) = self.fat_thickness {
            p.fat_thickness = v.0;
        }
        if let Some(v) = self.respiratory_phase {
            p.respiratory_phase = v.0;
        }
        if let Some(s) = &self.skin {
            p.skin = s.parse::<Skin>()?;
        }
        if let Some(c) = self.coarsen {
            if c == 0 {
                return Err("coarsen must be at least 1".into());
            }
            p.mesh.coarsen = c;
        }
        if let Some(r) = self.roi_radius {
            p.roi.radius = r.0;
        }
        if let Some(n) = self.roi_count {
            p.roi.max_count = Some(n);
        }
        p.tumours = self
            .tumours
            .iter()
            .map(|t| Tumour {
                center: [t.center[0].0, t.center[1].0, t.center[2].0],
                radius: t.radius.0,
                stiffness_factor: t.stiffness.0,
            })
            .collect();
        p.validate()?;
        Ok(p)
    }
}
