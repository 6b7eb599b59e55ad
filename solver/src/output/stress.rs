//! Stress measures for output: von Mises and the principal stresses of a symmetric tensor
//! stored as (xx, yy, zz, xy, yz, zx).

use nalgebra::{Matrix3, SymmetricEigen};

/// von Mises equivalent stress sqrt(3/2 s:s), s the deviator.
pub fn von_mises(s: &[f64; 6]) -> f64 {
    let [xx, yy, zz, xy, yz, zx] = *s;
    (0.5 * ((xx - yy).powi(2) + (yy - zz).powi(2) + (zz - xx).powi(2))
        + 3.0 * (xy * xy + yz * yz + zx * zx))
        .sqrt()
}

/// Principal stresses, largest first; all NaN if the tensor has a NaN (the element loop stops a
/// run before a non-finite stress reaches an output, so this only guards against a panic).
pub fn principal(s: &[f64; 6]) -> [f64; 3] {
    let [xx, yy, zz, xy, yz, zx] = *s;
    let m = Matrix3::new(xx, xy, zx, xy, yy, yz, zx, yz, zz);
    let e = SymmetricEigen::new(m).eigenvalues;
    let mut v = [e[0], e[1], e[2]];
    if v.iter().any(|x| x.is_nan()) {
        return [f64::NAN; 3];
    }
    // No NaN: partial_cmp is total here, and a stable sort keeps the solver's order of equal
    // values (so -0 and 0 print as before).
    v.sort_by(|a, b| b.partial_cmp(a).unwrap_or(std::cmp::Ordering::Equal));
    v
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniaxial_measures() {
        let s = [3.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        assert!((von_mises(&s) - 3.0).abs() < 1e-12);
        assert_eq!(principal(&s)[0], 3.0);
        let shear = [0.0, 0.0, 0.0, 2.0, 0.0, 0.0];
        assert!((von_mises(&shear) - 2.0 * 3f64.sqrt()).abs() < 1e-12);
        assert!((principal(&shear)[0] - 2.0).abs() < 1e-12);
    }

    #[test]
    fn principal_of_a_nan_tensor_is_nan_not_a_panic() {
        let p = principal(&[1.0, f64::NAN, 0.0, 0.0, 0.0, 0.0]);
        assert!(p.iter().all(|x| x.is_nan()));
    }
}
