//! Standard errors and the joint covariance of one direction's Stribeck parameters,
//! from the weighted Jacobian at the optimum (Gauss-Newton approximation).

use nalgebra::{Matrix4, Vector4};

/// Covariance of `(fc, fs, sigma2, vs)` and what it was computed from.
pub(super) struct Intervals {
    /// Standard errors (NaN when they cannot be computed).
    pub(super) std_err: Vec<f64>,
    /// Joint covariance, row-major 4x4 (NaN when it cannot be computed).
    pub(super) cov: Vec<f64>,
    /// Weighted residual standard deviation [N].
    pub(super) sigma: f64,
    /// Points with a nonzero weight.
    pub(super) n_used: usize,
    /// Degrees of freedom `n_used - 4`.
    pub(super) dof: f64,
}

/// `sigma^2 (J^T W J)^-1` at the parameters `p`, with `sigma^2` the weighted residual
/// variance on `n_used - 4` degrees of freedom; the inverse of the column-scaled matrix
/// (unit diagonal), which keeps it accurate across the parameters' magnitudes.
pub(super) fn covariance(a: &[f64], weights: &[f64], residuals: &[f64], p: &[f64; 4]) -> Intervals {
    let mut jtwj = Matrix4::<f64>::zeros();
    for (&ai, &wi) in a.iter().zip(weights) {
        if wi == 0.0 {
            continue;
        }
        let phi = (-(ai / p[3]).powi(2)).exp();
        let r = Vector4::new(
            1.0 - phi,
            phi,
            ai,
            (p[1] - p[0]) * phi * 2.0 * ai * ai / (p[3] * p[3] * p[3]),
        );
        jtwj += wi * r * r.transpose();
    }
    let n_used = weights.iter().filter(|w| **w > 0.0).count();
    let dof = n_used as f64 - 4.0;
    let ssq: f64 = residuals.iter().zip(weights).map(|(e, w)| w * e * e).sum();
    let sigma = if dof > 0.0 {
        (ssq / dof).sqrt()
    } else {
        f64::NAN
    };
    let d = Vector4::from_fn(|k, _| jtwj[(k, k)].sqrt());
    let mut std_err = vec![f64::NAN; 4];
    let mut cov_out = vec![f64::NAN; 16];
    if d.iter().all(|x| *x > 0.0 && x.is_finite()) && sigma.is_finite() {
        let dm = Matrix4::from_diagonal(&d.map(|x| 1.0 / x));
        let m = dm * jtwj * dm;
        if let Some(inv) = m.try_inverse() {
            let cov = dm * inv * dm * (sigma * sigma);
            for (k, se) in std_err.iter_mut().enumerate() {
                let v = cov[(k, k)];
                if v >= 0.0 {
                    *se = v.sqrt();
                }
            }
            if std_err.iter().all(|s| s.is_finite()) {
                for r in 0..4 {
                    for c in 0..4 {
                        cov_out[4 * r + c] = 0.5 * (cov[(r, c)] + cov[(c, r)]);
                    }
                }
            }
        }
    }
    Intervals {
        std_err,
        cov: cov_out,
        sigma,
        n_used,
        dof,
    }
}
