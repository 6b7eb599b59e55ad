//! The penalty stage on flat quad grids: force magnitudes, distribution, smoothness, friction,
//! broad phase, stiffness bound, energy balance and force control.
#![allow(clippy::needless_range_loop)]

mod common;
use common::*;
use contact::*;

const H: f64 = 1e-3; // face size (m)

fn fixed_sphere(center: [f64; 3], radius: f64) -> IndenterSpec {
    sphere("ball", center, radius, MotionSpec::Fixed)
}

fn eval(stage: &mut ContactStage, x: &[[f64; 3]], t: f64) -> Vec<[f64; 3]> {
    let mut f = vec![[0.0; 3]; x.len()];
    let v = vec![[0.0; 3]; x.len()];
    stage.apply(t, 1e-7, x, &v, &mut f);
    f
}

#[test]
fn plane_on_one_face_gives_k_times_penetration() {
    // One face, rigid plane penetrating it uniformly by g: F = k g with k = s K A^2 / V.
    let (x, surf) = flat_grid(1, H, 2e9);
    let g = 1e-6;
    let plane = IndenterSpec {
        name: "plate".into(),
        parts: vec![ShapeSpec::Plane {
            point: [0.0, 0.0, -g],
            normal: [0.0, 0.0, -1.0],
        }],
        direction: [0.0, 0.0, -1.0],
        motion: MotionSpec::Fixed,
        friction: None,
    };
    let mut st =
        ContactStage::new(&[plane], surf, &x, &[1e-6; 4], ContactParams::default()).unwrap();
    let f = eval(&mut st, &x, 0.0);
    let k = 0.1 * 2e9 * (H * H).powi(2) / (H * H * H);
    let s = &st.indenters()[0];
    assert!(
        (s.force[2] - k * g).abs() < 1e-9 * k * g,
        "{} vs {}",
        s.force[2],
        k * g
    );
    // Each node takes a quarter; body forces push the face down (-z), away from the plate above.
    for fi in &f {
        assert!((fi[2] + k * g / 4.0).abs() < 1e-9 * k * g);
    }
    assert!((s.area - H * H).abs() < 1e-15);
    assert!((s.max_penetration - g).abs() < 1e-15);
    assert!((st.penalty_energy() - 0.5 * k * g * g).abs() < 1e-9 * k * g * g);
    assert!((st.face_pressure()[0] - k * g / (H * H)).abs() < 1e-6 * k * g / (H * H));
}

#[test]
fn sphere_on_flat_grid_matches_cap_volume_and_nodal_sum() {
    // Rigid flat grid under a sphere penetrating by d. The gap is the distance to the sphere,
    // g = R - rho (rho = |x - c|), along the normal with n_z = z_c / rho, z_c = R - d:
    // F_z = int eps (R - rho) z_c / rho dA = 2 pi eps z_c int_{z_c}^{R} (R - rho) drho
    //     = eps pi d^2 (R - d).
    let n = 30;
    let (x, surf) = flat_grid(n, H, 1e9);
    let r = 5e-3;
    let d = 0.4e-3;
    let c = [15.3e-3, 14.6e-3, r - d];
    // 8 x 8 samples per face (the default would take 2 x 2 here, R = 5 h; see the doc test of
    // sample convergence below).
    let params = ContactParams {
        samples_min: 8,
        ..Default::default()
    };
    let mut st = ContactStage::new(
        &[fixed_sphere(c, r)],
        surf,
        &x,
        &vec![1e-6; x.len()],
        params,
    )
    .unwrap();
    let f = eval(&mut st, &x, 0.0);
    let eps = 0.1 * 1e9 * H * H / (H * H * H);
    let exact = eps * std::f64::consts::PI * d * d * (r - d);
    let s = &st.indenters()[0];
    let rel = (s.force[2] / exact - 1.0).abs();
    assert!(rel < 0.005, "force {} vs {exact} ({rel})", s.force[2]);
    assert!((s.reaction - s.force[2]).abs() < 1e-12 * s.force[2]);
    // The nodal forces sum exactly to minus the indenter force.
    let sum = sum_forces(&f);
    for k in 0..3 {
        assert!((sum[k] + s.force[k]).abs() <= 1e-12 * s.force[2].abs());
    }
    // Contact area ~ pi (2 R d - d^2), max penetration d.
    let a = std::f64::consts::PI * (2.0 * r * d - d * d);
    assert!((s.area / a - 1.0).abs() < 0.03, "area {} vs {a}", s.area);
    assert!((s.max_penetration / d - 1.0).abs() < 0.02);
    // The lateral resultant vanishes by symmetry of a sphere on a plane (up to sampling).
    assert!(s.force[0].abs() < 1e-3 * s.force[2].abs());
    // Pressure (normal force magnitude per area) integrates to a little more than the vertical
    // resultant (the sphere's normals tilt by up to a / R = 0.4 rad at the rim).
    let pf: f64 = st.face_pressure().iter().map(|p| p * H * H).sum();
    assert!(
        pf > s.force[2] && pf < 1.05 * s.force[2],
        "{pf} vs {}",
        s.force[2]
    );
}

/// Smoothness metric: a sphere of radius one face size slides across face boundaries at
/// constant penetration. Over 200 positions spaced h/50 (4 faces crossed), the step-to-step
/// change of the normal force must stay below 0.5 % of the mean and the total ripple
/// (max - min) below 5 % of the mean.
#[test]
fn sliding_sphere_gives_smooth_force() {
    let r = H;
    let d = 0.1 * r;
    // The sphere moves along +x (its `direction`) across 4 faces at constant penetration d.
    let (x, surf) = flat_grid(12, H, 1e9);
    let ind = IndenterSpec {
        name: "ball".into(),
        parts: vec![ShapeSpec::Sphere {
            center: [3.0 * H, 6.3 * H, r - d],
            radius: r,
        }],
        direction: [1.0, 0.0, 0.0],
        motion: MotionSpec::Displacement {
            curve: Curve::Ramp {
                amplitude: 4.0 * H,
                duration: 1.0,
                start: 0.0,
            },
        },
        friction: None,
    };
    let mut st = ContactStage::new(
        &[ind],
        surf,
        &x,
        &vec![1e-6; x.len()],
        ContactParams::default(),
    )
    .unwrap();
    let mut fz = Vec::new();
    for i in 0..=200 {
        eval(&mut st, &x, i as f64 / 200.0);
        fz.push(st.indenters()[0].force[2]);
    }
    let mean = fz.iter().sum::<f64>() / fz.len() as f64;
    let max_jump = fz
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f64::max)
        / mean;
    let (lo, hi) = fz
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(l, h), &f| (l.min(f), h.max(f)));
    let ripple = (hi - lo) / mean;
    eprintln!("sliding: mean {mean:.4e} N, max step jump {max_jump:.2e}, ripple {ripple:.2e}");
    assert!(max_jump < 5e-3, "max jump {max_jump}");
    assert!(ripple < 0.05, "ripple {ripple}");
}

#[test]
fn friction_opposes_sliding() {
    let (x, surf) = flat_grid(10, H, 1e9);
    let ind = IndenterSpec {
        name: "ball".into(),
        parts: vec![ShapeSpec::Sphere {
            center: [5.0 * H, 5.0 * H, 2.0 * H - 0.2 * H],
            radius: 2.0 * H,
        }],
        direction: [0.0, 0.0, -1.0],
        motion: MotionSpec::Fixed,
        friction: Some(0.3),
    };
    // Heavy nodes, so that the explicit-stability floor on the regularisation speed stays low.
    let mut st = ContactStage::new(
        &[ind],
        surf,
        &x,
        &vec![1e-2; x.len()],
        ContactParams::default(),
    )
    .unwrap();
    // Body slides in +x under the fixed sphere at 0.1 m/s (well above the regularisation speed).
    let v = vec![[0.1, 0.0, 0.0]; x.len()];
    let mut f = vec![[0.0; 3]; x.len()];
    let dt = 1e-7;
    st.apply(0.0, dt, &x, &v, &mut f);
    let s = &st.indenters()[0];
    let body = sum_forces(&f);
    // Friction on the body opposes its motion; on the indenter it drags along.
    assert!(body[0] < 0.0 && s.force[0] > 0.0);
    // Coulomb limit: |F_t| = mu F_n once sliding.
    // (Friction acts along each sample's tangent, so the resultant ratio is only near mu.)
    assert!(
        (body[0].abs() / body[2].abs() - 0.3).abs() < 0.01,
        "{body:?}"
    );
    // Dissipation equals |F_t| v dt.
    assert!(
        (st.dissipated_energy() - body[0].abs() * 0.1 * dt).abs() < 1e-9 * st.dissipated_energy()
    );
    let diss0 = st.dissipated_energy();
    // Below the regularisation speed the force is viscous (proportional to speed).
    let v_slow = vec![[1e-5, 0.0, 0.0]; x.len()];
    let mut f2 = vec![[0.0; 3]; x.len()];
    st.apply(0.0, dt, &x, &v_slow, &mut f2);
    let b2 = sum_forces(&f2);
    assert!(
        (b2[0].abs() / (0.3 * b2[2].abs()) / (1e-5 / 1e-3) - 1.0).abs() < 0.01,
        "{b2:?}"
    );
    assert!(st.dissipated_energy() > diss0);
}

#[test]
fn broad_phase_lists_only_nearby_faces() {
    let n = 200;
    let (x, surf) = flat_grid(n, H, 1e9);
    let nf = surf.faces.len();
    let faces = surf.faces.clone();
    let r = 3e-3;
    let ind = sphere(
        "ball",
        [100.5 * H, 80.2 * H, r - 0.3e-3],
        r,
        MotionSpec::Displacement {
            curve: Curve::Ramp {
                amplitude: 0.5e-3,
                duration: 1.0,
                start: 0.0,
            },
        },
    );
    // Reference: a margin covering the whole surface (brute force).
    let brute = ContactParams {
        margin: Some(1.0),
        ..Default::default()
    };
    let mut st = ContactStage::new(
        std::slice::from_ref(&ind),
        surf.clone(),
        &x,
        &vec![1e-6; x.len()],
        ContactParams::default(),
    )
    .unwrap();
    let mut bf = ContactStage::new(&[ind], surf, &x, &vec![1e-6; x.len()], brute).unwrap();
    let v = vec![[0.0; 3]; x.len()];
    for i in 0..=20 {
        let t = i as f64 / 20.0;
        let mut f1 = vec![[0.0; 3]; x.len()];
        let mut f2 = vec![[0.0; 3]; x.len()];
        st.apply(t, 1e-3, &x, &v, &mut f1);
        bf.apply(t, 1e-3, &x, &v, &mut f2);
        assert_eq!(f1, f2, "broad phase missed a face at t = {t}");
        let cands = st.candidates(0);
        // Indenter box (6 mm + 2 margins of 1 mm) covers at most 9 x 9 faces.
        assert!(
            cands.len() <= 100 && cands.len() < nf / 100,
            "{} candidates",
            cands.len()
        );
        // Every face with pressure is a candidate.
        for (fi, p) in st.face_pressure().iter().enumerate() {
            if *p > 0.0 {
                assert!(cands.contains(&(fi as u32)));
            }
        }
        // Candidates are near the indenter.
        let u = st.indenters()[0].offset;
        for &c in cands {
            let q = x[faces[c as usize][0] as usize];
            let dx = (q[0] - 100.5 * H).abs().max((q[1] - 80.2 * H).abs());
            assert!(dx < r + 3.0 * H && u[2] <= 0.0);
        }
    }
    let (rebuilds, faces_checked, _) = st.counters();
    assert!(
        rebuilds >= 1 && faces_checked < 21 * 100,
        "{rebuilds} {faces_checked}"
    );
}

#[test]
fn stiffness_bound_and_cap() {
    let (x, surf) = flat_grid(4, H, 2e9);
    let m = 1060.0 * H * H * H; // kg per node
    let dt = 2e-7;
    let ind = fixed_sphere([2.0 * H, 2.0 * H, 1e-3], 1e-3);
    // Uncapped segment penalty: interior node stiffness = eps * A (row sum of 4 quarter faces).
    let p0 = ContactParams {
        stiffness_cap: None,
        ..Default::default()
    };
    let st = ContactStage::new(
        std::slice::from_ref(&ind),
        surf.clone(),
        &x,
        &vec![m; x.len()],
        p0,
    )
    .unwrap();
    let k_face = 0.1 * 2e9 * H * H * H * H / (H * H * H);
    let expect = 2.0 * (m / k_face).sqrt();
    assert!(
        (st.stable_dt_bound() / expect - 1.0).abs() < 1e-12,
        "{} vs {expect}",
        st.stable_dt_bound()
    );
    // A cap of 0.1 m (2/dt)^2 at a design step where the segment penalty exceeds it: capped,
    // and the bound becomes 2 sqrt(m / (0.1 m 4 / dt^2)) = dt / sqrt(0.1).
    let dt_big = 1e-4;
    let p1 = ContactParams {
        design_dt: Some(dt_big),
        ..Default::default()
    };
    let st = ContactStage::new(
        std::slice::from_ref(&ind),
        surf.clone(),
        &x,
        &vec![m; x.len()],
        p1,
    )
    .unwrap();
    assert!(st.capped_faces() > 0);
    assert!(st.stable_dt_bound() >= dt_big / 0.1f64.sqrt() * (1.0 - 1e-12));
    // Soft penalty: k = s_soft m / dt^2 per face, eps = k / A.
    let p2 = ContactParams {
        penalty: PenaltyKind::Soft,
        design_dt: Some(dt),
        stiffness_cap: None,
        ..Default::default()
    };
    let st = ContactStage::new(
        std::slice::from_ref(&ind),
        surf.clone(),
        &x,
        &vec![m; x.len()],
        p2,
    )
    .unwrap();
    for e in st.face_penalty() {
        assert!((e / (0.1 * m / (dt * dt) / (H * H)) - 1.0).abs() < 1e-12);
    }
    // Soft with the default cap 0.1 at that step: s_soft m / dt^2 = 0.1 m/dt^2 < 0.1 m 4/dt^2: uncapped.
    let p3 = ContactParams {
        penalty: PenaltyKind::Soft,
        design_dt: Some(dt),
        ..Default::default()
    };
    assert_eq!(
        ContactStage::new(
            std::slice::from_ref(&ind),
            surf.clone(),
            &x,
            &vec![m; x.len()],
            p3
        )
        .unwrap()
        .capped_faces(),
        0
    );
    // Soft without a design step is an error.
    let p4 = ContactParams {
        penalty: PenaltyKind::Soft,
        ..Default::default()
    };
    assert!(ContactStage::new(&[ind], surf, &x, &vec![m; x.len()], p4).is_err());
}

/// Explicit run of a spring-supported surface under a prescribed sphere: the stage's contact
/// energy closes the balance KE + springs + damping + E_contact = W_drive within 1 %,
/// and the stage stays stable at the step given by its bound.
#[test]
fn energy_balance_with_prescribed_indentation() {
    let n = 30;
    let (x0, surf) = flat_grid(n, H, 2e7);
    let m = 1e-5;
    let ks = 100.0;
    let mut body = SpringSurface::new(x0.clone(), m, ks, 2e-3);
    let r = 7.5e-3;
    let ind = sphere(
        "finger",
        [15.2e-3, 14.9e-3, r + 0.5e-3],
        r,
        MotionSpec::Displacement {
            curve: Curve::SmoothStep {
                amplitude: 3.5e-3,
                duration: 0.02,
                start: 0.0,
            },
        },
    );
    let mut st = ContactStage::new(
        &[ind],
        surf,
        &x0,
        &vec![m; x0.len()],
        ContactParams::default(),
    )
    .unwrap();
    let dt_spring = 2.0 * (m / ks).sqrt();
    let dt = 0.5 / (1.0 / dt_spring.powi(2) + 1.0 / st.stable_dt_bound().powi(2)).sqrt();
    let steps = (0.03 / dt) as usize;
    let mut max_pen: f64 = 0.0;
    for i in 0..steps {
        body.step(&mut st, i as f64 * dt, dt);
        max_pen = max_pen.max(st.indenters()[0].max_penetration);
    }
    let e_body = body.kinetic_energy() + body.spring_energy() + body.damping_dissipated;
    let w = st.driver_work();
    let err = (e_body + st.energy() - w).abs() / w;
    let s = &st.indenters()[0];
    eprintln!(
        "energy: W_drive {w:.4e} J, body {e_body:.4e} J, contact {:.4e} J, error {err:.2e}; \
         force {:.3} N, depth {:.3e} m, max penetration {max_pen:.3e} m, steps {steps}",
        st.energy(),
        s.reaction,
        s.depth
    );
    assert!(err < 0.01, "energy error {err}");
    assert!(s.reaction > 0.0 && (s.depth - 3.0e-3).abs() < 0.05e-3);
}

/// Force control on a spring-supported surface reaches 20 N within 2 % and holds it.
#[test]
fn force_control_reaches_and_holds_target() {
    let n = 40;
    let (x0, surf) = flat_grid(n, H, 1e8);
    let m = 1e-5;
    let ks = 94.0;
    // Damping about half critical per node.
    let mut body = SpringSurface::new(x0.clone(), m, ks, (ks * m).sqrt());
    body.vertical_only = true;
    let r = 7.5e-3;
    let ind = sphere(
        "finger",
        [20.1e-3, 19.7e-3, r + 1e-3],
        r,
        MotionSpec::Force(ForceControl {
            ramp_time: 0.02,
            ..ForceControl::new(20.0)
        }),
    );
    let mut st = ContactStage::new(
        &[ind],
        surf,
        &x0,
        &vec![m; x0.len()],
        ContactParams::default(),
    )
    .unwrap();
    let dt_spring = 2.0 * (m / ks).sqrt();
    let dt = 0.5 / (1.0 / dt_spring.powi(2) + 1.0 / st.stable_dt_bound().powi(2)).sqrt();
    let t_end = 0.15;
    let steps = (t_end / dt) as usize;
    let mut worst_hold: f64 = 0.0;
    let mut t_reach = None;
    for i in 0..steps {
        let t = i as f64 * dt;
        body.step(&mut st, t, dt);
        let f = st.indenters()[0].reaction;
        if t_reach.is_none() && (f - 20.0).abs() < 0.4 {
            t_reach = Some(t);
        }
        if t > 0.08 {
            worst_hold = worst_hold.max((f - 20.0).abs() / 20.0);
        }
    }
    let s = &st.indenters()[0];
    eprintln!(
        "force control: reached 2 % at {:?} s, final {:.4} N, depth {:.3e} m, worst hold error {worst_hold:.2e}",
        t_reach, s.reaction, s.depth
    );
    assert!(t_reach.is_some());
    assert!(worst_hold < 0.02, "hold error {worst_hold}");
}

/// How the sampled penalty force converges with samples per face direction (sphere R = 5 h,
/// penetration 0.08 R, rigid flat grid; exact eps pi d^2 (R - d)): printed, and the error must
/// stay below 2 % from n = 3 on.
#[test]
fn sample_convergence() {
    let (x, surf) = flat_grid(30, H, 1e9);
    let r = 5e-3;
    let d = 0.4e-3;
    let eps = 0.1 * 1e9 * H * H / (H * H * H);
    let exact = eps * std::f64::consts::PI * d * d * (r - d);
    let mut errs = Vec::new();
    for n in [1u32, 2, 3, 4, 6, 8, 12] {
        let params = ContactParams {
            samples_min: n,
            samples_max: n,
            ..Default::default()
        };
        let mut st = ContactStage::new(
            &[fixed_sphere([15.3e-3, 14.6e-3, r - d], r)],
            surf.clone(),
            &x,
            &vec![1e-6; x.len()],
            params,
        )
        .unwrap();
        eval(&mut st, &x, 0.0);
        let e = st.indenters()[0].force[2] / exact - 1.0;
        eprintln!("samples {n}x{n}: relative force error {e:+.3e}");
        errs.push((n, e.abs()));
    }
    assert!(errs.iter().filter(|(n, _)| *n >= 3).all(|(_, e)| *e < 0.02));
}

/// A triangle-mesh sphere (STL) presses like the analytic sphere it approximates.
#[test]
fn stl_indenter_matches_analytic_sphere() {
    let (nu, nv) = (96, 48);
    let r = 5e-3;
    let mut tris = Vec::new();
    // In mm in the file.
    let p = |i: usize, j: usize| {
        let th = std::f64::consts::PI * j as f64 / nv as f64;
        let ph = 2.0 * std::f64::consts::PI * i as f64 / nu as f64;
        [
            5.0 * th.sin() * ph.cos(),
            5.0 * th.sin() * ph.sin(),
            5.0 * th.cos(),
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
    let path = std::env::temp_dir().join(format!("contact-ball-{}.stl", std::process::id()));
    std::fs::write(&path, contact::trimesh::write_binary_stl(&tris)).unwrap();
    let (x, surf) = flat_grid(30, H, 1e9);
    let d = 0.5e-3;
    let c = [15.3e-3, 14.6e-3, r - d];
    let mesh = IndenterSpec {
        name: "stl".into(),
        parts: vec![ShapeSpec::Stl {
            path: path.clone(),
            scale: 1e-3,
            translate: c,
        }],
        direction: [0.0, 0.0, -1.0],
        motion: MotionSpec::Fixed,
        friction: None,
    };
    let params = ContactParams {
        samples_min: 6,
        ..Default::default()
    };
    let mut a = ContactStage::new(
        &[mesh],
        surf.clone(),
        &x,
        &vec![1e-6; x.len()],
        params.clone(),
    )
    .unwrap();
    let mut b = ContactStage::new(
        &[fixed_sphere(c, r)],
        surf,
        &x,
        &vec![1e-6; x.len()],
        params,
    )
    .unwrap();
    eval(&mut a, &x, 0.0);
    eval(&mut b, &x, 0.0);
    std::fs::remove_file(&path).ok();
    let (fa, fb) = (a.indenters()[0].force[2], b.indenters()[0].force[2]);
    // The faceted sphere is inscribed (a pole vertex at the lowest point): slightly less force.
    eprintln!("stl {fa:.4} N, analytic {fb:.4} N");
    assert!(fa < fb && fa > 0.98 * fb, "{fa} vs {fb}");
}

#[test]
fn raycast_finds_surface_point_and_normal() {
    let (x, surf) = flat_grid(10, H, 1e9);
    let hit = surf
        .raycast(&x, [3.3e-3, 4.7e-3, 0.02], [0.0, 0.0, -1.0])
        .unwrap();
    assert!((hit.distance - 0.02).abs() < 1e-12);
    assert_eq!(hit.face, 4 * 10 + 3);
    assert!((hit.normal[2] - 1.0).abs() < 1e-12);
    assert!(surf
        .raycast(&x, [3.3e-3, 4.7e-3, 0.02], [0.0, 0.0, 1.0])
        .is_none());
    assert!(surf
        .raycast(&x, [-1.0, 4.7e-3, 0.02], [0.0, 0.0, -1.0])
        .is_none());
}

#[test]
fn velocity_motion_integrates_and_depth_counts_from_contact() {
    let (x, surf) = flat_grid(4, H, 1e9);
    let ind = sphere(
        "ball",
        [2e-3, 2e-3, 1e-3 + 0.2e-3],
        1e-3,
        MotionSpec::Velocity {
            curve: Curve::Constant { value: 0.1 },
        },
    );
    let mut st = ContactStage::new(
        &[ind],
        surf,
        &x,
        &vec![1e-6; x.len()],
        ContactParams::default(),
    )
    .unwrap();
    let dt = 1e-4;
    for i in 0..=50 {
        eval(&mut st, &x, i as f64 * dt);
    }
    let s = &st.indenters()[0];
    assert!((s.travel - 0.5e-3).abs() < 1e-12, "{s:?}");
    assert!((s.offset[2] + 0.5e-3).abs() < 1e-12);
    // First contact at travel 0.2 mm (to within a step of 10 um).
    assert!((s.depth - 0.3e-3).abs() <= 1.01e-5, "{}", s.depth);
    // Penetration is measured at the samples (the nearest is h/16 off the lowest point here).
    let n = st.face_samples().next().unwrap() as f64;
    let r0 = 2f64.sqrt() * H / (2.0 * n);
    let expect = 1e-3 - (0.7e-3f64.powi(2) + r0 * r0).sqrt();
    assert!(
        (s.max_penetration - expect).abs() < 1e-9,
        "{} vs {expect} (n {n})",
        s.max_penetration
    );
}
