//! Bindings of the estimators: convert in, run with the interpreter released, convert
//! the plain-data results into dicts of arrays and numbers.

use super::{interruptible, model_of, slice, to_py};
use crate::error::Error;
use crate::estimate::{
    fit_dynamic_with, fit_static, irls_linear as irls, irls_linear_grid as irls_grid,
    plateaus_from_recording, Design, DirectionFit, DynamicFitOptions, LinearFit, LinearIrlsOptions,
    PlateauOptions, StaticFitOptions, Weighting,
};
use crate::servo::Integrator;
use numpy::{IntoPyArray, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::borrow::Cow;

fn direction<'py>(py: Python<'py>, d: DirectionFit) -> PyResult<Bound<'py, PyDict>> {
    let o = PyDict::new(py);
    o.set_item("fc", d.set.fc)?;
    o.set_item("fs", d.set.fs)?;
    o.set_item("sigma2", d.set.sigma2)?;
    o.set_item("vs", d.set.vs)?;
    o.set_item("std_err", d.std_err)?;
    o.set_item("cov", d.cov)?;
    o.set_item("ci_low", d.ci_low)?;
    o.set_item("ci_high", d.ci_high)?;
    o.set_item("indices", d.indices)?;
    o.set_item("weights", d.weights.into_pyarray(py))?;
    o.set_item("residuals", d.residuals.into_pyarray(py))?;
    o.set_item("scale", d.scale)?;
    o.set_item("sigma", d.sigma)?;
    o.set_item("iterations", d.iterations)?;
    o.set_item("converged", d.converged)?;
    o.set_item("evaluations", d.evaluations)?;
    Ok(o)
}

/// Robust per-direction Stribeck fit of steady-state points; returns a dict.
#[pyfunction]
#[pyo3(signature = (v, f, weighting="igg", max_iter=20, scale_floor=0.0, max_start_points=400))]
pub(crate) fn fit_static_points<'py>(
    py: Python<'py>,
    v: PyReadonlyArray1<'py, f64>,
    f: PyReadonlyArray1<'py, f64>,
    weighting: &str,
    max_iter: usize,
    scale_floor: f64,
    max_start_points: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let r = (|| -> Result<_, Error> {
        let opts = StaticFitOptions {
            weighting: Weighting::from_name(weighting)?,
            max_iter,
            scale_floor,
            max_start_points,
            ..StaticFitOptions::default()
        };
        let (v, f) = (slice("v", &v)?, slice("F", &f)?);
        py.detach(|| fit_static(v, f, &opts))
    })()
    .map_err(|e| to_py(py, e))?;
    let o = PyDict::new(py);
    o.set_item("positive", direction(py, r.positive)?)?;
    o.set_item("negative", direction(py, r.negative)?)?;
    o.set_item("weights", r.weights.into_pyarray(py))?;
    o.set_item("rejected", r.rejected)?;
    o.set_item("n_zero_speed", r.n_zero_speed)?;
    o.set_item("weighting", r.weighting)?;
    o.set_item("notes", r.notes)?;
    Ok(o)
}

/// Steady-state points from a raw constant-velocity record; returns a dict.
#[pyfunction]
#[pyo3(signature = (t, x, force, v_ref=None, settle_fraction=0.3, velocity_tolerance=0.02, window=0, min_samples=20, chunks=1))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn plateaus<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'py, f64>,
    x: PyReadonlyArray1<'py, f64>,
    force: PyReadonlyArray1<'py, f64>,
    v_ref: Option<PyReadonlyArray1<'py, f64>>,
    settle_fraction: f64,
    velocity_tolerance: f64,
    window: usize,
    min_samples: usize,
    chunks: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let p = (|| -> Result<_, Error> {
        let opts = PlateauOptions {
            settle_fraction,
            velocity_tolerance,
            window,
            min_samples,
            chunks,
        };
        let (t, x, f) = (slice("t", &t)?, slice("x", &x)?, slice("F", &force)?);
        let vr = match &v_ref {
            Some(a) => Some(slice("v_ref", a)?),
            None => None,
        };
        py.detach(|| plateaus_from_recording(t, x, f, vr, &opts))
    })()
    .map_err(|e| to_py(py, e))?;
    let o = PyDict::new(py);
    o.set_item("v", p.v.into_pyarray(py))?;
    o.set_item("F", p.f.into_pyarray(py))?;
    o.set_item("F_std", p.f_std.into_pyarray(py))?;
    o.set_item("n_samples", p.n_samples)?;
    o.set_item("plateau", p.plateau)?;
    o.set_item("segment_start", p.segment_start)?;
    o.set_item("segment_end", p.segment_end)?;
    o.set_item("segment_velocity", p.segment_velocity)?;
    o.set_item("segment_first_used", p.segment_first_used)?;
    o.set_item("segment_settled", p.segment_settled)?;
    o.set_item("used", p.used)?;
    o.set_item("notes", p.notes)?;
    Ok(o)
}

/// sigma0 and sigma1 from a closed-loop position record; returns a dict.
#[pyfunction]
#[pyo3(signature = (model, t, x_ref, x, weighting="igg", c1=1.0, c2=0.0, sigma0_start=None, sigma1_start=None, grid=true, max_iter=20, scale_floor=0.0, substeps=1, integrator="exact"))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn fit_dynamic_record<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    t: PyReadonlyArray1<'py, f64>,
    x_ref: PyReadonlyArray1<'py, f64>,
    x: PyReadonlyArray1<'py, f64>,
    weighting: &str,
    c1: f64,
    c2: f64,
    sigma0_start: Option<f64>,
    sigma1_start: Option<f64>,
    grid: bool,
    max_iter: usize,
    scale_floor: f64,
    substeps: usize,
    integrator: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let m = model_of(py, model)?;
    let r = (|| -> Result<_, Error> {
        let mut opts = DynamicFitOptions {
            weighting: Weighting::from_name(weighting)?,
            c1,
            c2,
            sigma0_start,
            sigma1_start,
            grid,
            max_iter,
            scale_floor,
            ..DynamicFitOptions::default()
        };
        opts.sim.substeps = substeps;
        opts.sim.integrator = match integrator {
            "exact" => Integrator::Exact,
            "rk4" => Integrator::Rk4,
            other => {
                return Err(Error::input(
                    "integrator",
                    format!("unknown integrator \"{other}\": use \"exact\" or \"rk4\""),
                ))
            }
        };
        let (t, xr, xm) = (slice("t", &t)?, slice("x_ref", &x_ref)?, slice("x", &x)?);
        interruptible(py, |cancel| fit_dynamic_with(&m, t, xr, xm, &opts, cancel))
    })()
    .map_err(|e| to_py(py, e))?;
    let o = PyDict::new(py);
    o.set_item("sigma0", r.sigma0)?;
    o.set_item("sigma1", r.sigma1)?;
    o.set_item("std_err", r.std_err)?;
    o.set_item("ci_low", r.ci_low)?;
    o.set_item("ci_high", r.ci_high)?;
    o.set_item("rel_ci_half_width", r.rel_ci_half_width)?;
    o.set_item("identifiable", r.identifiable)?;
    o.set_item("correlation", r.correlation)?;
    o.set_item("residual_autocorrelation", r.residual_autocorrelation)?;
    o.set_item("notes", r.notes)?;
    o.set_item("residuals", r.residuals.into_pyarray(py))?;
    o.set_item("weights", r.weights.into_pyarray(py))?;
    o.set_item("rms_error", r.rms_error)?;
    o.set_item("max_error", r.max_error)?;
    o.set_item("objective", r.objective)?;
    o.set_item("scale", r.scale)?;
    o.set_item("iterations", r.iterations)?;
    o.set_item("evaluations", r.evaluations)?;
    o.set_item("converged", r.converged)?;
    Ok(o)
}

/// The values of a 2-D array column by column (no copy when it is Fortran-ordered) and
/// its number of rows.
fn column_major<'a>(a: &'a PyReadonlyArray2<'_, f64>) -> (Cow<'a, [f64]>, usize) {
    // the transpose is in standard (row-major) order when `a` is in Fortran order
    let t = a.as_array().reversed_axes();
    let rows = t.ncols();
    match t.to_slice() {
        Some(s) => (Cow::Borrowed(s), rows),
        None => (Cow::Owned(t.iter().copied().collect()), rows),
    }
}

fn linear_fit<'py>(py: Python<'py>, f: LinearFit) -> PyResult<Bound<'py, PyDict>> {
    let o = PyDict::new(py);
    o.set_item("coef", f.coef.into_pyarray(py))?;
    o.set_item("weights", f.weights.into_pyarray(py))?;
    o.set_item("residuals", f.residuals.into_pyarray(py))?;
    o.set_item("sse", f.sse)?;
    o.set_item("scale", f.scale)?;
    Ok(o)
}

/// Robust linear least squares `y ~ X b` by IRLS (`estimate::irls_linear`); returns a
/// dict (coef, weights, residuals, sse, scale).
#[pyfunction]
#[pyo3(signature = (x, y, weighting="igg", rounds=8))]
pub(crate) fn irls_linear<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    y: PyReadonlyArray1<'py, f64>,
    weighting: &str,
    rounds: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let (data, rows) = column_major(&x);
    let r = (|| -> Result<_, Error> {
        let opts = LinearIrlsOptions {
            weighting: Weighting::from_name(weighting)?,
            rounds,
        };
        let y = slice("y", &y)?;
        py.detach(|| irls(Design::new(&data, rows), y, &opts))
    })()
    .map_err(|e| to_py(py, e))?;
    linear_fit(py, r)
}

/// `irls_linear` of `X` alone and joined by each candidate's extra columns
/// (`estimate::irls_linear_grid`); returns a dict (chosen, fit, base_sse, sse).
#[pyfunction]
#[pyo3(signature = (x, extras, y, weighting="igg", rounds=8, ratio=0.98))]
pub(crate) fn irls_linear_grid<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    extras: Vec<PyReadonlyArray2<'py, f64>>,
    y: PyReadonlyArray1<'py, f64>,
    weighting: &str,
    rounds: usize,
    ratio: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let (data, rows) = column_major(&x);
    let extra: Vec<(Cow<[f64]>, usize)> = extras.iter().map(column_major).collect();
    let r = (|| -> Result<_, Error> {
        let opts = LinearIrlsOptions {
            weighting: Weighting::from_name(weighting)?,
            rounds,
        };
        let y = slice("y", &y)?;
        let designs: Vec<Design> = extra.iter().map(|(d, n)| Design::new(d, *n)).collect();
        py.detach(|| irls_grid(Design::new(&data, rows), &designs, y, &opts, ratio))
    })()
    .map_err(|e| to_py(py, e))?;
    let o = PyDict::new(py);
    o.set_item("chosen", r.chosen)?;
    o.set_item("fit", linear_fit(py, r.fit)?)?;
    o.set_item("base_sse", r.base_sse)?;
    o.set_item("sse", r.sse.into_pyarray(py))?;
    Ok(o)
}
