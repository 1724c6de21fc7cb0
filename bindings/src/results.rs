//! The results the bindings return: frozen classes with typed, read-only attributes
//! (`lugre._core.SimulationResult`, `StaticFitResult`, ...), in place of dicts whose keys
//! the facade had to spell right. Arrays are NumPy arrays made once from the core's
//! vectors (no copy on access); lists and numbers convert on access. Each has a `__repr__`
//! that says what the result holds. No numerics here.

use lugre::estimate::{DirectionFit, DynamicFit, GridFit, LinearFit, Plateaus, StaticFit};
use lugre::servo::SimResult;
use numpy::{IntoPyArray, PyArray1, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;

type Array = Py<PyArray1<f64>>;

fn array(py: Python<'_>, v: Vec<f64>) -> Array {
    v.into_pyarray(py).unbind()
}

/// A number as Python's `format(x, ".6g")` writes it (six significant digits, no
/// trailing zeros), for the representations.
fn g(x: f64) -> String {
    if x.is_nan() {
        return "nan".into();
    }
    if x.is_infinite() {
        return if x > 0.0 { "inf" } else { "-inf" }.into();
    }
    if x == 0.0 {
        return "0".into();
    }
    let e = format!("{x:.5e}");
    let (mant, exp) = e.split_once('e').unwrap_or((&e, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    if (-4..6).contains(&exp) {
        let s = format!("{:.*}", (5 - exp) as usize, x);
        trim(&s).to_string()
    } else {
        format!(
            "{}e{}{:02}",
            trim(mant),
            if exp < 0 { '-' } else { '+' },
            exp.abs()
        )
    }
}

fn trim(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

/// Samples of an array whose weight is zero (rejected points).
fn zeros(py: Python<'_>, a: &Array) -> usize {
    let a = a.bind(py).readonly();
    a.as_slice()
        .map_or(0, |w| w.iter().filter(|&&x| x == 0.0).count())
}

/// One closed-loop or open-loop simulation (`simulate`, `simulate_batch`): the arrays at
/// the sample times.
#[pyclass(module = "lugre._core", frozen, get_all)]
pub(crate) struct SimulationResult {
    /// Position [m].
    x: Array,
    /// Velocity [m/s].
    v: Array,
    /// Bristle deflection [m].
    z: Array,
    /// Current [A] (actual with a current loop, else the command).
    i: Array,
    /// Friction force [N].
    friction: Array,
    /// Motor force acting on the (motor) mass [N].
    force: Array,
}

impl SimulationResult {
    pub(crate) fn new(py: Python<'_>, r: SimResult) -> Self {
        SimulationResult {
            x: array(py, r.x),
            v: array(py, r.v),
            z: array(py, r.z),
            i: array(py, r.i),
            friction: array(py, r.friction),
            force: array(py, r.force),
        }
    }
}

#[pymethods]
impl SimulationResult {
    fn __repr__(&self, py: Python<'_>) -> String {
        let x = self.x.bind(py).readonly();
        let xs = x.as_slice().unwrap_or(&[]);
        let span = if xs.is_empty() {
            String::new()
        } else {
            let lo = xs.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            format!("; x in [{}, {}] m", g(lo), g(hi))
        };
        format!(
            "SimulationResult({} samples of x, v, z, i, friction, force{span})",
            x.len()
        )
    }
}

/// The Stribeck fit of one direction (`StaticFitResult.positive`, `.negative`); all
/// parameters positive, also for `v < 0`.
#[pyclass(module = "lugre._core", frozen, get_all)]
pub(crate) struct DirectionFitResult {
    /// Coulomb level [N].
    fc: f64,
    /// Static (break-away) level [N].
    fs: f64,
    /// Viscous coefficient [N s/m].
    sigma2: f64,
    /// Stribeck velocity [m/s].
    vs: f64,
    /// Standard errors of `fc, fs, sigma2, vs` (NaN where they cannot be computed).
    std_err: Vec<f64>,
    /// Their joint 4x4 covariance, row by row.
    cov: Vec<f64>,
    /// Lower ends of the 95 % intervals.
    ci_low: Vec<f64>,
    /// Upper ends of the 95 % intervals.
    ci_high: Vec<f64>,
    /// Indices of this direction's points in the input.
    indices: Vec<usize>,
    /// Final weight of each of these points (0: rejected).
    weights: Array,
    /// `F - F_model` at each of these points [N] (sign of the input).
    residuals: Array,
    /// Robust residual scale [N].
    scale: f64,
    /// Weighted residual standard deviation of the kept points [N].
    sigma: f64,
    /// IRLS iterations.
    iterations: usize,
    /// Whether the weights settled within the iteration limit.
    converged: bool,
    /// Evaluations of the objective.
    evaluations: usize,
}

impl DirectionFitResult {
    fn new(py: Python<'_>, d: DirectionFit) -> Self {
        DirectionFitResult {
            fc: d.set.fc,
            fs: d.set.fs,
            sigma2: d.set.sigma2,
            vs: d.set.vs,
            std_err: d.std_err,
            cov: d.cov,
            ci_low: d.ci_low,
            ci_high: d.ci_high,
            indices: d.indices,
            weights: array(py, d.weights),
            residuals: array(py, d.residuals),
            scale: d.scale,
            sigma: d.sigma,
            iterations: d.iterations,
            converged: d.converged,
            evaluations: d.evaluations,
        }
    }

    fn repr(&self, py: Python<'_>) -> String {
        format!(
            "DirectionFitResult(fc={}, fs={}, sigma2={}, vs={}; {} points, {} rejected, \
             scale {} N, {} iterations, {})",
            g(self.fc),
            g(self.fs),
            g(self.sigma2),
            g(self.vs),
            self.indices.len(),
            zeros(py, &self.weights),
            g(self.scale),
            self.iterations,
            if self.converged {
                "converged"
            } else {
                "NOT converged"
            }
        )
    }
}

#[pymethods]
impl DirectionFitResult {
    fn __repr__(&self, py: Python<'_>) -> String {
        self.repr(py)
    }
}

/// The robust per-direction Stribeck fit (`fit_static_points`).
#[pyclass(module = "lugre._core", frozen, get_all)]
pub(crate) struct StaticFitResult {
    /// The fit of the points with `v > 0`.
    positive: Py<DirectionFitResult>,
    /// The fit of the points with `v < 0`.
    negative: Py<DirectionFitResult>,
    /// Final weight of every input point (0 for rejected and zero-speed points).
    weights: Array,
    /// Indices of the points rejected as gross errors.
    rejected: Vec<usize>,
    /// Points at zero speed (ignored).
    n_zero_speed: usize,
    /// The weight function's name.
    weighting: String,
    /// What the fit could not determine, in words.
    notes: Vec<String>,
}

impl StaticFitResult {
    pub(crate) fn new(py: Python<'_>, r: StaticFit) -> PyResult<Self> {
        Ok(StaticFitResult {
            positive: Py::new(py, DirectionFitResult::new(py, r.positive))?,
            negative: Py::new(py, DirectionFitResult::new(py, r.negative))?,
            weights: array(py, r.weights),
            rejected: r.rejected,
            n_zero_speed: r.n_zero_speed,
            weighting: r.weighting,
            notes: r.notes,
        })
    }
}

#[pymethods]
impl StaticFitResult {
    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "StaticFitResult({} weights, {} points, {} rejected, {} at zero speed, {} notes; \
             positive={}, negative={})",
            self.weighting,
            self.weights.bind(py).len(),
            self.rejected.len(),
            self.n_zero_speed,
            self.notes.len(),
            self.positive.get().repr(py),
            self.negative.get().repr(py)
        )
    }
}

/// Steady-state points from a raw constant-velocity record (`plateaus`).
#[pyclass(module = "lugre._core", frozen, get_all)]
pub(crate) struct PlateauResult {
    /// Mean measured velocity of each point [m/s].
    v: Array,
    /// Mean force of each point [N].
    #[pyo3(name = "F")]
    f: Array,
    /// Standard deviation of the force samples behind each point [N].
    #[pyo3(name = "F_std")]
    f_std: Array,
    /// Samples averaged into each point.
    n_samples: Vec<usize>,
    /// Index of the plateau (segment) of each point.
    plateau: Vec<usize>,
    /// First sample of each detected plateau.
    segment_start: Vec<usize>,
    /// One past the last sample of each detected plateau.
    segment_end: Vec<usize>,
    /// Nominal velocity of each detected plateau [m/s].
    segment_velocity: Vec<f64>,
    /// First sample used of each detected plateau.
    segment_first_used: Vec<usize>,
    /// Whether each detected plateau settled.
    segment_settled: Vec<bool>,
    /// Whether each sample went into a point.
    used: Vec<bool>,
    /// What was skipped and why.
    notes: Vec<String>,
}

impl PlateauResult {
    pub(crate) fn new(py: Python<'_>, p: Plateaus) -> Self {
        PlateauResult {
            v: array(py, p.v),
            f: array(py, p.f),
            f_std: array(py, p.f_std),
            n_samples: p.n_samples,
            plateau: p.plateau,
            segment_start: p.segment_start,
            segment_end: p.segment_end,
            segment_velocity: p.segment_velocity,
            segment_first_used: p.segment_first_used,
            segment_settled: p.segment_settled,
            used: p.used,
            notes: p.notes,
        }
    }
}

#[pymethods]
impl PlateauResult {
    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "PlateauResult({} points from {} of {} plateaus settled, {} of {} samples used, \
             {} notes)",
            self.v.bind(py).len(),
            self.segment_settled.iter().filter(|&&s| s).count(),
            self.segment_settled.len(),
            self.used.iter().filter(|&&u| u).count(),
            self.used.len(),
            self.notes.len()
        )
    }
}

/// sigma0 and sigma1 from a closed-loop record (`fit_dynamic_record`).
#[pyclass(module = "lugre._core", frozen, get_all)]
pub(crate) struct DynamicFitResult {
    /// Bristle stiffness [N/m].
    sigma0: f64,
    /// Bristle damping [N s/m].
    sigma1: f64,
    /// Standard errors of sigma0, sigma1.
    std_err: Vec<f64>,
    /// Lower ends of the 95 % intervals.
    ci_low: Vec<f64>,
    /// Upper ends of the 95 % intervals.
    ci_high: Vec<f64>,
    /// Half-widths of the intervals relative to the estimates.
    rel_ci_half_width: Vec<f64>,
    /// Whether the record determines each parameter.
    identifiable: Vec<bool>,
    /// Correlation of the ln sigma0 and ln sigma1 estimates.
    correlation: f64,
    /// Lag-one autocorrelation of the kept residuals.
    residual_autocorrelation: f64,
    /// Verdicts in words.
    notes: Vec<String>,
    /// Measured minus simulated position [m].
    residuals: Array,
    /// Final IRLS weight of each sample.
    weights: Array,
    /// Weighted rms position error [m].
    rms_error: f64,
    /// Largest kept position error [m].
    max_error: f64,
    /// The objective at the estimate.
    objective: f64,
    /// Robust residual scale [m].
    scale: f64,
    /// IRLS iterations.
    iterations: usize,
    /// Closed-loop simulations run.
    evaluations: usize,
    /// Whether the weights settled within the iteration limit.
    converged: bool,
}

impl DynamicFitResult {
    pub(crate) fn new(py: Python<'_>, r: DynamicFit) -> Self {
        DynamicFitResult {
            sigma0: r.sigma0,
            sigma1: r.sigma1,
            std_err: r.std_err,
            ci_low: r.ci_low,
            ci_high: r.ci_high,
            rel_ci_half_width: r.rel_ci_half_width,
            identifiable: r.identifiable,
            correlation: r.correlation,
            residual_autocorrelation: r.residual_autocorrelation,
            notes: r.notes,
            residuals: array(py, r.residuals),
            weights: array(py, r.weights),
            rms_error: r.rms_error,
            max_error: r.max_error,
            objective: r.objective,
            scale: r.scale,
            iterations: r.iterations,
            evaluations: r.evaluations,
            converged: r.converged,
        }
    }
}

#[pymethods]
impl DynamicFitResult {
    fn __repr__(&self) -> String {
        let verdict = |k: usize| match self.identifiable.get(k) {
            Some(true) => "determined",
            _ => "not determined",
        };
        format!(
            "DynamicFitResult(sigma0={} ({}), sigma1={} ({}); rms error {} m, {} iterations, \
             {} evaluations, {})",
            g(self.sigma0),
            verdict(0),
            g(self.sigma1),
            verdict(1),
            g(self.rms_error),
            self.iterations,
            self.evaluations,
            if self.converged {
                "converged"
            } else {
                "NOT converged"
            }
        )
    }
}

/// A robust linear fit `y ~ X b` by IRLS (`irls_linear`, `GridFitResult.fit`).
#[pyclass(module = "lugre._core", frozen, get_all)]
pub(crate) struct LinearFitResult {
    /// Coefficients, one per column.
    coef: Array,
    /// Weight of each row (0: rejected).
    weights: Array,
    /// `y - X b`.
    residuals: Array,
    /// Weighted sum of squares.
    sse: f64,
    /// Scale the weights were computed at.
    scale: f64,
}

impl LinearFitResult {
    pub(crate) fn new(py: Python<'_>, f: LinearFit) -> Self {
        LinearFitResult {
            coef: array(py, f.coef),
            weights: array(py, f.weights),
            residuals: array(py, f.residuals),
            sse: f.sse,
            scale: f.scale,
        }
    }

    fn repr(&self, py: Python<'_>) -> String {
        let coef = self.coef.bind(py).readonly();
        let c: Vec<String> = coef
            .as_slice()
            .unwrap_or(&[])
            .iter()
            .map(|&x| g(x))
            .collect();
        format!(
            "LinearFitResult(coef=[{}]; {} rows, {} rejected, sse {}, scale {})",
            c.join(", "),
            self.weights.bind(py).len(),
            zeros(py, &self.weights),
            g(self.sse),
            g(self.scale)
        )
    }
}

#[pymethods]
impl LinearFitResult {
    fn __repr__(&self, py: Python<'_>) -> String {
        self.repr(py)
    }
}

/// The best of a base design and its candidates (`irls_linear_grid`).
#[pyclass(module = "lugre._core", frozen, get_all)]
pub(crate) struct GridFitResult {
    /// Index of the chosen candidate, None for the base design alone.
    chosen: Option<usize>,
    /// The chosen fit.
    fit: Py<LinearFitResult>,
    /// Weighted sum of squares of the base design alone.
    base_sse: f64,
    /// Weighted sum of squares of each candidate.
    sse: Array,
}

impl GridFitResult {
    pub(crate) fn new(py: Python<'_>, r: GridFit) -> PyResult<Self> {
        Ok(GridFitResult {
            chosen: r.chosen,
            fit: Py::new(py, LinearFitResult::new(py, r.fit))?,
            base_sse: r.base_sse,
            sse: array(py, r.sse),
        })
    }
}

#[pymethods]
impl GridFitResult {
    fn __repr__(&self, py: Python<'_>) -> String {
        let chosen = self
            .chosen
            .map_or_else(|| "None (the base design)".to_string(), |k| k.to_string());
        format!(
            "GridFitResult(chosen={chosen} of {} candidates, base_sse {}; fit={})",
            self.sse.bind(py).len(),
            g(self.base_sse),
            self.fit.get().repr(py)
        )
    }
}
