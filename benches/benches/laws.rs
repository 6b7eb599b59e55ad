//! Nanoseconds per constitutive evaluation (one integration point, one step), one core.
//!
//! Floors (issue 3): Ogden with 3 Prony terms <= 300 ns, simplified rubber/foam <= 200 ns,
//! piecewise-linear plasticity <= 150 ns. Each iteration evaluates one of 64 deformation
//! gradients (a mix of stretch, shear and rotation, typical of an indentation step), cycling
//! through them so that branch prediction and the table lookups see varied input.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use material::{named, with_law, Law, Material};

fn bench_law(c: &mut Criterion, label: &str, name: &str, dt: f64) {
    let m: Material = named(name).unwrap().build(name).unwrap();
    let fs = material::tensor::sample_gradients();
    let mut group = c.benchmark_group("laws");
    group.throughput(Throughput::Elements(1));
    with_law!(&m, law => {
        let n = law.history_len();
        // One history per gradient, so each evaluation continues its own point's state.
        let mut hist = vec![0.0; n * fs.len()];
        for h in hist.chunks_mut(n.max(1)) {
            law.init_history(h);
        }
        let mut k = 0usize;
        group.bench_function(label, |bch| {
            bch.iter(|| {
                let i = k & 63;
                k = k.wrapping_add(1);
                let h = if n == 0 { &mut [][..] } else { &mut hist[i * n..(i + 1) * n] };
                black_box(law.evaluate(black_box(&fs[i]), dt, h).unwrap())
            })
        });
    });
    group.finish();
}

fn laws(c: &mut Criterion) {
    bench_law(c, "ogden_3prony", "paper:liver", 1e-6);
    bench_law(c, "simplified_rubber", "paper:flesh", 1e-6);
    bench_law(c, "plasticity", "paper:ribs", 1e-6);
}

criterion_group!(benches, laws);
criterion_main!(benches);
