//! Prediction latency of the surrogates on one core (issue 7 floors: MLP <= 50 us, GP <= 20 us),
//! for the paper's ROI size R = 377 and the synthetic 150-sample training set.
//!
//! `cargo bench -p surrogate --bench surrogate`

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use surrogate::gp::GpOptions;
use surrogate::mlp::MlpOptions;
use surrogate::model::PredictorImpl;
use surrogate::synthetic::make_synthetic_dataset;
use surrogate::{train_model, ModelKind, TrainOptions};

fn predict_latency(c: &mut Criterion) {
    let data = make_synthetic_dataset(377);
    let opts = TrainOptions {
        mlp: MlpOptions {
            epochs: 300,
            ..Default::default()
        },
        gp: GpOptions {
            restarts: 0,
            max_iterations: 50,
            ..Default::default()
        },
    };
    let (mlp, _) = train_model(&data, ModelKind::Mlp, &opts).expect("train MLP");
    let (gp, _) = train_model(&data, ModelKind::Gp, &opts).expect("train GP");
    let inputs = [0.041, 0.057, 23.0];
    let mut group = c.benchmark_group("surrogate_predict");
    group.throughput(Throughput::Elements(1));
    let mut p = mlp.to_predictor();
    group.bench_function("mlp_3-64-126-256-512-377", |b| {
        b.iter(|| black_box(p.predict_inputs(black_box(&inputs))[0]))
    });
    let mut p = gp.to_predictor();
    group.bench_function("gp_mean_n150_r377", |b| {
        b.iter(|| black_box(p.predict_inputs(black_box(&inputs))[0]))
    });
    if let PredictorImpl::Gp(mut g) = gp.to_predictor() {
        group.bench_function("gp_mean_and_variance_n150_r377", |b| {
            b.iter(|| black_box(g.predict_with_variance(black_box(&inputs)).1))
        });
    }
    group.finish();
}

criterion_group!(benches, predict_latency);
criterion_main!(benches);
