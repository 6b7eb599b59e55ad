//! Times the one-point element kernel alone on one batch of eight elements held in cache:
//! `cargo run --release -p solver --example kernel_micro`. Prints ns per element for the
//! scalar kernel and the eight-lane kernel (f64 and f32 lanes on the baseline, and f64 lanes
//! built for AVX-512 where available), with the stiffness hourglass form of `palpa bench`'s
//! press case, and the law alone in eight `f64` lanes (ns per point). Every output of the
//! kernel goes through `black_box`: an earlier version kept one force entry and the step, and
//! LLVM could drop the rest of the force computation (it read 28-35 ns per element for the
//! flesh in `f32` lanes; docs/performance.md has the corrected figures).
use material::real::{F64x8, Real};
use material::real_f32::F32x8;
use material::{named, Material};
use solver::element::{one_point, HourglassForm, Nodal, StepInput};
use std::hint::black_box;
use std::time::Instant;

fn data<R: Real>(k: f64) -> (Nodal<R>, [[R; 8]; 4], Nodal<R>, Nodal<R>) {
    let s = [-1.0, 1.0, 1.0, -1.0, -1.0, 1.0, 1.0, -1.0];
    let t = [-1.0, -1.0, 1.0, 1.0, -1.0, -1.0, 1.0, 1.0];
    let w = [-1.0, -1.0, -1.0, -1.0, 1.0, 1.0, 1.0, 1.0];
    let h = 0.003;
    let grad: Nodal<R> =
        std::array::from_fn(|i| std::array::from_fn(|a| R::splat([s, t, w][i][a] / (4.0 * h))));
    let gamma = std::array::from_fn(|m| {
        std::array::from_fn(|a| {
            R::splat([s[a] * t[a], t[a] * w[a], s[a] * w[a], s[a] * t[a] * w[a]][m] / 8.0)
        })
    });
    let x: Nodal<R> =
        std::array::from_fn(|i| std::array::from_fn(|a| R::splat([s, t, w][i][a] * h / 2.0)));
    let u: Nodal<R> = std::array::from_fn(|i| {
        std::array::from_fn(|a| R::splat(1e-5 * k * ((i * 8 + a) as f64).sin()))
    });
    (grad, gamma, x, u)
}

macro_rules! run {
    ($law:expr, $R:ty, $n:expr) => {{
        let (grad, gamma, x, u) = data::<$R>(1.0);
        let r = one_point::OnePointRef {
            grad: &grad,
            gamma: &gamma,
            vol0: <$R>::splat(2.7e-8),
            hg_scale: <$R>::splat(1.0),
            physical: None,
        };
        let input = StepInput {
            dt: 1e-6,
            bulk: Some(Default::default()),
            want_stress: false,
            precision: Default::default(),
            macro_dt: None,
        };
        let mut h = vec![<<$R as Real>::Wide>::zero(); 64];
        let mut fe: Nodal<$R> = [[<$R>::zero(); 8]; 3];
        let t0 = Instant::now();
        let mut acc = 0.0;
        for _ in 0..$n {
            let o = one_point::compute_forces(
                black_box($law),
                black_box(&r),
                HourglassForm::Stiffness,
                black_box(&x),
                black_box(&u),
                black_box(&u),
                <$R>::splat(1.0),
                &input,
                &mut h,
                &mut fe,
            );
            black_box(&o);
            black_box(&mut fe);
            acc += o.dt.lane(0) + fe[0][0].lane(0);
        }
        (
            t0.elapsed().as_secs_f64() / ($n as f64 * <$R>::LANES as f64) * 1e9,
            acc,
        )
    }};
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512dq,avx512vl,avx512bw")]
unsafe fn lanes512<L: material::Law>(l: &L, n: usize) -> (f64, f64) {
    run!(l, F64x8, n)
}

/// The law alone on eight lanes (`f64`, the law's number type in both kernel precisions), with
/// the deformation gradient of `data` and its history: ns per point.
fn law_lanes<L: material::Law>(l: &L, n: usize) -> f64 {
    let (grad, _, _, u) = data::<F64x8>(1.0);
    let f = solver::element::wide_deformation_gradient(&u, &grad);
    let mut h = vec![F64x8::zero(); 64];
    let t0 = Instant::now();
    for _ in 0..n {
        let o = l.stress(black_box(&f), 1e-6, &mut h);
        black_box(&o);
    }
    t0.elapsed().as_secs_f64() / (n as f64 * 8.0) * 1e9
}

fn main() {
    for name in ["paper:flesh", "paper:liver"] {
        let m: Material = named(name).unwrap().build(name).unwrap();
        material::with_law!(&m, l => {
            let n = 200_000;
            let (s, _) = run!(l, f64, n);
            let (v, _) = run!(l, F64x8, n / 8);
            let (v32, _) = run!(l, F32x8, n / 8);
            let v5 = if std::arch::is_x86_feature_detected!("avx512f") { unsafe { lanes512(l, n / 8).0 } } else { f64::NAN };
            let law = law_lanes(l, n / 8);
            println!("{name}: scalar {s:.1} ns/element, 8 lanes {v:.1}, 8 f32 lanes {v32:.1}, 8 lanes avx512 {v5:.1}; the law alone in 8 f64 lanes {law:.1} ns/point");
        });
    }
}
