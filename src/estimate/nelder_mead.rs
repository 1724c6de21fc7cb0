//! Nelder-Mead simplex minimisation (the paper's "simplex method").
//!
//! A compact implementation with the dimension-adaptive coefficients of Gao and Han
//! (Comput. Optim. Appl. 51, 2012), which keep the method effective beyond two or
//! three parameters, and one restart from the best point (a collapsed simplex is the
//! classic failure of the method, McKinnon 1998). Non-finite objective values count as
//! `+inf`, so a parameter region where a simulation diverges is simply avoided.
//!
//! Kept in the crate rather than taken from `argmin` so that the IRLS loops can
//! warm-start it cheaply and so that the estimators do not depend on a solver
//! framework's trait bounds; the algorithm is the textbook one.

/// Stopping rules for [`minimize`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NmOptions {
    /// Maximum number of objective evaluations.
    pub max_evals: usize,
    /// Stop when every vertex is within `xtol` of the best one (max-norm, in the
    /// coordinates the objective takes).
    pub xtol: f64,
    /// ... and the objective values differ by at most `ftol*(|f_best| + ftol)`.
    pub ftol: f64,
    /// Restarts from the best point with the initial step (0 = none).
    pub restarts: usize,
}

impl Default for NmOptions {
    fn default() -> Self {
        Self {
            max_evals: 4000,
            xtol: 1e-9,
            ftol: 1e-12,
            restarts: 1,
        }
    }
}

/// Outcome of [`minimize`].
#[derive(Debug, Clone, PartialEq)]
pub struct NmResult {
    /// Best point.
    pub x: Vec<f64>,
    /// Objective at `x`.
    pub f: f64,
    /// Evaluations used.
    pub evals: usize,
    /// True when the tolerances were met before `max_evals`.
    pub converged: bool,
}

fn clean(v: f64) -> f64 {
    if v.is_nan() {
        f64::INFINITY
    } else {
        v
    }
}

/// Minimise `f` from `x0` with an initial simplex `x0 + step[k]*e_k`.
///
/// ```
/// use lugre::estimate::nelder_mead::{minimize, NmOptions};
/// let rosen = |x: &[f64]| (1.0 - x[0]).powi(2) + 100.0 * (x[1] - x[0] * x[0]).powi(2);
/// let r = minimize(&mut |x| rosen(x), &[-1.2, 1.0], &[0.5, 0.5], &NmOptions::default());
/// assert!((r.x[0] - 1.0).abs() < 1e-6 && (r.x[1] - 1.0).abs() < 1e-6);
/// ```
pub fn minimize(
    f: &mut dyn FnMut(&[f64]) -> f64,
    x0: &[f64],
    step: &[f64],
    opts: &NmOptions,
) -> NmResult {
    let n = x0.len();
    let mut evals = 0usize;
    let mut best_x = x0.to_vec();
    let mut best_f = clean(f(x0));
    evals += 1;
    if n == 0 {
        return NmResult {
            x: best_x,
            f: best_f,
            evals,
            converged: true,
        };
    }
    let mut converged = false;
    for round in 0..=opts.restarts {
        let (x, fx, e, conv) = run(
            f,
            &best_x,
            best_f,
            step,
            opts,
            opts.max_evals.saturating_sub(evals),
        );
        evals += e;
        let improved = fx < best_f;
        if fx <= best_f {
            best_x = x;
            best_f = fx;
        }
        converged = conv;
        if !conv || evals >= opts.max_evals || (round > 0 && !improved) {
            break;
        }
    }
    NmResult {
        x: best_x,
        f: best_f,
        evals,
        converged,
    }
}

fn run(
    f: &mut dyn FnMut(&[f64]) -> f64,
    x0: &[f64],
    f0: f64,
    step: &[f64],
    opts: &NmOptions,
    budget: usize,
) -> (Vec<f64>, f64, usize, bool) {
    let n = x0.len();
    let nf = n as f64;
    let (alpha, beta, gamma, delta) = if n >= 2 {
        (1.0, 1.0 + 2.0 / nf, 0.75 - 1.0 / (2.0 * nf), 1.0 - 1.0 / nf)
    } else {
        (1.0, 2.0, 0.5, 0.5)
    };
    let mut evals = 0usize;
    let mut sx: Vec<Vec<f64>> = Vec::with_capacity(n + 1);
    let mut sf: Vec<f64> = Vec::with_capacity(n + 1);
    sx.push(x0.to_vec());
    sf.push(f0);
    for k in 0..n {
        let mut x = x0.to_vec();
        let h = if step[k] != 0.0 && step[k].is_finite() {
            step[k]
        } else {
            0.05 * x0[k].abs().max(1e-3)
        };
        x[k] += h;
        sf.push(clean(f(&x)));
        evals += 1;
        sx.push(x);
    }
    let mut eval = |x: &[f64], evals: &mut usize| -> f64 {
        *evals += 1;
        clean(f(x))
    };
    let mut order: Vec<usize> = (0..=n).collect();
    let mut converged = false;
    loop {
        order.sort_by(|&a, &b| sf[a].total_cmp(&sf[b]));
        let (ib, iw, isw) = (order[0], order[n], order[n - 1]);
        // convergence
        let xspread = sx
            .iter()
            .flat_map(|x| x.iter().zip(&sx[ib]).map(|(a, b)| (a - b).abs()))
            .fold(0.0f64, f64::max);
        let fspread = (sf[iw] - sf[ib]).abs();
        let fdone = fspread <= opts.ftol * (sf[ib].abs() + opts.ftol);
        if (xspread <= opts.xtol && fdone) || xspread <= opts.xtol * 1e-3 {
            converged = true;
            break;
        }
        if evals >= budget {
            break;
        }
        // centroid of all but the worst
        let mut c = vec![0.0; n];
        for &i in &order[..n] {
            for (cj, xj) in c.iter_mut().zip(&sx[i]) {
                *cj += xj / nf;
            }
        }
        let along = |t: f64| -> Vec<f64> {
            c.iter()
                .zip(&sx[iw])
                .map(|(cj, wj)| cj + t * (cj - wj))
                .collect()
        };
        let xr = along(alpha);
        let fr = eval(&xr, &mut evals);
        if fr < sf[ib] {
            let xe = along(beta);
            let fe = eval(&xe, &mut evals);
            if fe < fr {
                sx[iw] = xe;
                sf[iw] = fe;
            } else {
                sx[iw] = xr;
                sf[iw] = fr;
            }
            continue;
        }
        if fr < sf[isw] {
            sx[iw] = xr;
            sf[iw] = fr;
            continue;
        }
        let (xc, fc) = if fr < sf[iw] {
            let xc = along(gamma);
            let fc = eval(&xc, &mut evals);
            (xc, fc)
        } else {
            let xc = along(-gamma);
            let fc = eval(&xc, &mut evals);
            (xc, fc)
        };
        if fc < sf[iw].min(fr) {
            sx[iw] = xc;
            sf[iw] = fc;
            continue;
        }
        // shrink towards the best vertex
        let xb = sx[ib].clone();
        for i in 0..=n {
            if i == ib {
                continue;
            }
            for (xj, bj) in sx[i].iter_mut().zip(&xb) {
                *xj = bj + delta * (*xj - bj);
            }
            sf[i] = eval(&sx[i], &mut evals);
        }
    }
    let ib = (0..=n)
        .min_by(|&a, &b| sf[a].total_cmp(&sf[b]))
        .unwrap_or(0);
    (sx[ib].clone(), sf[ib], evals, converged)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadratic_4d() {
        let mut f = |x: &[f64]| {
            x.iter()
                .enumerate()
                .map(|(k, v)| (k as f64 + 1.0) * (v - k as f64).powi(2))
                .sum::<f64>()
        };
        let r = minimize(&mut f, &[3.0; 4], &[0.5; 4], &NmOptions::default());
        assert!(r.converged);
        for (k, v) in r.x.iter().enumerate() {
            assert!((v - k as f64).abs() < 1e-6, "{:?}", r.x);
        }
    }

    #[test]
    fn nan_region_avoided() {
        let mut f = |x: &[f64]| {
            if x[0] < 0.0 {
                f64::NAN
            } else {
                (x[0] - 0.1).powi(2)
            }
        };
        let r = minimize(&mut f, &[1.0], &[0.5], &NmOptions::default());
        assert!((r.x[0] - 0.1).abs() < 1e-6);
    }
}
