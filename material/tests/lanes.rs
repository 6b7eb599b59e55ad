//! The batched path of every law against its scalar path: eight points evaluated at once
//! (`Law::stress::<F64x8>`, the solver's element loop) against each point alone
//! (`Law::stress::<f64>`, the material-point driver), over a history of steps, so that history
//! updates are compared too. The two differ only in the transcendental functions (the batch uses
//! the vectorisable polynomial `exp`/`ln`, within 1 ulp of the library), so they must agree to
//! round-off: 1e-12 of the stress scale of the state, and the same fault codes.

use material::law::{LawOut, FAULT_JACOBIAN};
use material::real::{F64x8, Mask, Real, LANES};
use material::tensor::M3;
use material::{named, with_law, Law, Material, MaterialSpec};

fn rng(seed: &mut u64) -> f64 {
    *seed ^= *seed << 13;
    *seed ^= *seed >> 7;
    *seed ^= *seed << 17;
    (*seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
}

/// Eight deformation paths: F(step) = I + step/steps * amplitude * random H; lane 5 is a pure
/// rotation-free stretch, lane 6 stays at the identity (isotropic eigen-case), lane 7 is
/// inverted at the last step when `invert` is set.
fn paths(seed: u64, amplitude: f64, steps: usize, invert: bool) -> Vec<[M3<f64>; LANES]> {
    let mut s = seed;
    let h: Vec<M3<f64>> = (0..LANES)
        .map(|_| std::array::from_fn(|_| std::array::from_fn(|_| rng(&mut s))))
        .collect();
    (1..=steps)
        .map(|k| {
            let t = k as f64 / steps as f64 * amplitude;
            std::array::from_fn(|l| {
                let mut f: M3<f64> = std::array::from_fn(|i| {
                    std::array::from_fn(|j| (i == j) as u8 as f64 + t * h[l][i][j])
                });
                if l == 5 {
                    f = [
                        [1.0 + t, 0.0, 0.0],
                        [0.0, 1.0 - 0.3 * t, 0.0],
                        [0.0, 0.0, 1.0],
                    ];
                }
                if l == 6 {
                    f = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
                }
                if l == 7 && invert && k == steps {
                    f[0][0] = -1.0;
                }
                f
            })
        })
        .collect()
}

fn to_lanes(f: &[M3<f64>; LANES]) -> M3<F64x8> {
    std::array::from_fn(|i| {
        std::array::from_fn(|j| F64x8::new(std::array::from_fn(|l| f[l][i][j])))
    })
}

fn compare<L: Law>(law: &L, what: &str, amplitude: f64, invert: bool) {
    let hl = law.history_len();
    let mut hs: Vec<Vec<f64>> = vec![vec![0.0; hl]; LANES];
    for h in hs.iter_mut() {
        law.init_history(h);
    }
    let mut hv: Vec<F64x8> = (0..hl)
        .map(|k| F64x8::new(std::array::from_fn(|l| hs[l][k])))
        .collect();
    let dt = 1e-4;
    let steps = 12;
    let mut worst: f64 = 0.0;
    let mut evaluated = 0;
    for (k, fs) in paths(0x5eed ^ hl as u64, amplitude, steps, invert)
        .iter()
        .enumerate()
    {
        let ov: LawOut<F64x8> = law.stress(&to_lanes(fs), dt, &mut hv);
        for l in 0..LANES {
            let os: LawOut<f64> = law.stress(&fs[l], dt, &mut hs[l]);
            assert_eq!(
                ov.fault.lane(l),
                os.fault,
                "{what}: step {k} lane {l} fault"
            );
            if os.fault != 0.0 {
                // Only the deliberately inverted lane, or large random paths, may fault.
                assert!(
                    amplitude > 1.0 || (l == 7 && k == steps - 1 && os.fault == FAULT_JACOBIAN)
                );
                continue;
            }
            evaluated += 1;
            let scale = os
                .pk2
                .iter()
                .flatten()
                .fold(os.wave_speed.abs() * 0.0 + 1e-30, |m, x| m.max(x.abs()));
            for i in 0..3 {
                for j in 0..3 {
                    let d = (ov.pk2[i][j].lane(l) - os.pk2[i][j]).abs() / scale;
                    worst = worst.max(d);
                }
            }
            let dc = (ov.wave_speed.lane(l) - os.wave_speed).abs() / os.wave_speed;
            assert!(dc < 1e-13, "{what}: wave speed differs by {dc:e}");
            let dd = (ov.dissipation.lane(l) - os.dissipation).abs();
            assert!(
                dd <= 1e-12 * os.dissipation.abs() + 1e-300,
                "{what}: dissipation {dd:e}"
            );
            assert_eq!(ov.failed.lane(l), os.failed, "{what}: failure flag");
            for q in 0..hl {
                let (a, b) = (hv[q].lane(l), hs[l][q]);
                let hscale = hs[l].iter().fold(1e-30f64, |m, x| m.max(x.abs()));
                assert!(
                    (a - b).abs() <= 1e-12 * hscale,
                    "{what}: history {q} lane {l}: {a:e} vs {b:e}"
                );
            }
        }
    }
    assert!(
        evaluated >= steps * 4,
        "{what}: only {evaluated} points evaluated"
    );
    assert!(
        worst < 1e-12,
        "{what}: stress differs by {worst:e} of its scale"
    );
}

fn card(text: &str) -> Material {
    toml::from_str::<MaterialSpec>(text)
        .unwrap()
        .build("m")
        .unwrap()
}

fn check(m: &Material, what: &str, amplitude: f64) {
    with_law!(m, l => {
        compare(l, what, amplitude, false);
        compare(l, what, amplitude, true);
    });
}

#[test]
fn ogden_prony_batch_equals_scalar() {
    check(
        &named("paper:liver").unwrap().build("liver").unwrap(),
        "paper liver",
        0.6,
    );
    let dev = card(
        "law = \"ogden\"\ndensity = \"1000 kg/m^3\"\nmu = [\"1 kPa\", \"-0.2 kPa\"]\nalpha = [2.0, -3.0]\n\
         poisson_ratio = 0.45\nprony = [{ modulus = \"2 kPa\", tau = \"10 ms\" }]\nprony_on = \"deviatoric\"\n",
    );
    check(&dev, "ogden deviatoric prony", 0.6);
}

#[test]
fn simplified_rubber_batch_equals_scalar() {
    check(
        &named("paper:flesh").unwrap().build("flesh").unwrap(),
        "paper flesh",
        0.6,
    );
    // Beyond the table (stretch 20) in some lanes: the extrapolation is selected per lane.
    check(
        &named("paper:flesh").unwrap().build("flesh").unwrap(),
        "flesh, large",
        12.0,
    );
}

#[test]
fn plasticity_batch_equals_scalar() {
    // Large enough that some lanes yield and others stay elastic in the same batch.
    check(
        &named("paper:ribs").unwrap().build("ribs").unwrap(),
        "paper ribs",
        0.15,
    );
}

#[test]
fn neo_hookean_and_linear_batch_equal_scalar() {
    let nh = card("law = \"neo_hookean\"\ndensity = \"1000 kg/m^3\"\nyoungs_modulus = \"1 MPa\"\npoisson_ratio = 0.45\n");
    check(&nh, "neo-Hookean", 0.6);
    for k in ["green", "small"] {
        let le = card(&format!(
            "law = \"linear_elastic\"\ndensity = \"1000 kg/m^3\"\nyoungs_modulus = \"1 MPa\"\npoisson_ratio = 0.3\nstrain = \"{k}\"\n"
        ));
        check(&le, k, 0.3);
    }
}
