//! NIfTI-1 input and output of label volumes (`.nii`, `.nii.gz`) through the `nifti` crate.
//!
//! Reading: the first three dimensions are taken (a fourth must have size 1); any stored data
//! type is read through the header's scaling (`scl_slope`, `scl_inter`) and rounded to a
//! label in 0..=255. The affine is the sform when `sform_code > 0`, else the qform built from
//! the quaternion (NIfTI-1 standard, `nifti1.h`: R from (b, c, d), with `qfac = pixdim[0]`
//! flipping the k axis), else `diag(pixdim)`. Lengths are converted to m with `xyzt_units`
//! (unknown units are taken as mm, the usual CT / MR convention).
//!
//! Writing: `uint8` data, lengths in mm, the affine in the sform (code 2, "aligned"), and the
//! qform too when the affine is a pure scaling plus translation.

use std::path::Path;

use nifti::{IntoNdArray, NiftiHeader, NiftiObject, ReaderOptions};

use super::LabelVolume;

/// Metres per unit of a NIfTI `xyzt_units` spatial code.
fn unit_scale(xyzt_units: u8) -> f64 {
    match xyzt_units & 0x07 {
        1 => 1.0,  // metre
        3 => 1e-6, // micron
        _ => 1e-3, // mm, or unknown
    }
}

/// The index-to-world affine of a NIfTI header, in the header's length unit.
fn header_affine(h: &NiftiHeader) -> [[f64; 4]; 4] {
    let mut a = [[0.0; 4]; 4];
    a[3][3] = 1.0;
    if h.sform_code > 0 {
        for c in 0..4 {
            a[0][c] = h.srow_x[c] as f64;
            a[1][c] = h.srow_y[c] as f64;
            a[2][c] = h.srow_z[c] as f64;
        }
    } else if h.qform_code > 0 {
        let (b, c, d) = (h.quatern_b as f64, h.quatern_c as f64, h.quatern_d as f64);
        let a0 = (1.0 - (b * b + c * c + d * d)).max(0.0).sqrt();
        let r = [
            [
                a0 * a0 + b * b - c * c - d * d,
                2.0 * (b * c - a0 * d),
                2.0 * (b * d + a0 * c),
            ],
            [
                2.0 * (b * c + a0 * d),
                a0 * a0 + c * c - b * b - d * d,
                2.0 * (c * d - a0 * b),
            ],
            [
                2.0 * (b * d - a0 * c),
                2.0 * (c * d + a0 * b),
                a0 * a0 + d * d - c * c - b * b,
            ],
        ];
        let qfac = if h.pixdim[0] < 0.0 { -1.0 } else { 1.0 };
        let s = [
            h.pixdim[1] as f64,
            h.pixdim[2] as f64,
            h.pixdim[3] as f64 * qfac,
        ];
        for row in 0..3 {
            for col in 0..3 {
                a[row][col] = r[row][col] * s[col];
            }
        }
        a[0][3] = h.quatern_x as f64;
        a[1][3] = h.quatern_y as f64;
        a[2][3] = h.quatern_z as f64;
    } else {
        for k in 0..3 {
            a[k][k] = h.pixdim[k + 1] as f64;
        }
    }
    a
}

/// The nifti crate's error in words: its I/O variant prints as Rust (`Io(Kind(UnexpectedEof))`).
fn nifti_message(e: &nifti::NiftiError) -> String {
    match e {
        nifti::NiftiError::Io(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            "the file ends early (truncated: the header or the voxel data is incomplete)".into()
        }
        nifti::NiftiError::Io(io) => format!("cannot read the file: {io}"),
        other => other.to_string(),
    }
}

/// Read a `.gz` file through to its end, so that its CRC-32 and length trailer are checked: a
/// damaged stream the NIfTI reader would otherwise mesh into different anatomy is an error.
fn check_gzip(path: &Path) -> Result<(), String> {
    let f =
        std::fs::File::open(path).map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
    let mut gz = flate2::read::MultiGzDecoder::new(std::io::BufReader::new(f));
    std::io::copy(&mut gz, &mut std::io::sink()).map_err(|e| {
        format!(
            "{}: the gzip stream is damaged ({e}); the file is corrupt or truncated",
            path.display()
        )
    })?;
    Ok(())
}

/// Read a label volume from `.nii` or `.nii.gz`; a `.gz` file's checksum is verified.
pub fn read_nifti(path: &Path) -> Result<LabelVolume, String> {
    let err = |e: nifti::NiftiError| format!("{}: {}", path.display(), nifti_message(&e));
    if path.to_string_lossy().to_ascii_lowercase().ends_with(".gz") {
        check_gzip(path)?;
    }
    let obj = ReaderOptions::new().read_file(path).map_err(err)?;
    let h = obj.header().clone();
    // The nifti crate sizes the voxel data by `bitpix` but decodes it by `datatype`; when the
    // two disagree it panics while decoding.
    let dt = h.data_type().map_err(err)?;
    if h.bitpix as usize != 8 * dt.size_of() {
        return Err(format!(
            "{}: the header's bitpix ({}) does not match its datatype ({dt:?}, {} bits a voxel); the header is damaged",
            path.display(),
            h.bitpix,
            8 * dt.size_of()
        ));
    }
    let nd = h.dim[0] as usize;
    if !(3..=7).contains(&nd) {
        return Err(format!(
            "{}: expected a 3-D volume, header has {nd} dimensions",
            path.display()
        ));
    }
    if h.dim[4..=nd].iter().any(|&d| d > 1) {
        return Err(format!(
            "{}: only 3-D label volumes are supported (dim = {:?})",
            path.display(),
            &h.dim[..=nd]
        ));
    }
    let dims = [h.dim[1] as usize, h.dim[2] as usize, h.dim[3] as usize];
    let arr = obj.into_volume().into_ndarray::<f64>().map_err(err)?;
    if arr.ndim() < 3 || arr.shape()[..3] != dims {
        return Err(format!(
            "{}: data shape {:?} does not match dims {dims:?}",
            path.display(),
            arr.shape()
        ));
    }
    let mut idx = vec![0usize; arr.ndim()];
    let mut labels = vec![0u8; dims[0] * dims[1] * dims[2]];
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                idx[0] = i;
                idx[1] = j;
                idx[2] = k;
                let v = arr[idx.as_slice()].round();
                if !(0.0..=255.0).contains(&v) {
                    return Err(format!(
                        "{}: voxel ({i},{j},{k}) has value {v}, not a label in 0..=255",
                        path.display()
                    ));
                }
                labels[i + dims[0] * (j + dims[1] * k)] = v as u8;
            }
        }
    }
    let scale = unit_scale(h.xyzt_units);
    let mut affine = header_affine(&h);
    for row in affine.iter_mut().take(3) {
        for v in row.iter_mut() {
            *v *= scale;
        }
    }
    LabelVolume::from_affine(dims, affine, labels)
}

/// Write a label volume as `uint8` NIfTI-1; `.gz` in the name compresses it.
pub fn write_nifti(vol: &LabelVolume, path: &Path) -> Result<(), String> {
    use ndarray::ShapeBuilder;
    let mm = 1e3;
    let a = &vol.affine;
    let mut h = NiftiHeader {
        sform_code: 2,
        qform_code: 0,
        xyzt_units: 2,
        ..NiftiHeader::default()
    };
    for c in 0..4 {
        h.srow_x[c] = (a[0][c] * mm) as f32;
        h.srow_y[c] = (a[1][c] * mm) as f32;
        h.srow_z[c] = (a[2][c] * mm) as f32;
    }
    h.pixdim = [1.0; 8];
    for k in 0..3 {
        h.pixdim[k + 1] = (vol.spacing[k] * mm) as f32;
    }
    let diagonal =
        (0..3).all(|r| (0..3).all(|c| r == c || a[r][c] == 0.0)) && (0..3).all(|k| a[k][k] > 0.0);
    if diagonal {
        h.qform_code = 2;
        h.quatern_b = 0.0;
        h.quatern_c = 0.0;
        h.quatern_d = 0.0;
        h.quatern_x = (a[0][3] * mm) as f32;
        h.quatern_y = (a[1][3] * mm) as f32;
        h.quatern_z = (a[2][3] * mm) as f32;
    }
    h.set_description_str("palpa label volume")
        .map_err(|e| e.to_string())?;
    let arr = ndarray::Array3::from_shape_vec(
        (vol.dims[0], vol.dims[1], vol.dims[2]).f(),
        vol.labels.clone(),
    )
    .map_err(|e| e.to_string())?;
    nifti::writer::WriterOptions::new(path)
        .reference_header(&h)
        .write_nifti(&arr)
        .map_err(|e| format!("{}: {e}", path.display()))
}
