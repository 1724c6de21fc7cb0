//! Bindings of the estimators: convert in, run with the interpreter released, convert
//! the plain-data results into the typed result classes of `results.rs`.

use super::results::{
    DynamicFitResult, GridFitResult, LinearFitResult, PlateauResult, StaticFitResult,
};
use super::{interruptible, model_of, slice, to_py};
use lugre::error::Error;
use lugre::estimate::{
    fit_dynamic_with, fit_static, irls_linear as irls, irls_linear_grid as irls_grid,
    plateaus_from_recording, Design, DynamicFitOptions, LinearIrlsOptions, PlateauOptions,
    StaticFitOptions, Weighting,
};
use lugre::servo::Integrator;
use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use std::borrow::Cow;

/// Robust per-direction Stribeck fit of steady-state points; returns a
/// `StaticFitResult`.
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
) -> PyResult<StaticFitResult> {
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
    StaticFitResult::new(py, r)
}

/// Steady-state points from a raw constant-velocity record; returns a `PlateauResult`.
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
) -> PyResult<PlateauResult> {
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
    Ok(PlateauResult::new(py, p))
}

/// sigma0 and sigma1 from a closed-loop position record; returns a `DynamicFitResult`.
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
) -> PyResult<DynamicFitResult> {
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
    Ok(DynamicFitResult::new(py, r))
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

/// Robust linear least squares `y ~ X b` by IRLS (`estimate::irls_linear`); returns a
/// `LinearFitResult` (coef, weights, residuals, sse, scale).
#[pyfunction]
#[pyo3(signature = (x, y, weighting="igg", rounds=8))]
pub(crate) fn irls_linear<'py>(
    py: Python<'py>,
    x: PyReadonlyArray2<'py, f64>,
    y: PyReadonlyArray1<'py, f64>,
    weighting: &str,
    rounds: usize,
) -> PyResult<LinearFitResult> {
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
    Ok(LinearFitResult::new(py, r))
}

/// `irls_linear` of `X` alone and joined by each candidate's extra columns
/// (`estimate::irls_linear_grid`); returns a `GridFitResult` (chosen, fit, base_sse,
/// sse).
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
) -> PyResult<GridFitResult> {
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
    GridFitResult::new(py, r)
}
