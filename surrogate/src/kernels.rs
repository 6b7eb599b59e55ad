//! The one inner kernel of both serving paths: `out += sum_i c_i * row_i`, i.e. `out += A^T c`
//! for a row-major `A` (rows of length `out.len()`), skipping zero coefficients (ReLU zeros).
//!
//! The MLP layers (f32) and the GP mean and variance (f64) all reduce to it. On x86-64 it is
//! compiled twice, once for the baseline target and once with AVX2 enabled, and the AVX2
//! version is chosen at run time when the processor has it (the build does not assume a CPU).

use std::ops::{AddAssign, Mul};

/// Element types of the kernel.
pub trait Real: Copy + PartialEq + Default + Mul<Output = Self> + AddAssign {}
impl Real for f32 {}
impl Real for f64 {}

/// `out += sum_i c[i] * rows[i * n .. (i + 1) * n]` with `n = out.len()`; extra rows or
/// coefficients beyond the shorter of the two are ignored.
pub fn accumulate_rows<T: Real>(c: &[T], rows: &[T], out: &mut [T]) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor supports AVX2, checked just above.
            unsafe { accumulate_rows_avx2(c, rows, out) };
            return;
        }
    }
    accumulate_rows_plain(c, rows, out)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn accumulate_rows_avx2<T: Real>(c: &[T], rows: &[T], out: &mut [T]) {
    accumulate_rows_plain(c, rows, out)
}

#[inline(always)]
fn accumulate_rows_plain<T: Real>(c: &[T], rows: &[T], out: &mut [T]) {
    let n = out.len();
    if n == 0 {
        return;
    }
    let zero = T::default();
    for (&ci, row) in c.iter().zip(rows.chunks_exact(n)) {
        if ci != zero {
            for (o, &r) in out.iter_mut().zip(row) {
                *o += ci * r;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_a_plain_matrix_vector_product() {
        let a = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]; // 3 rows of 2
        let c = [1.0, 0.0, -2.0];
        let mut out = [0.5, 0.5];
        accumulate_rows(&c, &a, &mut out);
        assert_eq!(out, [0.5 + 1.0 - 10.0, 0.5 + 2.0 - 12.0]);
    }
}
