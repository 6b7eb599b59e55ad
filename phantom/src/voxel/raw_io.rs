//! Raw label data plus a JSON header: the simplest exchange format.
//!
//! `NAME.json` holds `{"dims": [nx, ny, nz], "spacing_m": [..], "affine_m": [[..4]; 4],
//! "dtype": "uint8", "order": "x-fastest", "data": "NAME.raw"}`; `NAME.raw` holds
//! `nx * ny * nz` bytes, x fastest. The affine maps voxel-centre indices to metres.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::LabelVolume;

/// The JSON header of a raw label volume.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct RawHeader {
    /// Voxels along i, j, k.
    pub dims: [usize; 3],
    /// Voxel size (m).
    pub spacing_m: [f64; 3],
    /// Row-major index-to-world affine (m).
    pub affine_m: [[f64; 4]; 4],
    /// Always "uint8".
    pub dtype: String,
    /// Always "x-fastest".
    pub order: String,
    /// Data file name, relative to the header's folder.
    pub data: String,
}

/// Write `json_path` and the raw data next to it (same stem, `.raw`).
pub fn write_raw(vol: &LabelVolume, json_path: &Path) -> Result<PathBuf, String> {
    let raw_path = json_path.with_extension("raw");
    let name = raw_path
        .file_name()
        .and_then(|s| s.to_str())
        .ok_or("bad raw file name")?
        .to_string();
    let h = RawHeader {
        dims: vol.dims,
        spacing_m: vol.spacing,
        affine_m: vol.affine,
        dtype: "uint8".into(),
        order: "x-fastest".into(),
        data: name,
    };
    let s = serde_json::to_string_pretty(&h).map_err(|e| e.to_string())?;
    std::fs::write(json_path, s).map_err(|e| format!("{}: {e}", json_path.display()))?;
    std::fs::write(&raw_path, &vol.labels).map_err(|e| format!("{}: {e}", raw_path.display()))?;
    Ok(raw_path)
}

/// Read a volume written by [`write_raw`]. The data file's size is checked against `dims`
/// before it is read.
pub fn read_raw(json_path: &Path) -> Result<LabelVolume, String> {
    let j = json_path.display();
    let s = std::fs::read_to_string(json_path).map_err(|e| format!("{j}: {e}"))?;
    let h: RawHeader = serde_json::from_str(&s).map_err(|e| format!("{j}: {e}"))?;
    if h.dtype != "uint8" || h.order != "x-fastest" {
        return Err(format!("{j}: only uint8, x-fastest data is supported"));
    }
    let d = h.dims;
    if d.contains(&0) {
        return Err(format!(
            "{j}: dims {d:?}: a volume needs at least one voxel along each axis"
        ));
    }
    let n = d
        .iter()
        .try_fold(1u64, |n, &k| n.checked_mul(k as u64))
        .ok_or_else(|| {
            format!(
                "{j}: dims {d:?}: {} x {} x {} voxels overflow",
                d[0], d[1], d[2]
            )
        })?;
    let raw_path = json_path.parent().unwrap_or(Path::new(".")).join(&h.data);
    let r = raw_path.display();
    let size = std::fs::metadata(&raw_path)
        .map_err(|e| format!("{r}: {e}"))?
        .len();
    if size != n {
        return Err(format!(
            "{r}: {size} bytes, but the dims {d:?} of {j} need {n} (one byte per voxel)"
        ));
    }
    let labels = std::fs::read(&raw_path).map_err(|e| format!("{r}: {e}"))?;
    LabelVolume::from_affine(h.dims, h.affine_m, labels).map_err(|e| format!("{j}: {e}"))
}
