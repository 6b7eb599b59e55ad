//! Timing of `ContactStage::apply`: the two-finger hand pressing 15 mm in 25 ms into a flat,
//! spring-supported surface of `n x n` quads (2.8 mm, the paper's voxel size).
//!
//! `cargo run --release -p contact --example contact_timing -- [n]` (default n = 317: ~100k faces).
//! Prints the mean time per `apply` over the press and the faces/samples visited per call.

use contact::*;
use std::time::Instant;

fn main() {
    let n: usize = std::env::args().nth(1).map_or(317, |s| s.parse().unwrap());
    let h = 2.8e-3;
    let (x0, surface) = ContactSurface::flat_grid(n, h, 2e9);
    let nf = surface.faces.len();
    let m = 1060.0 * h * h * h;
    let c = n as f64 * h / 2.0;
    let hand = HandSpec {
        name: "hand".into(),
        point: [c, c, 0.0],
        direction: [0.0, 0.0, -1.0],
        spacing_axis: None,
        diameter: 15e-3,
        spacing: 20e-3,
        length: 70e-3,
        tilt: 0.0,
        gap: 0.0,
        motion: MotionSpec::Displacement {
            curve: Curve::SmoothStep {
                amplitude: 15e-3,
                duration: 25e-3,
                start: 0.0,
            },
        },
        friction: None,
    }
    .to_indenter_spec()
    .unwrap();
    let dt = 1.8e-6;
    let params = ContactParams {
        design_dt: Some(dt),
        ..Default::default()
    };
    let mut stage = ContactStage::new(&[hand], surface, &x0, &vec![m; x0.len()], params).unwrap();
    // A Winkler foundation (vertical springs) stands in for the body: ~the paper's 20-40 N.
    let ks = 50.0;
    let mut x = x0.clone();
    let mut v = vec![[0.0; 3]; x0.len()];
    let mut f = vec![[0.0; 3]; x0.len()];
    let steps = (25e-3 / dt) as usize;
    let mut t_contact = 0.0;
    let mut t_body = 0.0;
    for i in 0..steps {
        let t = i as f64 * dt;
        for fi in f.iter_mut() {
            *fi = [0.0; 3];
        }
        let a = Instant::now();
        stage.apply(t, dt, &x, &v, &mut f);
        let b = Instant::now();
        for k in 0..x.len() {
            let acc = (f[k][2] - ks * (x[k][2] - x0[k][2]) - 2.0 * (ks * m).sqrt() * v[k][2]) / m;
            v[k][2] += dt * acc;
            x[k][2] += dt * v[k][2];
        }
        t_contact += (b - a).as_secs_f64();
        t_body += b.elapsed().as_secs_f64();
    }
    let s = &stage.indenters()[0];
    let (rebuilds, fv, sv) = stage.counters();
    println!(
        "{nf} faces, {steps} steps: apply {:.2} us/step, spring update {:.2} us/step",
        1e6 * t_contact / steps as f64,
        1e6 * t_body / steps as f64
    );
    println!(
        "rebuilds {rebuilds}, faces visited {:.1}/step, samples {:.1}/step; final force {:.2} N, depth {:.2} mm, max penetration {:.3} mm, area {:.1} mm2",
        fv as f64 / steps as f64,
        sv as f64 / steps as f64,
        s.reaction,
        1e3 * s.depth,
        1e3 * s.max_penetration,
        1e6 * s.area
    );
}
