//! Prediction latency of the surrogates on one core (issue 7 floors: MLP <= 50 us, GP <= 20 us),
//! for the paper's ROI size R = 377:
//! - on the synthetic 150-sample training set (`surrogate::synthetic`): the paper's MLP and the
//!   GP on the principal stress (mean alone, and mean plus variance);
//! - on the committed default campaign (`data/default-campaign-3mm`, 150 training samples): the
//!   GP on the principal stress, and the GP on the stress tensor (6 x 377 outputs through its
//!   output basis, then the largest eigenvalue of each of the 377 predicted tensors), the
//!   default of `palpa train --model gp`, with its output basis and without (`_exact`: every
//!   output direction, the accuracy-versus-latency knob `GpOptions::output_tolerance`). Each
//!   iteration is one whole prediction of all 377 maximum principal stresses.
//!
//! `cargo bench -p benches --bench surrogate`

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use surrogate::gp::GpOptions;
use surrogate::mlp::MlpOptions;
use surrogate::model::PredictorImpl;
use surrogate::synthetic::make_synthetic_dataset;
use surrogate::target::TargetMap;
use surrogate::{train_model, Dataset, ModelKind, Target, TrainOptions};

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
        target: Some(Target::Principal),
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

    let campaign =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../data/default-campaign-3mm");
    let data = Dataset::read(&campaign).expect("read the committed default campaign");
    let r = data.n_roi();
    // a point between raster locations, at a mid-press force
    let inputs = [data.x[(0, 0)] + 0.01, data.x[(0, 1)] + 0.006, 30.0];
    let exact = GpOptions {
        output_tolerance: 0.0,
        ..Default::default()
    };
    for (target, gp_opts, name) in [
        (Target::Principal, GpOptions::default(), ""),
        (Target::Tensor, GpOptions::default(), ""),
        (Target::Tensor, exact, "_exact"),
    ] {
        let opts = TrainOptions {
            target: Some(target),
            gp: gp_opts,
            ..Default::default()
        };
        let (gp, report) = train_model(&data, ModelKind::Gp, &opts).expect("train GP");
        eprintln!(
            "default campaign, GP on the {target} target{name}: {}, held-out Fit {:.4}",
            report.size,
            report.test_fit.unwrap_or(f64::NAN)
        );
        let mut p = gp.to_predictor();
        let mut map = TargetMap::new(target, r);
        group.bench_function(format!("gp_{target}{name}_default_campaign_r{r}"), |b| {
            b.iter(|| black_box(map.apply(p.predict_inputs(black_box(&inputs)))[0]))
        });
    }
    group.finish();
}

criterion_group!(benches, predict_latency);
criterion_main!(benches);
