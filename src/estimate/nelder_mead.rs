//! Nelder-Mead simplex minimisation (the paper's "simplex method"), by `argmin`.
//!
//! [`minimize`] runs [`argmin::solver::neldermead::NelderMead`] over `Vec<f64>` with
//! the interface the IRLS loops use: a closure, a start point and a step per
//! coordinate (the initial simplex is `x0` and `x0 + step[k]*e_k`), an evaluation
//! budget and restarts from the best point (a collapsed simplex is the classic failure
//! of the method, McKinnon 1998).
//!
//! Details of the adaptation:
//! - the expansion and shrink coefficients follow the dimension-adaptive choice of Gao
//!   and Han (Comput. Optim. Appl. 51, 2012), `1 + 2/n` and `1 - 1/n` for `n >= 2`,
//!   which keeps the method effective beyond two or three parameters (their contraction
//!   `0.75 - 1/(2n)` exceeds argmin's admissible `(0, 0.5]` for `n > 2` and stays 0.5);
//! - argmin stops when the standard deviation of the vertex costs falls below a
//!   tolerance; each run divides the objective by its value at the run's start point,
//!   so [`NmOptions::ftol`] is relative;
//! - non-finite objective values are mapped to a large finite cost, so a parameter
//!   region where a simulation diverges is avoided (argmin sorts the vertices by cost);
//! - evaluations are counted by the wrapper, which also keeps the best point seen and
//!   ends the run (an error returned to argmin) when the budget is spent.

use argmin::core::{
    CostFunction, Error as ArgminError, Executor, State, TerminationReason, TerminationStatus,
};
use argmin::solver::neldermead::NelderMead;
use std::cell::RefCell;

/// Stopping rules for [`minimize`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NmOptions {
    /// Maximum number of objective evaluations.
    pub max_evals: usize,
    /// Smallest simplex: a vertex is never placed closer than this to the start point
    /// of a run (`|step|` is raised to it), in the coordinates the objective takes.
    pub xtol: f64,
    /// Stop when the standard deviation of the vertex costs is below
    /// `ftol*|f(start of the run)|`.
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

/// Cost of a point where the objective is not finite (after normalisation; its square
/// still fits in an `f64`, argmin's stopping rule squares cost differences).
const BIG: f64 = 1e150;

fn clean(v: f64) -> f64 {
    if v.is_finite() {
        v
    } else {
        f64::INFINITY
    }
}

struct Tracker {
    evals: usize,
    budget: usize,
    best_x: Vec<f64>,
    best_f: f64,
}

/// The objective as [`minimize`] takes it.
type Closure<'a, 'f> = &'a mut (dyn FnMut(&[f64]) -> f64 + 'f);

/// The closure as an argmin problem: `cost` takes `&self`, hence the `RefCell`s.
struct Objective<'a, 'f> {
    f: RefCell<Closure<'a, 'f>>,
    track: &'a RefCell<Tracker>,
    /// Divisor of the objective in this run.
    norm: f64,
}

impl CostFunction for Objective<'_, '_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, x: &Vec<f64>) -> Result<f64, ArgminError> {
        let mut t = self.track.borrow_mut();
        if t.evals >= t.budget {
            return Err(ArgminError::msg("evaluation budget spent"));
        }
        t.evals += 1;
        let v = clean((self.f.borrow_mut())(x));
        if v < t.best_f {
            t.best_f = v;
            t.best_x.clone_from(x);
        }
        let c = v / self.norm;
        Ok(if c.is_finite() { c.min(BIG) } else { BIG })
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
    let f0 = clean(f(x0));
    let mut evals = 1usize;
    let mut best_x = x0.to_vec();
    let mut best_f = f0;
    if n == 0 {
        return NmResult {
            x: best_x,
            f: best_f,
            evals,
            converged: true,
        };
    }
    let steps: Vec<f64> = (0..n)
        .map(|k| {
            let h = step.get(k).copied().unwrap_or(0.0);
            let h = if h != 0.0 && h.is_finite() {
                h
            } else {
                0.05 * x0[k].abs().max(1e-3)
            };
            h.signum() * h.abs().max(opts.xtol)
        })
        .collect();
    let nf = n as f64;
    let (gamma, sigma) = if n >= 2 {
        (1.0 + 2.0 / nf, 1.0 - 1.0 / nf)
    } else {
        (2.0, 0.5)
    };
    let mut converged = false;
    for round in 0..=opts.restarts {
        // argmin evaluates the n + 1 vertices in its `init` and cannot be stopped there
        if evals + n + 1 > opts.max_evals {
            break;
        }
        let start_f = best_f;
        let mut simplex = Vec::with_capacity(n + 1);
        simplex.push(best_x.clone());
        for (k, h) in steps.iter().enumerate() {
            let mut x = best_x.clone();
            x[k] += h;
            simplex.push(x);
        }
        let norm = if start_f.is_finite() && start_f != 0.0 {
            start_f.abs()
        } else {
            1.0
        };
        let track = RefCell::new(Tracker {
            evals: 0,
            budget: opts.max_evals - evals,
            best_x: best_x.clone(),
            best_f,
        });
        let problem = Objective {
            f: RefCell::new(&mut *f),
            track: &track,
            norm,
        };
        let solver = NelderMead::new(simplex)
            .with_gamma(gamma)
            .and_then(|s| s.with_sigma(sigma))
            .and_then(|s| s.with_sd_tolerance(opts.ftol.max(0.0)))
            .expect("valid Nelder-Mead coefficients");
        let max_iters = opts.max_evals as u64;
        // an error is the spent budget (the only error the objective returns)
        let conv = Executor::new(problem, solver)
            .configure(|s| s.max_iters(max_iters))
            .run()
            .is_ok_and(|res| {
                matches!(
                    res.state().get_termination_status(),
                    TerminationStatus::Terminated(TerminationReason::SolverConverged)
                )
            });
        let track = track.into_inner();
        evals += track.evals;
        let improved = track.best_f < start_f;
        if track.best_f <= best_f {
            best_x = track.best_x;
            best_f = track.best_f;
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

    #[test]
    fn budget_respected() {
        let mut n = 0usize;
        let mut f = |x: &[f64]| {
            n += 1;
            (1.0 - x[0]).powi(2) + 100.0 * (x[1] - x[0] * x[0]).powi(2)
        };
        let o = NmOptions {
            max_evals: 50,
            ..Default::default()
        };
        let r = minimize(&mut f, &[-1.2, 1.0], &[0.5, 0.5], &o);
        assert!(!r.converged);
        assert_eq!(r.evals, n);
        assert!(r.evals <= 50);
        assert!(r.f < 24.2, "{r:?}");
    }
}
