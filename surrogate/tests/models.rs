//! Both surrogates on the synthetic dataset (`surrogate::synthetic`): accuracy on the held-out
//! locations, save/load (on both targets), the serving forward pass against the trainer's, and
//! the tensor target's served value against nalgebra's eigenvalues of its predicted tensor.
//!
//! Threshold: Fit > 0.9 on the three held-out locations, the issue's floor (the paper reached
//! 0.9264). It is meaningful here because a model that ignores where the finger is scores far
//! below it: `location_blind_baseline_scores_below_threshold` predicts each test sample by the
//! mean training response at its force level, and stays under 0.5.

use ndarray::{s, Axis};
use surrogate::gp::GpOptions;
use surrogate::mlp::network::{forward_batch, BatchWorkspace};
use surrogate::mlp::{AdamOptions, GdxOptions, MlpOptions, Optimiser};
use surrogate::synthetic::{make_synthetic_dataset, FORCES};
use surrogate::target::TargetMap;
use surrogate::{
    compute_fit, train_model, ModelKind, Predictor, Target, TrainOptions, TrainedModel,
};

const R: usize = 40;
const FLOOR: f64 = 0.9;

fn mlp_options(epochs: usize) -> TrainOptions {
    TrainOptions {
        mlp: MlpOptions {
            hidden: vec![64, 128, 128],
            epochs,
            optimiser: Optimiser::Adam(AdamOptions {
                weight_decay: 3.0,
                ..Default::default()
            }),
            ..Default::default()
        },
        gp: GpOptions::default(),
        target: None,
    }
}

fn gp_options() -> TrainOptions {
    TrainOptions {
        gp: GpOptions {
            restarts: 1,
            ..Default::default()
        },
        ..Default::default()
    }
}

#[test]
fn location_blind_baseline_scores_below_threshold() {
    let d = make_synthetic_dataset(R);
    let test = d.rows_with_split(surrogate::Split::Test);
    let mut yhat = d.y.select(Axis(0), &test);
    for (k, &i) in test.iter().enumerate() {
        let same_force: Vec<usize> = d
            .rows_with_split(surrogate::Split::Train)
            .into_iter()
            .filter(|&j| d.x[(j, 2)] == d.x[(i, 2)])
            .collect();
        let m = d.y.select(Axis(0), &same_force).mean_axis(Axis(0)).unwrap();
        yhat.row_mut(k).assign(&m);
    }
    let fit = compute_fit(d.y.select(Axis(0), &test).view(), yhat.view());
    assert_eq!(FORCES.len(), 6);
    assert!(fit < 0.5, "baseline Fit {fit}");
}

#[test]
fn mlp_adam_fits_held_out_locations() {
    let d = make_synthetic_dataset(R);
    let (_, report) = train_model(&d, ModelKind::Mlp, &mlp_options(2000)).unwrap();
    let fit = report.test_fit.unwrap();
    assert!(fit > FLOOR, "{report}");
    assert_eq!(report.test_fit_by_location.len(), 3);
    assert_eq!(report.test_fit_by_location[0].label, "A");
}

#[test]
fn mlp_gdx_fits_held_out_locations() {
    let d = make_synthetic_dataset(R);
    let mut o = mlp_options(3000);
    o.mlp.optimiser = Optimiser::Gdx(GdxOptions::default());
    let (_, report) = train_model(&d, ModelKind::Mlp, &o).unwrap();
    assert!(report.test_fit.unwrap() > FLOOR, "{report}");
}

#[test]
fn mlp_minibatch_adam_trains() {
    let d = make_synthetic_dataset(R);
    let mut o = mlp_options(300);
    o.mlp.optimiser = Optimiser::Adam(AdamOptions {
        batch_size: Some(16),
        ..Default::default()
    });
    let (_, report) = train_model(&d, ModelKind::Mlp, &o).unwrap();
    assert!(report.train_fit > 0.85, "{report}");
}

#[test]
fn gp_fits_held_out_locations_with_sensible_variance() {
    let d = make_synthetic_dataset(R);
    // on Y here; the tensor target has its own test below
    let opts = TrainOptions {
        target: Some(Target::Principal),
        ..gp_options()
    };
    let (model, report) = train_model(&d, ModelKind::Gp, &opts).unwrap();
    assert_eq!(report.target, Target::Principal);
    assert!(report.test_fit.unwrap() > FLOOR, "{report}");
    let TrainedModel::Gp(g) = &model else {
        unreachable!()
    };
    let mut p = match model.to_predictor() {
        surrogate::model::PredictorImpl::Gp(p) => p,
        _ => unreachable!(),
    };
    // at a training input the latent variance is far below the prior's; far away it is the prior
    let prior = g.kernel.signal_variance * g.output_scaling.std[0].powi(2);
    let (_, v_near) = p.predict_with_variance(&[d.x[(10, 0)], d.x[(10, 1)], d.x[(10, 2)]]);
    let (_, v_far) = p.predict_with_variance(&[5.0, 5.0, 500.0]);
    assert!(v_near < 0.05 * prior, "near {v_near} prior {prior}");
    assert!(
        (v_far - prior).abs() < 1e-9 * prior,
        "far {v_far} prior {prior}"
    );
}

#[test]
fn fits_are_deterministic_for_a_seed() {
    let d = make_synthetic_dataset(8);
    let o = mlp_options(50);
    let (a, _) = train_model(&d, ModelKind::Mlp, &o).unwrap();
    let (b, _) = train_model(&d, ModelKind::Mlp, &o).unwrap();
    let (TrainedModel::Mlp(a), TrainedModel::Mlp(b)) = (a, b) else {
        unreachable!()
    };
    assert_eq!(a.params, b.params);
}

/// Save a trained model into `dir` and load it back as `palpa predict` does.
fn save_and_load(
    model: &TrainedModel,
    d: &surrogate::Dataset,
    report: &surrogate::report::TrainReport,
    dir: &std::path::Path,
) -> Predictor {
    let path = dir.join("model.safetensors");
    model
        .save(
            &path,
            d.roi_ids.as_slice().unwrap(),
            d.roi_centroids.view(),
            report,
        )
        .unwrap();
    Predictor::load(&path).unwrap()
}

fn assert_round_trip(kind: ModelKind, opts: &TrainOptions) {
    let dir = tempfile::tempdir().unwrap();
    let d = make_synthetic_dataset(R);
    let (model, report) = train_model(&d, kind, opts).unwrap();
    if let TrainedModel::Gp(g) = &model {
        // the synthetic targets are smooth: the output basis is in use, and saved with the model
        assert!(g.basis.is_some(), "{report}");
    }
    let mut loaded = save_and_load(&model, &d, &report, dir.path());
    assert_eq!(loaded.meta().report, report);
    assert_eq!(loaded.roi_centroids(), d.roi_centroids.view());
    let mut direct = model.to_predictor();
    let mut map = TargetMap::new(report.target, R);
    for i in [0, 37, 160] {
        let (x, y, f) = (d.x[(i, 0)], d.x[(i, 1)], d.x[(i, 2)]);
        let a = map.apply(direct.predict_inputs(&[x, y, f])).to_vec();
        assert_eq!(a.len(), R);
        assert_eq!(loaded.predict(x, y, f), &a[..], "row {i}");
    }
}

#[test]
fn gp_on_the_stress_tensor_serves_the_largest_eigenvalue_of_its_prediction() {
    let d = make_synthetic_dataset(R);
    let (model, report) = train_model(&d, ModelKind::Gp, &gp_options()).unwrap();
    // the synthetic dataset has S, so the GP's default target is the tensor
    assert_eq!(report.target, Target::Tensor);
    assert!(report.test_fit.unwrap() > FLOOR, "{report}");
    let mut raw = model.to_predictor();
    let mut map = TargetMap::new(Target::Tensor, R);
    for i in d.rows_with_split(surrogate::Split::Test) {
        let s6 = raw
            .predict_inputs(&[d.x[(i, 0)], d.x[(i, 1)], d.x[(i, 2)]])
            .to_vec();
        assert_eq!(s6.len(), 6 * R);
        let served = map.apply(&s6).to_vec();
        for (e, s) in s6.chunks_exact(6).enumerate() {
            let want = nalgebra::Matrix3::new(s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2])
                .symmetric_eigenvalues()
                .max();
            assert!(
                (served[e] - want).abs() <= 1e-9 * (1.0 + want.abs()),
                "row {i} element {e}: {} against {want}",
                served[e]
            );
        }
    }
    // without S the tensor target is an error naming S
    let mut no_s = d.clone();
    no_s.stress = None;
    let opts = TrainOptions {
        target: Some(Target::Tensor),
        ..gp_options()
    };
    let err = train_model(&no_s, ModelKind::Gp, &opts)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("S") && err.contains("--target principal"),
        "{err}"
    );
}

#[test]
fn tensor_gp_save_load_round_trip_predicts_identically() {
    let mut o = gp_options();
    o.target = Some(Target::Tensor);
    o.gp.restarts = 0;
    o.gp.max_iterations = 20;
    assert_round_trip(ModelKind::Gp, &o);
}

#[test]
fn version_1_gp_files_load_and_a_bad_output_basis_is_an_error() {
    use surrogate::tensor_file::{read_metadata, read_tensors, write_tensors};
    let dir = tempfile::tempdir().unwrap();
    let d = make_synthetic_dataset(R);
    let opts = TrainOptions {
        target: Some(Target::Principal),
        gp: GpOptions {
            restarts: 0,
            max_iterations: 20,
            ..Default::default()
        },
        ..Default::default()
    };
    let (model, report) = train_model(&d, ModelKind::Gp, &opts).unwrap();
    let path = dir.path().join("m.safetensors");
    let save = |m: &TrainedModel| {
        m.save(
            &path,
            d.roi_ids.as_slice().unwrap(),
            d.roi_centroids.view(),
            &report,
        )
        .unwrap()
    };
    let x = [d.x[(40, 0)], d.x[(40, 1)], d.x[(40, 2)]];
    // a version-1 file: the full coefficients named `alpha`, no basis, no target field
    let TrainedModel::Gp(g) = &model else {
        unreachable!()
    };
    let mut exact = g.clone();
    exact.coef = exact.coef.dot(exact.basis.as_ref().unwrap());
    exact.basis = None;
    let exact = TrainedModel::Gp(exact);
    save(&exact);
    let want = Predictor::load(&path)
        .unwrap()
        .predict(x[0], x[1], x[2])
        .to_vec();
    let mut set = read_tensors(&path).unwrap();
    let coef = set.remove("coef").unwrap();
    set.insert("alpha".into(), coef);
    // version-1 files carried no header metadata
    write_tensors(&path, &set, &Default::default()).unwrap();
    let json = path.with_extension("json");
    let text = std::fs::read_to_string(&json).unwrap();
    let mut meta: serde_json::Value = serde_json::from_str(&text).unwrap();
    meta["version"] = 1.into();
    meta["report"].as_object_mut().unwrap().remove("target");
    std::fs::write(&json, serde_json::to_string(&meta).unwrap()).unwrap();
    let mut v1 = Predictor::load(&path).unwrap();
    assert_eq!(v1.predict(x[0], x[1], x[2]), &want[..]);
    // the basis model predicts the projection of that mean: close, not equal
    save(&model);
    let got = Predictor::load(&path)
        .unwrap()
        .predict(x[0], x[1], x[2])
        .to_vec();
    let scale = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for (a, b) in got.iter().zip(&want) {
        assert!((a - b).abs() <= 1e-2 * scale, "{a} against {b}");
    }
    // the header says what the file is: kind, target, version, inputs and units
    let header = read_metadata(&path).unwrap();
    assert_eq!(header["kind"], "gp");
    assert_eq!(header["target"], "principal");
    assert_eq!(header["version"], "2");
    assert_eq!(header["input_columns"], r#"["x","y","force"]"#);
    assert_eq!(header["input_units"], r#"["m","m","N"]"#);
    assert_eq!(header["output_unit"], "Pa");
    // input columns other than x, y, force (and phase) are an error naming them
    let json = path.with_extension("json");
    let good = std::fs::read_to_string(&json).unwrap();
    let bad = good.replacen("\"force\"", "\"time\"", 1);
    std::fs::write(&json, &bad).unwrap();
    let err = Predictor::load(&path).unwrap_err().to_string();
    assert!(
        err.contains("input_columns") && err.contains("time"),
        "{err}"
    );
    std::fs::write(&json, &good).unwrap();
    // a header that contradicts the JSON is an error naming the file
    let set = read_tensors(&path).unwrap();
    let mut wrong = header.clone();
    wrong.insert("target".into(), "tensor".into());
    write_tensors(&path, &set, &wrong).unwrap();
    let err = Predictor::load(&path).unwrap_err().to_string();
    assert!(
        err.contains("m.safetensors") && err.contains("target"),
        "{err}"
    );
    // an empty basis would silently serve the mean field: it is an error naming the file
    let mut set = read_tensors(&path).unwrap();
    let m = set["basis"].shape[1];
    let n = set["coef"].shape[0];
    set.insert(
        "basis".into(),
        surrogate::tensor_file::Tensor {
            shape: vec![0, m],
            data: surrogate::tensor_file::TensorData::F64(Vec::new()),
        },
    );
    set.insert(
        "coef".into(),
        surrogate::tensor_file::Tensor {
            shape: vec![n, 0],
            data: surrogate::tensor_file::TensorData::F64(Vec::new()),
        },
    );
    write_tensors(&path, &set, &header).unwrap();
    let err = Predictor::load(&path).unwrap_err().to_string();
    assert!(
        err.contains("m.safetensors") && err.contains("basis"),
        "{err}"
    );
}

#[test]
fn mlp_save_load_round_trip_predicts_identically() {
    assert_round_trip(ModelKind::Mlp, &mlp_options(20));
}

#[test]
fn gp_save_load_round_trip_predicts_identically() {
    let mut o = gp_options();
    o.target = Some(Target::Principal);
    o.gp.restarts = 0;
    o.gp.max_iterations = 20;
    assert_round_trip(ModelKind::Gp, &o);
}

#[test]
fn serving_forward_equals_trainer_forward() {
    let d = make_synthetic_dataset(R);
    let (model, _) = train_model(&d, ModelKind::Mlp, &mlp_options(300)).unwrap();
    let TrainedModel::Mlp(m) = &model else {
        unreachable!()
    };
    let x3 = d.x.slice(s![.., 0..3]).to_owned();
    let n = x3.nrows();
    let mut ws = BatchWorkspace::new(&m.params.sizes, n);
    let u = m.input_scaling.compute_forward(x3.view());
    for (h, v) in ws.h[0].iter_mut().zip(u.iter()) {
        *h = *v as f32;
    }
    forward_batch(&m.params, &mut ws);
    let out = &ws.h[m.params.n_layers()];
    let mut pred = model.to_predictor();
    let mut worst = 0.0f64;
    let scale = out.iter().fold(0.0f32, |m, v| m.max(v.abs())) as f64;
    for i in 0..n {
        let p = pred.predict_inputs(&[x3[(i, 0)], x3[(i, 1)], x3[(i, 2)]]);
        for (j, &pj) in p.iter().enumerate() {
            // compare in normalised units, where outputs are O(1)
            let serving = (pj - m.output_scaling.mean[j]) / m.output_scaling.std[j];
            worst = worst.max((serving - out[i * R + j] as f64).abs());
        }
    }
    // both passes run in f32 (epsilon 1.2e-7) with different summation orders: agree to 1e-6
    // of the largest output
    assert!(
        worst <= 1e-6 * scale,
        "largest difference {worst:e}, largest output {scale}"
    );
}

#[test]
fn bad_inputs_are_errors_not_panics() {
    let dir = tempfile::tempdir().unwrap();
    let e = Predictor::load(dir.path()).unwrap_err().to_string();
    assert!(e.contains("model.json"), "{e}");
    let mut d = make_synthetic_dataset(4);
    d.split.fill(1);
    let e = train_model(&d, ModelKind::Gp, &gp_options())
        .unwrap_err()
        .to_string();
    assert!(e.contains("split"), "{e}");
    let e = surrogate::predict(&dir.path().join("m.json"), f64::NAN, 0.0, 1.0)
        .unwrap_err()
        .to_string();
    assert!(e.contains('x'), "{e}");
}

/// A campaign's dataset repeats one target row once per location. At t = 0 the force is 0 and
/// the stress is the unloaded one. When the likelihood counted those rows once each, it
/// rewarded a vanishing noise variance: on the 25 mm-fat paper campaign it chose a force
/// length scale of 0.01 with sn2 = 5e-6, and the held-out Fit fell to 0.15. Here the training
/// targets carry deterministic noise of 80 % of their RMS, except the unloaded rows, which stay
/// exactly zero as in a campaign. The test targets are the clean field.
/// - Measured, likelihood over the 126 distinct rows: sn2 = 0.53 and Fit 0.77 against the
///   clean field.
/// - Measured, likelihood over all 150 rows: a y length scale of 0.11 and Fit 0.01.
#[test]
fn gp_with_repeated_unloaded_rows_and_noisy_targets_keeps_a_noise_term() {
    let mut d = make_synthetic_dataset(R);
    // the noise goes on Y; without S the GP's default target is Y
    d.stress = None;
    let train = d.rows_with_split(surrogate::Split::Train);
    let rms = (train
        .iter()
        .map(|&i| d.y.row(i).iter().map(|v| v * v).sum::<f64>())
        .sum::<f64>()
        / (train.len() * R) as f64)
        .sqrt();
    for &i in &train {
        if d.x[(i, 2)] == 0.0 {
            continue;
        }
        for r in 0..R {
            // a fixed pseudo-random sequence in [-1, 1], uniform: RMS 1/sqrt(3)
            let u = ((i * 7919 + r * 104_729) as f64 * 0.618_033_988_75).fract() * 2.0 - 1.0;
            d.y[(i, r)] += 0.8 * 3f64.sqrt() * rms * u;
        }
    }
    let (model, report) = train_model(&d, ModelKind::Gp, &gp_options()).unwrap();
    let TrainedModel::Gp(g) = &model else {
        unreachable!()
    };
    assert_eq!(g.likelihood_rows, 25 * (FORCES.len() - 1) + 1, "{report}");
    assert!(g.kernel.noise_variance > 0.1, "{:?}", g.kernel);
    assert!(report.test_fit.unwrap() > 0.6, "{report}");
}

#[test]
fn a_model_whose_fit_is_nan_saves_and_loads() {
    // One held-out location whose stresses do not vary: its Fit divides by zero (NaN), which
    // JSON cannot hold. The model used to save with `"fit": null` and then fail to load.
    let mut d = make_synthetic_dataset(R);
    let held = (0..d.split.len()).find(|&i| d.split[i] == 1).unwrap();
    let loc = d.location[held];
    for i in 0..d.split.len() {
        if d.location[i] == loc {
            d.y.row_mut(i).fill(1000.0);
        }
    }
    let (model, report) = train_model(&d, ModelKind::Mlp, &mlp_options(5)).unwrap();
    let nan = report
        .test_fit_by_location
        .iter()
        .find(|l| l.location == loc)
        .unwrap();
    assert!(nan.fit.is_nan(), "{report}");
    let dir = tempfile::tempdir().unwrap();
    let loaded = save_and_load(&model, &d, &report, dir.path());
    let back = &loaded.meta().report;
    let fit = |r: &surrogate::report::TrainReport| -> Vec<f64> {
        r.test_fit_by_location.iter().map(|l| l.fit).collect()
    };
    for (a, b) in fit(back).iter().zip(fit(&report)) {
        assert!(a == &b || (a.is_nan() && b.is_nan()), "{a} against {b}");
    }
    assert_eq!(back.train_fit, report.train_fit);
}
