//! Labelled voxel volumes and voxel-to-hexahedron meshing.
//!
//! The pipeline of the paper's model (one hexahedron per CT voxel, parts from segmentation
//! labels, then smoothing; Ghajari et al.), in small steps:
//!
//! - [`LabelVolume`] (`volume.rs`): dims, spacing, affine (m), `u8` labels, x fastest; crop and
//!   majority-vote coarsening.
//! - I/O: NIfTI-1 through the `nifti` crate ([`read_nifti`], [`write_nifti`], `nifti_io.rs`)
//!   and raw bytes plus a JSON header ([`read_raw`], [`write_raw`], `raw_io.rs`).
//! - [`LabelMap`] (`label_map.rs`): label -> part name, from TOML.
//! - Clean-up (`cleanup.rs`): islands, detached pieces, edge- and corner-only connections.
//! - Hexahedra and smoothing ([`mesh_volume`], `mesher.rs`, `smooth.rs`): shared nodes,
//!   constrained Taubin smoothing of the outer surface and the part interfaces that keeps every
//!   corner Jacobian positive.
//! - [`MeshQuality`] (`quality.rs`), corner Jacobians (`jacobian.rs`), PNG slice previews
//!   ([`write_preview`], `preview.rs`).

mod cleanup;
pub mod jacobian;
mod label_map;
mod mesher;
mod nifti_io;
mod preview;
mod quality;
mod raw_io;
mod smooth;
mod volume;

pub use cleanup::{
    block_is_manifold, cleanup, fix_nonmanifold, remove_detached, remove_label_islands,
    CleanupReport,
};
pub use label_map::LabelMap;
pub use mesher::{build_hexes, mesh_volume, MeshOptions};
pub use nifti_io::{read_nifti, write_nifti};
pub use preview::{label_colour, write_preview, write_preview_at};
pub use quality::MeshQuality;
pub use raw_io::{read_raw, write_raw, RawHeader};
pub use smooth::{smooth_surfaces, SmoothOptions, SmoothReport, SurfaceFace};
pub use volume::LabelVolume;

/// Read a label volume, choosing the format from the name: `.nii`, `.nii.gz` or `.json`
/// (raw + JSON header).
pub fn read_volume(path: &std::path::Path) -> Result<LabelVolume, String> {
    let name = path.to_string_lossy();
    if name.ends_with(".json") {
        read_raw(path)
    } else {
        read_nifti(path)
    }
}

#[cfg(test)]
mod tests;
