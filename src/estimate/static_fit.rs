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
//! gives a start that gross errors do not pull away. With a rejecting weight function (IGG, Tukey) two such
//! starts are followed to the end, a Huber grid and a least-trimmed-squares grid (the
//! latter also resists gross errors at the fastest or slowest speeds, which have high
//! leverage), and the fit with the smaller bounded loss is returned; the
//! kept points are then refitted by plain least squares, with the rejections
//! re-checked, which recovers the efficiency the down-weighting band costs.

use super::nelder_mead::{minimize, NmOptions};
use super::robust::{median, robust_scale, t_quantile_975, Weighting};
use crate::error::{check_finite, check_len, Error, Result};
use crate::friction::StaticSet;
use nalgebra::{Matrix4, Vector4};

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

/// The Stribeck shape `phi_i = exp(-(a_i/vs)^2)` of every point.
#[inline]
fn fill_phi(a: &[f64], vs: f64, phi: &mut [f64]) {
    let iv = 1.0 / vs;
    for (p, &ai) in phi.iter_mut().zip(a) {
        let r = ai * iv;
        // below exp(-40) = 4e-18 the term is under the rounding of the force
        *p = if r * r < 40.0 { (-(r * r)).exp() } else { 0.0 };
    }
}

/// Weighted normal equations of the linear part for fixed `vs`: columns
/// `(1, phi, a)`, unknowns `(fc - fc_min, fs - fc, sigma2)`.
#[derive(Clone, Copy, Default)]
struct Normal {
    m: [[f64; 3]; 3],
    b: [f64; 3],
}

impl Normal {
    #[inline]
    fn add(&mut self, phi: f64, a: f64, y: f64, w: f64) {
        let (wp, wa) = (w * phi, w * a);
        self.m[0][0] += w;
        self.m[0][1] += wp;
        self.m[0][2] += wa;
        self.m[1][1] += wp * phi;
        self.m[1][2] += wp * a;
        self.m[2][2] += wa * a;
        self.b[0] += w * y;
        self.b[1] += wp * y;
        self.b[2] += wa * y;
    }

    /// Solve on the free unknowns (`free` bit k set) with the others held at zero, by
    /// Cholesky of the column-scaled system (unit diagonal); `None` when (nearly)
    /// singular.
    fn solve_free(&self, free: u8) -> Option<[f64; 3]> {
        const PIVOT: f64 = 1e-13;
        let m = &self.m;
        let inv_sqrt = |v: f64| (v > 0.0 && v.is_finite()).then(|| 1.0 / v.sqrt());
        let mut x = [0.0; 3];
        match free {
            0b111 => {
                let (d0, d1, d2) = (inv_sqrt(m[0][0])?, inv_sqrt(m[1][1])?, inv_sqrt(m[2][2])?);
                let (a, b, c) = (m[0][1] * d0 * d1, m[0][2] * d0 * d2, m[1][2] * d1 * d2);
                let p1 = 1.0 - a * a;
                if p1.is_nan() || p1 <= PIVOT {
                    return None;
                }
                let l11 = p1.sqrt();
                let l21 = (c - a * b) / l11;
                let p2 = 1.0 - b * b - l21 * l21;
                if p2.is_nan() || p2 <= PIVOT {
                    return None;
                }
                let l22 = p2.sqrt();
                let z0 = self.b[0] * d0;
                let z1 = (self.b[1] * d1 - a * z0) / l11;
                let z2 = (self.b[2] * d2 - b * z0 - l21 * z1) / l22;
                let u2 = z2 / l22;
                let u1 = (z1 - l21 * u2) / l11;
                let u0 = z0 - a * u1 - b * u2;
                x = [u0 * d0, u1 * d1, u2 * d2];
            }
            0b011 | 0b101 | 0b110 => {
                let (i, j) = match free {
                    0b011 => (0, 1),
                    0b101 => (0, 2),
                    _ => (1, 2),
                };
                let (di, dj) = (inv_sqrt(m[i][i])?, inv_sqrt(m[j][j])?);
                let a = m[i][j] * di * dj;
                let det = 1.0 - a * a;
                if det.is_nan() || det <= PIVOT {
                    return None;
                }
                let (bi, bj) = (self.b[i] * di, self.b[j] * dj);
                x[i] = (bi - a * bj) / det * di;
                x[j] = (bj - a * bi) / det * dj;
            }
            0b001 | 0b010 | 0b100 => {
                let i = free.trailing_zeros() as usize;
                let mii = m[i][i];
                if !(mii > 0.0 && mii.is_finite()) {
                    return None;
                }
                x[i] = self.b[i] / mii;
            }
            _ => {}
        }
        x.iter().all(|v| v.is_finite()).then_some(x)
    }

    /// `x^T M x - 2 x^T b` (the weighted sum of squares up to a constant).
    fn quad(&self, x: &[f64; 3]) -> f64 {
        let m = &self.m;
        let mx = [
            m[0][0] * x[0] + m[0][1] * x[1] + m[0][2] * x[2],
            m[0][1] * x[0] + m[1][1] * x[1] + m[1][2] * x[2],
            m[0][2] * x[0] + m[1][2] * x[1] + m[2][2] * x[2],
        ];
        (0..3).map(|k| x[k] * (mx[k] - 2.0 * self.b[k])).sum()
    }

    /// Least squares with every unknown nonnegative (`fc >= fc_min`, `fs >= fc`,
    /// `sigma2 >= 0`): the unconstrained solution when it is feasible, else the best
    /// feasible solution over the faces (an exhaustive active set; three unknowns).
    fn solve_nonneg(&self) -> [f64; 3] {
        if let Some(x) = self.solve_free(0b111) {
            if x.iter().all(|v| *v >= 0.0) {
                return x;
            }
        }
        let mut best = ([0.0; 3], 0.0);
        for free in [0b011u8, 0b101, 0b110, 0b001, 0b010, 0b100] {
            if let Some(x) = self.solve_free(free) {
                if x.iter().all(|v| *v >= 0.0) {
                    let q = self.quad(&x);
                    if q < best.1 {
                        best = (x, q);
                    }
                }
            }
        }
        best.0
    }
}

/// One direction's points and work buffers of the separable (variable projection)
/// problem: for fixed `vs` the curve is linear in `(fc, fs - fc, sigma2)`, solved in
/// closed form, so the nonlinear search is over `ln vs` alone (Golub and Pereyra 1973).
struct Sep<'a> {
    a: &'a [f64],
    y: &'a [f64],
    /// Smallest `fc` (a tiny positive force: the model needs `fc > 0`).
    fc_min: f64,
    /// Search interval of `ln vs` (the profile is flat far outside the speed range).
    ln_lo: f64,
    ln_hi: f64,
    phi: Vec<f64>,
}

impl<'a> Sep<'a> {
    fn new(a: &'a [f64], y: &'a [f64], fscale: f64) -> Self {
        let amin = a.iter().copied().fold(f64::INFINITY, f64::min);
        let amax = a.iter().copied().fold(0.0, f64::max);
        Self {
            a,
            y,
            fc_min: 1e-9 * fscale,
            ln_lo: amin.ln() - 7.0,
            ln_hi: amax.ln() + 7.0,
            phi: vec![0.0; a.len()],
        }
    }

    /// Normal equations at the `phi` in the buffer.
    fn normal(&self, w: &[f64]) -> Normal {
        let mut ne = Normal::default();
        for (((&phi, &a), &y), &wi) in self.phi.iter().zip(self.a).zip(self.y).zip(w) {
            if wi != 0.0 {
                ne.add(phi, a, y - self.fc_min, wi);
            }
        }
        ne
    }

    fn params(&self, x: &[f64; 3], vs: f64) -> [f64; 4] {
        let fc = self.fc_min + x[0];
        [fc, fc + x[1], x[2], vs]
    }

    /// The variable-projection objective: the weighted sum of squares at the best
    /// linear parameters for `vs = exp(ln_vs)`, and the four parameters.
    fn profile(&mut self, w: &[f64], ln_vs: f64) -> (f64, [f64; 4]) {
        let vs = ln_vs.exp();
        if !(ln_vs >= self.ln_lo && ln_vs <= self.ln_hi) {
            return (f64::INFINITY, [f64::NAN; 4]);
        }
        fill_phi(self.a, vs, &mut self.phi);
        let x = self.normal(w).solve_nonneg();
        let p = self.params(&x, vs);
        let d = p[1] - p[0];
        let mut ss = 0.0;
        for (((&phi, &a), &y), &wi) in self.phi.iter().zip(self.a).zip(self.y).zip(w) {
            let e = y - (p[0] + d * phi + p[2] * a);
            ss += wi * e * e;
        }
        (ss, p)
    }

    fn residuals(&self, p: &[f64; 4]) -> Vec<f64> {
        self.a
            .iter()
            .zip(self.y)
            .map(|(&ai, &yi)| yi - curve(p, ai))
            .collect()
    }
}

/// Minimum of the weighted profile over `ln vs` by Nelder-Mead from `ln_vs0`.
/// Returns the parameters and the evaluations used.
fn vp_minimize(
    sep: &mut Sep,
    w: &[f64],
    ln_vs0: f64,
    step: f64,
    nm: &NmOptions,
    floor: f64,
) -> ([f64; 4], usize) {
    // `floor` (a constant) makes the relative stopping rule of the simplex absolute
    // near a zero sum of squares (noise-free data)
    let mut f = |x: f64| sep.profile(w, x).0 + floor;
    // bracket: three nodes `step` apart, moved downhill with a doubling step until
    // the middle one is the lowest
    let (mut xa, mut xb, mut xc) = (ln_vs0 - step, ln_vs0, ln_vs0 + step);
    let (mut fa, mut fb, mut fc) = (f(xa), f(xb), f(xc));
    let mut evals = 3;
    let mut h = step;
    while evals < 40 {
        if fa < fb && fa <= fc {
            h *= 2.0;
            (xc, fc, xb, fb) = (xb, fb, xa, fa);
            xa = xb - h;
            fa = f(xa);
        } else if fc < fb {
            h *= 2.0;
            (xa, fa, xb, fb) = (xb, fb, xc, fc);
            xc = xb + h;
            fc = f(xc);
        } else {
            break;
        }
        evals += 1;
    }
    // Nelder-Mead from the vertex of the parabola through the bracket (the best node
    // when that is not lower), with a small simplex: the parabola is close to the
    // minimum of the smooth profile, and the simplex expands if it is not
    let (da, dc) = (xb - xa, xb - xc);
    let den = da * (fb - fc) - dc * (fb - fa);
    let mut x0 = xb;
    if den != 0.0 && den.is_finite() {
        let xp = xb - 0.5 * (da * da * (fb - fc) - dc * dc * (fb - fa)) / den;
        if xp > xa && xp < xc {
            let fp = f(xp);
            evals += 1;
            if fp < fb {
                x0 = xp;
            }
        }
    }
    let simplex = (1e-3 * h).max(1e-7);
    let mut g = |x: &[f64]| f(x[0]);
    let r = minimize(&mut g, &[x0], &[simplex], nm);
    let (_, p) = sep.profile(w, r.x[0]);
    (p, evals + r.evals + 1)
}

/// Outcome of one IRLS path.
struct Outcome {
    p: [f64; 4],
    residuals: Vec<f64>,
    weights: Vec<f64>,
    scale: f64,
    iterations: usize,
    converged: bool,
    evals: usize,
}

/// Role of an IRLS run.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Stage {
    /// A pass that only provides the start of the next one: weights settled to 1e-2.
    Pre,
    /// Followed by the least-squares refit of the kept points.
    Refit,
    /// The result: the last weighted problem is solved again to full precision.
    Polish,
}

/// Settings shared by the IRLS runs of one direction.
struct Cfg {
    max_outer: usize,
    tol: f64,
    scale_floor: f64,
    nm: NmOptions,
    /// Looser simplex tolerance of the IRLS rounds (whose weights change again).
    nm_loose: NmOptions,
    /// Loosest tolerance, for the passes that only give the start of the next.
    nm_pre: NmOptions,
    /// Added to the profile objective (see [`vp_minimize`]).
    obj_floor: f64,
}

/// Largest relative change between two parameter vectors.
fn max_rel_change(p: &[f64; 4], q: &[f64; 4]) -> f64 {
    p.iter()
        .zip(q)
        .map(|(a, b)| (a - b).abs() / a.abs().max(b.abs()).max(1e-300))
        .fold(0.0, f64::max)
}

/// IRLS (eqs. 19-24): weights from the residuals at the current parameters and their
/// robust scale, then the weighted profile minimised over `ln vs`, until the weights
/// or the parameters settle.
fn irls_vp(sep: &mut Sep, p0: [f64; 4], weighting: Weighting, cfg: &Cfg, stage: Stage) -> Outcome {
    let mut p = p0;
    let mut e = sep.residuals(&p);
    let scale_of = |e: &[f64]| robust_scale(e).max(cfg.scale_floor);
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

/// Least squares on the points IRLS kept, re-checking the rejections (`|e| > k1*s`,
/// `s` the scale of the kept residuals at the refit) until the kept set settles.
fn refit_kept(sep: &mut Sep, out: &mut Outcome, k1: f64, cfg: &Cfg) {
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

/// Median of a scratch buffer (reordered; NaN-free input).
fn median_mut(b: &mut [f64]) -> f64 {
    let n = b.len();
    let (lo, m, _) = b.select_nth_unstable_by(n / 2, |x, y| x.total_cmp(y));
    let m = *m;
    if n % 2 == 1 {
        m
    } else {
        0.5 * (m + lo.iter().copied().fold(f64::NEG_INFINITY, f64::max))
    }
}

/// Nodes of the start grid over `ln vs`: from half the slowest to twice the fastest
/// speed.
fn grid_nodes(a: &[f64], count: usize) -> Vec<f64> {
    let amin = a.iter().copied().fold(f64::INFINITY, f64::min);
    let amax = a.iter().copied().fold(0.0, f64::max);
    let (lo, hi) = ((amin * 0.5).ln(), (amax * 2.0).ln());
    (0..count)
        .map(|k| (lo + (hi - lo) * k as f64 / (count - 1) as f64).exp())
        .collect()
}

/// Number of `ln vs` nodes of the start grids.
const GRID_NODES: usize = 17;

/// Start values `(fc, fs, sigma2, vs)` from the `ln vs` grid (Huber).
///
/// At each node a few Huber IRLS steps of the linear fit, scored by the median
/// absolute residual.
fn start_values_huber(sep: &mut Sep) -> Option<[f64; 4]> {
    let n = sep.a.len();
    let huber = Weighting::huber();
    let mut w = vec![1.0; n];
    let mut e = vec![0.0; n];
    let mut buf = vec![0.0; n];
    let mut best: Option<(f64, [f64; 4])> = None;
    let fscale = sep.fc_min * 1e9;
    for vs in grid_nodes(sep.a, GRID_NODES) {
        fill_phi(sep.a, vs, &mut sep.phi);
        w.iter_mut().for_each(|v| *v = 1.0);
        let mut score = f64::INFINITY;
        let mut p = [f64::NAN; 4];
        for it in 0..4 {
            p = sep.params(&sep.normal(&w).solve_nonneg(), vs);
            let d = p[1] - p[0];
            for (((ei, &phi), &a), &y) in e.iter_mut().zip(&sep.phi).zip(sep.a).zip(sep.y) {
                *ei = y - (p[0] + d * phi + p[2] * a);
            }
            buf.iter_mut().zip(&e).for_each(|(b, x)| *b = *x);
            let med = median_mut(&mut buf);
            buf.iter_mut()
                .zip(&e)
                .for_each(|(b, x)| *b = (x - med).abs());
            let s = (1.4826 * median_mut(&mut buf)).max(1e-12 * fscale);
            if it == 3 {
                buf.iter_mut().zip(&e).for_each(|(b, x)| *b = x.abs());
                score = median_mut(&mut buf);
                break;
            }
            for (wi, ei) in w.iter_mut().zip(&e) {
                *wi = huber.weight(ei / s);
            }
        }
        if score.is_finite() && best.is_none_or(|(b, _)| score < b) {
            best = Some((score, p));
        }
    }
    best.map(|b| b.1)
}

/// Elemental subsets (three distinct indices below `n`) from a fixed-seed generator,
/// so that fits are reproducible: one point from each third of the speed range (by
/// rank), so that the three rows determine the level at low speed, the Coulomb level
/// and the viscous slope.
fn elemental_seeds(a: &[f64], count: usize) -> Vec<[usize; 3]> {
    let n = a.len();
    let mut by_speed: Vec<usize> = (0..n).collect();
    by_speed.sort_by(|&i, &j| a[i].total_cmp(&a[j]));
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut next = |m: usize| {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) % m.max(1) as u64) as usize
    };
    let (t1, t2) = (n / 3, (2 * n) / 3);
    let mut out = Vec::with_capacity(count);
    if t1 == 0 || t2 == t1 {
        return out;
    }
    while out.len() < count {
        out.push([
            by_speed[next(t1)],
            by_speed[t1 + next(t2 - t1)],
            by_speed[t2 + next(n - t2)],
        ]);
    }
    out
}

/// Least-trimmed-squares work at one `ln vs` node (the `phi` of the node in `sep`).
struct Lts {
    h: usize,
    r2: Vec<f64>,
    order: Vec<usize>,
}

impl Lts {
    /// Fit on the points `sub`.
    fn fit(sep: &Sep, sub: &[usize], vs: f64) -> [f64; 4] {
        let mut ne = Normal::default();
        for &i in sub {
            ne.add(sep.phi[i], sep.a[i], sep.y[i] - sep.fc_min, 1.0);
        }
        sep.params(&ne.solve_nonneg(), vs)
    }

    /// One concentration step (Rousseeuw and Van Driessen 2006): the trimmed sum of
    /// `p` (the `h` smallest squared residuals) and the fit on those `h` points, whose
    /// trimmed sum is no larger.
    fn cstep(&mut self, sep: &Sep, p: &[f64; 4]) -> (f64, [f64; 4]) {
        let d = p[1] - p[0];
        for i in 0..sep.a.len() {
            let e = sep.y[i] - (p[0] + d * sep.phi[i] + p[2] * sep.a[i]);
            self.r2[i] = e * e;
        }
        let r2 = &self.r2;
        let h = self.h;
        if h < self.order.len() {
            self.order
                .select_nth_unstable_by(h, |&i, &j| r2[i].total_cmp(&r2[j]));
        }
        let sum = self.order[..h].iter().map(|&i| r2[i]).sum();
        (sum, Lts::fit(sep, &self.order[..h], p[3]))
    }

    /// Concentration steps from `p` until the trimmed sum stops decreasing (at most
    /// `max_steps`); the best trimmed sum, its fit and its subset in `self.order[..h]`.
    fn concentrate(&mut self, sep: &Sep, p: [f64; 4], max_steps: usize) -> (f64, [f64; 4]) {
        let (mut obj, mut next) = self.cstep(sep, &p);
        let mut cur = p;
        for _ in 1..max_steps {
            let (o, nx) = self.cstep(sep, &next);
            if o.is_nan() || o >= obj * (1.0 - 1e-12) {
                if o <= obj {
                    return (o, next);
                }
                // the last step did not improve: restore the subset of `cur`
                self.cstep(sep, &cur);
                return (obj, cur);
            }
            cur = next;
            obj = o;
            next = nx;
        }
        (obj, cur)
    }
}

/// Start values `(fc, fs, sigma2, vs)` from the `ln vs` grid (least trimmed squares).
///
/// At each node the curve is linear in `(fc, fs, sigma2)`; a least-trimmed-squares
/// fit there (on three quarters of the points) resists gross errors also at the ends of
/// the speed range, where a single point has high leverage on `sigma2` and `fc` and
/// a monotone M-estimate (Huber) follows it. The node with the smallest trimmed sum
/// gives the start: the high-breakdown first stage of an MM-estimate (Yohai 1987).
///
/// The nodes are visited in order of speed; at each, concentration steps start from
/// the plain fit, from the best subsets of the previous node and of all nodes so far,
/// and from a few fresh elemental (three-point) subsets, so that a good subset found
/// at one node is carried to its neighbours and the elemental subsets are spread over
/// the grid instead of being repeated at every node.
fn start_values_lts(sep: &mut Sep) -> Option<[f64; 4]> {
    let n = sep.a.len();
    let h = (3 * n).div_ceil(4).min(n);
    const SEEDS_PER_NODE: usize = 3;
    let nodes = grid_nodes(sep.a, GRID_NODES);
    let seeds = elemental_seeds(sep.a, SEEDS_PER_NODE * nodes.len());
    let mut lts = Lts {
        h,
        r2: vec![0.0; n],
        order: (0..n).collect(),
    };
    let all: Vec<usize> = (0..n).collect();
    let mut prev: Option<Vec<usize>> = None;
    let mut global: Option<(f64, [f64; 4], Vec<usize>)> = None;
    let mut node_subsets: Vec<Option<Vec<usize>>> = vec![None; nodes.len()];
    let mut found_at = 0;
    for (k, &vs) in nodes.iter().enumerate() {
        fill_phi(sep.a, vs, &mut sep.phi);
        let mut starts: Vec<[f64; 4]> = Vec::with_capacity(SEEDS_PER_NODE + 3);
        starts.push(Lts::fit(sep, &all, vs));
        if let Some(s) = &prev {
            starts.push(Lts::fit(sep, s, vs));
        }
        if let Some((_, _, s)) = &global {
            if prev.as_ref() != Some(s) {
                starts.push(Lts::fit(sep, s, vs));
            }
        }
        for sd in seeds.iter().skip(k * SEEDS_PER_NODE).take(SEEDS_PER_NODE) {
            starts.push(Lts::fit(sep, sd, vs));
        }
        // two concentration steps from each start, the best to convergence
        let mut node_best: Option<(f64, [f64; 4])> = None;
        for p0 in starts {
            let (obj, p) = lts.concentrate(sep, p0, 2);
            if obj.is_finite() && node_best.is_none_or(|b| obj < b.0) {
                node_best = Some((obj, p));
            }
        }
        let Some((_, p)) = node_best else {
            continue;
        };
        let (obj, p) = lts.concentrate(sep, p, 8);
        let mut sub = lts.order[..h].to_vec();
        sub.sort_unstable();
        node_subsets[k] = Some(sub.clone());
        prev = Some(sub.clone());
        if global.as_ref().is_none_or(|g| obj < g.0) {
            global = Some((obj, p, sub));
            found_at = k;
        }
    }
    // the best subset carried back to the nodes visited before it was found (the
    // later ones started from it)
    let (_, _, best_sub) = global.clone()?;
    for (k, &vs) in nodes.iter().enumerate().take(found_at) {
        if node_subsets[k].as_ref() == Some(&best_sub) {
            continue;
        }
        fill_phi(sep.a, vs, &mut sep.phi);
        let (obj, p) = lts.concentrate(sep, Lts::fit(sep, &best_sub, vs), 8);
        if obj.is_finite() && global.as_ref().is_none_or(|g| obj < g.0) {
            global = Some((obj, p, best_sub.clone()));
        }
    }
    global.map(|g| g.1)
}

/// Keep start values inside the model's domain (all positive, `fs > fc`).
fn clamp_start(p: Option<[f64; 4]>, a: &[f64], fscale: f64) -> [f64; 4] {
    let amin = a.iter().copied().fold(f64::INFINITY, f64::min);
    let amax = a.iter().copied().fold(0.0, f64::max);
    let mut p =
        p.filter(|p| p.iter().all(|v| v.is_finite()))
            .unwrap_or([fscale, 1.5 * fscale, 0.0, amax]);
    p[0] = p[0].max(1e-3 * fscale);
    p[1] = p[1].max(p[0] * 1.01 + 1e-6 * fscale);
    p[2] = p[2].max(1e-6 * fscale / amax.max(1e-300));
    p[3] = p[3].clamp(amin * 0.5, amax * 2.0);
    p
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
    let mut sep = Sep::new(a, y, fscale);
    let scale_floor = opts.scale_floor.max(1e-6 * fscale);
    let cfg = Cfg {
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
    };
    let reject_at = match opts.weighting {
        Weighting::Igg { k1, .. } => Some(k1),
        Weighting::Tukey { c } => Some(c),
        _ => None,
    };
    // One path: from a start, an optional IRLS pass with another weight function,
    // IRLS, then (rejecting weight functions) the least-squares refit on the kept points.
    let path = |sep: &mut Sep, p0: [f64; 4], pre: Option<Weighting>| -> Outcome {
        let mut p0 = p0;
        let mut evals = 0;
        if let Some(w) = pre {
            let o = irls_vp(sep, p0, w, &cfg, Stage::Pre);
            p0 = o.p;
            evals = o.evals;
        }
        let refit = opts.refit_kept && reject_at.is_some();
        let stage = if refit { Stage::Refit } else { Stage::Polish };
        let mut out = irls_vp(sep, p0, opts.weighting, &cfg, stage);
        out.evals += evals;
        if let (true, Some(k1)) = (refit, reject_at) {
            refit_kept(sep, &mut out, k1, &cfg);
        }
        out
    };
    let huber_start = clamp_start(start_values_huber(&mut sep), a, fscale);
    let out = if reject_at.is_some() {
        // Redescending weights (IGG, Tukey) settle on the set of rejected points near
        // their start. Two starts, as in MM-estimation (Yohai 1987): (a) a Huber pass
        // (monotone, unique fixed point) from the Huber grid; (b) a Tukey pass from the
        // least-trimmed-squares grid, which also resists gross errors of high leverage
        // (the fastest and slowest points) that a Huber fit follows. The fit with the
        // smaller bounded (Tukey) loss at a common scale wins, as in the choice among
        // local minima of an MM-estimate.
        let fa = path(&mut sep, huber_start, Some(Weighting::huber()));
        let lts_start = clamp_start(start_values_lts(&mut sep), a, fscale);
        let fb = path(&mut sep, lts_start, Some(Weighting::tukey()));
        // Tukey's rho at a common scale (the smaller robust scale of the two): a
        // rejected point costs the same in both, a kept one its misfit
        let s = robust_scale(&fa.residuals)
            .min(robust_scale(&fb.residuals))
            .max(scale_floor);
        let c = 4.685;
        let rho = |o: &Outcome| -> f64 {
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
        best
    } else {
        path(&mut sep, huber_start, None)
    };
    if !out.p.iter().all(|v| v.is_finite()) {
        return Err(Error::Data(format!(
            "{label} direction: the Stribeck curve could not be evaluated at the start values; check the data for extreme values"
        )));
    }
    let p = out.p;
    // covariance from the weighted Jacobian at the optimum
    let mut jtwj = Matrix4::<f64>::zeros();
    for (i, &ai) in a.iter().enumerate() {
        let wi = out.weights[i];
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
    let d = Vector4::from_fn(|k, _| jtwj[(k, k)].sqrt());
    let mut std_err = vec![f64::NAN; 4];
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
