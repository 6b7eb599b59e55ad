//! `palpa check` prints the mesh's own critical step ([`solver::global_step`]) whichever
//! estimate the scene asks for: on the free block of 1 mm cubes of
//! `verification/python/hex_stability_eigen.py` (one-point, nu = 0.49) the dense eigenvalues
//! give 0.855 h / c. Beside subcycling or a factor above 0.9, which a run refuses with the global
//! estimate, the estimate is still printed and the refusal named.

#[path = "support/cli.rs"]
mod cli;
#[path = "../scene/tests/integration/common/mod.rs"]
mod common;

/// A free 5 x 4 x 4 mm block of 1 mm cubes of a nu = 0.49 linear elastic solid, `run_extra`
/// in `[run]`.
fn free_block(run_extra: &str) -> String {
    common::free_box(run_extra, [5.0, 4.0, 4.0], [5, 4, 4], "")
}

/// `palpa check`'s global-step line for `scene`.
fn global_line(scene: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("block.toml");
    std::fs::write(&path, scene).unwrap();
    let stdout = cli::ok(&["check", cli::s(&path), "--no-pilot"]);
    stdout
        .lines()
        .find(|l| l.contains("global step estimate"))
        .unwrap_or_else(|| panic!("no global-step line:\n{stdout}"))
        .to_string()
}

/// The number after `key` in `line`.
fn number_after(line: &str, key: &str) -> f64 {
    let rest = &line[line.find(key).unwrap_or_else(|| panic!("{key} in {line}")) + key.len()..];
    rest.split_whitespace().next().unwrap().parse().unwrap()
}

#[test]
fn check_prints_the_meshs_critical_step() {
    let (e, nu, rho): (f64, f64, f64) = (300e3, 0.49, 1000.0);
    let c = (e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu)) / rho).sqrt();
    for (extra, tail) in [
        ("", "would use it"),
        ("step_estimate = \"global\"", "the run uses it"),
        (
            "subcycling = 2",
            "a run refuses it beside run.subcycling = 2",
        ),
        (
            "dt_factor = 0.95",
            "a run refuses it beside run.dt_factor = 0.95",
        ),
    ] {
        let line = global_line(&free_block(extra));
        let ratio = number_after(&line, "critical step") / (1e-3 / c);
        assert!((ratio - 0.855).abs() < 0.0015, "{ratio}: {line}");
        assert!(line.contains(tail), "{line}");
        // the bound at factor 0.9 (0.95 is set aside), and the steps it gives to 1 ms
        let words: Vec<&str> = line[line.find("at factor 0.9:").unwrap()..]
            .split_whitespace()
            .collect();
        let (bound, steps): (f64, f64) = (words[3].parse().unwrap(), words[5].parse().unwrap());
        assert!(
            (bound / (0.9 * ratio * 1e-3 / c) - 1.0).abs() < 1e-3,
            "{line}"
        );
        assert_eq!(steps, (1e-3 / bound).ceil(), "{line}");
    }
}

/// A scene that asks for the global estimate where a run refuses it fails `check` as the run
/// would, naming the setting.
#[test]
fn check_refuses_what_a_run_refuses() {
    let dir = tempfile::tempdir().unwrap();
    for (extra, named) in [
        (
            "step_estimate = \"global\"\ndt_factor = 0.95",
            "run.dt_factor = 0.95",
        ),
        (
            "step_estimate = \"global\"",
            "fully integrated elements without F-bar",
        ),
    ] {
        let mut src = free_block(extra);
        if named.contains("F-bar") {
            src = src.replace(
                "material = \"m\"",
                "material = \"m\"\nformulation = \"full\"",
            );
        }
        let path = dir.path().join("block.toml");
        std::fs::write(&path, src).unwrap();
        let out = cli::palpa(&["check", cli::s(&path), "--no-pilot"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(err.contains(named) && err.contains("block.toml"), "{err}");
    }
}
