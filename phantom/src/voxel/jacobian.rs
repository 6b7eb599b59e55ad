//! Corner Jacobians of 8-node hexahedra.
//!
//! At corner c with edge neighbours (a, b, d) taken in right-handed order for VTK_HEXAHEDRON
//! numbering, the corner Jacobian is J_c = (x_a - x_c) . ((x_b - x_c) x (x_d - x_c)) and
//! the scaled Jacobian is J_c / (|x_a - x_c| |x_b - x_c| |x_d - x_c|), 1 for a cube corner
//! and <= 0 for a folded one (Knupp, "Achieving finite element mesh quality via optimization
//! of the Jacobian matrix norm and associated quantities", IJNME 48, 2000; Verdict manual).

/// For each corner, its three edge neighbours in right-handed order.
pub const CORNER_EDGES: [[usize; 3]; 8] = [
    [1, 3, 4],
    [2, 0, 5],
    [3, 1, 6],
    [0, 2, 7],
    [7, 5, 0],
    [4, 6, 1],
    [5, 7, 2],
    [6, 4, 3],
];

#[inline]
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
fn det3(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0])
}

#[inline]
fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// The eight corner coordinates of element `conn`.
#[inline]
pub fn element_coords(nodes: &[[f64; 3]], conn: &[u32; 8]) -> [[f64; 3]; 8] {
    let mut x = [[0.0; 3]; 8];
    for (a, &n) in conn.iter().enumerate() {
        x[a] = nodes[n as usize];
    }
    x
}

/// Corner Jacobians (m^3) of a hexahedron.
pub fn corner_jacobians(x: &[[f64; 3]; 8]) -> [f64; 8] {
    let mut j = [0.0; 8];
    for (c, e) in CORNER_EDGES.iter().enumerate() {
        j[c] = det3(sub(x[e[0]], x[c]), sub(x[e[1]], x[c]), sub(x[e[2]], x[c]));
    }
    j
}

/// Minimum scaled corner Jacobian (dimensionless, 1 for a cube).
pub fn min_scaled_jacobian(x: &[[f64; 3]; 8]) -> f64 {
    let mut m = f64::INFINITY;
    for (c, e) in CORNER_EDGES.iter().enumerate() {
        let (a, b, d) = (sub(x[e[0]], x[c]), sub(x[e[1]], x[c]), sub(x[e[2]], x[c]));
        let l = norm(a) * norm(b) * norm(d);
        let s = if l > 0.0 { det3(a, b, d) / l } else { -1.0 };
        m = m.min(s);
    }
    m
}

/// Jacobian determinant at the element centre (m^3 per unit natural volume, i.e. V/8 for a
/// parallelepiped): det of the mean edge vectors along xi, eta, zeta, each halved.
pub fn centre_jacobian(x: &[[f64; 3]; 8]) -> f64 {
    let mut g = [[0.0; 3]; 3];
    for k in 0..3 {
        g[0][k] =
            (x[1][k] - x[0][k] + x[2][k] - x[3][k] + x[5][k] - x[4][k] + x[6][k] - x[7][k]) / 8.0;
        g[1][k] =
            (x[3][k] - x[0][k] + x[2][k] - x[1][k] + x[7][k] - x[4][k] + x[6][k] - x[5][k]) / 8.0;
        g[2][k] =
            (x[4][k] - x[0][k] + x[5][k] - x[1][k] + x[6][k] - x[2][k] + x[7][k] - x[3][k]) / 8.0;
    }
    det3(g[0], g[1], g[2])
}

/// Characteristic length V / A_max (m) of a hexahedron, the length that sets its explicit
/// stable time step (LS-DYNA's default for solids): V is eight times the centre Jacobian,
/// and each face area is half the cross product of the face's diagonals.
pub fn characteristic_length(x: &[[f64; 3]; 8]) -> f64 {
    let v = 8.0 * centre_jacobian(x);
    let mut amax: f64 = 0.0;
    for f in solver::mesh::FACES.iter() {
        let d1 = sub(x[f[2]], x[f[0]]);
        let d2 = sub(x[f[3]], x[f[1]]);
        let c = [
            d1[1] * d2[2] - d1[2] * d2[1],
            d1[2] * d2[0] - d1[0] * d2[2],
            d1[0] * d2[1] - d1[1] * d2[0],
        ];
        amax = amax.max(0.5 * norm(c));
    }
    if amax > 0.0 {
        v / amax
    } else {
        0.0
    }
}
