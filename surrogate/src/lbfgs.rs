//! Limited-memory BFGS with a backtracking (Armijo) line search and box bounds by projection,
//! used to maximise the Gaussian-process marginal likelihood.
//!
//! Source: J. Nocedal and S. J. Wright, *Numerical Optimization*, 2nd ed., Springer 2006,
//! Algorithm 7.4 (two-loop recursion) and Algorithm 3.1 (backtracking line search).

/// Settings of [`minimise`].
#[derive(Clone, Debug)]
pub struct LbfgsOptions {
    /// Maximum number of iterations.
    pub max_iterations: usize,
    /// Number of correction pairs kept.
    pub memory: usize,
    /// Stop when the infinity norm of the projected gradient falls below this.
    pub gradient_tolerance: f64,
    /// Stop when the objective changes by less than this (relative) between iterations.
    pub relative_tolerance: f64,
}

impl Default for LbfgsOptions {
    fn default() -> Self {
        LbfgsOptions {
            max_iterations: 200,
            memory: 8,
            gradient_tolerance: 1e-6,
            relative_tolerance: 1e-10,
        }
    }
}

/// Minimises `f` (returning value and gradient, or `None` where it cannot be evaluated) from
/// `x0`, keeping each `x_i` within `bounds[i]`. Returns the best point and its value.
pub fn minimise(
    mut f: impl FnMut(&[f64]) -> Option<(f64, Vec<f64>)>,
    x0: &[f64],
    bounds: &[(f64, f64)],
    opts: &LbfgsOptions,
) -> Option<(Vec<f64>, f64)> {
    let project = |x: &mut [f64]| {
        for (v, (lo, hi)) in x.iter_mut().zip(bounds) {
            *v = v.clamp(*lo, *hi);
        }
    };
    let mut x = x0.to_vec();
    project(&mut x);
    let (mut fx, mut g) = f(&x)?;
    let mut s_hist: Vec<Vec<f64>> = Vec::new();
    let mut y_hist: Vec<Vec<f64>> = Vec::new();
    for _ in 0..opts.max_iterations {
        // projected gradient: components pushing against an active bound do not count
        let pg = projected_gradient(&x, &g, bounds);
        if pg.iter().fold(0.0f64, |m, v| m.max(v.abs())) < opts.gradient_tolerance {
            break;
        }
        let mut dir = two_loop(&pg, &s_hist, &y_hist);
        if dot(&dir, &pg) >= 0.0 {
            // not a descent direction: fall back to steepest descent
            s_hist.clear();
            y_hist.clear();
            dir = pg.iter().map(|v| -v).collect();
        }
        let slope = dot(&dir, &g);
        let mut step = if s_hist.is_empty() {
            1.0 / pg.iter().map(|v| v * v).sum::<f64>().sqrt().max(1.0)
        } else {
            1.0
        };
        let mut accepted = None;
        for _ in 0..40 {
            let mut xn: Vec<f64> = x.iter().zip(&dir).map(|(a, d)| a + step * d).collect();
            project(&mut xn);
            if let Some((fn_, gn)) = f(&xn) {
                if fn_.is_finite() && fn_ <= fx + 1e-4 * step * slope.min(0.0) {
                    accepted = Some((xn, fn_, gn));
                    break;
                }
            }
            step *= 0.5;
        }
        let Some((xn, fn_, gn)) = accepted else {
            if s_hist.is_empty() {
                break;
            }
            s_hist.clear();
            y_hist.clear();
            continue;
        };
        let s: Vec<f64> = xn.iter().zip(&x).map(|(a, b)| a - b).collect();
        let yv: Vec<f64> = gn.iter().zip(&g).map(|(a, b)| a - b).collect();
        if dot(&s, &yv) > 1e-12 {
            s_hist.push(s);
            y_hist.push(yv);
            if s_hist.len() > opts.memory {
                s_hist.remove(0);
                y_hist.remove(0);
            }
        }
        let change = (fx - fn_).abs() / fx.abs().max(1.0);
        x = xn;
        fx = fn_;
        g = gn;
        if change < opts.relative_tolerance {
            break;
        }
    }
    Some((x, fx))
}

fn projected_gradient(x: &[f64], g: &[f64], bounds: &[(f64, f64)]) -> Vec<f64> {
    x.iter()
        .zip(g)
        .zip(bounds)
        .map(|((xi, gi), (lo, hi))| {
            if (*xi <= *lo && *gi > 0.0) || (*xi >= *hi && *gi < 0.0) {
                0.0
            } else {
                *gi
            }
        })
        .collect()
}

/// Two-loop recursion: returns `-H g` for the L-BFGS inverse-Hessian estimate H.
fn two_loop(g: &[f64], s_hist: &[Vec<f64>], y_hist: &[Vec<f64>]) -> Vec<f64> {
    let mut q = g.to_vec();
    let m = s_hist.len();
    let mut alpha = vec![0.0; m];
    for i in (0..m).rev() {
        let rho = 1.0 / dot(&y_hist[i], &s_hist[i]);
        alpha[i] = rho * dot(&s_hist[i], &q);
        for (qj, yj) in q.iter_mut().zip(&y_hist[i]) {
            *qj -= alpha[i] * yj;
        }
    }
    if m > 0 {
        let gamma = dot(&s_hist[m - 1], &y_hist[m - 1]) / dot(&y_hist[m - 1], &y_hist[m - 1]);
        q.iter_mut().for_each(|v| *v *= gamma);
    }
    for i in 0..m {
        let rho = 1.0 / dot(&y_hist[i], &s_hist[i]);
        let beta = rho * dot(&y_hist[i], &q);
        for (qj, sj) in q.iter_mut().zip(&s_hist[i]) {
            *qj += (alpha[i] - beta) * sj;
        }
    }
    q.iter().map(|v| -v).collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_rosenbrock_minimum() {
        let f = |x: &[f64]| {
            let (a, b) = (x[0], x[1]);
            let v = (1.0 - a).powi(2) + 100.0 * (b - a * a).powi(2);
            let g = vec![
                -2.0 * (1.0 - a) - 400.0 * a * (b - a * a),
                200.0 * (b - a * a),
            ];
            Some((v, g))
        };
        let opts = LbfgsOptions {
            max_iterations: 500,
            ..Default::default()
        };
        let (x, v) = minimise(f, &[-1.2, 1.0], &[(-5.0, 5.0), (-5.0, 5.0)], &opts).unwrap();
        assert!(v < 1e-8, "value {v}");
        assert!((x[0] - 1.0).abs() < 1e-3 && (x[1] - 1.0).abs() < 1e-3);
    }

    #[test]
    fn respects_bounds() {
        let f = |x: &[f64]| Some(((x[0] - 3.0).powi(2), vec![2.0 * (x[0] - 3.0)]));
        let (x, _) = minimise(f, &[0.0], &[(-1.0, 1.0)], &LbfgsOptions::default()).unwrap();
        assert!((x[0] - 1.0).abs() < 1e-12);
    }
}
