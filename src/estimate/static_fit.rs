//! Step 1 of the paper's identification: the Stribeck curve of each direction from
//! steady-state (constant-velocity) points.
//!
//! For `v > 0` the model is `F = fc + (fs - fc)*exp(-(v/vs)^2) + sigma2*v` (eq. 7);
//! for `v < 0` the same curve mirrored, `F = -(fc + ...) + sigma2*v`, with its own
//! positive parameters (eq. 9). Each direction is fitted separately by robust IRLS
//! (eqs. 19-24) with Nelder-Mead on `(ln fc, ln(fs - fc), ln sigma2, ln vs)`: the
//! log-parameters are of order one whatever the units, and `fs >= fc`, all positive,
//! hold by construction.
//!
//! Start values need no user input: for a fixed `vs` the curve is linear in
//! `(fc, fs, sigma2)`, so a grid over `ln vs` with a robust linear fit at each node
//! gives a start that gross errors do not pull away (a variable-projection start,
//! Golub and Pereyra 1973). With a rejecting weight function (IGG, Tukey) two such
//! starts are followed to the end, a Huber grid and a least-trimmed-squares grid (the
//! latter also resists gross errors at the fastest or slowest speeds, which have high
//! leverage), and the fit with the smaller bounded loss is returned; the
//! kept points are then refitted by plain least squares, with the rejections
//! re-checked, which recovers the efficiency the down-weighting band costs.

use super::irls::{irls, IrlsOutcome, IrlsSetup};
use super::nelder_mead::{minimize, NmOptions};
use super::robust::{median, robust_scale, t_quantile_975, Weighting};
use crate::error::{check_finite, check_len, Error, Result};
use crate::friction::StaticSet;
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

/// Fewest nonzero-speed points per direction that [`fit_static`] accepts (4 parameters
/// plus one degree of freedom for the residual scale).
pub const MIN_POINTS_PER_DIRECTION: usize = 5;

/// Names of the static parameters in the order of the per-parameter vectors.
pub const STATIC_PARAM_NAMES: [&str; 4] = ["fc", "fs", "sigma2", "vs"];

/// Options of [`fit_static`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticFitOptions {
    /// Weight function (IGG by default).
    pub weighting: Weighting,
    /// Maximum IRLS (outer) iterations.
    pub max_iter: usize,
    /// Stop when the log-parameters move by less than this between iterations.
    pub tol: f64,
    /// Lower bound of the residual scale [N] used for the weights. The scale is never
    /// below `1e-6*median|F|`, so that rounding in noise-free data is not taken for
    /// gross errors; set this to the force resolution to raise the bound.
    pub scale_floor: f64,
    /// Objective evaluations per Nelder-Mead run.
    pub max_evals: usize,
    /// With a rejecting weight function (IGG, Tukey): after IRLS, refit by plain least
    /// squares on the points it kept, then re-check the rejections at the robust scale
    /// and repeat until the kept set settles (true by default). The down-weighting band
    /// of IGG costs efficiency on clean Gaussian points; this recovers it.
    pub refit_kept: bool,
}

impl Default for StaticFitOptions {
    fn default() -> Self {
        Self {
            weighting: Weighting::igg(),
            max_iter: 20,
            tol: 1e-7,
            scale_floor: 0.0,
            max_evals: 4000,
            refit_kept: true,
        }
    }
}

/// The fit of one direction.
#[derive(Debug, Clone, PartialEq)]
pub struct DirectionFit {
    /// Estimated Stribeck parameters (all positive, also for `v < 0`).
    pub set: StaticSet<f64>,
    /// Standard errors of `fc, fs, sigma2, vs` (NaN when they cannot be computed).
    pub std_err: Vec<f64>,
    /// Lower ends of the 95 % intervals of `fc, fs, sigma2, vs`.
    pub ci_low: Vec<f64>,
    /// Upper ends of the 95 % intervals.
    pub ci_high: Vec<f64>,
    /// Indices (into the input) of this direction's points.
    pub indices: Vec<usize>,
    /// Final IRLS weight of each of these points (0 = rejected).
    pub weights: Vec<f64>,
    /// Residual `F - F_model` of each of these points [N] (input sign convention).
    pub residuals: Vec<f64>,
    /// Robust scale `1.4826*MAD` of the residuals at the optimum [N].
    pub scale: f64,
    /// Weighted residual standard deviation used for the covariance [N].
    pub sigma: f64,
    /// IRLS iterations.
    pub iterations: usize,
    /// True when the weights or the parameters settled before `max_iter`.
    pub converged: bool,
    /// Objective evaluations.
    pub evaluations: usize,
}

/// Result of [`fit_static`].
#[derive(Debug, Clone, PartialEq)]
pub struct StaticFit {
    /// Fit of the `v > 0` points.
    pub positive: DirectionFit,
    /// Fit of the `v < 0` points.
    pub negative: DirectionFit,
    /// Final weight of every input point (0 for rejected and for zero-speed points).
    pub weights: Vec<f64>,
    /// Indices of the rejected points (weight 0, zero speeds not included).
    pub rejected: Vec<usize>,
    /// Number of zero-speed points ignored.
    pub n_zero_speed: usize,
    /// Name of the weight function.
    pub weighting: String,
    /// Warnings (iteration limit, ill-determined parameters, ...).
    pub notes: Vec<String>,
}

/// `g(a) + sigma2*a` for a speed magnitude `a`.
#[inline]
fn curve(p: &[f64; 4], a: f64) -> f64 {
    let r = a / p[3];
    p[0] + (p[1] - p[0]) * (-(r * r)).exp() + p[2] * a
}

fn to_params(th: &[f64]) -> [f64; 4] {
    let fc = th[0].exp();
    [fc, fc + th[1].exp(), th[2].exp(), th[3].exp()]
}

/// Weighted linear least squares of `y = fc*(1 - phi) + fs*phi + s2*a` for fixed `vs`.
fn linear_fit(a: &[f64], y: &[f64], w: &[f64], vs: f64) -> Option<Vector3<f64>> {
    linear_fit_rows(&design(a, vs), y, w)
}

/// Rows `(1 - phi, phi, a)` of the linear problem for fixed `vs`.
fn design(a: &[f64], vs: f64) -> Vec<Vector3<f64>> {
    a.iter()
        .map(|&ai| {
            let phi = (-(ai / vs).powi(2)).exp();
            Vector3::new(1.0 - phi, phi, ai)
        })
        .collect()
}

/// Weighted linear least squares on precomputed rows.
fn linear_fit_rows(rows: &[Vector3<f64>], y: &[f64], w: &[f64]) -> Option<Vector3<f64>> {
    let mut ata = Matrix3::zeros();
    let mut aty = Vector3::zeros();
    for ((row, &yi), &wi) in rows.iter().zip(y).zip(w) {
        if wi == 0.0 {
            continue;
        }
        ata += wi * row * row.transpose();
        aty += wi * yi * row;
    }
    // scale the columns to make the solve well conditioned
    let d = Vector3::new(
        ata[(0, 0)].sqrt().max(1e-300),
        ata[(1, 1)].sqrt().max(1e-300),
        ata[(2, 2)].sqrt().max(1e-300),
    );
    let dm = Matrix3::from_diagonal(&d.map(|x| 1.0 / x));
    let m = dm * ata * dm;
    let sol = m.try_inverse()? * (dm * aty);
    let x = dm * sol;
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Least trimmed squares of `y = fc*(1 - phi) + fs*phi + s2*a` for fixed `vs`: the
/// three coefficients minimising the sum of the `h` smallest squared residuals,
/// by concentration steps (Rousseeuw and Van Driessen 2006) from elemental starts.
/// Returns the coefficients and that trimmed sum.
fn lts_linear(
    a: &[f64],
    y: &[f64],
    vs: f64,
    h: usize,
    seeds: &[[usize; 3]],
) -> Option<(Vector3<f64>, f64)> {
    let n = a.len();
    let rows = design(a, vs);
    let mut w = vec![0.0; n];
    let mut r2 = vec![0.0; n];
    let mut order: Vec<usize> = (0..n).collect();
    // one concentration step: keep the h points nearest to the curve of x, refit
    let mut cstep = |x: &Vector3<f64>, w: &mut Vec<f64>| -> Option<(Vector3<f64>, f64)> {
        for i in 0..n {
            let e = y[i] - rows[i].dot(x);
            r2[i] = e * e;
        }
        order.sort_unstable_by(|&p, &q| r2[p].total_cmp(&r2[q]));
        let before: f64 = order[..h].iter().map(|&i| r2[i]).sum();
        w.iter_mut().for_each(|v| *v = 0.0);
        for &i in &order[..h] {
            w[i] = 1.0;
        }
        Some((linear_fit_rows(&rows, y, w)?, before))
    };
    let trimmed = |x: &Vector3<f64>| -> f64 {
        let mut e: Vec<f64> = (0..n).map(|i| (y[i] - rows[i].dot(x)).powi(2)).collect();
        e.sort_unstable_by(|p, q| p.total_cmp(q));
        e[..h].iter().sum()
    };
    let mut cands: Vec<(f64, Vector3<f64>)> = Vec::new();
    // the plain least-squares fit and elemental fits through three points, two
    // concentration steps each
    let mut starts = Vec::with_capacity(seeds.len() + 1);
    starts.push(linear_fit_rows(&rows, y, &vec![1.0; n]));
    for sd in seeds {
        w.iter_mut().for_each(|v| *v = 0.0);
        for &i in sd {
            w[i] = 1.0;
        }
        starts.push(linear_fit_rows(&rows, y, &w));
    }
    for x0 in starts.into_iter().flatten() {
        let mut x = x0;
        for _ in 0..2 {
            match cstep(&x, &mut w) {
                Some((xn, _)) => x = xn,
                None => break,
            }
        }
        let obj = trimmed(&x);
        if obj.is_finite() {
            cands.push((obj, x));
        }
    }
    cands.sort_by(|p, q| p.0.total_cmp(&q.0));
    // the best few to convergence
    let mut best: Option<(Vector3<f64>, f64)> = None;
    for (_, x0) in cands.into_iter().take(4) {
        let mut x = x0;
        let mut obj = trimmed(&x);
        for _ in 0..20 {
            let Some((xn, _)) = cstep(&x, &mut w) else {
                break;
            };
            let on = trimmed(&xn);
            if on.is_nan() || on >= obj * (1.0 - 1e-12) {
                if on <= obj {
                    x = xn;
                    obj = on;
                }
                break;
            }
            x = xn;
            obj = on;
        }
        if best.as_ref().is_none_or(|b| obj < b.1) {
            best = Some((x, obj));
        }
    }
    best
}

/// Elemental subsets (three distinct indices below `n`) from a fixed-seed generator,
/// so that fits are reproducible.
fn elemental_seeds(n: usize, count: usize) -> Vec<[usize; 3]> {
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut next = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) % n as u64) as usize
    };
    let mut out = Vec::with_capacity(count);
    while out.len() < count && n >= 3 {
        let (i, j, k) = (next(), next(), next());
        if i != j && j != k && i != k {
            out.push([i, j, k]);
        }
    }
    out
}

/// Start values `(fc, fs, sigma2, vs)` from the `ln vs` grid (Huber).
///
/// At each node a Huber IRLS linear fit, scored by the median absolute residual.
fn start_values_huber(a: &[f64], y: &[f64]) -> [f64; 4] {
    let amin = a.iter().copied().fold(f64::INFINITY, f64::min);
    let amax = a.iter().copied().fold(0.0, f64::max);
    let fscale = median(&y.iter().map(|v| v.abs()).collect::<Vec<_>>()).max(1e-12);
    let huber = Weighting::huber();
    let mut best: Option<(f64, [f64; 4])> = None;
    let ngrid = 41;
    let (lo, hi) = ((amin * 0.5).ln(), (amax * 2.0).ln());
    for k in 0..ngrid {
        let vs = (lo + (hi - lo) * k as f64 / (ngrid - 1) as f64).exp();
        let mut w = vec![1.0; a.len()];
        let mut x = match linear_fit(a, y, &w, vs) {
            Some(x) => x,
            None => continue,
        };
        for _ in 0..10 {
            let e: Vec<f64> = a
                .iter()
                .zip(y)
                .map(|(&ai, &yi)| yi - curve(&[x[0], x[1], x[2], vs], ai))
                .collect();
            let s = robust_scale(&e).max(1e-12 * fscale);
            w = huber.weights(&e, s);
            match linear_fit(a, y, &w, vs) {
                Some(xn) => x = xn,
                None => break,
            }
        }
        let p = [x[0], x[1], x[2], vs];
        let score = median(
            &a.iter()
                .zip(y)
                .map(|(&ai, &yi)| (yi - curve(&p, ai)).abs())
                .collect::<Vec<_>>(),
        );
        if score.is_finite() && best.is_none_or(|(b, _)| score < b) {
            best = Some((score, p));
        }
    }
    let mut p = best
        .map(|b| b.1)
        .unwrap_or([fscale, 1.5 * fscale, 0.0, amax]);
    // keep inside the parametrisation (all positive, fs > fc)
    p[0] = p[0].max(1e-3 * fscale);
    p[1] = p[1].max(p[0] * 1.01 + 1e-6 * fscale);
    p[2] = p[2].max(1e-6 * fscale / amax.max(1e-300));
    p[3] = p[3].clamp(amin * 0.5, amax * 2.0);
    p
}

/// Start values `(fc, fs, sigma2, vs)` from the `ln vs` grid (least trimmed squares).
///
/// At each node the curve is linear in `(fc, fs, sigma2)`; a least-trimmed-squares
/// fit there (on three quarters of the points) resists gross errors also at the ends of
/// the speed range, where a single point has high leverage on `sigma2` and `fc` and
/// a monotone M-estimate (Huber) follows it. The node with the smallest trimmed sum
/// gives the start: the high-breakdown first stage of an MM-estimate (Yohai 1987).
fn start_values_lts(a: &[f64], y: &[f64]) -> [f64; 4] {
    let amin = a.iter().copied().fold(f64::INFINITY, f64::min);
    let amax = a.iter().copied().fold(0.0, f64::max);
    let fscale = median(&y.iter().map(|v| v.abs()).collect::<Vec<_>>()).max(1e-12);
    let n = a.len();
    let h = (3 * n).div_ceil(4).min(n);
    let seeds = elemental_seeds(n, 30);
    let mut best: Option<(f64, [f64; 4])> = None;
    let ngrid = 41;
    let (lo, hi) = ((amin * 0.5).ln(), (amax * 2.0).ln());
    for k in 0..ngrid {
        let vs = (lo + (hi - lo) * k as f64 / (ngrid - 1) as f64).exp();
        let Some((x, score)) = lts_linear(a, y, vs, h, &seeds) else {
            continue;
        };
        let p = [x[0], x[1], x[2], vs];
        if score.is_finite() && best.is_none_or(|(b, _)| score < b) {
            best = Some((score, p));
        }
    }
    let mut p = best
        .map(|b| b.1)
        .unwrap_or([fscale, 1.5 * fscale, 0.0, amax]);
    // keep inside the parametrisation (all positive, fs > fc)
    p[0] = p[0].max(1e-3 * fscale);
    p[1] = p[1].max(p[0] * 1.01 + 1e-6 * fscale);
    p[2] = p[2].max(1e-6 * fscale / amax.max(1e-300));
    p[3] = p[3].clamp(amin * 0.5, amax * 2.0);
    p
}

/// Least squares on the points IRLS kept, re-checking the rejections (`|e| > k1*s`,
/// `s` the robust scale of all residuals at the refit) until the kept set settles.
fn refit_kept(
    resid: &dyn Fn(&[f64]) -> Option<Vec<f64>>,
    objective: &dyn Fn(&[f64], &[f64]) -> f64,
    out: &mut IrlsOutcome,
    k1: f64,
    setup: &IrlsSetup,
) {
    let mut keep: Vec<f64> = out
        .weights
        .iter()
        .map(|w| if *w > 0.0 { 1.0 } else { 0.0 })
        .collect();
    let step: Vec<f64> = setup.step.iter().map(|s| 0.1 * s).collect();
    for _ in 0..5 {
        if keep.iter().sum::<f64>() < MIN_POINTS_PER_DIRECTION as f64 {
            return;
        }
        let mut f = |th: &[f64]| match resid(th) {
            Some(r) => objective(&r, &keep),
            None => f64::INFINITY,
        };
        let r = minimize(&mut f, &out.theta, &step, &setup.nm);
        out.evals += r.evals + 1;
        let Some(e) = resid(&r.x) else {
            return;
        };
        // scale of the kept points (n_kept - 4 degrees of freedom), made consistent for
        // a Gaussian truncated at +-k1: more efficient than the MAD of all residuals,
        // whose noise in a small sample moves the rejection threshold
        let n_kept = keep.iter().sum::<f64>();
        let ss: f64 = e.iter().zip(&keep).map(|(ei, wi)| wi * ei * ei).sum();
        let phi = (-0.5 * k1 * k1).exp() / (2.0 * std::f64::consts::PI).sqrt();
        let var_factor = 1.0 - 2.0 * k1 * phi / libm::erf(k1 / std::f64::consts::SQRT_2);
        let s = (ss / (n_kept - 4.0) / var_factor)
            .sqrt()
            .max(setup.scale_floor);
        let new_keep: Vec<f64> = e
            .iter()
            .map(|ei| if ei.abs() <= k1 * s { 1.0 } else { 0.0 })
            .collect();
        out.theta = r.x;
        out.residuals = e;
        out.scale = s;
        out.weights = keep.clone();
        if new_keep == keep {
            return;
        }
        keep = new_keep;
    }
}

/// Fit one direction to magnitudes `a = |v|` and mirrored forces `y = sign(v)*F`.
fn fit_direction(
    a: &[f64],
    y: &[f64],
    sign: f64,
    indices: Vec<usize>,
    opts: &StaticFitOptions,
    notes: &mut Vec<String>,
    label: &str,
) -> Result<DirectionFit> {
    let to_theta = |p: [f64; 4]| vec![p[0].ln(), (p[1] - p[0]).ln(), p[2].ln(), p[3].ln()];
    let resid = |th: &[f64]| -> Option<Vec<f64>> {
        let p = to_params(th);
        if !p.iter().all(|v| v.is_finite() && *v > 0.0) {
            return None;
        }
        Some(
            a.iter()
                .zip(y)
                .map(|(&ai, &yi)| yi - curve(&p, ai))
                .collect(),
        )
    };
    let objective = |e: &[f64], w: &[f64]| e.iter().zip(w).map(|(ei, wi)| wi * ei * ei).sum();
    let step = [0.1, 0.3, 0.1, 0.3];
    let setup = IrlsSetup {
        weighting: opts.weighting,
        max_outer: opts.max_iter,
        tol: opts.tol,
        scale_floor: opts
            .scale_floor
            .max(1e-6 * median(&y.iter().map(|v| v.abs()).collect::<Vec<_>>())),
        nm: NmOptions {
            max_evals: opts.max_evals,
            xtol: 1e-10,
            ftol: 1e-14,
            restarts: 1,
        },
        step: &step,
    };
    let reject_at = match opts.weighting {
        Weighting::Igg { k1, .. } => Some(k1),
        Weighting::Tukey { c } => Some(c),
        _ => None,
    };
    // One path: from a start, an optional IRLS pass with another weight function,
    // IRLS, then (rejecting weight functions) the least-squares refit on the kept points.
    let path = |p0: [f64; 4], pre: Option<Weighting>| -> Option<IrlsOutcome> {
        let mut theta0 = to_theta(p0);
        let mut evals = 0;
        if let Some(w) = pre {
            let pre = IrlsSetup {
                weighting: w,
                ..setup
            };
            if let Some(o) = irls(&resid, &objective, theta0.clone(), &pre) {
                theta0 = o.theta;
                evals = o.evals;
            }
        }
        let mut out = irls(&resid, &objective, theta0, &setup)?;
        out.evals += evals;
        if let (true, Some(k1)) = (opts.refit_kept, reject_at) {
            refit_kept(&resid, &objective, &mut out, k1, &setup);
        }
        Some(out)
    };
    let out = if reject_at.is_some() {
        // Redescending weights (IGG, Tukey) settle on the set of rejected points near
        // their start. Two starts, as in MM-estimation (Yohai 1987): (a) a Huber pass
        // (monotone, unique fixed point) from the Huber grid; (b) a Tukey pass from the
        // least-trimmed-squares grid, which also resists gross errors of high leverage
        // (the fastest and slowest points) that a Huber fit follows. The fit with the
        // smaller bounded (Tukey) loss at a common scale wins, as in the choice among
        // local minima of an MM-estimate.
        let a_fit = path(start_values_huber(a, y), Some(Weighting::huber()));
        let b_fit = path(start_values_lts(a, y), Some(Weighting::tukey()));
        match (a_fit, b_fit) {
            (Some(fa), Some(fb)) => {
                // Tukey's rho at a common scale (the smaller robust scale of the two):
                // a rejected point costs the same in both, a kept one its misfit
                let s = robust_scale(&fa.residuals)
                    .min(robust_scale(&fb.residuals))
                    .max(setup.scale_floor);
                let c = 4.685;
                let rho = |o: &IrlsOutcome| -> f64 {
                    o.residuals
                        .iter()
                        .map(|e| {
                            let u = (e / (c * s)).abs().min(1.0);
                            1.0 - (1.0 - u * u).powi(3)
                        })
                        .sum()
                };
                let evals = fa.evals + fb.evals;
                let mut best = if rho(&fb) < rho(&fa) { fb } else { fa };
                best.evals = evals;
                Some(best)
            }
            (fa, fb) => fa.or(fb),
        }
    } else {
        path(start_values_huber(a, y), None)
    };
    let out = out.ok_or_else(|| {
        Error::Data(format!(
            "{label} direction: the Stribeck curve could not be evaluated at the start values; check the data for extreme values"
        ))
    })?;
    let p = to_params(&out.theta);
    // covariance from the weighted Jacobian at the optimum
    let n = a.len();
    let mut j = DMatrix::<f64>::zeros(n, 4);
    for (i, &ai) in a.iter().enumerate() {
        let phi = (-(ai / p[3]).powi(2)).exp();
        j[(i, 0)] = 1.0 - phi;
        j[(i, 1)] = phi;
        j[(i, 2)] = ai;
        j[(i, 3)] = (p[1] - p[0]) * phi * 2.0 * ai * ai / (p[3] * p[3] * p[3]);
    }
    let wv = DVector::from_vec(out.weights.clone());
    let n_used = out.weights.iter().filter(|w| **w > 0.0).count();
    let dof = n_used as f64 - 4.0;
    let ssq: f64 = out
        .residuals
        .iter()
        .zip(&out.weights)
        .map(|(e, w)| w * e * e)
        .sum();
    let sigma = if dof > 0.0 {
        (ssq / dof).sqrt()
    } else {
        f64::NAN
    };
    let mut jtwj = DMatrix::<f64>::zeros(4, 4);
    for i in 0..n {
        let r = j.row(i);
        jtwj += wv[i] * r.transpose() * r;
    }
    let d: Vec<f64> = (0..4).map(|k| jtwj[(k, k)].sqrt()).collect();
    let mut std_err = vec![f64::NAN; 4];
    if d.iter().all(|x| *x > 0.0 && x.is_finite()) && sigma.is_finite() {
        let dm = DMatrix::from_diagonal(&DVector::from_iterator(4, d.iter().map(|x| 1.0 / x)));
        let m = &dm * &jtwj * &dm;
        if let Some(inv) = m.try_inverse() {
            let cov = &dm * inv * &dm * (sigma * sigma);
            for (k, se) in std_err.iter_mut().enumerate() {
                let v = cov[(k, k)];
                if v >= 0.0 {
                    *se = v.sqrt();
                }
            }
        }
    }
    if std_err.iter().any(|s| s.is_nan()) {
        notes.push(format!(
            "{label} direction: standard errors unavailable ({n_used} points kept for 4 parameters, or a singular Jacobian); add speeds around the Stribeck velocity"
        ));
    }
    let tq = t_quantile_975(dof);
    let ci_low: Vec<f64> = p.iter().zip(&std_err).map(|(v, s)| v - tq * s).collect();
    let ci_high: Vec<f64> = p.iter().zip(&std_err).map(|(v, s)| v + tq * s).collect();
    for (k, name) in STATIC_PARAM_NAMES.iter().enumerate() {
        let rel = std_err[k] / p[k];
        if rel > 0.25 {
            notes.push(format!(
                "{label} direction: {name} is poorly determined (standard error {:.0} % of the estimate); add constant-velocity points where it acts (around vs for fs and vs, at high speed for sigma2)",
                rel * 100.0
            ));
        }
    }
    if !out.converged {
        notes.push(format!(
            "{label} direction: IRLS stopped at the iteration limit ({}) before the weights settled",
            out.iterations
        ));
    }
    Ok(DirectionFit {
        set: StaticSet {
            fc: p[0],
            fs: p[1],
            sigma2: p[2],
            vs: p[3],
        },
        std_err,
        ci_low,
        ci_high,
        indices,
        weights: out.weights,
        residuals: out.residuals.iter().map(|e| sign * e).collect(),
        scale: out.scale,
        sigma,
        iterations: out.iterations,
        converged: out.converged,
        evaluations: out.evals,
    })
}

/// Fit the Stribeck curve of each direction to steady-state points `(v, F)`.
///
/// `F` is the force needed to move at constant speed `v` (the motor force, `K_F*i`);
/// it is negative for `v < 0`. Zero speeds are ignored (and counted). Each direction
/// needs at least [`MIN_POINTS_PER_DIRECTION`] points.
///
/// ```
/// use lugre::estimate::{fit_static, StaticFitOptions};
/// use lugre::friction::StaticSet;
/// let truth = StaticSet::new(28.7, 60.2, 332.5, 0.01).unwrap();
/// let v: Vec<f64> = (0..12)
///     .map(|k| 2e-4 * (2000.0f64).powf(k as f64 / 11.0))
///     .flat_map(|s| [s, -s])
///     .collect();
/// let f: Vec<f64> = v.iter().map(|&s| truth.stribeck(s)).collect();
/// let fit = fit_static(&v, &f, &StaticFitOptions::default()).unwrap();
/// assert!((fit.positive.set.fs - 60.2).abs() < 1e-3);
/// assert!((fit.negative.set.vs - 0.01).abs() < 1e-6);
/// ```
pub fn fit_static(v: &[f64], f: &[f64], opts: &StaticFitOptions) -> Result<StaticFit> {
    check_len("f", f, v.len(), "v")?;
    if v.is_empty() {
        return Err(Error::input(
            "v",
            "is empty: give steady-state (v, F) points",
        ));
    }
    check_finite("v", v)?;
    check_finite("f", f)?;
    opts.weighting.validate()?;
    if !(opts.scale_floor >= 0.0 && opts.scale_floor.is_finite()) {
        return Err(Error::parameter(
            "scale_floor",
            opts.scale_floor,
            "must be finite and zero or greater",
        ));
    }
    let n_zero = v.iter().filter(|x| **x == 0.0).count();
    if n_zero == v.len() {
        return Err(Error::Data(
            "every speed is zero: the Stribeck curve needs constant-velocity points in both directions".into(),
        ));
    }
    let split = |pos: bool| -> (Vec<f64>, Vec<f64>, Vec<usize>) {
        let mut a = Vec::new();
        let mut y = Vec::new();
        let mut idx = Vec::new();
        for (k, (&vk, &fk)) in v.iter().zip(f).enumerate() {
            if (pos && vk > 0.0) || (!pos && vk < 0.0) {
                a.push(vk.abs());
                y.push(if pos { fk } else { -fk });
                idx.push(k);
            }
        }
        (a, y, idx)
    };
    let (ap, yp, ip) = split(true);
    let (an, yn, in_) = split(false);
    if ap.is_empty() || an.is_empty() {
        let (have, miss) = if ap.is_empty() {
            ("v < 0", "v > 0")
        } else {
            ("v > 0", "v < 0")
        };
        return Err(Error::Data(format!(
            "only one direction of motion in the data ({have}): add constant-velocity points with {miss}, each direction has its own friction parameters"
        )));
    }
    for (label, a) in [("v > 0", &ap), ("v < 0", &an)] {
        if a.len() < MIN_POINTS_PER_DIRECTION {
            return Err(Error::Data(format!(
                "{} points with {label}: at least {MIN_POINTS_PER_DIRECTION} are needed for the 4 Stribeck parameters; add constant-velocity runs in that direction",
                a.len()
            )));
        }
    }
    let mut notes = Vec::new();
    let pos = fit_direction(&ap, &yp, 1.0, ip, opts, &mut notes, "positive")?;
    let neg = fit_direction(&an, &yn, -1.0, in_, opts, &mut notes, "negative")?;
    let mut weights = vec![0.0; v.len()];
    for d in [&pos, &neg] {
        for (&k, &w) in d.indices.iter().zip(&d.weights) {
            weights[k] = w;
        }
    }
    let mut rejected: Vec<usize> = (0..v.len())
        .filter(|&k| v[k] != 0.0 && weights[k] == 0.0)
        .collect();
    rejected.sort_unstable();
    Ok(StaticFit {
        positive: pos,
        negative: neg,
        weights,
        rejected,
        n_zero_speed: n_zero,
        weighting: opts.weighting.name().to_string(),
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn data_errors() {
        let o = StaticFitOptions::default();
        let e = fit_static(&[0.0, 0.0], &[1.0, 2.0], &o).unwrap_err();
        assert!(matches!(e, Error::Data(_)), "{e}");
        let v = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6];
        let e = fit_static(&v, &v, &o).unwrap_err();
        assert!(e.to_string().contains("one direction"), "{e}");
        let v = [0.1, 0.2, 0.3, 0.4, 0.5, -0.6];
        let e = fit_static(&v, &v, &o).unwrap_err();
        assert!(e.to_string().contains("1 points with v < 0"), "{e}");
        let e = fit_static(&[0.1], &[1.0, 2.0], &o).unwrap_err();
        assert!(matches!(e, Error::Input { .. }));
        let e = fit_static(&[0.1, f64::NAN], &[1.0, 2.0], &o).unwrap_err();
        assert!(matches!(e, Error::Input { .. }));
    }

    #[test]
    fn exact_curve_recovered_with_zero_speeds() {
        let tp = StaticSet::new(10.0, 15.0, 50.0, 0.02).unwrap();
        let tn = StaticSet::new(12.0, 14.0, 40.0, 0.05).unwrap();
        let mut v = vec![0.0];
        let mut f = vec![0.3];
        for k in 0..15 {
            let s = 1e-3 * 500f64.powf(k as f64 / 14.0);
            v.push(s);
            f.push(tp.stribeck(s));
            v.push(-s);
            f.push(tn.stribeck(-s));
        }
        let fit = fit_static(&v, &f, &StaticFitOptions::default()).unwrap();
        assert_eq!(fit.n_zero_speed, 1);
        assert_eq!(fit.weights[0], 0.0);
        assert!(fit.rejected.is_empty(), "{:?}", fit.rejected);
        let p = fit.positive.set;
        let n = fit.negative.set;
        assert!(
            (p.fc - 10.0).abs() < 1e-4 && (p.vs - 0.02).abs() < 1e-7,
            "{p:?}"
        );
        assert!(
            (n.fs - 14.0).abs() < 1e-4 && (n.sigma2 - 40.0).abs() < 1e-3,
            "{n:?}"
        );
        assert!(fit.negative.residuals.iter().all(|e| e.abs() < 1e-5));
    }
}
