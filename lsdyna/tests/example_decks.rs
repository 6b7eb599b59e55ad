//! The example decks of `scenes/decks/` run, each against its TOML twin (the same model in
//! palpa's scene format) and, where one exists, a closed form:
//! - four compression blocks, one per supported LS-DYNA law, agree with their twins to 1e-8 of
//!   each history column's largest value (they differ only by the decimal rounding of the
//!   deck's node coordinates);
//! - the elastic block's reaction is St. Venant-Kirchhoff's in uniaxial stress,
//!   `F = A0 l E (l^2 - 1) / 2` at stretch `l = 0.9` (0.5 %);
//! - the plastic block's reaction is the bilinear law's in uniaxial stress with logarithmic
//!   strain, `F = A0 tau / l`, `tau = (sigma_y + H |ln l|) / (1 + H / E)`,
//!   `H = E E_t / (E - E_t)` (1 %);
//! - the rigid sphere of shells pressed into the gel follows Hertz, `F = 4/3 E* sqrt(R) d^1.5`,
//!   within 7 % at d/R = 0.02 ... 0.08 (the analytic sphere of the twin: within 3.5 %; the
//!   faceted one is softer at the smallest depth, where the contact radius spans two facets).

use lsdyna::{load_deck, ReadOptions, Units};
use scene::run::run_scene;
use scene::{load_scene, Scene};
use solver::output::history::{column, read_history};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

fn decks() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/decks")
}

fn run(mut scene: Scene) -> (Vec<String>, Vec<Vec<f64>>) {
    let tmp = tempfile::tempdir().unwrap();
    let (summary, err) = run_scene(&mut scene, tmp.path(), &AtomicBool::new(false), |_| {});
    assert!(err.is_none(), "run failed: {err:?} ({})", summary.status);
    read_history(&tmp.path().join("history.csv")).unwrap()
}

fn deck(name: &str) -> Scene {
    let opts = ReadOptions {
        units: Some(Units::parse("kg-mm-ms").unwrap()),
        ..Default::default()
    };
    load_deck(&decks().join(name), &opts).unwrap().0
}

/// Largest difference of each column the twin has, relative to that column's largest value.
fn worst_difference(
    a: &(Vec<String>, Vec<Vec<f64>>),
    b: &(Vec<String>, Vec<Vec<f64>>),
) -> (String, f64) {
    assert_eq!(a.1.len(), b.1.len(), "row count");
    let mut worst = (String::new(), 0.0);
    for c in &a.0 {
        let (Some(x), Some(y)) = (column(&a.0, &a.1, c), column(&b.0, &b.1, c)) else {
            panic!("column {c} missing in the deck's history");
        };
        let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if scale == 0.0 {
            continue;
        }
        let d = x
            .iter()
            .zip(&y)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max)
            / scale;
        if d > worst.1 {
            worst = (c.clone(), d);
        }
    }
    worst
}

/// Mean of column `c` over the rows with time in [t0, t1].
fn mean(h: &(Vec<String>, Vec<Vec<f64>>), c: &str, t0: f64, t1: f64) -> f64 {
    let t = column(&h.0, &h.1, "time").unwrap();
    let v = column(&h.0, &h.1, c).unwrap();
    let sel: Vec<f64> = t
        .iter()
        .zip(&v)
        .filter(|(t, _)| **t >= t0 && **t <= t1)
        .map(|(_, v)| *v)
        .collect();
    sel.iter().sum::<f64>() / sel.len() as f64
}

#[test]
fn compression_decks_match_their_twins_and_closed_forms() {
    for law in ["elastic", "ogden", "rubber", "plastic"] {
        let d = run(deck(&format!("compression-{law}.k")));
        let t = run(load_scene(&decks().join(format!("compression-{law}.toml"))).unwrap());
        let (c, w) = worst_difference(&t, &d);
        println!("compression-{law}: largest difference from the twin {w:.2e} (column {c})");
        assert!(w < 1e-8, "compression-{law}: {c} differs by {w:e}");
        // Closed forms, on the reaction averaged over the hold (22 - 30 ms).
        let f = -mean(&d, "zmax_reaction_z", 0.022, 0.030);
        let (a0, l) = (1e-4, 0.9);
        let expect = match law {
            "elastic" => Some(a0 * l * 1e6 * (1.0 - l * l) / 2.0),
            "plastic" => {
                let (e, et, sy) = (40e6, 1e6, 1.8e6);
                let h = e * et / (e - et);
                let tau = (sy + h * (-f64::ln(l))) / (1.0 + h / e);
                Some(a0 * tau / l)
            }
            _ => None,
        };
        if let Some(x) = expect {
            let rel = (f - x) / x;
            println!(
                "compression-{law}: reaction {f:.5} N, closed form {x:.5} N ({:+.3} %)",
                100.0 * rel
            );
            let tol = if law == "elastic" { 5e-3 } else { 1e-2 };
            assert!(rel.abs() < tol, "compression-{law}: {f} N against {x} N");
        }
    }
}

#[test]
fn hertz_deck_follows_hertz() {
    let h = run(deck("hertz-sphere.k"));
    let travel = column(&h.0, &h.1, "sphere_travel").unwrap();
    let fz = column(&h.0, &h.1, "sphere_force_z").unwrap();
    let (e, nu, r) = (30e3, 0.49, 5e-3);
    let es = e / (1.0 - nu * nu);
    let n = travel.iter().position(|&s| s >= 0.5e-3 - 1e-9).unwrap() + 1;
    for k in 1..=4 {
        let d = 0.02 * k as f64 * r;
        let i = (1..n).find(|&j| travel[j] >= d).unwrap();
        let f = 4.0
            * (fz[i - 1] + (fz[i] - fz[i - 1]) * (d - travel[i - 1]) / (travel[i] - travel[i - 1]));
        let f_h = 4.0 / 3.0 * es * r.sqrt() * d.powf(1.5);
        let rel = (f - f_h) / f_h;
        println!(
            "d/R = {:.2}: F = {f:.4e} N, Hertz {f_h:.4e} N ({:+.2} %)",
            d / r,
            100.0 * rel
        );
        assert!(rel.abs() < 0.07, "d/R = {}: {:.2} %", d / r, 100.0 * rel);
    }
}
