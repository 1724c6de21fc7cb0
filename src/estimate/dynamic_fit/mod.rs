//! Step 2 of the paper's identification: the bristle stiffness `sigma0` and damping
//! `sigma1` from a closed-loop position record.
//!
//! With the static sets held, the PID position loop is simulated
//! ([`crate::servo::simulate`]) for trial `(sigma0, sigma1)` and the objective of the
//! paper's eq. 18, `J = c1*sum(w*e^2) + c2*max|e|` over the points with `w > 0`,
//! `e = x_measured - x_sim`, is minimised by Nelder-Mead over `(ln sigma0, ln sigma1)`
//! inside an IRLS loop. A coarse grid, simulated in parallel (rayon), gives the start.
//!
//! The uncertainty comes from the weighted Jacobian of the position residuals
//! (central differences in the log-parameters), inflated for the serial correlation of
//! the residuals (AR(1) variance factor `(1 + rho)/(1 - rho)`): successive position
//! samples of a servo record are far from independent. Each parameter gets a verdict:
//! with the paper's axis, `sigma0` shapes the whole presliding phase and is well
//! determined, while `sigma1` acts only during the short transitions and is confounded
//! with `sigma2` (the presliding damping is `sigma1 + sigma2`), so it is often not.

mod uncertainty;

use super::irls::{irls, IrlsOutcome, IrlsSetup};
use super::nelder_mead::NmOptions;
use super::robust::{robust_scale, Weighting};
use crate::error::{check_finite, check_len, check_time, Error, Result};
use crate::servo::{simulate, ControlLaw, Drive, Model, SimOptions};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use uncertainty::{lag_one_autocorrelation, notes, Intervals};

/// Options of [`fit_dynamic`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DynamicFitOptions {
    /// Weight function (IGG by default).
    pub weighting: Weighting,
    /// Weight of the sum of squares in eq. 18 (1 by default).
    pub c1: f64,
    /// Weight of the maximum absolute error in eq. 18 [1/m] (0 by default: the max
    /// term is non-smooth and the paper gives no value; scale it to the record, e.g.
    /// `c2 = 0.1*N*typical_error` to give it a tenth of the weight).
    pub c2: f64,
    /// Start value of sigma0 (default: the model's).
    pub sigma0_start: Option<f64>,
    /// Start value of sigma1 (default: the model's).
    pub sigma1_start: Option<f64>,
    /// Evaluate a coarse grid (5 x 3 nodes, a factor 10 either side of the start) first.
    pub grid: bool,
    /// Maximum IRLS (outer) iterations.
    pub max_iter: usize,
    /// Stop when the log-parameters move by less than this.
    pub tol: f64,
    /// Simulations per Nelder-Mead run.
    pub max_evals: usize,
    /// Refine the start by a few Huber-weighted Gauss-Newton steps and run Nelder-Mead
    /// in coordinates decorrelated and scaled by the Gauss-Newton Hessian there (true
    /// by default; false: Nelder-Mead on the log-parameters from the grid node).
    pub rescale: bool,
    /// Lower bound of the residual scale [m] (e.g. the encoder resolution).
    pub scale_floor: f64,
    /// Relative uncertainty of sigma2 from the static step, for the note on sigma1
    /// (0.01 by default).
    pub sigma2_rel_uncertainty: f64,
    /// Simulation options (substeps, integrator, initial state).
    pub sim: SimOptions,
}

impl Default for DynamicFitOptions {
    fn default() -> Self {
        Self {
            weighting: Weighting::igg(),
            c1: 1.0,
            c2: 0.0,
            sigma0_start: None,
            sigma1_start: None,
            grid: true,
            max_iter: 20,
            tol: 1e-3,
            max_evals: 200,
            rescale: true,
            scale_floor: 0.0,
            sigma2_rel_uncertainty: 0.01,
            sim: SimOptions::default(),
        }
    }
}

/// Result of [`fit_dynamic`].
#[derive(Debug, Clone, PartialEq)]
pub struct DynamicFit {
    /// Estimated bristle stiffness [N/m].
    pub sigma0: f64,
    /// Estimated bristle damping [N s/m].
    pub sigma1: f64,
    /// Standard errors of `sigma0, sigma1` (delta method; NaN when unavailable).
    pub std_err: Vec<f64>,
    /// Lower ends of the 95 % intervals of `sigma0, sigma1` (from the log-parameters).
    pub ci_low: Vec<f64>,
    /// Upper ends of the 95 % intervals.
    pub ci_high: Vec<f64>,
    /// Half-width of each interval relative to the estimate.
    pub rel_ci_half_width: Vec<f64>,
    /// Verdict per parameter: true when it is determined by the record.
    pub identifiable: Vec<bool>,
    /// Correlation of the `ln sigma0` and `ln sigma1` estimates.
    pub correlation: f64,
    /// Lag-one autocorrelation of the weighted residuals (used to widen the intervals).
    pub residual_autocorrelation: f64,
    /// Plain-language verdicts and suggested experiments.
    pub notes: Vec<String>,
    /// `x_measured - x_sim` at the estimate [m].
    pub residuals: Vec<f64>,
    /// Final IRLS weights (0 = rejected sample).
    pub weights: Vec<f64>,
    /// Root mean square of the weighted residuals [m].
    pub rms_error: f64,
    /// Largest absolute residual among the kept samples [m].
    pub max_error: f64,
    /// Eq. 18 objective at the estimate.
    pub objective: f64,
    /// Robust scale of the residuals [m].
    pub scale: f64,
    /// IRLS iterations.
    pub iterations: usize,
    /// Closed-loop simulations run.
    pub evaluations: usize,
    /// True when IRLS settled before `max_iter`.
    pub converged: bool,
}

fn with_sigmas(model: &Model, s0: f64, s1: f64) -> Model {
    let mut m = model.clone();
    m.friction.sigma0 = s0;
    m.friction.sigma1 = s1;
    m
}

fn check_options(o: &DynamicFitOptions) -> Result<()> {
    o.weighting.validate()?;
    for (name, v) in [
        ("c1", o.c1),
        ("c2", o.c2),
        ("scale_floor", o.scale_floor),
        ("sigma2_rel_uncertainty", o.sigma2_rel_uncertainty),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(Error::parameter(
                name,
                v,
                "must be finite and zero or greater",
            ));
        }
    }
    if o.c1 == 0.0 && o.c2 == 0.0 {
        return Err(Error::parameter("c1", 0.0, "c1 and c2 cannot both be zero"));
    }
    for (name, v) in [
        ("sigma0_start", o.sigma0_start),
        ("sigma1_start", o.sigma1_start),
    ] {
        if let Some(x) = v {
            if !(x.is_finite() && x > 0.0) {
                return Err(Error::parameter(
                    name,
                    x,
                    "must be a finite number greater than zero",
                ));
            }
        }
    }
    Ok(())
}

/// Start point and coordinate map for the Nelder-Mead of [`fit_dynamic`].
struct LocalMetric {
    centre: [f64; 2],
    /// `theta = centre + t*z`.
    t: [[f64; 2]; 2],
    /// The last Jacobian (residual sign) and the point where it was taken.
    jac: ([f64; 2], [Vec<f64>; 2]),
}

/// Forward-difference Jacobian of the simulated positions, `dx_sim/dtheta_k =
/// -(de/dtheta_k)`, in the log-parameters (the two simulations in parallel).
fn jacobian(
    resid: &(dyn Fn(&[f64]) -> Option<Vec<f64>> + Sync),
    th: &[f64; 2],
    e: &[f64],
    h: f64,
) -> Option<[Vec<f64>; 2]> {
    let (a, b) = rayon::join(|| resid(&[th[0] + h, th[1]]), || resid(&[th[0], th[1] + h]));
    let col =
        |r: Vec<f64>| -> Vec<f64> { e.iter().zip(&r).map(|(e0, e1)| (e0 - e1) / h).collect() };
    Some([col(a?), col(b?)])
}

/// Gauss-Newton refinement of the start (Huber weights, step halving, at most a few
/// steps) and the map `theta = centre + T*z` with `T = sqrt(f)*L^-T`, `L*L^T = J^T W J`
/// (Cholesky) at the last Jacobian: in `z` the quadratic model of the cost is
/// `f*(1 + |z|^2)`. `None` when the Jacobian is singular or a simulation fails (the
/// caller then works in the log-parameters).
fn local_metric(
    resid: &(dyn Fn(&[f64]) -> Option<Vec<f64>> + Sync),
    theta0: Vec<f64>,
    c1: f64,
    evaluations: &mut usize,
) -> Option<LocalMetric> {
    let huber = Weighting::huber();
    let wss = |e: &[f64], w: &[f64]| -> f64 { e.iter().zip(w).map(|(a, b)| b * a * a).sum() };
    let mut th = [theta0[0], theta0[1]];
    let mut e = resid(&th)?;
    *evaluations += 1;
    let mut metric = None;
    let mut last_jac = None;
    for _ in 0..10 {
        let s = robust_scale(&e);
        if s.is_nan() || s <= 0.0 {
            break;
        }
        let w = huber.weights(&e, s);
        let j = jacobian(resid, &th, &e, 1e-3)?;
        *evaluations += 2;
        let (mut m00, mut m01, mut m11, mut g0, mut g1) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for k in 0..e.len() {
            let (a, b, wk) = (j[0][k], j[1][k], w[k]);
            m00 += wk * a * a;
            m01 += wk * a * b;
            m11 += wk * b * b;
            g0 += wk * a * e[k];
            g1 += wk * b * e[k];
        }
        let det = m00 * m11 - m01 * m01;
        if !(m00 > 0.0 && m11 > 0.0 && det > 1e-12 * m00 * m11) {
            return None;
        }
        metric = Some((m00, m01, m11));
        last_jac = Some((th, j));
        // e(th + d) ~ e - J d: d = M^-1 J^T W e
        let d = [(m11 * g0 - m01 * g1) / det, (m00 * g1 - m01 * g0) / det];
        let f = wss(&e, &w);
        // predicted decrease; done when the step would gain less than about one
        // standard error squared (or the prediction is not a number)
        let predicted = d[0] * g0 + d[1] * g1;
        if predicted.is_nan() || predicted <= f / e.len() as f64 {
            break;
        }
        let mut lambda = 1.0;
        let mut accepted = false;
        for _ in 0..4 {
            // never more than a factor e per step in either parameter
            let big = (lambda * d[0]).abs().max((lambda * d[1]).abs());
            let lam = if big > 1.0 { lambda / big } else { lambda };
            let trial = [th[0] + lam * d[0], th[1] + lam * d[1]];
            *evaluations += 1;
            if let Some(et) = resid(&trial) {
                if wss(&et, &w) < f {
                    th = trial;
                    e = et;
                    accepted = true;
                    break;
                }
            }
            lambda = lam * 0.5;
        }
        if !accepted {
            break;
        }
    }
    let (m00, m01, m11) = metric?;
    let jac = last_jac?;
    let f = c1 * e.iter().map(|x| x * x).sum::<f64>();
    let (m00, m01, m11) = (c1 * m00, c1 * m01, c1 * m11);
    // L = [[l00, 0], [l10, l11]]
    let l00 = m00.sqrt();
    let l10 = m01 / l00;
    let l11 = (m11 - l10 * l10).max(0.0).sqrt();
    if !(l11 > 0.0 && f > 0.0 && f.is_finite()) {
        return None;
    }
    // L^-T = [[1/l00, -l10/(l00*l11)], [0, 1/l11]]
    let r = f.sqrt();
    Some(LocalMetric {
        centre: th,
        t: [[r / l00, -r * l10 / (l00 * l11)], [0.0, r / l11]],
        jac,
    })
}

/// Estimate `sigma0` and `sigma1` from a closed-loop position record.
///
/// `model` holds the axis, the static friction sets (held fixed) and a `pid`
/// controller; `t`, `x_ref`, `x_measured` the record (same length). The model's
/// `sigma0`, `sigma1` are the start values unless the options give others.
///
/// ```no_run
/// use lugre::estimate::{fit_dynamic, DynamicFitOptions};
/// use lugre::servo::{simulate, Drive, Model, SimOptions};
/// let m = Model::from_json(r#"{"axis": {"mass": 25, "force_constant": 25},
///   "friction": {"sigma0": 1e5, "sigma1": 31.62,
///     "positive": {"fc": 28.7, "fs": 60.2, "sigma2": 332.5, "vs": 0.01},
///     "negative": {"fc": 28.5, "fs": 60.1, "sigma2": 333.0, "vs": 0.01}},
///   "controller": {"type": "pid", "kp": 5e4, "ki": 5e5, "kd": 1500, "rate_hz": 10000}}"#).unwrap();
/// let t: Vec<f64> = (0..20001).map(|k| k as f64 * 1e-4).collect();
/// let xr: Vec<f64> = t.iter().map(|&s| 1e-3 * s).collect();
/// let x = simulate(&m, &t, Drive::Position(&xr), &SimOptions::default(), &mut || true).unwrap().x;
/// let mut start = m.clone();
/// start.friction.sigma0 = 5e4;
/// let fit = fit_dynamic(&start, &t, &xr, &x, &DynamicFitOptions::default()).unwrap();
/// assert!((fit.sigma0 / 1e5 - 1.0).abs() < 1e-3);
/// ```
pub fn fit_dynamic(
    model: &Model,
    t: &[f64],
    x_ref: &[f64],
    x_measured: &[f64],
    opts: &DynamicFitOptions,
) -> Result<DynamicFit> {
    fit_dynamic_with(model, t, x_ref, x_measured, opts, &AtomicBool::new(false))
}

/// As [`fit_dynamic`], stopping with [`Error::Interrupted`] once `cancel` is set (from
/// another thread, e.g. on Ctrl-C).
pub fn fit_dynamic_with(
    model: &Model,
    t: &[f64],
    x_ref: &[f64],
    x_measured: &[f64],
    opts: &DynamicFitOptions,
    cancel: &AtomicBool,
) -> Result<DynamicFit> {
    let r = fit_dynamic_body(model, t, x_ref, x_measured, opts, cancel);
    if cancel.load(Ordering::Relaxed) {
        return Err(Error::Interrupted);
    }
    r
}

/// The position residuals `x_measured - x_sim` at `theta = (ln sigma0, ln sigma1)`,
/// `None` where the loop cannot be simulated.
type Resid<'a> = dyn Fn(&[f64]) -> Option<Vec<f64>> + Sync + 'a;

/// A Jacobian of the simulated positions and the point where it was taken.
type TakenJacobian = ([f64; 2], [Vec<f64>; 2]);

fn fit_dynamic_body(
    model: &Model,
    t: &[f64],
    x_ref: &[f64],
    x_measured: &[f64],
    opts: &DynamicFitOptions,
    cancel: &AtomicBool,
) -> Result<DynamicFit> {
    check_record(model, t, x_ref, x_measured, opts)?;
    let sim_opts = opts.sim;
    // check the model runs at all (errors in the model or inputs surface here)
    simulate(model, t, Drive::Position(x_ref), &sim_opts, &mut || true)?;

    let resid = |th: &[f64]| -> Option<Vec<f64>> {
        let (s0, s1) = (th[0].exp(), th[1].exp());
        if cancel.load(Ordering::Relaxed) || !(s0.is_finite() && s1.is_finite() && s0 > 0.0) {
            return None;
        }
        let m = with_sigmas(model, s0, s1);
        let r = simulate(&m, t, Drive::Position(x_ref), &sim_opts, &mut || {
            !cancel.load(Ordering::Relaxed)
        })
        .ok()?;
        Some(x_measured.iter().zip(&r.x).map(|(a, b)| a - b).collect())
    };
    let (c1, c2) = (opts.c1, opts.c2);
    let objective = move |e: &[f64], w: &[f64]| -> f64 { eq18(c1, c2, e, w) };

    let mut evaluations = 0usize;
    let start = start(&resid, model, t.len(), opts, &mut evaluations);
    let (out, reuse_jac) = minimise(&resid, &objective, start, t.len(), opts, &mut evaluations)?;
    evaluations += out.evals;
    let th = out.theta.clone();
    let (s0, s1) = (th[0].exp(), th[1].exp());
    let jac = jacobian_at_estimate(&resid, &th, reuse_jac, &mut evaluations);
    let w = &out.weights;
    let e = &out.residuals;
    let rho = lag_one_autocorrelation(e, w);
    let inflation = (1.0 + rho) / (1.0 - rho);
    let iv = Intervals::new(jac.as_ref(), e, w, inflation, [s0, s1]);
    let notes = notes(model, opts, &out, &iv, [s0, s1], rho, inflation);
    let wsum: f64 = w.iter().sum();
    let ssq: f64 = e.iter().zip(w).map(|(ei, wi)| wi * ei * ei).sum();
    let max_error = e
        .iter()
        .zip(w)
        .filter(|(_, wi)| **wi > 0.0)
        .fold(0.0f64, |m, (ei, _)| m.max(ei.abs()));
    Ok(DynamicFit {
        sigma0: s0,
        sigma1: s1,
        std_err: iv.std_err,
        ci_low: iv.ci_low,
        ci_high: iv.ci_high,
        rel_ci_half_width: iv.rel,
        identifiable: iv.identifiable,
        correlation: iv.correlation,
        residual_autocorrelation: rho,
        notes,
        objective: objective(e, w),
        rms_error: if wsum > 0.0 {
            (ssq / wsum).sqrt()
        } else {
            f64::NAN
        },
        max_error,
        scale: out.scale,
        residuals: out.residuals,
        weights: out.weights,
        iterations: out.iterations,
        evaluations,
        converged: out.converged,
    })
}

/// Refuse a record [`fit_dynamic`] cannot use: lengths, non-finite values, no `pid`
/// controller, too short, or no motion at all.
fn check_record(
    model: &Model,
    t: &[f64],
    x_ref: &[f64],
    x_measured: &[f64],
    opts: &DynamicFitOptions,
) -> Result<()> {
    check_time("t", t)?;
    check_len("x_ref", x_ref, t.len(), "t")?;
    check_len("x_measured", x_measured, t.len(), "t")?;
    check_finite("x_ref", x_ref)?;
    check_finite("x_measured", x_measured)?;
    check_options(opts)?;
    match model.controller.as_ref().map(|c| c.law) {
        Some(ControlLaw::Pid { .. }) => {}
        _ => {
            return Err(Error::model(
                "controller",
                "fit_dynamic needs a \"pid\" position controller (the loop of the record)",
            ))
        }
    }
    if t.len() < 10 {
        return Err(Error::Data(format!(
            "{} samples: a dynamic fit needs a record of many control periods",
            t.len()
        )));
    }
    // a record that never moves holds no information on the bristles
    let span = x_measured.iter().fold(f64::NEG_INFINITY, |m, &x| m.max(x))
        - x_measured.iter().fold(f64::INFINITY, |m, &x| m.min(x));
    if span <= 0.0 {
        return Err(Error::Data(
            "x_measured is constant: record a motion (a slow ramp that sticks and slips)".into(),
        ));
    }
    Ok(())
}

/// The paper's eq. 18: `c1*sum(w*e^2) + c2*max|e|` over the points with `w > 0`.
fn eq18(c1: f64, c2: f64, e: &[f64], w: &[f64]) -> f64 {
    let mut ss = 0.0;
    let mut mx = 0.0f64;
    for (ei, wi) in e.iter().zip(w) {
        ss += wi * ei * ei;
        if *wi > 0.0 {
            mx = mx.max(ei.abs());
        }
    }
    c1 * ss + c2 * mx
}

/// The start `theta0` of the search and its simplex steps: the options' (or the
/// model's) sigmas, or with `opts.grid` the best node of a coarse grid around them
/// (5 x 3 decades apart by half and one, simulated in parallel).
fn start(
    resid: &Resid,
    model: &Model,
    n: usize,
    opts: &DynamicFitOptions,
    evaluations: &mut usize,
) -> (Vec<f64>, Vec<f64>) {
    let s0_start = opts.sigma0_start.unwrap_or(model.friction.sigma0);
    let s1_start = opts.sigma1_start.unwrap_or(model.friction.sigma1).max(1e-6);
    let theta0 = vec![s0_start.ln(), s1_start.ln()];
    let step = vec![0.2, 0.5];
    if !opts.grid {
        return (theta0, step);
    }
    let ln10 = std::f64::consts::LN_10;
    let mut nodes = Vec::new();
    for i in 0..5 {
        for j in 0..3 {
            nodes.push([
                theta0[0] + ln10 * (i as f64 - 2.0) / 2.0,
                theta0[1] + ln10 * (j as f64 - 1.0),
            ]);
        }
    }
    let ones = vec![1.0; n];
    let scores: Vec<f64> = nodes
        .par_iter()
        .map(|th| match resid(th) {
            Some(e) => eq18(opts.c1, opts.c2, &e, &ones),
            None => f64::INFINITY,
        })
        .collect();
    *evaluations += nodes.len();
    match (0..nodes.len())
        .filter(|&k| scores[k].is_finite())
        .min_by(|&a, &b| scores[a].total_cmp(&scores[b]))
    {
        Some(k) => (nodes[k].to_vec(), vec![ln10 / 4.0, ln10 / 2.0]),
        None => (theta0, step),
    }
}

/// IRLS around Nelder-Mead from the start `(theta0, step)`: in the coordinates of the
/// local metric when `opts.rescale` finds one (its last Jacobian returned for reuse),
/// else in the log-parameters.
fn minimise(
    resid: &Resid,
    objective: &dyn Fn(&[f64], &[f64]) -> f64,
    (theta0, step): (Vec<f64>, Vec<f64>),
    n: usize,
    opts: &DynamicFitOptions,
    evaluations: &mut usize,
) -> Result<(IrlsOutcome, Option<TakenJacobian>)> {
    let nm = NmOptions {
        max_evals: opts.max_evals,
        xtol: opts.tol.max(1e-8),
        ftol: 1e-6,
        restarts: 1,
    };
    let fail = || {
        Error::Data(
            "the closed loop could not be simulated at the start values: give sigma0_start and sigma1_start near the expected values".into(),
        )
    };
    let local = if opts.rescale {
        local_metric(resid, theta0.clone(), opts.c1, evaluations)
    } else {
        None
    };
    let Some(lm) = local else {
        let setup = IrlsSetup {
            weighting: opts.weighting,
            max_outer: opts.max_iter,
            tol: opts.tol,
            scale_floor: opts.scale_floor,
            nm,
            step: &step,
        };
        return Ok((
            irls(resid, objective, theta0, &setup).ok_or_else(fail)?,
            None,
        ));
    };
    // Nelder-Mead in z, theta = centre + T*z: the Gauss-Newton model of the cost is
    // f*(1 + |z|^2) there, so the thin, tilted sigma0/sigma1 valley becomes round and
    // the simplex needs few evaluations
    let to_theta = |z: &[f64]| -> [f64; 2] {
        [
            lm.centre[0] + lm.t[0][0] * z[0] + lm.t[0][1] * z[1],
            lm.centre[1] + lm.t[1][0] * z[0] + lm.t[1][1] * z[1],
        ]
    };
    let resid_z = |z: &[f64]| resid(&to_theta(z));
    // |d theta|_inf <= ||T||_inf * |d z|_inf
    let tnorm = (lm.t[0][0].abs() + lm.t[0][1].abs()).max(lm.t[1][0].abs() + lm.t[1][1].abs());
    // a few standard errors: the cost rises by ~1/N relative per standard error
    let n = n as f64;
    let step_z = [2.0 / n.sqrt(); 2];
    let setup = IrlsSetup {
        weighting: opts.weighting,
        max_outer: opts.max_iter,
        tol: opts.tol / tnorm.max(1e-300),
        scale_floor: opts.scale_floor,
        nm: NmOptions {
            xtol: 1e-8,
            ftol: nm.ftol.min(0.04 / n),
            ..nm
        },
        step: &step_z,
    };
    let mut o = irls(&resid_z, objective, vec![0.0, 0.0], &setup).ok_or_else(fail)?;
    o.theta = to_theta(&o.theta).to_vec();
    Ok((o, Some(lm.jac)))
}

/// Jacobian of the simulated positions in the log-parameters at the estimate `th`:
/// the Gauss-Newton one when it was taken within its own difference step of it, else
/// central differences here (`None` when a simulation fails).
fn jacobian_at_estimate(
    resid: &Resid,
    th: &[f64],
    reuse: Option<TakenJacobian>,
    evaluations: &mut usize,
) -> Option<[Vec<f64>; 2]> {
    let h = 1e-3;
    match reuse {
        Some((at, j)) if (at[0] - th[0]).abs().max((at[1] - th[1]).abs()) <= h => Some(j),
        _ => {
            let probes: Vec<[f64; 2]> = vec![
                [th[0] + h, th[1]],
                [th[0] - h, th[1]],
                [th[0], th[1] + h],
                [th[0], th[1] - h],
            ];
            let sims: Vec<Option<Vec<f64>>> = probes.par_iter().map(|p| resid(p)).collect();
            *evaluations += 4;
            match &sims[..] {
                [Some(a), Some(b), Some(c), Some(d)] => Some([
                    a.iter().zip(b).map(|(p, q)| (p - q) / (2.0 * h)).collect(),
                    c.iter().zip(d).map(|(p, q)| (p - q) / (2.0 * h)).collect(),
                ]),
                _ => None,
            }
        }
    }
}
