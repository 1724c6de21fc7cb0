//! IRLS over the variable-projection profile (the paper's eqs. 19-24) and the
//! least-squares refit of the points it kept.

use super::super::nelder_mead::NmOptions;
use super::super::robust::{robust_scale, Weighting};
use super::varpro::{vp_minimize, Sep};
use super::MIN_POINTS_PER_DIRECTION;

/// Outcome of one IRLS path.
pub(super) struct Outcome {
    pub(super) p: [f64; 4],
    pub(super) residuals: Vec<f64>,
    pub(super) weights: Vec<f64>,
    pub(super) scale: f64,
    pub(super) iterations: usize,
    pub(super) converged: bool,
    pub(super) evals: usize,
}

/// Role of an IRLS run.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Stage {
    /// A pass that only provides the start of the next one: weights settled to 1e-2.
    Pre,
    /// Followed by the least-squares refit of the kept points.
    Refit,
    /// The result: the last weighted problem is solved again to full precision.
    Polish,
}

/// Settings shared by the IRLS runs of one direction.
pub(super) struct Cfg {
    pub(super) max_outer: usize,
    pub(super) tol: f64,
    pub(super) scale_floor: f64,
    pub(super) nm: NmOptions,
    /// Looser simplex tolerance of the IRLS rounds (whose weights change again).
    pub(super) nm_loose: NmOptions,
    /// Loosest tolerance, for the passes that only give the start of the next.
    pub(super) nm_pre: NmOptions,
    /// Added to the profile objective (see [`vp_minimize`]).
    pub(super) obj_floor: f64,
}

/// Largest relative change between two parameter vectors.
pub(super) fn max_rel_change(p: &[f64; 4], q: &[f64; 4]) -> f64 {
    p.iter()
        .zip(q)
        .map(|(a, b)| (a - b).abs() / a.abs().max(b.abs()).max(1e-300))
        .fold(0.0, f64::max)
}

/// IRLS (eqs. 19-24): weights from the residuals at the current parameters and their
/// robust scale (or the fixed scale `fixed`, the M-step of an MM-estimate), then the weighted profile minimised over `ln vs`, until the weights
/// or the parameters settle.
pub(super) fn irls_vp(
    sep: &mut Sep,
    p0: [f64; 4],
    weighting: Weighting,
    cfg: &Cfg,
    stage: Stage,
    fixed: Option<f64>,
) -> Outcome {
    let mut p = p0;
    let mut e = sep.residuals(&p);
    let scale_of = |e: &[f64]| {
        fixed
            .unwrap_or_else(|| robust_scale(e))
            .max(cfg.scale_floor)
    };
    let mut s = scale_of(&e);
    let mut w = weighting.weights(&e, s);
    let mut evals = 1;
    let mut converged = false;
    let mut iterations = 0;
    let mut step = 0.3;
    while iterations < cfg.max_outer.max(1) {
        iterations += 1;
        let nm = if stage == Stage::Pre {
            &cfg.nm_pre
        } else {
            &cfg.nm_loose
        };
        let (pn, ev) = vp_minimize(sep, &w, p[3].ln(), step, nm, cfg.obj_floor);
        evals += ev;
        let dtheta = max_rel_change(&p, &pn);
        let d_ln_vs = (pn[3] / p[3]).ln().abs();
        p = pn;
        e = sep.residuals(&p);
        s = scale_of(&e);
        let w_new = weighting.weights(&e, s);
        let (dw, dw_sum) = w_new
            .iter()
            .zip(&w)
            .map(|(a, b)| (a - b).abs())
            .fold((0.0f64, 0.0), |(m, t), d| (m.max(d), t + d));
        let dw_mean = dw_sum / w.len().max(1) as f64;
        w = w_new;
        let dw_tol = if stage == Stage::Pre { 1e-2 } else { 1e-3 };
        if dw <= dw_tol || dw_mean <= 1e-5 || dtheta <= cfg.tol {
            converged = true;
            break;
        }
        // later rounds start close to the answer: a simplex of a few times the last
        // move (the simplex expands if that is too small)
        step = (3.0 * d_ln_vs).clamp(1e-3, 0.1);
    }
    if stage == Stage::Polish {
        // the weighted problem of the final weights to full precision
        let (pn, ev) = vp_minimize(sep, &w, p[3].ln(), 1e-3, &cfg.nm, cfg.obj_floor);
        evals += ev;
        p = pn;
        e = sep.residuals(&p);
        s = scale_of(&e);
    }
    Outcome {
        p,
        residuals: e,
        weights: w,
        scale: s,
        iterations,
        converged,
        evals,
    }
}

/// Smallest rejection threshold of the refit, in units of the residual scale: the
/// rejection point of Tukey's bisquare at 95 % efficiency. The IGG band (2.5), applied
/// again to the least-squares residuals with a scale from a score of points, rejected
/// about 3 % of clean points in the Monte Carlo of the README (0.3 % at this bound) and
/// lost 4 % of efficiency; gross errors of tens of noise levels are rejected either way.
pub(super) const REFIT_REJECT_MIN: f64 = 4.685;

/// Least squares on the points IRLS kept, re-checking the rejections (`|e| > k1*s`,
/// `s` the scale of the kept residuals at the refit) until the kept set settles.
pub(super) fn refit_kept(sep: &mut Sep, out: &mut Outcome, k1: f64, cfg: &Cfg) {
    let mut keep: Vec<f64> = out
        .weights
        .iter()
        .map(|w| if *w > 0.0 { 1.0 } else { 0.0 })
        .collect();
    // a Gaussian truncated at +-k1 has this fraction of the unit variance
    let phi = (-0.5 * k1 * k1).exp() / (2.0 * std::f64::consts::PI).sqrt();
    let var_factor = 1.0 - 2.0 * k1 * phi / libm::erf(k1 / std::f64::consts::SQRT_2);
    for _ in 0..5 {
        let n_kept = keep.iter().sum::<f64>();
        if n_kept < MIN_POINTS_PER_DIRECTION as f64 {
            return;
        }
        let (p, ev) = vp_minimize(sep, &keep, out.p[3].ln(), 1e-3, &cfg.nm, cfg.obj_floor);
        out.evals += ev;
        let e = sep.residuals(&p);
        // scale of the kept points (n_kept - 4 degrees of freedom), made consistent for
        // a Gaussian truncated at +-k1: more efficient than the MAD of all residuals,
        // whose noise in a small sample moves the rejection threshold
        let ss: f64 = e.iter().zip(&keep).map(|(ei, wi)| wi * ei * ei).sum();
        let s = (ss / (n_kept - 4.0) / var_factor)
            .sqrt()
            .max(cfg.scale_floor);
        let new_keep: Vec<f64> = e
            .iter()
            .map(|ei| if ei.abs() <= k1 * s { 1.0 } else { 0.0 })
            .collect();
        out.p = p;
        out.residuals = e;
        out.scale = s;
        out.weights = keep.clone();
        if new_keep == keep {
            return;
        }
        keep = new_keep;
    }
}
