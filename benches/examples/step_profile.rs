//! Run N explicit steps of the 100k-element block and print element-cycles/s
//! (for profiling: `perf record --call-graph dwarf target/release/examples/step_profile`).

use benches::{block_simulation, one_point};
use std::time::Instant;

fn main() {
    let steps: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(50);
    let n: usize = std::env::args()
        .nth(2)
        .and_then(|s| s.parse().ok())
        .unwrap_or(50);
    let mut sim = block_simulation([n, n, n * 4 / 5], one_point());
    sim.initialise().unwrap();
    let t = Instant::now();
    for _ in 0..steps {
        sim.step(f64::INFINITY).unwrap();
    }
    let s = t.elapsed().as_secs_f64();
    let ne = sim.model.mesh.elements.len();
    println!(
        "{} elements, {} steps, {:.3} s: {:.3} M element-cycles/s on {} threads",
        ne,
        steps,
        s,
        (ne * steps) as f64 / s / 1e6,
        rayon::current_num_threads()
    );
    for st in &sim.timers {
        println!("  {:<16} {:.3} s", st.name, st.time.as_secs_f64());
    }
}
