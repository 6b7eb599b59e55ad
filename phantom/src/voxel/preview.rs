//! PNG previews of a label volume: one axial, one sagittal and one coronal slice with the
//! labels coloured, so the anatomy can be checked without ParaView.
//!
//! Slices are taken in index space through a chosen voxel (default: the volume centre):
//! axial = the (i, k) plane at fixed j, sagittal = the (j, k) plane at fixed i, coronal =
//! the (i, j) plane at fixed k. With the phantom's frame (x left, y cranial, z anterior) the
//! axial view shows the body cross-section with the anterior side up, the sagittal view has
//! the head to the right and the anterior side up, and the coronal view is seen from the
//! front-above with the head up. Each voxel is drawn as a block of about 1 mm square pixels.

use std::path::{Path, PathBuf};

use super::LabelVolume;

/// RGB colour of a label: fixed colours for the phantom's labels 1-6, a hash for the rest.
pub fn label_colour(l: u8) -> [u8; 3] {
    match l {
        0 => [0, 0, 0],
        1 => [235, 190, 150], // flesh
        2 => [140, 30, 30],   // liver
        3 => [245, 245, 235], // ribs
        4 => [215, 120, 140], // viscera
        5 => [120, 140, 200], // spine
        6 => [60, 200, 60],   // tumour
        _ => {
            let h = (l as u32).wrapping_mul(2654435761);
            [
                (h >> 24) as u8 | 64,
                (h >> 16) as u8 | 64,
                (h >> 8) as u8 | 64,
            ]
        }
    }
}

fn write_png(path: &Path, w: usize, h: usize, rgb: &[u8]) -> Result<(), String> {
    let file = std::fs::File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut enc = png::Encoder::new(std::io::BufWriter::new(file), w as u32, h as u32);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut wr = enc.write_header().map_err(|e| e.to_string())?;
    wr.write_image_data(rgb).map_err(|e| e.to_string())
}

/// Render the plane spanned by index axes `u` (to the right) and `v` (up) at `fixed`
/// along the third axis; `scale` pixels per voxel along each axis.
fn render(
    vol: &LabelVolume,
    u: usize,
    v: usize,
    fixed: [usize; 3],
    scale: [usize; 2],
) -> (usize, usize, Vec<u8>) {
    let (nu, nv) = (vol.dims[u], vol.dims[v]);
    let (w, h) = (nu * scale[0], nv * scale[1]);
    let mut rgb = vec![0u8; w * h * 3];
    for py in 0..h {
        let jv = nv - 1 - py / scale[1];
        for px in 0..w {
            let iu = px / scale[0];
            let mut idx = fixed;
            idx[u] = iu;
            idx[v] = jv;
            let c = label_colour(vol.get(idx[0], idx[1], idx[2]));
            rgb[(py * w + px) * 3..(py * w + px) * 3 + 3].copy_from_slice(&c);
        }
    }
    (w, h, rgb)
}

/// Write `axial.png`, `sagittal.png` and `coronal.png` into `dir` (created if needed), with
/// slices through voxel `at` (default: the centre voxel). Returns the paths written.
pub fn write_preview_at(
    vol: &LabelVolume,
    dir: &Path,
    at: Option<[usize; 3]>,
) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let c = at.unwrap_or([vol.dims[0] / 2, vol.dims[1] / 2, vol.dims[2] / 2]);
    let c = [
        c[0].min(vol.dims[0] - 1),
        c[1].min(vol.dims[1] - 1),
        c[2].min(vol.dims[2] - 1),
    ];
    let px = |a: usize| ((vol.spacing[a] * 1e3).round() as usize).clamp(1, 16);
    let mut out = Vec::new();
    for (name, u, v) in [("axial", 0, 2), ("sagittal", 1, 2), ("coronal", 0, 1)] {
        let (w, h, rgb) = render(vol, u, v, c, [px(u), px(v)]);
        let p = dir.join(format!("{name}.png"));
        write_png(&p, w, h, &rgb)?;
        out.push(p);
    }
    Ok(out)
}

/// [`write_preview_at`] through the volume centre.
pub fn write_preview(vol: &LabelVolume, dir: &Path) -> Result<Vec<PathBuf>, String> {
    write_preview_at(vol, dir, None)
}
