//! The library functions the command line calls: train to a file, predict, evaluate, render.

use surrogate::gp::GpOptions;
use surrogate::mlp::MlpOptions;
use surrogate::synthetic::make_synthetic_dataset;
use surrogate::{
    evaluate, predict, render_map, train, ModelConfig, ModelKind, Predictor, TrainOptions,
};

#[test]
fn train_writes_a_model_that_predict_serves() {
    let dir = tempfile::tempdir().unwrap();
    let data = make_synthetic_dataset(12);
    data.write(dir.path().join("data")).unwrap();
    let opts = TrainOptions {
        gp: GpOptions {
            restarts: 0,
            ..Default::default()
        },
        ..Default::default()
    };
    let model = dir.path().join("gp-model");
    let report = train(&dir.path().join("data"), ModelKind::Gp, &opts, &model).unwrap();
    assert!(report.test_fit.unwrap() > 0.9, "{report}");
    assert!(model.join("model.safetensors").exists() && model.join("model.json").exists());
    let p = predict(&model, 0.04, 0.05, 20.0).unwrap();
    assert_eq!(p.stress.len(), 12);
    assert!(p.variance.unwrap() >= 0.0);
    let mut loaded = Predictor::load(&model).unwrap();
    assert_eq!(loaded.predict(0.04, 0.05, 20.0), &p.stress[..]);
}

#[test]
fn evaluate_builds_the_accuracy_cost_table() {
    let data = make_synthetic_dataset(6);
    let configs = vec![
        ModelConfig {
            name: "gp".into(),
            kind: ModelKind::Gp,
            options: TrainOptions {
                gp: GpOptions {
                    restarts: 0,
                    max_iterations: 30,
                    ..Default::default()
                },
                ..Default::default()
            },
        },
        ModelConfig {
            name: "mlp-tiny".into(),
            kind: ModelKind::Mlp,
            options: TrainOptions {
                mlp: MlpOptions {
                    hidden: vec![8],
                    epochs: 20,
                    ..Default::default()
                },
                ..Default::default()
            },
        },
    ];
    let report = evaluate(&data, &configs).unwrap();
    assert_eq!(report.n_folds, 28);
    assert_eq!(report.rows.len(), 2);
    let gp = &report.rows[0];
    assert_eq!(gp.by_location.len(), 28);
    assert!(gp.fit_pooled > 0.8, "{report}");
    let table = report.to_string();
    assert!(
        table.contains("| gp | gp |") && table.contains("mlp-tiny"),
        "{table}"
    );
}

#[test]
fn render_map_writes_a_png() {
    let dir = tempfile::tempdir().unwrap();
    let data = make_synthetic_dataset(60);
    let png = dir.path().join("map.png");
    render_map(
        data.roi_centroids.view(),
        data.y.row(100).as_slice().unwrap(),
        &png,
    )
    .unwrap();
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let e = render_map(data.roi_centroids.view(), &[1.0, 2.0], &png).unwrap_err();
    assert!(e.to_string().contains("centroids"), "{e}");
}
