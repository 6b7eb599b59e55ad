//! Evaluates one named law N times over the 64 deformation gradients of the `laws` criterion
//! bench, for instruction counting: `valgrind --tool=callgrind target/release/examples/law_loop
//! paper:liver 100000` minus the same run with N = 0, divided by N, is the instruction count
//! per evaluation.
//!
//! Usage: `law_loop NAME N` (NAME: paper:liver, paper:flesh, paper:ribs).

use material::{named, with_law, Law, Mat3, Material};
use std::hint::black_box;

fn gradients() -> Vec<Mat3> {
    (0..64)
        .map(|k| {
            let s = k as f64 / 63.0;
            let (a, b, c) = (
                0.3 * s - 0.15,
                0.1 * (s * 7.0).sin(),
                0.05 * (s * 3.0).cos(),
            );
            let stretch = Mat3::new(
                1.0 + a,
                b,
                0.0,
                b * 0.5,
                1.0 - 0.5 * a,
                c,
                0.0,
                c * 0.3,
                1.0 - 0.4 * a,
            );
            let rot =
                nalgebra::Rotation3::from_euler_angles(0.2 * s, -0.4 * s, 0.7 * s).into_inner();
            rot * stretch
        })
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map(String::as_str).unwrap_or("paper:liver");
    let n: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(100_000);
    let m: Material = named(name).unwrap().build(name).unwrap();
    let fs = gradients();
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
