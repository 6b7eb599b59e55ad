//! Element-cycles per second of the explicit step on a 100k-element neo-Hookean block
//! (one-point with viscous hourglass control, and fully integrated F-bar), on 1 and 2 threads.
//! Throughput is reported in elements per iteration: criterion's "elem/s" is element-cycles/s.
//! Floor (issue 2): 5 M element-cycles/s on 2 threads for one-point; aim 15 M.

use benches::{block_simulation, one_point};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use solver::element::Formulation;

fn step_bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("explicit_step_100k");
    group.sample_size(10);
    for (label, form) in [
        ("one_point", one_point()),
        ("full_fbar", Formulation::Full { fbar: true }),
    ] {
        for threads in [1usize, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut sim = block_simulation([50, 50, 40], form);
            let ne = sim.model.mesh.elements.len() as u64;
            group.throughput(Throughput::Elements(ne));
            pool.install(|| sim.initialise().unwrap());
            group.bench_function(format!("{label}/{threads}_threads"), |b| {
                b.iter(|| pool.install(|| sim.step(f64::INFINITY).unwrap()))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, step_bench);
criterion_main!(benches);
