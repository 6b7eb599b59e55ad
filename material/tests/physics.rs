//! Each law against a number that physics gives, through the material-point driver.

use material::driver::{run_driver_file, run_driver_str, DriverOutput};
use material::foam::UniaxialCurve;
use material::{Law, Mat3, Material, MaterialSpec};
use std::path::Path;

const MU: [f64; 3] = [89.14, 9.965, -92.75];
const ALPHA: [f64; 3] = [1.0, 19.0656, -10.9604];

fn col(o: &DriverOutput, name: &str) -> Vec<f64> {
    o.column(name)
        .unwrap_or_else(|| panic!("no column {name} in {:?}", o.header))
}

/// Incompressible uniaxial nominal stress of the original-form Ogden solid.
fn ogden_p(l: f64) -> f64 {
    (0..3)
        .map(|p| MU[p] * (l.powf(ALPHA[p] - 1.0) - l.powf(-ALPHA[p] / 2.0 - 1.0)))
        .sum()
}

#[test]
fn liver_ogden_uniaxial_stress_matches_incompressible_closed_form() {
    // K / mu0 = 1e6 (>= 1e4): nearly incompressible.
    let k = 1e6 * 647.85;
    let text = format!(
        "mode = \"uniaxial_stress\"\n[material]\nlaw = \"ogden\"\ndensity = \"1050 kg/m^3\"\n\
         mu = [\"89.14 Pa\", \"9.965 Pa\", \"-92.75 Pa\"]\nalpha = [1.0, 19.0656, -10.9604]\nbulk_modulus = \"{k} Pa\"\n\
         [[segment]]\nramp_to = 0.5\nduration = 1\nsteps = 50\n[[segment]]\nramp_to = 1.6\nduration = 1\nsteps = 110\n"
    );
    let o = run_driver_str(&text, None).unwrap();
    let (l, p) = (col(&o, "stretch"), col(&o, "nominal_stress"));
    let mut n = 0;
    let mut worst: f64 = 0.0;
    for (l, p) in l.iter().zip(&p) {
        if (l - 1.0).abs() < 1e-9 {
            continue;
        }
        let want = ogden_p(*l);
        assert!(
            (p - want).abs() <= 1e-3 * want.abs(),
            "l = {l}: P = {p}, closed form {want}"
        );
        worst = worst.max((p - want).abs() / want.abs());
        n += 1;
    }
    eprintln!(
        "liver Ogden uniaxial: worst relative error {worst:.2e} over {n} stretches in [0.5, 1.6]"
    );
    assert!(n > 150);
    // The lateral stresses are zero.
    let syy = col(&o, "sigma_yy");
    let sxx = col(&o, "sigma_xx");
    assert!(syy
        .iter()
        .zip(&sxx)
        .all(|(y, x)| y.abs() <= 1e-8 * x.abs() + 1e-5));
}

/// Linear viscoelastic shear stress for a ramp of rate `rate` until `tr`, then a hold.
fn lve_shear(t: f64, tr: f64, rate: f64, mu0: f64, prony: &[(f64, f64)]) -> f64 {
    let te = t.min(tr);
    let mut s = mu0 * te;
    for &(g, tau) in prony {
        s += g * tau * ((-(t - te) / tau).exp() - (-t / tau).exp());
    }
    rate * s
}

#[test]
fn prony_ramp_and_hold_matches_linear_viscoelasticity() {
    // Paper liver in simple shear at gamma = 1e-3: ramp in 50 ms, hold 3 s.
    let text = "material = \"paper:liver\"\nmode = \"simple_shear\"\n\
                [[segment]]\nramp_to = 1e-3\nduration = \"50 ms\"\nsteps = 100\n\
                [[segment]]\nhold = \"3 s\"\nsteps = 600\n";
    let o = run_driver_str(text, None).unwrap();
    let prony = [(6970.1, 0.01), (58327.0, 0.1), (35291.0, 1.0)];
    let mu0 = 0.5 * (0..3).map(|p| MU[p] * ALPHA[p]).sum::<f64>();
    let (t, s) = (col(&o, "time"), col(&o, "sigma_xy"));
    let mut worst: f64 = 0.0;
    for (t, s) in t.iter().zip(&s).skip(1) {
        let want = lve_shear(*t, 0.05, 1e-3 / 0.05, mu0, &prony);
        worst = worst.max((s - want).abs() / want.abs());
    }
    eprintln!("Prony ramp-and-hold: worst relative error {worst:.2e}");
    assert!(worst < 5e-3, "worst relative error {worst:e}");
    // And the dissipation column grows.
    let d = col(&o, "dissipated");
    assert!(d.last().unwrap() > &0.0 && d.windows(2).all(|w| w[1] >= w[0]));
}

#[test]
fn prony_relaxes_to_the_ogden_curve() {
    let run = |mat: &str| {
        let text = format!(
            "mode = \"uniaxial_stress\"\n{mat}\n[[segment]]\nramp_to = 1.3\nduration = \"100 ms\"\nsteps = 50\n\
             [[segment]]\nhold = \"30 s\"\nsteps = 300\n"
        );
        run_driver_str(&text, None).unwrap()
    };
    let visco = run("material = \"paper:liver\"");
    let elastic = run(
        "[material]\nlaw = \"ogden\"\ndensity = 1050\nmu = [89.14, 9.965, -92.75]\nalpha = [1.0, 19.0656, -10.9604]\npoisson_ratio = 0.49",
    );
    let pv = col(&visco, "nominal_stress");
    let pe = col(&elastic, "nominal_stress");
    // At the end of the ramp the viscous stress dominates ...
    let end_ramp = 50;
    assert!(
        pv[end_ramp] > 5.0 * pe[end_ramp],
        "{} vs {}",
        pv[end_ramp],
        pe[end_ramp]
    );
    // ... and after 30 tau_max it is gone.
    let (a, b) = (pv.last().unwrap(), pe.last().unwrap());
    eprintln!(
        "Prony relaxed after 30 s: {a} vs Ogden {b} (rel {:.2e})",
        (a - b).abs() / b.abs()
    );
    assert!((a - b).abs() < 1e-3 * b.abs(), "relaxed {a} vs Ogden {b}");
}

#[test]
fn foam_reproduces_its_input_curve() {
    // A stiffening curve P = 20 kPa (l - l^-2) + 500 Pa (l^3 - l^-3), tabulated at 33 points.
    let p = |l: f64| 2e4 * (l - l.powi(-2)) + 500.0 * (l.powi(3) - l.powi(-3));
    let pts: Vec<String> = (0..=32)
        .map(|k| {
            let l = 0.4 + 0.05 * k as f64;
            format!("[{l}, \"{} kPa\"]", p(l) / 1e3)
        })
        .collect();
    let text = format!(
        "mode = \"uniaxial_stress\"\n[material]\nlaw = \"foam\"\ndensity = 1000\nbulk_modulus = \"1 GPa\"\n\
         curve = [{}]\n[[segment]]\nramp_to = 0.5\nduration = 1\nsteps = 97\n[[segment]]\nramp_to = 1.8\nduration = 1\nsteps = 251\n",
        pts.join(", ")
    );
    let o = run_driver_str(&text, None).unwrap();
    let table: Vec<(f64, f64)> = (0..=32)
        .map(|k| (0.4 + 0.05 * k as f64, p(0.4 + 0.05 * k as f64)))
        .collect();
    let curve = UniaxialCurve::table("t", &table).unwrap();
    let mut worst: f64 = 0.0;
    for (l, pm) in col(&o, "stretch").iter().zip(col(&o, "nominal_stress")) {
        if (l - 1.0).abs() < 1e-9 {
            continue;
        }
        let want = curve.nominal(*l).0;
        worst = worst.max((pm - want).abs() / want.abs());
    }
    eprintln!("foam: worst relative deviation from its input curve {worst:.2e}");
    assert!(
        worst < 0.01,
        "worst relative deviation from the input curve {worst:e}"
    );
}

#[test]
fn flesh_follows_default_curve_and_its_damping_term() {
    let path = "mode = \"uniaxial_stress\"\n[[segment]]\nramp_to = 0.7\nduration = 1\nsteps = 60\n";
    // Undamped card with the paper's K and G: the default curve P = G (l - l^-2).
    let card = "[material]\nlaw = \"simplified_rubber\"\ndensity = 1060\nbulk_modulus = \"2 GPa\"\nshear_modulus = \"40 kPa\"\n";
    let el = run_driver_str(&format!("{path}{card}"), None).unwrap();
    let (l, p) = (col(&el, "stretch"), col(&el, "nominal_stress"));
    for k in 1..l.len() {
        let want = 4e4 * (l[k] - l[k].powi(-2));
        // Compressibility is O(G/K) = 2e-5.
        assert!(
            (p[k] - want).abs() < 1e-3 * want.abs(),
            "l = {}: {} vs {want}",
            l[k],
            p[k]
        );
    }
    // The paper's flesh (damping 0.40) to 30 % compression: finite, nearly isochoric, and the
    // damping stress S_v = 2 MU G dev(dE) (see foam.rs) adds, with the lateral balance
    // S_yy = 0 carried by the elastic pressure, 2 MU G dE' (l_y^2 / (3 l) + 2 l / 3) to P_xx,
    // where dE' = dE_xx - dE_yy.
    let o = run_driver_str(&format!("material = \"paper:flesh\"\n{path}"), None).unwrap();
    let (pd, ly, c) = (
        col(&o, "nominal_stress"),
        col(&o, "stretch_y"),
        col(&o, "wave_speed"),
    );
    for k in 1..l.len() {
        assert!(pd[k].is_finite() && c[k].is_finite() && c[k] >= 1373.6);
        let de =
            0.5 * ((l[k] * l[k] - l[k - 1] * l[k - 1]) - (ly[k] * ly[k] - ly[k - 1] * ly[k - 1]));
        let want = 2.0 * 0.4 * 4e4 * de * (ly[k] * ly[k] / (3.0 * l[k]) + 2.0 * l[k] / 3.0);
        assert!(
            (pd[k] - p[k] - want).abs() < 0.01 * want.abs(),
            "l = {}: {} vs {want}",
            l[k],
            pd[k] - p[k]
        );
    }
    let j: f64 = l.last().unwrap() * ly.last().unwrap() * col(&o, "stretch_z").last().unwrap();
    assert!(
        (l.last().unwrap() - 0.7).abs() < 1e-12 && (j - 1.0).abs() < 1e-4,
        "J = {j}"
    );
}

/// Uniaxial Kirchhoff stress and effective plastic strain of bilinear plasticity in log strain,
/// for a load to `e1` and a reversal, at log strain `e` on the `leg` (0 loading, 1 reversing).
fn bilinear(e: f64, leg: usize, e1: f64) -> (f64, f64) {
    let (ee, et, sy) = (40e6, 1e6, 1.8e6);
    let ey = sy / ee;
    let load = |e: f64| {
        if e <= ey {
            (ee * e, 0.0)
        } else {
            let t = sy + et * (e - ey);
            (t, e - t / ee)
        }
    };
    if leg == 0 {
        return load(e);
    }
    let (t1, p1) = load(e1);
    let er = e1 - 2.0 * t1 / ee; // reverse yield: tau = -t1 (isotropic hardening)
    if e >= er {
        (t1 - ee * (e1 - e), p1)
    } else {
        let t = -t1 - et * (er - e);
        let pa = e - t / ee; // axial plastic strain
        (t, p1 + (p1 - pa))
    }
}

#[test]
fn rib_plasticity_load_unload_reverse_matches_bilinear_closed_form() {
    let text = "material = \"paper:ribs\"\nmode = \"uniaxial_stress\"\n\
                [[segment]]\nramp_to = 1.1\nrate = \"1 1/s\"\nsteps = 40\n\
                [[segment]]\nramp_to = 0.9\nrate = \"1 1/s\"\nsteps = 80\n";
    let o = run_driver_str(text, None).unwrap();
    let (l, sx, ly, lz, ep) = (
        col(&o, "stretch"),
        col(&o, "sigma_xx"),
        col(&o, "stretch_y"),
        col(&o, "stretch_z"),
        col(&o, "eps_p"),
    );
    let e1 = 1.1f64.ln();
    for k in 0..l.len() {
        let leg = if k <= 40 { 0 } else { 1 };
        let (tau, epw) = bilinear(l[k].ln(), leg, e1);
        let tau_m = sx[k] * l[k] * ly[k] * lz[k]; // Kirchhoff = J sigma
        assert!(
            (tau_m - tau).abs() < 1e-6 * 1.8e6,
            "k = {k}, l = {}: tau {tau_m} vs {tau}",
            l[k]
        );
        assert!(
            (ep[k] - epw).abs() < 1e-8,
            "k = {k}: eps_p {} vs {epw}",
            ep[k]
        );
    }
    // Plastic work was dissipated.
    assert!(col(&o, "dissipated").last().unwrap() > &1e4);
}

#[test]
fn hard_cases_give_finite_stress_and_wave_speed() {
    // Paper liver (with its Prony terms) at stretch 0.4 and 1.8 in uniaxial stress.
    for to in [0.4, 1.8] {
        let text = format!(
            "material = \"paper:liver\"\nmode = \"uniaxial_stress\"\n[[segment]]\nramp_to = {to}\nduration = \"25 ms\"\nsteps = 200\n"
        );
        let o = run_driver_str(&text, None).unwrap();
        let last = o.rows.last().unwrap();
        assert!(last.iter().all(|x| x.is_finite()), "{last:?}");
        let c = col(&o, "wave_speed");
        assert!(
            c.last().unwrap() > &c[0],
            "stretch stiffening raises the wave speed"
        );
    }
    // The same in one evaluation, far from the reference state, for each library law.
    for name in ["paper:liver", "paper:flesh", "paper:ribs"] {
        let m = material::named(name).unwrap().build(name).unwrap();
        material::with_law!(&m, l => {
            for f in [
                Mat3::from_diagonal(&[0.4, 1.0 / 0.4f64.sqrt(), 1.0 / 0.4f64.sqrt()].into()),
                Mat3::from_diagonal(&[1.8, 0.75, 0.75].into()),
                Mat3::from_diagonal(&[0.7, 1.0, 1.0].into()),
            ] {
                let mut h = vec![0.0; l.history_len()];
                l.init_history(&mut h);
                let r = l.evaluate(&f, 1e-5, &mut h).unwrap();
                assert!(r.pk2.iter().all(|x| x.is_finite()) && r.wave_speed.is_finite(), "{name}");
                assert!(r.wave_speed >= 0.99 * l.initial_wave_speed(), "{name}");
            }
        });
    }
}

#[test]
fn shipped_examples_run() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/materials");
    for f in [
        "liver-uniaxial.toml",
        "liver-relaxation.toml",
        "flesh-uniaxial.toml",
        "rib-cyclic.toml",
    ] {
        let csv = run_driver_file(&dir.join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
        let lines: Vec<&str> = csv.lines().collect();
        assert!(lines.len() > 100, "{f}");
        assert!(
            lines[0].starts_with("time,stretch,nominal_stress,sigma_xx"),
            "{}",
            lines[0]
        );
        assert!(!csv.contains("NaN") && !csv.contains("inf"), "{f}");
    }
}

#[test]
fn curve_file_is_read_relative_to_the_driver_file() {
    let dir = std::env::temp_dir().join(format!("palpa-material-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("c.csv"),
        "stretch,stress\n0.5, -140 kPa\n1.0, 0\n1.5, 42222.2\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("d.toml"),
        "mode = \"uniaxial_strain\"\n[material]\nlaw = \"foam\"\ndensity = 1000\nbulk_modulus = \"1 MPa\"\ncurve_file = \"c.csv\"\n\
         [[segment]]\nramp_to = 1.01\nduration = 1\n",
    )
    .unwrap();
    let csv = run_driver_file(&dir.join("d.toml")).unwrap();
    assert!(csv.lines().count() == 102);
    let spec: MaterialSpec = toml::from_str(
        "law = \"foam\"\ndensity = 1000\nbulk_modulus = \"1 MPa\"\ncurve_file = \"does-not-exist.csv\"\n",
    )
    .unwrap();
    let e = spec.build("skin").unwrap_err();
    assert!(
        e.contains("skin") && e.contains("does-not-exist.csv"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
    let _ = Material::density; // keep the import used
}
