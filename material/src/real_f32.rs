//! Single-precision lanes for the element kernels: [`F32x8`], eight `f32` (one AVX2 register,
//! half an AVX-512 one), the number type of the solver's `precision = "f32"` kernels.
//!
//! The element kernels (gradients, hourglass modes, nodal forces, critical step) run in `f32`;
//! the laws do not. [`Real::Wide`] of [`F32x8`] is [`F64x8`]: a kernel widens its displacement
//! gradient `H = sum_a u_a (x) grad N_a` to `f64`, adds the identity there, calls the law in
//! `f64` and narrows the first Piola-Kirchhoff stress back. The reason is the flesh's K/G = 5e4:
//! `J - 1` formed from an `f32` `F = I + H` carries an absolute error of about 6e-8 (half an
//! `f32` ulp of 1), which the bulk modulus K = 2 GPa turns into pressure noise of about 100 Pa,
//! half a percent of the stress the liver's region of interest reports. From `H` widened before
//! the identity is added, the error is 6e-8 relative to the strain instead. The Ogden law's
//! closed-form principal stretches and its thresholds (1e-200 and below) also need `f64`. LS-DYNA's
//! single-precision executable runs everything in 32 bits; this is the cautious half of that.
//!
//! History stays in `f64` (it belongs to the law). Conversions round to nearest, so the results
//! do not depend on the instruction set. Transcendentals are those of [`F64x8`], narrowed.

use crate::real::{lane_operators, lane_real_methods, F64x8, Mask, Real, LANES, M8};
use std::ops::{
    Add, AddAssign, BitAnd, BitOr, Div, DivAssign, Mul, MulAssign, Neg, Not, Sub, SubAssign,
};
use wide::f32x8;

/// Eight `f32` lanes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(transparent)]
pub struct F32x8(pub f32x8);

/// Eight boolean lanes of [`F32x8`] (all bits set where true).
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(transparent)]
pub struct M8f(pub f32x8);

impl F32x8 {
    /// From an array of lanes.
    #[inline(always)]
    pub fn new(x: [f32; LANES]) -> F32x8 {
        F32x8(f32x8::new(x))
    }
    /// The lanes as an array.
    #[inline(always)]
    pub fn to_array(self) -> [f32; LANES] {
        self.0.to_array()
    }
}

lane_operators!(F32x8, M8f, f32x8, f32);

/// A function of [`F64x8`] applied to [`F32x8`] lanes: widened, evaluated, narrowed.
#[inline(always)]
fn through_f64(x: F32x8, f: impl Fn(F64x8) -> F64x8) -> F32x8 {
    F32x8::narrow(f(x.widen()))
}

impl Real for F32x8 {
    type Mask = M8f;
    const LANES: usize = LANES;
    type Wide = F64x8;
    #[inline(always)]
    fn widen(self) -> F64x8 {
        let a = self.0.to_array();
        F64x8::new(crate::arr![LANES, |i| a[i] as f64])
    }
    #[inline(always)]
    fn narrow(w: F64x8) -> Self {
        let a = w.to_array();
        F32x8::new(crate::arr![LANES, |i| a[i] as f32])
    }
    #[inline(always)]
    fn narrow_mask(m: M8) -> M8f {
        let b = m.0.to_bitmask();
        let on = f32::from_bits(u32::MAX);
        M8f(f32x8::new(crate::arr![LANES, |i| if b >> i & 1 == 1 {
            on
        } else {
            0.0
        }]))
    }
    #[inline(always)]
    fn splat(x: f64) -> Self {
        F32x8(f32x8::splat(x as f32))
    }
    #[inline(always)]
    fn lane(self, i: usize) -> f64 {
        self.0.as_array()[i] as f64
    }
    #[inline(always)]
    fn set_lane(&mut self, i: usize, x: f64) {
        self.0.as_mut_array()[i] = x as f32;
    }
    #[inline(always)]
    fn from_slice(x: &[f64]) -> Self {
        F32x8::new(crate::arr![LANES, |i| x[i] as f32])
    }
    #[inline(always)]
    fn write_to(self, out: &mut [f64]) {
        let a = self.0.to_array();
        for i in 0..LANES {
            out[i] = a[i] as f64;
        }
    }
    #[inline(always)]
    fn cbrt(self) -> Self {
        through_f64(self, F64x8::cbrt)
    }
    #[inline(always)]
    fn exp(self) -> Self {
        through_f64(self, F64x8::exp)
    }
    #[inline(always)]
    fn exp_m1(self) -> Self {
        through_f64(self, F64x8::exp_m1)
    }
    #[inline(always)]
    fn ln(self) -> Self {
        through_f64(self, F64x8::ln)
    }
    #[inline(always)]
    fn ln_1p(self) -> Self {
        through_f64(self, F64x8::ln_1p)
    }
    lane_real_methods!(F32x8, M8f, f32x8, f32);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_round_to_nearest_and_back() {
        let x = F64x8::new([1.0, 1.0 + 1e-9, -3.5, 1e-30, 1e30, 0.1, 2.0 / 3.0, -0.0]);
        let n = F32x8::narrow(x);
        for i in 0..LANES {
            assert_eq!(n.lane(i), x.lane(i) as f32 as f64);
        }
        assert_eq!(n.widen().to_array(), n.to_array().map(|v| v as f64));
    }

    #[test]
    fn arithmetic_and_masks_match_f32_lane_by_lane() {
        let a = F32x8::new([0.5, -1.0, 2.0, 1e-3, 7.0, -0.25, 3.0, 9.0]);
        let b = F32x8::splat(2.0);
        let s = (a * b + a / b - b).max(a.min(b)).sqrt();
        for i in 0..LANES {
            let x = a.to_array()[i];
            let r = (x * 2.0 + x / 2.0 - 2.0).max(x.min(2.0)).sqrt();
            assert_eq!(s.to_array()[i].to_bits(), r.to_bits(), "lane {i}");
        }
        let m = a.gt(F32x8::zero());
        assert!(m.lane(0) && !m.lane(1));
        let wide_m = F64x8::new([1.0, -1.0, 1.0, 1.0, -1.0, 1.0, -1.0, 1.0]).gt(F64x8::zero());
        let nm = F32x8::narrow_mask(wide_m);
        for i in 0..LANES {
            assert_eq!(nm.lane(i), wide_m.lane(i));
        }
        assert_eq!(F32x8::select(m, a, b).lane(1), 2.0);
        let nan = F32x8::splat(f64::NAN);
        assert_eq!(nan.max(b).lane(0), 2.0);
        assert!(!nan.is_finite().any() && b.is_finite().lane(7));
    }

    #[test]
    fn transcendentals_are_the_wide_ones_narrowed() {
        let a = F32x8::new([0.5, 1.0, 2.0, 1e-3, 7.0, 0.25, 3.0, 9.0]);
        for (got, f) in [
            (a.exp(), f64::exp as fn(f64) -> f64),
            (a.ln(), f64::ln),
            (a.cbrt(), f64::cbrt),
            (a.ln_1p(), f64::ln_1p),
        ] {
            for i in 0..LANES {
                let want = f(a.lane(i)) as f32 as f64;
                assert!(
                    (got.lane(i) - want).abs() <= 1.2e-7 * want.abs(),
                    "lane {i}"
                );
            }
        }
    }
}
