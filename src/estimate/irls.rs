//! The outer IRLS loop shared by the static and dynamic estimators.
//!
//! Outer iteration: residuals at the current parameters, robust scale, weights; inner:
//! Nelder-Mead on the weighted objective. Stops when the weights no longer change (none
//! by more than 1e-3, or 1e-5 on average for long records) or the parameters move by
//! less than `tol` (the estimators work in log-parameters, so this is a relative
//! change).

use super::nelder_mead::{minimize, NmOptions};
use super::robust::{robust_scale, Weighting};

pub(crate) struct IrlsSetup<'a> {
    pub weighting: Weighting,
    pub max_outer: usize,
    pub tol: f64,
    pub scale_floor: f64,
    pub nm: NmOptions,
    pub step: &'a [f64],
}

pub(crate) struct IrlsOutcome {
    pub theta: Vec<f64>,
    pub residuals: Vec<f64>,
    pub weights: Vec<f64>,
    pub scale: f64,
    pub iterations: usize,
    pub converged: bool,
    pub evals: usize,
}

/// `residuals(theta)` returns `None` where the model cannot be evaluated;
/// `objective(e, w)` is minimised with the weights held.
pub(crate) fn irls(
    residuals: &dyn Fn(&[f64]) -> Option<Vec<f64>>,
    objective: &dyn Fn(&[f64], &[f64]) -> f64,
    theta0: Vec<f64>,
    setup: &IrlsSetup,
) -> Option<IrlsOutcome> {
    let mut theta = theta0;
    let mut e = residuals(&theta)?;
    let mut evals = 1usize;
    let scale_of = |e: &[f64]| robust_scale(e).max(setup.scale_floor);
    let mut s = scale_of(&e);
    let mut w = setup.weighting.weights(&e, s);
    let mut converged = false;
    let mut iterations = 0usize;
    let mut step: Vec<f64> = setup.step.to_vec();
    while iterations < setup.max_outer.max(1) {
        iterations += 1;
        let wk = w.clone();
        let mut f = |th: &[f64]| match residuals(th) {
            Some(r) => objective(&r, &wk),
            None => f64::INFINITY,
        };
        let r = minimize(&mut f, &theta, &step, &setup.nm);
        evals += r.evals;
        let dtheta =
            r.x.iter()
                .zip(&theta)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0f64, f64::max);
        theta = r.x;
        e = residuals(&theta)?;
        evals += 1;
        s = scale_of(&e);
        let w_new = setup.weighting.weights(&e, s);
        let dw = w_new
            .iter()
            .zip(&w)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f64, f64::max);
        let dw_mean = w_new
            .iter()
            .zip(&w)
            .map(|(a, b)| (a - b).abs())
            .sum::<f64>()
            / w.len().max(1) as f64;
        w = w_new;
        if dw <= 1e-3 || dw_mean <= 1e-5 || dtheta <= setup.tol {
            converged = true;
            break;
        }
        // later rounds start close to the answer: a smaller simplex saves evaluations
        for (sk, s0) in step.iter_mut().zip(setup.step) {
            *sk = s0 * 0.1;
        }
    }
    Some(IrlsOutcome {
        theta,
        residuals: e,
        weights: w,
        scale: s,
        iterations,
        converged,
        evals,
    })
}
