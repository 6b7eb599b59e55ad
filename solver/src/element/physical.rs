//! Physical (assumed-strain) hourglass stabilisation of the one-point hexahedron.
//!
//! The one-point element sees only the mean strain; the twelve hourglass modes (four shapes
//! times three components) are the rest of the trilinear displacement field. Flanagan and
//! Belytschko's forms ([`super::HourglassForm::Viscous`], [`super::HourglassForm::Stiffness`])
//! resist them with an arbitrary coefficient. The physical form gives each mode the strain
//! energy of the field it stands for, following the assumed-strain idea of Belytschko and
//! Bindeman (1993), "Assumed strain stabilization of the eight node hexahedral element",
//! CMAME 105:225-260 (LS-DYNA hourglass type 6, OpenRadioss Isolid 24):
//!
//! In the element's own frame (axes `e_j` along its natural directions, half-lengths `a_j`, from
//! the polar decomposition of the reference Jacobian at the centre `J0 = R0 U0`, `a_j` the
//! length of column `j` of `J0`), the hourglass field is
//!   u(xi) = sum_alpha q_alpha h_alpha(xi),  h = xi eta, eta zeta, zeta xi, xi eta zeta,
//! with generalised displacements `q_alpha = 1/8 sum_a gamma_alpha,a u_a` (the unnormalised
//! Flanagan-Belytschko vectors of [`crate::hex::hourglass_gamma`]; for a parallelepiped `q_alpha`
//! is exactly the coefficient of `h_alpha`). Its strains, with the parasitic shear of the
//! bending modes removed (the cause of shear locking) and the normal strains taken in plane
//! or uniaxial stress (so Young's modulus, not the P-wave modulus, resists them, and a nearly
//! incompressible solid does not lock), give the energy, averaged over the element
//! (`<xi^2> = 1/3`, `<xi^2 eta^2> = 1/9`):
//!
//! - bending: the mode `h = xi_i xi_k` in component `i` strains `eps_ii = s_i xi_k`,
//!   `s_i = q / a_i` (six modes). The two normal strains that vary along the same `xi_k`
//!   (`i, j != k`) act together in plane stress (`eps_kk` linear in `xi_k` is not in the
//!   trilinear field, so `sigma_kk = 0`):
//!   `W = E/(1 - nu^2) V/6 (s_i^2 + s_j^2 + 2 nu s_i s_j)`. A beam's Poisson contraction
//!   (`s_j = -nu s_i`) is then free and its bending stiffness is `E`; a plate's is
//!   `E / (1 - nu^2)`; both stay finite as nu -> 1/2;
//! - twist: the mode `h = xi_j xi_k` in component `i` (no normal strain); the shears of the
//!   three twist modes combine, `gamma_ij = xi_k (t_i / a_j + t_j / a_i)`, so a rigid twist of
//!   a bar (torsion) is strain-free across the pair it rotates:
//!   `W = mu V/6 sum_{i<j} (t_i / a_j + t_j / a_i)^2`;
//! - warp: `h = xi eta zeta` in component `i`:
//!   `W = V/18 (E (q_i / a_i)^2 + mu sum_{j != i} (q_i / a_j)^2)`.
//!
//! For a rectangular element in pure bending this is exactly the energy of beam theory,
//! `E I kappa^2 / 2` per length, whatever the number of elements through the thickness. `E`,
//! `nu` and `mu` are the law's initial moduli; the hourglass coefficient Q multiplies the energy (Q = 1 is
//! the exact stiffness; LS-DYNA's QM for type 6).
//!
//! **Large deformation.** palpa's elements are total Lagrangian, so the modes are measured in
//! the material frame: `q~_alpha = F^T q_alpha` with `F` the element's mean deformation gradient
//! (the hourglass part of the Green strain is `sym(F^T q (x) grad h)`), and in the element frame
//! `q^_alpha = R0^T q~_alpha`. The energy `W(u) = 1/2 q^ . K q^` is then a potential: a rigid
//! rotation leaves it unchanged (objective), and the nodal forces are its exact gradient,
//!   f_a = sum_alpha [ 1/8 gamma_alpha,a F Q~_alpha + (b_a . Q~_alpha) q_alpha ],
//! with `Q~_alpha = R0 dW/dq^_alpha` and `b_a` the mean gradient; the second term comes from the
//! dependence of `F` on the nodes. The energy is the strain energy of the assumed field, so the
//! element books it as internal energy (the work of its forces), not as hourglass energy: the
//! hourglass guard and the summary's hourglass warning concern the spurious modes of the
//! viscous and stiffness forms only. (LS-DYNA reports its type 6 energy as hourglass energy.)
//!
//! `F^T q` is a Green-strain (St Venant-Kirchhoff-like) measure: under a stretch `lambda` along
//! an element axis the hourglass stiffness of the modes along it scales with `lambda^2`, about
//! half the small-strain value at 30 % compression. LS-DYNA's type 6, a co-rotational rate
//! form, does not scale so; the two agree at small strain only.
//!
//! **Limits.** The element frame and half-lengths make the energy exact for rectangular
//! elements and an approximation for distorted ones (as in Belytschko and Bindeman). The
//! moduli are elastic and initial: in plastic flow the hourglass modes stay elastic (too stiff,
//! as LS-DYNA warns for type 6), and a stiffening law's hourglass modes do not stiffen.

use super::{add_nodal_forces, dot8, Nodal};
use material::real::Real;
use material::tensor::M3;
use nalgebra::Matrix3;

/// The element frame of the physical form, per element (or batch, one element per lane).
pub struct PhysicalRef<'a, R: Real = f64> {
    /// `R0`: component `i` of the element axis `j` is `frame[i][j]`.
    pub frame: &'a [[R; 3]; 3],
    /// `1 / a_j`, the element's inverse half-lengths (1/m).
    pub inv_len: &'a [R; 3],
    /// Young's modulus the modes are given (Pa).
    pub young: f64,
    /// Poisson's ratio the modes are given.
    pub poisson: f64,
    /// Shear modulus the modes are given (Pa).
    pub shear: f64,
}

/// The element frame `R0` (rows: components, columns: axes) and inverse half-lengths `1 / a_j`
/// of an element with reference corners `x`: the polar decomposition of `J0 = dX/dxi` at the
/// centre. `None` if `J0` is singular.
pub fn element_frame(x: &[[f64; 3]; 8]) -> Option<([[f64; 3]; 3], [f64; 3])> {
    let d = crate::hex::dn_dxi([0.0; 3]);
    let j0 = Matrix3::from_fn(|i, j| (0..8).map(|a| x[a][i] * d[a][j]).sum::<f64>());
    let mut inv_len = [0.0; 3];
    for (j, il) in inv_len.iter_mut().enumerate() {
        let a = j0.column(j).norm();
        if a.is_nan() || a <= 0.0 {
            return None;
        }
        *il = 1.0 / a;
    }
    let svd = j0.svd(true, true);
    let r = svd.u? * svd.v_t?;
    if r.determinant().is_nan() || r.determinant() <= 0.0 {
        return None;
    }
    Some((
        std::array::from_fn(|i| std::array::from_fn(|j| r[(i, j)])),
        inv_len,
    ))
}

/// Adds the physical hourglass forces to `fe` and returns the stored hourglass energy (J).
/// `scale` = Q V0 / 3 (m^3), `f` the mean deformation gradient, `u` the nodal displacements,
/// `gamma` the unnormalised hourglass vectors, `grad` the mean gradient.
#[inline(always)]
pub fn add_forces<R: Real>(
    r: &PhysicalRef<R>,
    scale: R,
    f: &M3<R>,
    u: &Nodal<R>,
    gamma: &[[R; 8]; 4],
    grad: &Nodal<R>,
    fe: &mut Nodal<R>,
) -> R {
    let rf = r.frame;
    // q[alpha][i]: generalised hourglass displacements (global components).
    let q: [[R; 3]; 4] = material::arr![4, |al| material::arr![3, |i| dot8(&u[i], &gamma[al])
        * 0.125]];
    // q^ = R0^T F^T q, in the element frame.
    let qh: [[R; 3]; 4] = material::arr![4, |al| {
        let qt: [R; 3] = material::arr![3, |j| f[0][j] * q[al][0]
            + f[1][j] * q[al][1]
            + f[2][j] * q[al][2]];
        material::arr![3, |j| rf[0][j] * qt[0]
            + rf[1][j] * qt[1]
            + rf[2][j] * qt[2]]
    }];
    let (e, g, nu) = (R::splat(r.young), R::splat(r.shear), R::splat(r.poisson));
    let plate = R::splat(r.young / (1.0 - r.poisson * r.poisson));
    let il = *r.inv_len;
    let [i0, i1, i2] = il;
    let sq = [i0 * i0, i1 * i1, i2 * i2];
    let mut qf = [[R::zero(); 3]; 4];
    // Bending: the two normal strains that vary along xi_k, in plane stress
    // (k = 0: eps_yy of mode 0 in y, eps_zz of mode 2 in z; k = 1: eps_xx of mode 0 in x,
    // eps_zz of mode 1 in z; k = 2: eps_xx of mode 2 in x, eps_yy of mode 1 in y).
    for ((ma, ia), (mb, ib)) in [((0, 1), (2, 2)), ((0, 0), (1, 2)), ((2, 0), (1, 1))] {
        let sa = qh[ma][ia] * il[ia];
        let sb = qh[mb][ib] * il[ib];
        qf[ma][ia] = plate * (sa + nu * sb) * il[ia];
        qf[mb][ib] = plate * (sb + nu * sa) * il[ib];
    }
    // Twist: t_i is the mode without xi_i in component i (modes 1, 2, 0 for x, y, z).
    let (t0, t1, t2) = (qh[1][0], qh[2][1], qh[0][2]);
    let g01 = t0 * i1 + t1 * i0;
    let g12 = t1 * i2 + t2 * i1;
    let g20 = t2 * i0 + t0 * i2;
    qf[1][0] = g * (g01 * i1 + g20 * i2);
    qf[2][1] = g * (g01 * i0 + g12 * i2);
    qf[0][2] = g * (g12 * i1 + g20 * i0);
    // Warp: mode 3, with <(xi eta)^2> = 1/9 = (1/3) (1/3).
    let third = 1.0 / 3.0;
    for i in 0..3 {
        let lateral = sq[(i + 1) % 3] + sq[(i + 2) % 3];
        qf[3][i] = (e * sq[i] + g * lateral) * qh[3][i] * third;
    }
    let mut w = R::zero();
    for al in 0..4 {
        for i in 0..3 {
            w += qh[al][i] * qf[al][i];
        }
    }
    // Q~ = R0 Q^ (global components), then the nodal forces.
    let qg: [[R; 3]; 4] = material::arr![4, |al| material::arr![3, |i| rf[i][0] * qf[al][0]
        + rf[i][1] * qf[al][1]
        + rf[i][2] * qf[al][2]]];
    // 1/8 F Q~, per mode.
    let fq: [[R; 3]; 4] = material::arr![4, |al| material::arr![3, |m| (f[m][0] * qg[al][0]
        + f[m][1] * qg[al][1]
        + f[m][2] * qg[al][2])
        * 0.125]];
    for m in 0..3 {
        let (c0, c1, c2, c3) = (
            scale * fq[0][m],
            scale * fq[1][m],
            scale * fq[2][m],
            scale * fq[3][m],
        );
        for a in 0..8 {
            fe[m][a] += c0 * gamma[0][a] + c1 * gamma[1][a] + c2 * gamma[2][a] + c3 * gamma[3][a];
        }
    }
    // The dependence of F on the nodes: sum_alpha q_alpha (x) Q~_alpha contracted with b_a.
    let mq: M3<R> = material::arr![3, |m| material::arr![3, |j| q[0][m] * qg[0][j]
        + q[1][m] * qg[1][j]
        + q[2][m] * qg[2][j]
        + q[3][m] * qg[3][j]]];
    add_nodal_forces(fe, &mq, grad, scale);
    scale * w * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hex::{element_geometry, hourglass_gamma};
    use crate::mesh::CORNERS;

    /// A box of half-lengths `a`, rotated by `rot` and translated.
    fn box_corners(a: [f64; 3], rot: &Matrix3<f64>) -> [[f64; 3]; 8] {
        std::array::from_fn(|n| {
            let c = CORNERS[n];
            let p = nalgebra::Vector3::new(a[0] * c[0], a[1] * c[1], a[2] * c[2]);
            let x = rot * p;
            [x[0] + 0.3, x[1] - 0.1, x[2] + 0.2]
        })
    }

    fn forces(x: &[[f64; 3]; 8], u: &[[f64; 3]; 8], young: f64, shear: f64) -> (Nodal, f64) {
        let geo = element_geometry(x).unwrap();
        let gamma = hourglass_gamma(x, &geo.mean_grad);
        let (frame, inv_len) = element_frame(x).unwrap();
        let un: Nodal = std::array::from_fn(|i| std::array::from_fn(|a| u[a][i]));
        let f = crate::element::deformation_gradient(&un, &geo.mean_grad);
        let r = PhysicalRef {
            frame: &frame,
            inv_len: &inv_len,
            young,
            poisson: young / (2.0 * shear) - 1.0,
            shear,
        };
        let mut fe = [[0.0; 8]; 3];
        let w = add_forces(
            &r,
            geo.volume / 3.0,
            &f,
            &un,
            &gamma,
            &geo.mean_grad,
            &mut fe,
        );
        (fe, w)
    }

    fn rot(angle: f64) -> Matrix3<f64> {
        nalgebra::Rotation3::from_axis_angle(
            &nalgebra::Unit::new_normalize(nalgebra::Vector3::new(0.3, -0.5, 0.8)),
            angle,
        )
        .into_inner()
    }

    #[test]
    fn pure_bending_has_the_beam_and_plate_energy() {
        // A beam: u_x = kappa x z with its Poisson contraction u_y = -nu kappa y z on a box 2a:
        // W = E I kappa^2 / 2 * length, I = (2 a1)(2 a2)^3 / 12. A plate (u_y = 0): the same
        // with E / (1 - nu^2).
        let a = [0.02, 0.01, 0.005];
        let x = box_corners(a, &Matrix3::identity());
        let kappa = 1e-3;
        for (e, mu) in [(2.6e5, 1.0e5), (2.999e5, 1.0e5)] {
            let nu = e / (2.0 * mu) - 1.0;
            let i = (2.0 * a[1]) * (2.0 * a[2]).powi(3) / 12.0;
            for (contraction, modulus) in [(nu, e), (0.0, e / (1.0 - nu * nu))] {
                let u: [[f64; 3]; 8] = std::array::from_fn(|n| {
                    let p = [
                        a[0] * CORNERS[n][0],
                        a[1] * CORNERS[n][1],
                        a[2] * CORNERS[n][2],
                    ];
                    [kappa * p[0] * p[2], -contraction * kappa * p[1] * p[2], 0.0]
                });
                let (_, w) = forces(&x, &u, e, mu);
                let exact = 0.5 * modulus * i * kappa * kappa * 2.0 * a[0];
                assert!((w - exact).abs() < 1e-6 * exact, "nu {nu}: {w} vs {exact}");
            }
        }
    }

    #[test]
    fn rigid_twist_strains_only_the_faces_it_shears() {
        // Torsion about x: u_y = -theta x z, u_z = theta x y; the twist modes cancel in
        // gamma_yz, leaving mu theta^2 (y^2 + z^2) / 2 averaged over the box.
        let a = [0.02, 0.01, 0.005];
        let x = box_corners(a, &Matrix3::identity());
        let th = 1e-3;
        let u: [[f64; 3]; 8] = std::array::from_fn(|n| {
            let p = [
                a[0] * CORNERS[n][0],
                a[1] * CORNERS[n][1],
                a[2] * CORNERS[n][2],
            ];
            [0.0, -th * p[0] * p[2], th * p[0] * p[1]]
        });
        let mu = 1.0e5;
        let (_, w) = forces(&x, &u, 3.0 * mu, mu);
        let v = 8.0 * a[0] * a[1] * a[2];
        let exact = 0.5 * mu * th * th * (a[1] * a[1] + a[2] * a[2]) / 3.0 * v;
        assert!((w - exact).abs() < 1e-6 * exact, "{w} vs {exact}");
    }

    #[test]
    fn forces_are_the_gradient_of_the_energy_and_objective() {
        let a = [0.02, 0.012, 0.007];
        let r0 = rot(0.7);
        let x = box_corners(a, &r0);
        let mut u = [[0.0; 3]; 8];
        let mut rng = crate::generate::SplitMix::new(7);
        for n in 0..8 {
            for i in 0..3 {
                u[n][i] = 2e-3 * rng.symmetric();
            }
        }
        let (e, mu) = (3.0e5, 1.0e5);
        let (fe, w) = forces(&x, &u, e, mu);
        assert!(w > 0.0);
        // Central differences of W.
        let h = 1e-8;
        for n in 0..8 {
            for i in 0..3 {
                let mut up = u;
                up[n][i] += h;
                let mut um = u;
                um[n][i] -= h;
                let d = (forces(&x, &up, e, mu).1 - forces(&x, &um, e, mu).1) / (2.0 * h);
                assert!(
                    (d - fe[i][n]).abs() < 1e-6 * fe[i][n].abs().max(1.0),
                    "node {n} comp {i}: dW/du {d} vs f {}",
                    fe[i][n]
                );
            }
        }
        // A rigid rotation superposed on the deformed element leaves W unchanged and rotates
        // the forces.
        let q = rot(1.1);
        let ur: [[f64; 3]; 8] = std::array::from_fn(|n| {
            let y = nalgebra::Vector3::from(x[n]) + nalgebra::Vector3::from(u[n]);
            let yr = q * y;
            [yr[0] - x[n][0], yr[1] - x[n][1], yr[2] - x[n][2]]
        });
        let (fr, wr) = forces(&x, &ur, e, mu);
        assert!((wr - w).abs() < 1e-9 * w, "{wr} vs {w}");
        let fmax = fe.iter().flatten().fold(0.0f64, |m, f| m.max(f.abs()));
        for n in 0..8 {
            let f0 = q * nalgebra::Vector3::new(fe[0][n], fe[1][n], fe[2][n]);
            for i in 0..3 {
                assert!((fr[i][n] - f0[i]).abs() < 1e-9 * fmax);
            }
        }
    }

    #[test]
    fn linear_fields_carry_no_hourglass_force() {
        let x = box_corners([0.02, 0.01, 0.01], &rot(0.4));
        let u: [[f64; 3]; 8] = std::array::from_fn(|n| {
            let p = x[n];
            [
                0.01 * p[0] + 0.02 * p[1] - 0.005 * p[2] + 1e-3,
                -0.01 * p[1] + 0.003 * p[2],
                0.02 * p[0] + 0.01 * p[2],
            ]
        });
        let (fe, w) = forces(&x, &u, 3.0e5, 1.0e5);
        assert!(w.abs() < 1e-20);
        assert!(fe.iter().flatten().all(|f| f.abs() < 1e-12));
    }

    /// The other two bending planes, the warp mode and torsion about z, each on an aligned and
    /// on a rotated box (catches a transposed frame, a mis-paired bending couple or a wrong
    /// warp coefficient, which the tests above cannot see).
    #[test]
    fn every_bending_plane_warp_and_torsion_about_z_on_aligned_and_rotated_boxes() {
        let a = [0.02, 0.01, 0.005];
        let (e, mu) = (2.6e5, 1.0e5);
        let nu = e / (2.0 * mu) - 1.0;
        let v = 8.0 * a[0] * a[1] * a[2];
        let k = 1e-3;
        for r in [Matrix3::identity(), rot(0.9)] {
            let case = |field: &dyn Fn([f64; 3]) -> [f64; 3]| {
                let x = box_corners(a, &r);
                let u: [[f64; 3]; 8] = std::array::from_fn(|n| {
                    let p = [
                        a[0] * CORNERS[n][0],
                        a[1] * CORNERS[n][1],
                        a[2] * CORNERS[n][2],
                    ];
                    let ul = field(p);
                    let ug = r * nalgebra::Vector3::new(ul[0], ul[1], ul[2]);
                    [ug[0], ug[1], ug[2]]
                });
                forces(&x, &u, e, mu).1
            };
            // Beam along y bent in x, with its contraction.
            let w = case(&|p| [0.0, k * p[0] * p[1], -nu * k * p[0] * p[2]]);
            let i = (2.0 * a[2]) * (2.0 * a[0]).powi(3) / 12.0;
            let exact = 0.5 * e * i * k * k * 2.0 * a[1];
            assert!((w - exact).abs() < 1e-6 * exact, "y-beam {w} {exact}");
            // Beam along z bent in y, with its contraction.
            let w = case(&|p| [-nu * k * p[1] * p[0], 0.0, k * p[1] * p[2]]);
            let i = (2.0 * a[0]) * (2.0 * a[1]).powi(3) / 12.0;
            let exact = 0.5 * e * i * k * k * 2.0 * a[2];
            assert!((w - exact).abs() < 1e-6 * exact, "z-beam {w} {exact}");
            // Warp in x: u_x = c x y z.
            let c = 1e-2;
            let w = case(&|p| [c * p[0] * p[1] * p[2], 0.0, 0.0]);
            let q = c * a[0] * a[1] * a[2];
            let exact = v / 18.0
                * (e * (q / a[0]).powi(2) + mu * ((q / a[1]).powi(2) + (q / a[2]).powi(2)));
            assert!((w - exact).abs() < 1e-6 * exact, "warp {w} {exact}");
            // Torsion about z.
            let th = 1e-3;
            let w = case(&|p| [-th * p[2] * p[1], th * p[2] * p[0], 0.0]);
            let exact = 0.5 * mu * th * th * (a[0] * a[0] + a[1] * a[1]) / 3.0 * v;
            assert!((w - exact).abs() < 1e-6 * exact, "torsion z {w} {exact}");
        }
    }
}
