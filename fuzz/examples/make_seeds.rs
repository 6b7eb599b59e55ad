//! Writes the generated part of the seed corpus: small surrogate models (an MLP and a GP on a
//! cut-down synthetic dataset) and small NIfTI label volumes, plain and gzipped.
//!
//! `cargo run --release --example make_seeds` (from `fuzz/`) writes into `corpus/model/` and
//! `corpus/nifti/`. The text seeds (scenes, campaigns, material cards, decks, meshes, lines)
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
    models(&root.join("model"));
    nifti(&root.join("nifti"));
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

fn nifti(dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    let mut vol = solver::voxel::LabelVolume::new([4, 3, 2], [0.002, 0.002, 0.003], [0.0; 3]);
    for k in 0..2 {
        for j in 0..3 {
            for i in 0..4 {
                vol.set(i, j, k, ((i + j + k) % 3) as u8);
            }
        }
    }
    for name in ["labels.nii", "labels.nii.gz"] {
        let p = dir.join(name);
        solver::voxel::write_nifti(&vol, &p).unwrap();
        println!("{name}: {} bytes", std::fs::metadata(&p).unwrap().len());
    }
}
