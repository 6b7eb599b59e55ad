//! Writes the generated part of the seed corpus: small surrogate models (an MLP and a GP on a
//! cut-down synthetic dataset), small NIfTI label volumes, plain and gzipped, the same volume as
//! a raw volume (JSON header and raw bytes), and a tetrahedron as ASCII and binary STL.
//!
//! `cargo run --release --example make_seeds [model|nifti|raw_volume|stl]...` (from `fuzz/`)
//! writes into `corpus/model/`, `corpus/nifti/`, `corpus/raw_volume/` and `corpus/stl/` (all
//! four without arguments). The text seeds (scenes, campaigns, material cards, decks, meshes, lines)
//! are copies of repository files or written by hand; see docs/fuzzing.md.

use ndarray::Axis;
use palpa_fuzz::MODEL_SEPARATOR;
use std::path::Path;
use surrogate::gp::GpOptions;
use surrogate::mlp::MlpOptions;
use surrogate::synthetic::make_synthetic_dataset;
use surrogate::{train_model, ModelKind, TrainOptions};

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("corpus");
    let args: Vec<String> = std::env::args().skip(1).collect();
    let want = |t: &str| args.is_empty() || args.iter().any(|a| a == t);
    if want("model") {
        models(&root.join("model"));
    }
    if want("nifti") {
        nifti(&root.join("nifti"));
    }
    if want("raw_volume") {
        raw_volume(&root.join("raw_volume"));
    }
    if want("stl") {
        stl(&root.join("stl"));
    }
}

fn models(dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    // 3 ROI elements; the synthetic dataset's training locations 0, 6, 12, 18, 24 and its test
    // locations, every force
    let mut data = make_synthetic_dataset(3);
    let keep: Vec<usize> = (0..data.x.nrows())
        .filter(|&i| data.location[i] % 6 == 0 || data.location[i] >= 25)
        .collect();
    data.x = data.x.select(Axis(0), &keep);
    data.y = data.y.select(Axis(0), &keep);
    data.stress = data.stress.map(|s| s.select(Axis(0), &keep));
    data.location = data.location.select(Axis(0), &keep);
    data.split = data.split.select(Axis(0), &keep);
    let tmp = std::env::temp_dir().join(format!("palpa-fuzz-seeds-{}", std::process::id()));
    for (name, kind, opts) in [
        (
            "mlp",
            ModelKind::Mlp,
            TrainOptions {
                mlp: MlpOptions {
                    hidden: vec![4],
                    epochs: 5,
                    ..Default::default()
                },
                ..Default::default()
            },
        ),
        (
            "gp",
            ModelKind::Gp,
            TrainOptions {
                gp: GpOptions {
                    restarts: 0,
                    max_iterations: 5,
                    ..Default::default()
                },
                ..Default::default()
            },
        ),
    ] {
        let (model, report) = train_model(&data, kind, &opts).unwrap();
        let out = tmp.join(name);
        model
            .save_with_domain(
                &out,
                data.roi_ids.as_slice().unwrap(),
                data.roi_centroids.view(),
                &report,
                surrogate::domain::TrainingDomain::of_training_rows(&data).as_ref(),
            )
            .unwrap();
        let mut seed = std::fs::read(out.join("model.json")).unwrap();
        seed.extend_from_slice(MODEL_SEPARATOR);
        seed.extend(std::fs::read(out.join("model.safetensors")).unwrap());
        std::fs::write(dir.join(format!("{name}-model")), &seed).unwrap();
        println!("{name}-model: {} bytes", seed.len());
    }
    std::fs::remove_dir_all(&tmp).unwrap();
}

/// The 4 x 3 x 2 label volume of the NIfTI and raw seeds.
fn labels() -> phantom::voxel::LabelVolume {
    let mut vol = phantom::voxel::LabelVolume::new([4, 3, 2], [0.002, 0.002, 0.003], [0.0; 3]);
    for k in 0..2 {
        for j in 0..3 {
            for i in 0..4 {
                vol.set(i, j, k, ((i + j + k) % 3) as u8);
            }
        }
    }
    vol
}

fn nifti(dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    let vol = labels();
    for name in ["labels.nii", "labels.nii.gz"] {
        let p = dir.join(name);
        phantom::voxel::write_nifti(&vol, &p).unwrap();
        println!("{name}: {} bytes", std::fs::metadata(&p).unwrap().len());
    }
}

/// The header (`data` is `volume.raw`, the name the harness writes the data under), the
/// separator line, then the raw bytes.
fn raw_volume(dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    let tmp = std::env::temp_dir().join(format!("palpa-fuzz-seeds-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let raw = phantom::voxel::write_raw(&labels(), &tmp.join("volume.json")).unwrap();
    let mut seed = std::fs::read(tmp.join("volume.json")).unwrap();
    seed.extend_from_slice(MODEL_SEPARATOR);
    seed.extend(std::fs::read(raw).unwrap());
    std::fs::write(dir.join("labels"), &seed).unwrap();
    println!("labels: {} bytes", seed.len());
    std::fs::remove_dir_all(&tmp).unwrap();
}

/// A tetrahedron of 10 mm edges along the axes, wound counter-clockwise seen from outside.
fn stl(dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    let v = [
        [0.0, 0.0, 0.0],
        [10.0, 0.0, 0.0],
        [0.0, 10.0, 0.0],
        [0.0, 0.0, 10.0],
    ];
    let tris: Vec<[[f64; 3]; 3]> = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
        .iter()
        .map(|t| t.map(|i| v[i]))
        .collect();
    let bin = contact::trimesh::write_binary_stl(&tris);
    std::fs::write(dir.join("tetra-binary.stl"), &bin).unwrap();
    let s = 1.0 / 3f64.sqrt();
    let normals = [
        [0.0, 0.0, -1.0],
        [0.0, -1.0, 0.0],
        [-1.0, 0.0, 0.0],
        [s, s, s],
    ];
    let mut ascii = String::from("solid tetra\n");
    for (t, n) in tris.iter().zip(normals) {
        ascii.push_str(&format!(
            "  facet normal {} {} {}\n    outer loop\n",
            n[0], n[1], n[2]
        ));
        for p in t {
            ascii.push_str(&format!("      vertex {} {} {}\n", p[0], p[1], p[2]));
        }
        ascii.push_str("    endloop\n  endfacet\n");
    }
    ascii.push_str("endsolid tetra\n");
    std::fs::write(dir.join("tetra-ascii.stl"), &ascii).unwrap();
    println!(
        "tetra-binary.stl: {} bytes, tetra-ascii.stl: {} bytes",
        bin.len(),
        ascii.len()
    );
}
