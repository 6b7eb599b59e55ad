//! The surrogate commands end to end through the real binary (issue 7): `palpa train` for the
//! MLP and the GP on a small synthetic dataset (model files written, Fit printed and finite),
//! `palpa predict` one-shot with `--png` (vector of ROI length, PNG written) and `--stdin`
//! (one JSON line per input, an error line for a malformed one), and bad input (missing
//! dataset, missing model, wrong `--model`, `--target tensor` without stress tensors) giving a
//! message naming it and a non-zero exit.

use std::io::Write;
use std::path::Path;
use std::process::{Command, Output, Stdio};
#[path = "support/cli.rs"]
mod cli;

/// ROI elements of the synthetic dataset.
const R: usize = 8;

fn palpa(args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_palpa"))
        .args(args)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "panic: {err}");
    out
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// The overall held-out Fit printed by `palpa train`.
fn overall_fit(stdout: &str) -> f64 {
    let line = stdout
        .lines()
        .find(|l| l.starts_with("Fit on all") && l.contains("test samples"))
        .unwrap_or_else(|| panic!("no overall Fit line in:\n{stdout}"));
    line.rsplit(':').next().unwrap().trim().parse().unwrap()
}

fn train(data: &Path, model: &str, out: &Path, extra: &[&str]) -> String {
    let mut args = vec![
        "train",
        data.to_str().unwrap(),
        "--model",
        model,
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let o = palpa(&args);
    let stdout = text(&o.stdout);
    assert!(
        o.status.success(),
        "train {model}: {}\n{stdout}",
        text(&o.stderr)
    );
    assert!(out.join("model.safetensors").is_file() && out.join("model.json").is_file());
    assert!(stdout.contains("training time:"), "{stdout}");
    // per test location (A, B, C of the synthetic dataset) and overall
    for loc in ["A", "B", "C"] {
        assert!(
            stdout.contains(&format!("Fit on test location {loc} ")),
            "{stdout}"
        );
    }
    let fit = overall_fit(&stdout);
    assert!(fit.is_finite() && fit <= 1.0, "Fit {fit}: {stdout}");
    stdout
}

#[test]
fn train_predict_and_stream() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    surrogate::synthetic::make_synthetic_dataset(R)
        .write(&data)
        .unwrap();

    // MLP: small and short, only the plumbing is under test here
    let mlp = dir.path().join("mlp");
    train(
        &data,
        "mlp",
        &mlp,
        &["--epochs", "30", "--hidden", "16,16", "--seed", "3"],
    );
    // GP: one start only; the synthetic field is smooth, the GP must get it. The dataset holds
    // stress tensors, so the GP learns them by default and serves their largest eigenvalues
    // (R values, checked below).
    let gp = dir.path().join("gp");
    let gp_out = train(&data, "gp", &gp, &["--restarts", "0"]);
    assert!(overall_fit(&gp_out) > 0.8, "{gp_out}");
    assert!(gp_out.contains("model gp on the tensor target"), "{gp_out}");

    // one-shot with a map
    let png = dir.path().join("map.png");
    let o = palpa(&[
        "predict",
        gp.to_str().unwrap(),
        "--x",
        "0.04",
        "--y",
        "0.05",
        "--force",
        "20",
        "--png",
        png.to_str().unwrap(),
    ]);
    let stdout = text(&o.stdout);
    assert!(o.status.success(), "{}\n{stdout}", text(&o.stderr));
    let vector: Vec<f64> = stdout
        .lines()
        .skip_while(|l| !l.starts_with("element_id"))
        .skip(1)
        .map(|l| l.split_whitespace().nth(1).unwrap().parse().unwrap())
        .collect();
    assert_eq!(vector.len(), R, "{stdout}");
    assert!(vector.iter().all(|v| v.is_finite()), "{stdout}");
    let bytes = std::fs::read(&png).unwrap();
    assert!(bytes.starts_with(b"\x89PNG"), "not a PNG");

    // streaming: two good lines and a malformed one in the middle
    for model in [&mlp, &gp] {
        let o = cli::predict_stdin(
            model,
            b"{\"x\": 0.04, \"y\": 0.05, \"force\": 20, \"id\": 7}\n\
                  {\"x\": 0.04, \"y\": oops}\n\
                  {\"x\": 0.06, \"y\": 0.03, \"force\": 37.0}\n",
        );
        let stdout = text(&o.stdout);
        assert!(o.status.success(), "{}\n{stdout}", text(&o.stderr));
        let lines: Vec<serde_json::Value> = stdout
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        assert_eq!(lines.len(), 3, "{stdout}");
        for (k, v) in lines.iter().enumerate() {
            assert_eq!(v["line"], k + 1, "{stdout}");
        }
        assert_eq!(lines[0]["id"], 7);
        for good in [&lines[0], &lines[2]] {
            assert_eq!(good["stress"].as_array().unwrap().len(), R, "{stdout}");
        }
        assert!(lines[2].get("error").is_none());
        let err = lines[1]["error"].as_str().unwrap();
        assert!(err.contains("line 2"), "{err}");
        // a GP reports its variance, an MLP has none
        assert_eq!(lines[0]["variance"].is_number(), model == &gp, "{stdout}");
    }
}

#[test]
fn bad_input_names_the_file_or_flag() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("no-such-dataset");
    let out = dir.path().join("m");
    for model in ["mlp", "gp"] {
        let o = palpa(&[
            "train",
            missing.to_str().unwrap(),
            "--model",
            model,
            "--out",
            out.to_str().unwrap(),
        ]);
        let err = text(&o.stderr);
        assert!(!o.status.success());
        assert!(err.contains(missing.to_str().unwrap()), "{err}");
    }
    let o = palpa(&["evaluate", missing.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(text(&o.stderr).contains(missing.to_str().unwrap()));

    // wrong --model value
    let o = palpa(&[
        "train",
        missing.to_str().unwrap(),
        "--model",
        "svm",
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = text(&o.stderr);
    assert!(!o.status.success());
    assert!(err.contains("--model") && err.contains("svm"), "{err}");

    // --target tensor on a dataset without stress tensors names S and the way out
    let no_s = dir.path().join("no-s");
    let mut d = surrogate::synthetic::make_synthetic_dataset(R);
    d.stress = None;
    d.write(&no_s).unwrap();
    let o = palpa(&[
        "train",
        no_s.to_str().unwrap(),
        "--model",
        "gp",
        "--target",
        "tensor",
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = text(&o.stderr);
    assert!(!o.status.success());
    assert!(
        err.contains(no_s.to_str().unwrap())
            && err.contains("S")
            && err.contains("--target principal"),
        "{err}"
    );

    // missing model, and a model file that is not one
    let o = palpa(&[
        "predict",
        out.to_str().unwrap(),
        "--x",
        "0",
        "--y",
        "0",
        "--force",
        "1",
    ]);
    let err = text(&o.stderr);
    assert!(!o.status.success());
    assert!(err.contains(out.to_str().unwrap()), "{err}");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("model.json"), "{ not json").unwrap();
    std::fs::write(out.join("model.safetensors"), "junk").unwrap();
    let o = palpa(&["predict", out.to_str().unwrap(), "--stdin"]);
    let err = text(&o.stderr);
    assert!(!o.status.success());
    assert!(err.contains("model.json"), "{err}");
}

/// Issue 29: one line of invalid UTF-8 ended `predict --stdin` and lost every later line; it
/// gets an error reply naming its line and the stream goes on.
#[test]
fn predict_stdin_survives_invalid_utf8() {
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/default-model-gp");
    let mut child = Command::new(env!("CARGO_BIN_EXE_palpa"))
        .args(["predict", model.to_str().unwrap(), "--stdin"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let good = b"{\"x\": 0.0, \"y\": 0.1, \"force\": 10.0}\n";
    let mut input = Vec::new();
    input.extend_from_slice(good);
    input.extend_from_slice(b"{\"x\": \xff\xfe 0.0}\n");
    input.extend_from_slice(good);
    child.stdin.take().unwrap().write_all(&input).unwrap();
    let out = child.wait_with_output().unwrap();
    let err = text(&out.stderr);
    assert!(out.status.success() && !err.contains("panicked"), "{err}");
    let replies: Vec<serde_json::Value> = text(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(replies.len(), 3, "{replies:?}");
    assert_eq!(replies[1]["line"], 2);
    let e = replies[1]["error"].as_str().unwrap();
    assert!(e.contains("line 2") && e.contains("UTF-8"), "{e}");
    assert_eq!(replies[2]["line"], 3);
    assert!(replies[2]["stress"]
        .as_array()
        .is_some_and(|s| !s.is_empty()));
}
