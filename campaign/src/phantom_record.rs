//! The phantom's parameters as a plan and a dataset manifest record them (SI, JSON):
//! [`PhantomRecord`], so that the phantom of a dataset can be rebuilt without its campaign file.

use phantom::{Anatomy, GridParams, PhantomParams, Skin, Tumour};
use serde::{Deserialize, Serialize};

/// The phantom parameters a campaign's plan and its dataset's manifest record.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhantomRecord {
    /// `reduced` or `full`.
    pub variant: String,
    /// Voxel edge (m).
    pub voxel_m: f64,
    /// Subcutaneous fat thickness (m).
    pub fat_thickness_m: f64,
    /// Respiratory phase (0..1).
    pub respiratory_phase: f64,
    /// Largest caudal shift of the liver over the breathing cycle (m).
    pub max_liver_shift_m: f64,
    /// Torso width, depth and length (m).
    pub torso_m: [f64; 3],
    /// `voxel` or `fitted` (`voxel` when absent: plans written before the fitted skin).
    #[serde(default, skip_serializing_if = "Skin::is_voxel")]
    pub skin: Skin,
    /// Voxels merged per element edge (1 when absent).
    #[serde(default = "one")]
    pub coarsen: usize,
    /// Tumours.
    #[serde(default)]
    pub tumours: Vec<Tumour>,
    /// ROI radius (m).
    pub roi_radius_m: f64,
    /// Largest ROI element count, `None` for no limit.
    pub roi_max_count: Option<usize>,
    /// The raster of palpation points.
    pub grid: GridRecord,
}

fn one() -> usize {
    1
}

/// The raster of a [`PhantomRecord`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridRecord {
    /// Centre (x, y; m).
    pub center_m: [f64; 2],
    /// Spacing (x, y; m).
    pub spacing_m: [f64; 2],
    /// Points along x and y.
    pub n: [usize; 2],
}

/// A deserialisation error with the key it happened at (`` `grid.n`: invalid length 1 ``), or
/// without one at the top level (`missing field `variant``).
pub(crate) fn at_key(e: &serde_path_to_error::Error<serde_json::Error>) -> String {
    match e.path().to_string().as_str() {
        "." | "" => e.inner().to_string(),
        p => format!("`{p}`: {}", e.inner()),
    }
}

impl PhantomRecord {
    /// The record of `p`.
    pub fn of(p: &PhantomParams) -> PhantomRecord {
        PhantomRecord {
            variant: format!("{:?}", p.variant).to_lowercase(),
            voxel_m: p.voxel,
            fat_thickness_m: p.fat_thickness,
            respiratory_phase: p.respiratory_phase,
            max_liver_shift_m: p.max_liver_shift,
            torso_m: [p.torso_width, p.torso_depth, p.torso_length],
            skin: p.skin,
            coarsen: p.mesh.coarsen,
            tumours: p.tumours.clone(),
            roi_radius_m: p.roi.radius,
            roi_max_count: p.roi.max_count,
            grid: GridRecord {
                center_m: p.grid.center,
                spacing_m: p.grid.spacing,
                n: p.grid.n,
            },
        }
    }

    /// Read a record from JSON (a plan's `phantom`, a manifest's `phantom.parameters`).
    pub fn from_value(v: &serde_json::Value) -> Result<PhantomRecord, String> {
        serde_path_to_error::deserialize(v)
            .map_err(|e| format!("phantom parameters: {}", at_key(&e)))
    }

    /// The phantom parameters back. Meshing options other than `coarsen` take their defaults,
    /// as a campaign's do; the ROI centre is the default one (the liver's edge below the
    /// raster's centre) unless `roi_center` names another.
    pub fn to_params(&self, roi_center: Option<[f64; 3]>) -> Result<PhantomParams, String> {
        let mut p = PhantomParams {
            variant: self.variant.parse()?,
            voxel: self.voxel_m,
            fat_thickness: self.fat_thickness_m,
            respiratory_phase: self.respiratory_phase,
            max_liver_shift: self.max_liver_shift_m,
            ..Default::default()
        };
        [p.torso_width, p.torso_depth, p.torso_length] = self.torso_m;
        p.skin = self.skin;
        p.mesh.coarsen = self.coarsen;
        p.tumours = self.tumours.clone();
        p.roi.radius = self.roi_radius_m;
        p.roi.max_count = self.roi_max_count;
        p.grid = GridParams {
            center: self.grid.center_m,
            spacing: self.grid.spacing_m,
            n: self.grid.n,
        };
        if let Some(rc) = roi_center {
            // the default centre, unless the given one is elsewhere (a JSON round trip may move
            // the last digit: 1 nm decides)
            let an = Anatomy::new(&p);
            let d = an.liver_edge_point(p.grid.center[0]);
            if (0..3).any(|k| (d[k] - rc[k]).abs() > 1e-9) {
                p.roi.center = Some(rc);
            }
        }
        p.validate()?;
        Ok(p)
    }
}
