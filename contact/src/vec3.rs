//! Tiny fixed-size vector helpers on `[f64; 3]` (no dependency, all `#[inline]`).

/// A 3-vector.
pub type V3 = [f64; 3];

#[inline]
pub(crate) fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
#[inline]
pub(crate) fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
#[inline]
pub(crate) fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
#[inline]
pub(crate) fn axpy(s: f64, a: V3, y: V3) -> V3 {
    [y[0] + s * a[0], y[1] + s * a[1], y[2] + s * a[2]]
}
#[inline]
pub(crate) fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
#[inline]
pub(crate) fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
#[inline]
pub(crate) fn norm2(a: V3) -> f64 {
    dot(a, a)
}
#[inline]
pub(crate) fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}
/// Unit vector along `a`, or `None` for a (near-)zero vector.
#[inline]
pub(crate) fn normalize(a: V3) -> Option<V3> {
    let n = norm(a);
    if n > 1e-300 && n.is_finite() {
        Some(scale(a, 1.0 / n))
    } else {
        None
    }
}
/// Some unit vector perpendicular to the unit vector `a`.
#[inline]
pub(crate) fn any_perpendicular(a: V3) -> V3 {
    let t = if a[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let p = sub(t, scale(a, dot(t, a)));
    scale(p, 1.0 / norm(p))
}
/// Rotate `v` about the unit axis `k` by `angle` (rad), Rodrigues' formula.
#[inline]
pub(crate) fn rotate(v: V3, k: V3, angle: f64) -> V3 {
    let (s, c) = angle.sin_cos();
    add(
        add(scale(v, c), scale(cross(k, v), s)),
        scale(k, dot(k, v) * (1.0 - c)),
    )
}
