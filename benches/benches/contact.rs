//! Microseconds per contact evaluation (`ContactStage::apply`), one core: the two-finger hand of
//! the reference study (15 mm fingers, 20 mm apart) pressed 10 mm into a flat surface of
//! ~100k quads of 2.8 mm (the paper's voxel size). The surface is held fixed at the deformed
//! state of a Winkler foundation so every evaluation sees a full contact zone; the benchmark
//! alternates the indenter between two nearby times so broad-phase rebuilds happen at their
//! natural rate. Throughput: faces of the whole surface per second (the stage's cost must not
//! depend on it; compare `surface_12k`, the surface of a 100k-element block, 46^3).

use contact::{ContactParams, ContactStage, ContactSurface, Curve, HandSpec, MotionSpec};
use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};

fn setup(n: usize) -> (ContactStage, Vec<[f64; 3]>) {
    let h = 2.8e-3;
    let (mut x, surface) = ContactSurface::flat_grid(n, h, 2e9);
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
            curve: Curve::Ramp {
                amplitude: 10e-3,
                duration: 1.0,
                start: 0.0,
            },
        },
        friction: Some(0.2),
    }
    .to_indenter_spec()
    .unwrap();
    let m = 1060.0 * h * h * h;
    let params = ContactParams {
        design_dt: Some(1.8e-6),
        ..Default::default()
    };
    let stage = ContactStage::new(&[hand], surface, &x, &vec![m; x.len()], params).unwrap();
    // Deform the surface like the fingers would (nodes under a finger pushed to its surface,
    // minus a small penetration), so the contact zone is realistic.
    let depth = 10e-3;
    for p in x.iter_mut() {
        for fx in [c - 10e-3, c + 10e-3] {
            let r2 = (p[0] - fx).powi(2) + (p[1] - c).powi(2);
            let r = 7.5e-3;
            if r2 < r * r {
                let z = -depth + r - (r * r - r2).sqrt() - 0.05e-3;
                p[2] = p[2].min(z);
            }
        }
    }
    (stage, x)
}

fn contact(c: &mut Criterion) {
    let mut group = c.benchmark_group("contact");
    for (label, n) in [
        ("apply_hand_100k_faces", 317usize),
        ("apply_hand_surface_12k", 110),
    ] {
        let (mut stage, x) = setup(n);
        let v = vec![[0.0; 3]; x.len()];
        let mut f = vec![[0.0; 3]; x.len()];
        group.throughput(Throughput::Elements((n * n) as u64));
        let mut k = 0u64;
        group.bench_function(label, |b| {
            b.iter(|| {
                k += 1;
                // Times 1.0 +- 1e-4 s: travel 10 mm +- 1 um.
                let t = 1.0 + 1e-4 * ((k & 1) as f64);
                stage.apply(t, 1.8e-6, black_box(&x), &v, &mut f);
                black_box(stage.indenters()[0].force)
            })
        });
    }
    group.finish();
}

criterion_group!(benches, contact);
criterion_main!(benches);
