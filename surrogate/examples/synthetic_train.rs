//! Trains both surrogates on the synthetic dataset and prints their reports.
//!
//! `cargo run --release -p surrogate --example synthetic_train -- [R] [epochs] [gdx|adam] [hidden,sizes]`

use surrogate::mlp::{AdamOptions, GdxOptions, MlpOptions, Optimiser, PAPER_HIDDEN};
use surrogate::synthetic::make_synthetic_dataset;
use surrogate::{train_model, ModelKind, TrainOptions};

fn main() -> surrogate::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let r: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(377);
    let epochs: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(3000);
    let optimiser = match args.get(3).map(String::as_str) {
        Some("gdx") => Optimiser::Gdx(GdxOptions {
            l2: env("L2", 1e-4),
            ..Default::default()
        }),
        _ => Optimiser::Adam(AdamOptions {
            weight_decay: env("WD", 0.0),
            lr: env("LR", 2e-3),
            batch_size: std::env::var("BATCH").ok().and_then(|v| v.parse().ok()),
            ..Default::default()
        }),
    };
    let hidden = args
        .get(4)
        .map(|s| s.split(',').filter_map(|v| v.parse().ok()).collect())
        .unwrap_or(PAPER_HIDDEN.to_vec());
    let data = make_synthetic_dataset(r);
    let opts = TrainOptions {
        mlp: MlpOptions {
            hidden,
            optimiser,
            epochs,
            ..Default::default()
        },
        ..Default::default()
    };
    let only = args.get(5).map(String::as_str);
    if only != Some("mlp") {
        let (gp_model, gp) = train_model(&data, ModelKind::Gp, &opts)?;
        println!("{gp}\n");
        if let Ok(png) = std::env::var("MAP") {
            // the GP's prediction at test location A, full force
            // raw outputs (6R stress components on the tensor target) to the R principal stresses
            let mut p = gp_model.to_predictor();
            let mut map = surrogate::target::TargetMap::new(gp.target, data.n_roi());
            let values = map.apply(p.predict_inputs(&[0.037, 0.062, 37.0])).to_vec();
            surrogate::render_map(
                data.roi_centroids.view(),
                &values,
                std::path::Path::new(&png),
            )?;
        }
    }
    if only != Some("gp") {
        let (_, mlp) = train_model(&data, ModelKind::Mlp, &opts)?;
        println!("{mlp}");
    }
    Ok(())
}

fn env(name: &str, default: f64) -> f64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}
