//! Step 1 of the paper's identification: the Stribeck curve of each direction from
//! steady-state (constant-velocity) points.
//!
//! For `v > 0` the model is `F = fc + (fs - fc)*exp(-(v/vs)^2) + sigma2*v` (eq. 7);
//! for `v < 0` the same curve mirrored, `F = -(fc + ...) + sigma2*v`, with its own
//! positive parameters (eq. 9). Each direction is fitted separately by robust IRLS
//! (eqs. 19-24). For a fixed `vs` the curve is linear in `(fc, fs - fc, sigma2)`:
//! each weighted problem is solved by variable projection (separable least squares,
//! Golub and Pereyra 1973), the linear parameters in closed form from the 3x3 normal
//! equations (column-scaled Cholesky; `fc > 0`, `fs >= fc`, `sigma2 >= 0` by an
//! exhaustive active set when the unconstrained solution violates them), so the
//! nonlinear search is over `ln vs` alone: a bracket walked downhill, then Nelder-Mead
//! from the vertex of its parabola.
//!
//! Start values need no user input: for a fixed `vs` the curve is linear in
//! `(fc, fs, sigma2)`, so a grid over `ln vs` with a robust linear fit at each node
//! gives a start that gross errors do not pull away. With a rejecting weight function
//! (IGG, Tukey) several such starts are followed to the end, a Huber grid and
//! least-trimmed-squares grids (which also resist gross errors at the fastest or
//! slowest speeds, which have high leverage, and, at the trimmed fit's scale held
//! fixed, a direction with half or more gross errors); each path's kept points are
//! refitted by plain least squares, with the rejections re-checked (beyond 4.685 scale
//! units at least, the bisquare's rejection point), which recovers the efficiency the
//! down-weighting band costs, and the path with the largest likelihood of a
//! Gaussian-plus-uniform mixture is returned.
//!
//! A direction with more than [`StaticFitOptions::max_start_points`] points (400 by
//! default) is fitted as FAST-LTS fits large samples (Rousseeuw and Van Driessen
//! 2006): the starts, their paths and their ranking on a subsample of that many points
//! spread over the speeds (one from each run of the speed ranks, drawn by a fixed-seed
//! generator, `starts::subsample`); the best two distinct paths (kept sets) once
//! more on all points from their subsample answers, without the pre-pass, at their
//! kind of scale (the MAD, or held: all points' scale reweighted from the path's own,
//! `starts::rescale`); of those the one of the larger mixture likelihood on all
//! points. The starts cost `O(n)` per concentration step and grid node; this way only
//! a few IRLS paths see all points (20 000 points: 1 s before, about 70 ms). Up to
//! `max_start_points` points per direction the fit is the one described above.
//!
//! One idea per file: [`varpro`] the separable problem for fixed weights,
//! [`reweight`] IRLS and the refit of the kept points, [`starts`] the robust starts
//! (Huber grid, least trimmed squares), [`intervals`] the covariance; this file the
//! options, the results and the path from start to answer.

mod intervals;
mod reweight;
mod starts;
mod varpro;

use super::nelder_mead::NmOptions;
use super::robust::{median, t_quantile_975, Weighting};
use crate::error::{check_finite, check_len, Error, Result};
use crate::friction::StaticSet;
use reweight::{irls_vp, refit_kept, Cfg, Outcome, Stage};
use starts::{
    clamp_start, lts_scale, lts_sizes, refine_lts, rescale, start_values_huber, start_values_lts,
    subsample,
};
use varpro::Sep;

/// Fewest nonzero-speed points per direction that [`fit_static`] accepts (4 parameters
/// plus one degree of freedom for the residual scale).
pub const MIN_POINTS_PER_DIRECTION: usize = 5;

/// Default of [`StaticFitOptions::max_start_points`].
pub const DEFAULT_MAX_START_POINTS: usize = 400;

/// Paths finished on all points when the starts ran on a subsample
/// ([`StaticFitOptions::max_start_points`]).
const FINISHED_PATHS: usize = 2;

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
    /// Most points of a direction on which the starts are searched (400 by default;
    /// at least [`MIN_POINTS_PER_DIRECTION`]). A direction with more points is fitted
    /// as least trimmed squares is for large samples (FAST-LTS, Rousseeuw and Van
    /// Driessen 2006): the starts and their paths on a subsample of this many points
    /// spread over the speeds (the same in every run), then the best two once more on
    /// all points. `usize::MAX`: the starts on all points always.
    pub max_start_points: usize,
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
            max_start_points: DEFAULT_MAX_START_POINTS,
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
    /// Joint covariance of `fc, fs, sigma2, vs`, row-major 4x4 (NaN when the standard
    /// errors are): the static errors are correlated (fs with vs above all), which an
    /// interval carried into the dynamic step must keep.
    pub cov: Vec<f64>,
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

/// How a path held the residual scale of its weights.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum ScaleRule {
    /// The MAD of the residuals, recomputed at each IRLS round.
    Mad,
    /// A scale held fixed (the high-breakdown scale of a trimmed fit).
    Held,
}

/// The settings of one direction's paths (from a start to an answer).
struct Paths<'c> {
    cfg: &'c Cfg,
    weighting: Weighting,
    /// A rejecting weight function (IGG, Tukey): the robust starts are followed.
    rejects: bool,
    /// Rejecting weights with the refit of the kept points: its rejection threshold.
    refit_at: Option<f64>,
    scale_floor: f64,
}

impl Paths<'_> {
    /// One path: from a start, an optional IRLS pass with another weight function,
    /// IRLS, then (rejecting weight functions) the least-squares refit on the kept
    /// points. `fixed`: the residual scale held through both IRLS runs (an
    /// MM-estimate's M-step) instead of the MAD recomputed at each round.
    fn run(
        &self,
        sep: &mut Sep,
        p0: [f64; 4],
        pre: Option<Weighting>,
        fixed: Option<f64>,
    ) -> Outcome {
        let cfg = self.cfg;
        let mut p0 = p0;
        let mut evals = 0;
        if let Some(w) = pre {
            let o = irls_vp(sep, p0, w, cfg, Stage::Pre, fixed);
            p0 = o.p;
            evals = o.evals;
        }
        let stage = if self.refit_at.is_some() {
            Stage::Refit
        } else {
            Stage::Polish
        };
        let mut out = irls_vp(sep, p0, self.weighting, cfg, stage, fixed);
        out.evals += evals;
        if let Some(k) = self.refit_at {
            refit_kept(sep, &mut out, k, cfg);
        }
        out
    }

    /// The starts on all of `sep`'s points and the path from each, each with the kind
    /// of scale it held, best first ([`Paths::cost`]; of equal costs the earlier path).
    fn ranked(&self, sep: &mut Sep, fscale: f64) -> Vec<(Outcome, ScaleRule)> {
        let (a, y) = (sep.a, sep.y);
        let huber_start = clamp_start(start_values_huber(sep), a, fscale);
        if !self.rejects {
            return vec![(self.run(sep, huber_start, None, None), ScaleRule::Mad)];
        }
        // Redescending weights (IGG, Tukey) settle on the set of rejected points near
        // their start. Seven starts, as in MM-estimation (Yohai 1987): (a) a Huber pass
        // (monotone, unique fixed point, MAD scale) from the Huber grid; (b)-(d) the two
        // best fits of least trimmed squares on half, three quarters and two fifths of
        // the points (grid, then `vs` freed, [`lts_sizes`]), which also resist gross
        // errors of high leverage (the fastest and slowest points) that a Huber fit
        // follows, each followed by a Tukey pass and IGG at the trimmed fit's
        // high-breakdown scale held fixed ([`lts_scale`]).
        let mut paths = vec![(
            self.run(sep, huber_start, Some(Weighting::huber()), None),
            ScaleRule::Mad,
        )];
        let n = a.len();
        for h in lts_sizes(n) {
            let mut refined: Vec<(f64, [f64; 4])> = start_values_lts(sep, h)
                .into_iter()
                .map(|p0| {
                    refine_lts(
                        sep,
                        clamp_start(Some(p0), a, fscale),
                        h,
                        &self.cfg.nm_pre,
                        self.cfg.obj_floor,
                    )
                })
                .filter(|r| r.0.is_finite())
                .collect();
            refined.sort_by(|x, y| x.0.total_cmp(&y.0));
            for (_, p) in refined.into_iter().take(2) {
                let p = clamp_start(Some(p), a, fscale);
                let s = lts_scale(&sep.residuals(&p), h);
                let fixed = s.is_finite().then_some(s);
                let rule = match fixed {
                    Some(_) => ScaleRule::Held,
                    None => ScaleRule::Mad,
                };
                paths.push((self.run(sep, p, Some(Weighting::tukey()), fixed), rule));
            }
        }
        let width = self.width(y);
        let mut ranked: Vec<(f64, (Outcome, ScaleRule))> = paths
            .into_iter()
            .map(|o| (self.cost(&o.0, width), o))
            .collect();
        ranked.sort_by(|x, y| x.0.total_cmp(&y.0));
        ranked.into_iter().map(|x| x.1).collect()
    }

    /// Range of the forces `y` (at least the scale floor), over which [`Paths::cost`]
    /// spreads the rejected points.
    fn width(&self, y: &[f64]) -> f64 {
        let ymax = y.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let ymin = y.iter().copied().fold(f64::INFINITY, f64::min);
        (ymax - ymin).max(self.scale_floor)
    }

    /// The choice among the paths (the local minima): the negative log-likelihood of a
    /// mixture, the kept points Gaussian at the path's own scale (that of its
    /// least-squares refit), the rejected ones uniform over the range `width` of the
    /// forces (MLESAC, Torr and Zisserman 2000). A fit to a few points at a small scale
    /// pays for every clean point it leaves out, a compromise through the gross errors
    /// for its large scale; no common scale is needed, which a direction with half or
    /// more gross errors would inflate (the MAD) and a fit to a subset would shrink.
    fn cost(&self, o: &Outcome, width: f64) -> f64 {
        let half_ln_2pi_e = 0.5 * (1.0 + (2.0 * std::f64::consts::PI).ln());
        let kept = o.weights.iter().filter(|w| **w > 0.0).count() as f64;
        let out = o.weights.len() as f64 - kept;
        kept * (o.scale.max(self.scale_floor).ln() + half_ln_2pi_e) + out * width.ln()
    }

    /// The best path on all points, from starts on all of them.
    fn best(&self, a: &[f64], y: &[f64], fscale: f64) -> Outcome {
        let ranked = self.ranked(&mut Sep::new(a, y, fscale), fscale);
        let evals = ranked.iter().map(|o| o.0.evals).sum();
        let mut best = ranked.into_iter().next().expect("at least one path").0;
        best.evals = evals;
        best
    }

    /// The best path among many points (FAST-LTS, Rousseeuw and Van Driessen 2006): the
    /// starts and their paths on a subsample spread over the speeds; the best
    /// [`FINISHED_PATHS`] distinct ones (kept sets) once more on all points, each from
    /// its subsample answer at its kind of scale (the MAD, or held: the scale of all
    /// points there reweighted from the path's own, [`rescale`]), and of those the one
    /// of the smallest cost on all points.
    fn best_by_subsample(
        &self,
        a: &[f64],
        y: &[f64],
        fscale: f64,
        max_start_points: usize,
    ) -> Outcome {
        let sub = subsample(a, max_start_points);
        let a_s: Vec<f64> = sub.iter().map(|&i| a[i]).collect();
        let y_s: Vec<f64> = sub.iter().map(|&i| y[i]).collect();
        let ranked = self.ranked(&mut Sep::new(&a_s, &y_s, fscale), fscale);
        let mut evals: usize = ranked.iter().map(|o| o.0.evals).sum();
        let mut sep = Sep::new(a, y, fscale);
        let mut kept_sets: Vec<Vec<bool>> = Vec::new();
        let mut finished: Vec<Outcome> = Vec::new();
        for (o, rule) in ranked {
            let kept: Vec<bool> = o.weights.iter().map(|w| *w > 0.0).collect();
            if kept_sets.contains(&kept) {
                continue;
            }
            kept_sets.push(kept);
            let p0 = clamp_start(Some(o.p), a, fscale);
            let fixed = match rule {
                ScaleRule::Mad => None,
                ScaleRule::Held => {
                    let s = rescale(&sep.residuals(&p0), o.scale);
                    (s.is_finite() && s > 0.0).then_some(s)
                }
            };
            let f = self.run(&mut sep, p0, None, fixed);
            evals += f.evals;
            finished.push(f);
            if finished.len() == FINISHED_PATHS {
                break;
            }
        }
        let width = self.width(y);
        let mut best = finished
            .into_iter()
            .map(|o| (self.cost(&o, width), o))
            .min_by(|x, y| x.0.total_cmp(&y.0))
            .map(|x| x.1)
            .expect("at least one path");
        best.evals = evals;
        best
    }
}

impl Cfg {
    /// The settings of one direction's fit: the options' limits, the residual scale
    /// floor `scale_floor` and three simplex tolerances.
    fn new(opts: &StaticFitOptions, scale_floor: f64) -> Cfg {
        Cfg {
            max_outer: opts.max_iter,
            tol: opts.tol,
            scale_floor,
            nm: NmOptions {
                max_evals: opts.max_evals,
                xtol: 1e-10,
                ftol: 1e-12,
                restarts: 0,
            },
            nm_loose: NmOptions {
                max_evals: opts.max_evals,
                xtol: 1e-10,
                ftol: 1e-7,
                restarts: 0,
            },
            nm_pre: NmOptions {
                max_evals: opts.max_evals,
                xtol: 1e-10,
                ftol: 1e-5,
                restarts: 0,
            },
            obj_floor: 1e-6 * scale_floor * scale_floor,
        }
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
    let fscale = median(&y.iter().map(|v| v.abs()).collect::<Vec<_>>()).max(1e-12);
    let scale_floor = opts.scale_floor.max(1e-6 * fscale);
    let cfg = Cfg::new(opts, scale_floor);
    let reject_at = match opts.weighting {
        Weighting::Igg { k1, .. } => Some(k1),
        Weighting::Tukey { c } => Some(c),
        _ => None,
    };
    let paths = Paths {
        cfg: &cfg,
        weighting: opts.weighting,
        rejects: reject_at.is_some(),
        refit_at: reject_at
            .filter(|_| opts.refit_kept)
            .map(|k1| k1.max(reweight::REFIT_REJECT_MIN)),
        scale_floor,
    };
    let out = if a.len() > opts.max_start_points {
        paths.best_by_subsample(a, y, fscale, opts.max_start_points)
    } else {
        paths.best(a, y, fscale)
    };
    if !out.p.iter().all(|v| v.is_finite()) {
        return Err(Error::Data(format!(
            "{label} direction: the Stribeck curve could not be evaluated at the start values; check the data for extreme values"
        )));
    }
    let p = out.p;
    let iv = intervals::covariance(a, &out.weights, &out.residuals, &p);
    let (std_err, cov, sigma, n_used, dof) = (iv.std_err, iv.cov, iv.sigma, iv.n_used, iv.dof);
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
        cov,
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
    if opts.max_start_points < MIN_POINTS_PER_DIRECTION {
        return Err(Error::parameter(
            "max_start_points",
            opts.max_start_points as f64,
            "must be at least 5 (the points a direction needs)",
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
