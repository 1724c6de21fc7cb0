//! The uncertainty of a dynamic fit: intervals from the weighted Jacobian of the position
//! residuals, inflated for their serial correlation, and the fit's verdicts in words.

use super::DynamicFitOptions;
use crate::estimate::irls::IrlsOutcome;
use crate::servo::Model;

/// Lag-one autocorrelation of the kept residuals (weights `w > 0`), in `[0, 0.999]`.
pub(super) fn lag_one_autocorrelation(e: &[f64], w: &[f64]) -> f64 {
    let mut num = 0.0;
    let mut den = 0.0;
    for k in 0..e.len() {
        if w[k] > 0.0 {
            den += w[k] * e[k] * e[k];
            if k + 1 < e.len() && w[k + 1] > 0.0 {
                num += (w[k] * w[k + 1]).sqrt() * e[k] * e[k + 1];
            }
        }
    }
    if den > 0.0 {
        (num / den).clamp(0.0, 0.999)
    } else {
        0.0
    }
}

/// The uncertainty of `(sigma0, sigma1)` from `J^T W J` of the weighted position
/// residuals, its variance inflated for their serial correlation.
pub(super) struct Intervals {
    pub(super) std_err: Vec<f64>,
    pub(super) ci_low: Vec<f64>,
    pub(super) ci_high: Vec<f64>,
    /// Half-width of the 95 % interval relative to the estimate.
    pub(super) rel: Vec<f64>,
    pub(super) correlation: f64,
    /// No Jacobian: a simulation next to the estimate failed.
    pub(super) failed: bool,
    /// `J^T W J` near-singular (or no Jacobian).
    pub(super) singular: bool,
    pub(super) identifiable: Vec<bool>,
}

impl Intervals {
    pub(super) fn new(
        jac: Option<&[Vec<f64>; 2]>,
        e: &[f64],
        w: &[f64],
        inflation: f64,
        est: [f64; 2],
    ) -> Self {
        let mut iv = Intervals {
            std_err: vec![f64::NAN; 2],
            ci_low: vec![f64::NAN; 2],
            ci_high: vec![f64::NAN; 2],
            rel: vec![f64::INFINITY; 2],
            correlation: f64::NAN,
            failed: jac.is_none(),
            singular: true,
            identifiable: vec![false; 2],
        };
        if let Some([ja, jb]) = jac {
            iv.singular = !iv.fill(ja, jb, e, w, inflation, est);
        }
        for k in 0..2 {
            iv.identifiable[k] = !iv.singular && iv.rel[k].is_finite() && iv.rel[k] <= 0.5;
        }
        iv
    }

    /// Fill in the intervals from the Jacobian columns `ja`, `jb`; `false` when
    /// `J^T W J` is near-singular (or the residual variance undefined).
    fn fill(
        &mut self,
        ja: &[f64],
        jb: &[f64],
        e: &[f64],
        w: &[f64],
        inflation: f64,
        est: [f64; 2],
    ) -> bool {
        // de/dtheta = -(dx_sim/dtheta); the sign does not matter for J^T W J
        let mut m = [[0.0f64; 2]; 2];
        for k in 0..e.len() {
            let (j0, j1) = (ja[k], jb[k]);
            m[0][0] += w[k] * j0 * j0;
            m[0][1] += w[k] * j0 * j1;
            m[1][1] += w[k] * j1 * j1;
        }
        m[1][0] = m[0][1];
        let n_used = w.iter().filter(|x| **x > 0.0).count();
        let dof = n_used as f64 - 2.0;
        let ssq: f64 = e.iter().zip(w).map(|(ei, wi)| wi * ei * ei).sum();
        let s2 = if dof > 0.0 { ssq / dof } else { f64::NAN };
        let det = m[0][0] * m[1][1] - m[0][1] * m[0][1];
        let scale = (m[0][0] * m[1][1]).max(0.0);
        let cond_ok = scale > 0.0 && det > 1e-10 * scale;
        if !(cond_ok && s2.is_finite()) {
            return false;
        }
        let c00 = m[1][1] / det * s2 * inflation;
        let c11 = m[0][0] / det * s2 * inflation;
        let c01 = -m[0][1] / det * s2 * inflation;
        self.correlation = c01 / (c00 * c11).sqrt();
        let se_th = [c00.sqrt(), c11.sqrt()];
        for k in 0..2 {
            self.std_err[k] = est[k] * se_th[k];
            self.ci_low[k] = est[k] * (-1.96 * se_th[k]).exp();
            self.ci_high[k] = est[k] * (1.96 * se_th[k]).exp();
            self.rel[k] = (self.ci_high[k] - self.ci_low[k]) / (2.0 * est[k]);
        }
        true
    }
}

/// What the fit says in words: failures, which parameter the record determines, the
/// confounding of `sigma1` with `sigma2`, correlated residuals or parameters, and an
/// IRLS stopped at its limit.
pub(super) fn notes(
    model: &Model,
    opts: &DynamicFitOptions,
    out: &IrlsOutcome,
    iv: &Intervals,
    [s0, s1]: [f64; 2],
    rho: f64,
    inflation: f64,
) -> Vec<String> {
    let rel = &iv.rel;
    let mut notes = Vec::new();
    if iv.failed {
        notes.push("the simulation failed next to the estimate: no intervals".into());
    }
    if iv.singular {
        notes.push(
            "the objective is flat in at least one direction (near-singular Hessian): sigma0 and sigma1 cannot be separated by this record".into(),
        );
    }
    if iv.identifiable[0] {
        notes.push(format!(
            "sigma0 = {s0:.4e} N/m is determined by the record (95 % interval +-{:.2} %)",
            rel[0] * 100.0
        ));
    } else {
        notes.push(format!(
            "sigma0 is NOT determined by this record (95 % interval +-{:.0} %): record small back-and-forth moves below the break-away force (presliding), where the force-displacement slope is sigma0",
            rel[0] * 100.0
        ));
    }
    if iv.identifiable[1] {
        notes.push(format!(
            "sigma1 = {s1:.4} N s/m is determined by the record (95 % interval +-{:.1} %)",
            rel[1] * 100.0
        ));
    } else {
        notes.push(format!(
            "sigma1 is NOT determined by this record: the objective is nearly flat in sigma1 (95 % interval +-{:.0} %). Break-away tests with small displacements (force ramps or steps below fs, with fast position sampling) excite the bristle damping; otherwise keep the start value and report it as assumed",
            rel[1].min(1e6) * 100.0
        ));
    }
    let s2max = model
        .friction
        .positive
        .sigma2
        .max(model.friction.negative.sigma2);
    let bias = s2max * opts.sigma2_rel_uncertainty;
    if bias > 0.1 * s1 {
        notes.push(format!(
            "sigma1 is confounded with sigma2 (the presliding damping is sigma1 + sigma2): a {:.1} % error in sigma2 ({bias:.3} N s/m) is {:.0} % of sigma1; reduce sigma2's uncertainty (more fast constant-velocity points) before trusting sigma1",
            opts.sigma2_rel_uncertainty * 100.0,
            100.0 * bias / s1
        ));
    }
    if rho > 0.5 {
        notes.push(format!(
            "residuals are serially correlated (lag-one {rho:.3}); intervals widened by a factor {:.1}",
            inflation.sqrt()
        ));
    }
    if iv.correlation.abs() > 0.95 {
        notes.push(format!(
            "ln sigma0 and ln sigma1 are strongly correlated ({:.3})",
            iv.correlation
        ));
    }
    if !out.converged {
        notes.push(format!(
            "IRLS stopped at the iteration limit ({}) before the weights settled",
            out.iterations
        ));
    }
    notes
}
