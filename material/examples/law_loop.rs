//! Evaluates one named law N times over the 64 deformation gradients of the `laws` criterion
//! bench, for instruction counting: `valgrind --tool=callgrind target/release/examples/law_loop
//! paper:liver 100000` minus the same run with N = 0, divided by N, is the instruction count
//! per evaluation.
//!
//! Usage: `law_loop NAME N` (NAME: paper:liver, paper:flesh, paper:ribs).

use material::{named, with_law, Law, Material};
use std::hint::black_box;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map(String::as_str).unwrap_or("paper:liver");
    let n: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(100_000);
    let m: Material = named(name).unwrap().build(name).unwrap();
    let fs = material::tensor::sample_gradients();
    let mut acc = 0.0;
    with_law!(&m, law => {
        let hl = law.history_len();
        let mut hist = vec![0.0; hl * fs.len()];
        for h in hist.chunks_mut(hl.max(1)) {
            law.init_history(h);
        }
        for k in 0..n {
            let i = k & 63;
            let h = if hl == 0 { &mut [][..] } else { &mut hist[i * hl..(i + 1) * hl] };
            let r = black_box(law.evaluate(black_box(&fs[i]), 1e-6, h).unwrap());
            acc += r.pk2[(0, 0)] + r.wave_speed;
        }
    });
    println!("{name} x{n}: checksum {acc:.6e}");
}
