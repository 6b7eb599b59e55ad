//! Signed distances, normals, STL reading and the hand preset.
#![allow(clippy::needless_range_loop)]

use contact::*;

fn shape(s: ShapeSpec) -> Shape {
    Shape::from_spec(&s).unwrap()
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

/// The returned normal must be the gradient of the returned distance (central differences),
/// away from the medial axis; checked on a cloud of points.
fn check_gradient(s: &Shape, pts: &[[f64; 3]]) {
    let h = 1e-7;
    for &p in pts {
        let (phi, n) = s.signed_distance(p);
        let nn = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!(close(nn, 1.0, 1e-12), "normal not unit at {p:?}");
        let mut g = [0.0; 3];
        for k in 0..3 {
            let mut a = p;
            let mut b = p;
            a[k] += h;
            b[k] -= h;
            g[k] = (s.signed_distance(a).0 - s.signed_distance(b).0) / (2.0 * h);
        }
        let err = ((g[0] - n[0]).powi(2) + (g[1] - n[1]).powi(2) + (g[2] - n[2]).powi(2)).sqrt();
        // Skip points within h of a gradient discontinuity (medial axis).
        if err > 1e-4 {
            let (pa, _) = s.signed_distance([p[0] + 1e-5, p[1], p[2]]);
            assert!(
                (pa - phi).abs() > 0.0,
                "gradient mismatch at {p:?}: fd {g:?} vs normal {n:?}"
            );
            panic!("gradient mismatch at {p:?}: phi {phi}, fd {g:?} vs normal {n:?}");
        }
    }
}

fn cloud(lo: f64, hi: f64, n: usize, seed: u64) -> Vec<[f64; 3]> {
    // Deterministic LCG, avoiding a dev-dependency.
    let mut s = seed;
    let mut r = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        lo + (hi - lo) * ((s >> 11) as f64 / (1u64 << 53) as f64)
    };
    (0..n).map(|_| [r(), r(), r()]).collect()
}

#[test]
fn sphere_distance_and_normal() {
    let s = shape(ShapeSpec::Sphere {
        center: [1.0, 2.0, 3.0],
        radius: 0.5,
    });
    let (phi, n) = s.signed_distance([1.0, 2.0, 4.0]);
    assert!(close(phi, 0.5, 1e-15) && close(n[2], 1.0, 1e-15));
    let (phi, n) = s.signed_distance([1.2, 2.0, 3.0]);
    assert!(close(phi, -0.3, 1e-15) && close(n[0], 1.0, 1e-15));
    check_gradient(&s, &cloud(0.0, 4.0, 200, 1));
}

#[test]
fn capsule_distance_and_normal() {
    // Tip centre at origin, axis +z, straight length 2, radius 0.5.
    let s = shape(ShapeSpec::Capsule {
        center: [0.0; 3],
        axis: [0.0, 0.0, 2.0],
        radius: 0.5,
        length: 2.0,
    });
    // Below the tip: hemisphere.
    let (phi, n) = s.signed_distance([0.0, 0.0, -1.0]);
    assert!(close(phi, 0.5, 1e-15) && close(n[2], -1.0, 1e-15));
    // Beside the straight part.
    let (phi, n) = s.signed_distance([2.0, 0.0, 1.0]);
    assert!(close(phi, 1.5, 1e-15) && close(n[0], 1.0, 1e-15));
    // Inside.
    let (phi, n) = s.signed_distance([0.0, 0.3, 1.5]);
    assert!(close(phi, -0.2, 1e-15) && close(n[1], 1.0, 1e-15));
    // Beyond the far end.
    let (phi, _) = s.signed_distance([0.0, 0.0, 3.0]);
    assert!(close(phi, 0.5, 1e-15));
    check_gradient(&s, &cloud(-1.5, 3.5, 200, 2));
}

#[test]
fn cylinder_distance_and_normal() {
    // Flat punch: end face at origin, axis +z, radius 1, length 2.
    let s = shape(ShapeSpec::Cylinder {
        center: [0.0; 3],
        axis: [0.0, 0.0, 1.0],
        radius: 1.0,
        length: 2.0,
    });
    let (phi, n) = s.signed_distance([0.3, 0.2, -0.5]);
    assert!(close(phi, 0.5, 1e-15) && close(n[2], -1.0, 1e-15));
    let (phi, n) = s.signed_distance([0.0, 0.0, -0.0]);
    assert!(close(phi, 0.0, 1e-15) && close(n[2], -1.0, 1e-15));
    // Inside, nearer to the bottom face than to the mantle.
    let (phi, n) = s.signed_distance([0.0, 0.5, 0.1]);
    assert!(close(phi, -0.1, 1e-15) && close(n[2], -1.0, 1e-15));
    // Inside, nearer to the mantle.
    let (phi, n) = s.signed_distance([0.0, 0.9, 1.0]);
    assert!(close(phi, -0.1, 1e-14) && close(n[1], 1.0, 1e-15));
    // Outside the rim: distance to the circular edge.
    let (phi, n) = s.signed_distance([2.0, 0.0, -1.0]);
    assert!(close(phi, 2f64.sqrt(), 1e-14));
    assert!(close(n[0], 0.5f64.sqrt(), 1e-14) && close(n[2], -(0.5f64.sqrt()), 1e-14));
    check_gradient(&s, &cloud(-2.0, 3.0, 300, 3));
}

#[test]
fn box_distance_and_normal() {
    let s = shape(ShapeSpec::Box {
        center: [0.0; 3],
        half_extents: [1.0, 2.0, 3.0],
        axes: None,
    });
    let (phi, n) = s.signed_distance([0.0, 0.0, 4.0]);
    assert!(close(phi, 1.0, 1e-15) && close(n[2], 1.0, 1e-15));
    let (phi, n) = s.signed_distance([0.8, 0.0, 0.0]);
    assert!(close(phi, -0.2, 1e-15) && close(n[0], 1.0, 1e-15));
    let (phi, _) = s.signed_distance([2.0, 3.0, 0.0]);
    assert!(close(phi, 2f64.sqrt(), 1e-15));
    check_gradient(&s, &cloud(-4.0, 4.0, 300, 4));
    // A rotated box equals the axis-aligned one in rotated coordinates.
    let c = 0.5f64.sqrt();
    let r = shape(ShapeSpec::Box {
        center: [0.0; 3],
        half_extents: [1.0, 2.0, 3.0],
        axes: Some([[c, c, 0.0], [-c, c, 0.0], [0.0, 0.0, 1.0]]),
    });
    for p in cloud(-4.0, 4.0, 100, 5) {
        let q = [c * p[0] - c * p[1], c * p[0] + c * p[1], p[2]];
        assert!(close(r.signed_distance(q).0, s.signed_distance(p).0, 1e-12));
    }
}

#[test]
fn plane_distance_and_normal() {
    let s = shape(ShapeSpec::Plane {
        point: [0.0, 0.0, 1.0],
        normal: [0.0, 0.0, -2.0],
    });
    let (phi, n) = s.signed_distance([5.0, 3.0, 0.0]);
    assert!(close(phi, 1.0, 1e-15) && n == [0.0, 0.0, -1.0]);
    assert!(close(s.signed_distance([0.0, 0.0, 1.5]).0, -0.5, 1e-15));
    assert!(s.aabb().is_none());
}

fn cube_triangles(lo: f64, hi: f64) -> Vec<[[f64; 3]; 3]> {
    // Unit cube corners; each face as two counter-clockwise (outward) triangles.
    let c = |i: usize| {
        [
            if i & 1 == 0 { lo } else { hi },
            if i & 2 == 0 { lo } else { hi },
            if i & 4 == 0 { lo } else { hi },
        ]
    };
    let quads = [
        [0, 2, 3, 1], // z = lo, normal -z
        [4, 5, 7, 6], // z = hi
        [0, 1, 5, 4], // y = lo
        [2, 6, 7, 3], // y = hi
        [0, 4, 6, 2], // x = lo
        [1, 3, 7, 5], // x = hi
    ];
    let mut t = Vec::new();
    for q in quads {
        t.push([c(q[0]), c(q[1]), c(q[2])]);
        t.push([c(q[0]), c(q[2]), c(q[3])]);
    }
    t
}

fn ascii_stl(tris: &[[[f64; 3]; 3]]) -> String {
    let mut s = String::from("solid cube\n");
    for t in tris {
        s += "  facet normal 0 0 0\n    outer loop\n";
        for p in t {
            s += &format!("      vertex {} {} {}\n", p[0], p[1], p[2]);
        }
        s += "    endloop\n  endfacet\n";
    }
    s += "endsolid cube\n";
    s
}

#[test]
fn stl_cube_ascii_and_binary_match_the_box() {
    let tris = cube_triangles(-1.0, 1.0);
    let dir = std::env::temp_dir().join(format!("contact-stl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let a = dir.join("cube_ascii.stl");
    let b = dir.join("cube_binary.stl");
    std::fs::write(&a, ascii_stl(&tris)).unwrap();
    std::fs::write(&b, contact::trimesh::write_binary_stl(&tris)).unwrap();
    let boxed = shape(ShapeSpec::Box {
        center: [0.01, 0.0, 0.0],
        half_extents: [0.01, 0.01, 0.01],
        axes: None,
    });
    for path in [&a, &b] {
        // File in cm: scale 0.01, shifted by 1 cm in x.
        let m = shape(ShapeSpec::Stl {
            path: path.clone(),
            scale: 0.01,
            translate: [0.01, 0.0, 0.0],
        });
        if let Shape::Mesh(mesh) = &m {
            assert_eq!(mesh.triangle_count(), 12);
        } else {
            panic!("not a mesh");
        }
        let bb = m.aabb().unwrap();
        assert!(close(bb.min[0], 0.0, 1e-9) && close(bb.max[2], 0.01, 1e-9));
        for p in cloud(-0.02, 0.03, 500, 6) {
            let (pm, nm) = m.signed_distance(p);
            let (pb, nb) = boxed.signed_distance(p);
            assert!(close(pm, pb, 1e-9), "at {p:?}: mesh {pm} box {pb}");
            // Normals agree except on the inner medial planes (ties between faces).
            let dn = (nm[0] - nb[0]).abs() + (nm[1] - nb[1]).abs() + (nm[2] - nb[2]).abs();
            if pb > 0.0 {
                assert!(dn < 1e-6, "normal at {p:?}: {nm:?} vs {nb:?}");
            }
        }
        // Exactly on a face and on an edge/vertex: sign by pseudo-normal.
        assert!(m.signed_distance([0.02, 0.0, 0.0]).0.abs() < 1e-9);
        assert!(m.signed_distance([0.019, 0.0, 0.0]).0 < 0.0);
        assert!(m.signed_distance([0.021, 0.011, 0.0]).0 > 0.0);
        assert!(m.signed_distance([0.0205, 0.0105, 0.0105]).0 > 0.0);
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn stl_errors_are_reported() {
    assert!(TriMesh::from_stl_bytes(b"garbage", 1.0, [0.0; 3]).is_err());
    assert!(TriMesh::from_stl_bytes(b"solid x\nendsolid x\n", 1.0, [0.0; 3]).is_err());
    let r = Shape::from_spec(&ShapeSpec::Stl {
        path: "/nonexistent/finger.stl".into(),
        scale: 1.0,
        translate: [0.0; 3],
    });
    assert!(matches!(r, Err(ContactError::Io(_))));
}

#[test]
fn finer_mesh_sphere_approximates_sphere() {
    // An icosphere-like UV sphere mesh: the signed distance approaches the analytic sphere's.
    let (nu, nv) = (64, 32);
    let r = 1.0;
    let mut tris = Vec::new();
    let p = |i: usize, j: usize| {
        let th = std::f64::consts::PI * j as f64 / nv as f64;
        let ph = 2.0 * std::f64::consts::PI * i as f64 / nu as f64;
        [
            r * th.sin() * ph.cos(),
            r * th.sin() * ph.sin(),
            r * th.cos(),
        ]
    };
    for j in 0..nv {
        for i in 0..nu {
            let (a, b, c, d) = (p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
            if j != 0 {
                tris.push([a, c, b]);
            }
            if j != nv - 1 {
                tris.push([a, d, c]);
            }
        }
    }
    let m =
        TriMesh::from_stl_bytes(&contact::trimesh::write_binary_stl(&tris), 1.0, [0.0; 3]).unwrap();
    for q in cloud(-2.0, 2.0, 300, 7) {
        let exact = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt() - r;
        let (phi, _) = m.signed_distance(q);
        assert!((phi - exact).abs() < 0.01, "at {q:?}: {phi} vs {exact}");
    }
}

#[test]
fn hand_preset_places_two_fingers() {
    let hand = HandSpec {
        name: "hand".into(),
        point: [0.0, 0.0, 0.05],
        direction: [0.0, 0.0, -1.0],
        spacing_axis: None,
        diameter: 0.015,
        spacing: 0.02,
        length: 0.07,
        tilt: 0.3,
        gap: 0.001,
        motion: MotionSpec::Fixed,
        friction: None,
    };
    let spec = hand.to_indenter_spec().unwrap();
    assert_eq!(spec.parts.len(), 2);
    let ind = Indenter::from_spec(&spec).unwrap();
    // The lowest point of each finger is at (+-1 cm, 0, 5.1 cm): distance from just below is ~0.
    for x in [-0.01, 0.01] {
        let (phi, n) = ind.signed_distance([x, 0.0, 0.051 - 1e-4], [0.0; 3]);
        assert!(close(phi, 1e-4, 1e-9), "{phi}");
        assert!(close(n[2], -1.0, 1e-9));
    }
    // Between the fingers there is nothing.
    assert!(ind.signed_distance([0.0, 0.0, 0.051], [0.0; 3]).0 > 1e-3);
    // Tilt rotates the finger axis (tip to knuckle) from +z about the spacing axis (x) by the
    // right-hand rule: towards -y, i.e. towards direction x e_s = (0,0,-1) x (1,0,0) = (0,-1,0).
    let c = 0.0585; // tip hemisphere centre height
    let on_axis = [0.01, -0.04 * 0.3f64.sin(), c + 0.04 * 0.3f64.cos()];
    assert!(close(
        ind.signed_distance(on_axis, [0.0; 3]).0,
        -0.0075,
        1e-12
    ));
    let mirrored = [0.01, 0.04 * 0.3f64.sin(), c + 0.04 * 0.3f64.cos()];
    assert!(ind.signed_distance(mirrored, [0.0; 3]).0 > 0.0);
    // Overlapping fingers are rejected.
    let mut bad = hand.clone();
    bad.spacing = 0.01;
    assert!(bad.to_indenter_spec().is_err());
}

#[test]
fn curves_and_motion_specs() {
    let c = Curve::SmoothStep {
        amplitude: 0.015,
        duration: 0.025,
        start: 0.0,
    };
    assert_eq!(c.value(0.0), 0.0);
    assert!(close(c.value(0.025), 0.015, 1e-15));
    assert!(close(c.value(0.0125), 0.0075, 1e-15));
    assert!(close(c.value(1.0), 0.015, 1e-15));
    // Peak rate 1.875 a / T at mid-time, zero at the ends.
    assert!(close(c.rate(0.0125), 1.875 * 0.015 / 0.025, 1e-12));
    assert_eq!(c.rate(0.0), 0.0);
    // Rate is the derivative.
    for t in [0.003, 0.01, 0.02] {
        let fd = (c.value(t + 1e-7) - c.value(t - 1e-7)) / 2e-7;
        assert!(close(fd, c.rate(t), 1e-6));
    }
    let tab = Curve::Table {
        points: vec![[0.0, 0.0], [1.0, 2.0], [3.0, 2.0]],
    };
    assert!(close(tab.value(0.5), 1.0, 1e-15) && close(tab.rate(0.5), 2.0, 1e-15));
    assert!(close(tab.value(5.0), 2.0, 1e-15));

    // Scene-style deserialisation (plain SI numbers).
    let toml_src = r#"
        name = "finger1"
        direction = [0, 0, -1]
        motion = { kind = "displacement", curve = { curve = "smooth_step", amplitude = 0.015, duration = 0.025 } }
        [[parts]]
        shape = "capsule"
        center = [0, 0, 0.0575]
        axis = [0, 0, 1]
        radius = 0.0075
        length = 0.05
    "#;
    let spec: IndenterSpec = toml::from_str(toml_src).unwrap();
    assert_eq!(spec.motion, MotionSpec::Displacement { curve: c.clone() });
    let f: MotionSpec =
        toml::from_str("kind = \"force\"\ntarget = 20.0\nramp_time = 0.01").unwrap();
    match f {
        MotionSpec::Force(fc) => {
            assert_eq!(fc.target, 20.0);
            assert_eq!(fc.ramp_time, 0.01);
            assert_eq!(fc.time_constant, ForceControl::new(20.0).time_constant);
        }
        _ => panic!(),
    }
    let h: HandSpec = toml::from_str(
        r#"
        name = "hand"
        point = [0.0, 0.0, 0.05]
        direction = [0, 0, -1]
        diameter = 0.015
        spacing = 0.02
        length = 0.07
        tilt = 0.2
        motion = { kind = "velocity", curve = { curve = "constant", value = 0.1 } }
        "#,
    )
    .unwrap();
    assert_eq!(h.to_indenter_spec().unwrap().parts.len(), 2);
    let p: ContactParams =
        toml::from_str("penalty = \"soft\"\ndesign_dt = 1e-6\nfriction = 0.2").unwrap();
    assert_eq!(p.penalty, PenaltyKind::Soft);
    assert_eq!(p.samples_max, ContactParams::default().samples_max);
}
