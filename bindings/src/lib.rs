//! Python bindings (`lugre._core`): convert in, call the core with the interpreter
//! released, convert out. No numerics here.

use lugre::error::{check_finite, Error};
use lugre::friction::{
    friction_force_general_into, friction_force_into, friction_force_varstep_into,
};
use lugre::servo::{self, CouplingOptions, Drive, Integrator, SimOptions, SimResult};
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::exceptions::{PyKeyboardInterrupt, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::RecvTimeoutError;
use std::time::Duration;

mod estimate;
mod inverse;
mod results;

pub(crate) use inverse::model_of;
use results::SimulationResult;

/// Map a core error onto the package's exception classes (`lugre.exceptions`).
pub(crate) fn to_py(py: Python<'_>, e: Error) -> PyErr {
    let class = match &e {
        Error::Parameter { .. } => "ParameterError",
        Error::Model { .. } => "ModelError",
        Error::Input { .. } => "InputError",
        Error::Data(_) => "DataError",
        Error::Interrupted => return PyKeyboardInterrupt::new_err("interrupted"),
        // the core's error is non-exhaustive: a variant added later maps to the base class
        _ => "LugreError",
    };
    let msg = e.to_string();
    match py.import("lugre.exceptions").and_then(|m| m.getattr(class)) {
        Ok(cls) => {
            let err = match cls.call1((msg.clone(),)) {
                Ok(inst) => PyErr::from_value(inst),
                Err(err) => err,
            };
            let inst = err.value(py);
            match &e {
                Error::Parameter { name, value, .. } => {
                    let _ = inst.setattr("name", name.as_str());
                    let _ = inst.setattr("value", *value);
                }
                Error::Input { name, .. } => {
                    let _ = inst.setattr("name", name.as_str());
                }
                Error::Model { path, .. } => {
                    let _ = inst.setattr("path", path.as_str());
                }
                _ => {}
            }
            err
        }
        Err(_) => PyValueError::new_err(msg),
    }
}

type ArrayPair<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

pub(crate) fn slice<'a>(name: &str, a: &'a PyReadonlyArray1<'_, f64>) -> Result<&'a [f64], Error> {
    a.as_slice()
        .map_err(|_| Error::input(name, "must be a contiguous 1-D float64 array"))
}

/// Run `work` on a scoped thread with the interpreter released, while this thread
/// polls for Ctrl-C every 20 ms and sets the cancel flag that `work` watches.
pub(crate) fn interruptible<T: Send>(
    py: Python<'_>,
    work: impl FnOnce(&AtomicBool) -> T + Send,
) -> T {
    let cancel = AtomicBool::new(false);
    py.detach(|| {
        std::thread::scope(|s| {
            let (tx, rx) = std::sync::mpsc::channel();
            let cancel = &cancel;
            s.spawn(move || {
                let _ = tx.send(work(cancel));
            });
            loop {
                match rx.recv_timeout(Duration::from_millis(20)) {
                    Ok(r) => return r,
                    Err(RecvTimeoutError::Timeout) => {
                        if !cancel.load(Ordering::Relaxed)
                            && Python::attach(|py| py.check_signals().is_err())
                        {
                            cancel.store(true, Ordering::Relaxed);
                        }
                    }
                    // the worker panicked: let the scope re-raise it
                    Err(RecvTimeoutError::Disconnected) => {
                        std::panic::resume_unwind(Box::new("worker thread failed"))
                    }
                }
            }
        })
    })
}

/// Validate a model given as JSON text; returns whether its friction is passive.
#[pyfunction]
fn check_model(py: Python<'_>, model: &Bound<'_, PyAny>) -> PyResult<bool> {
    Ok(model_of(py, model)?.friction.is_passive())
}

/// Steady-state (Stribeck) friction force for each velocity.
#[pyfunction]
fn stribeck<'py>(
    py: Python<'py>,
    v: PyReadonlyArray1<'py, f64>,
    model: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let m = model_of(py, model)?;
    let v = slice("v", &v).map_err(|e| to_py(py, e))?;
    check_finite("v", v).map_err(|e| to_py(py, e))?;
    let out: Vec<f64> = py.detach(|| v.iter().map(|&x| m.friction.stribeck(x)).collect());
    Ok(out.into_pyarray(py))
}

/// LuGre force driven by a sampled velocity; returns `(F, z)` (z empty unless asked).
///
/// The model's `stribeck_shape` applies; `scale` (one per sample) multiplies `g(v)`.
#[pyfunction]
#[pyo3(signature = (v, dt, model, z0=0.0, return_z=false, scale=None))]
fn friction_force<'py>(
    py: Python<'py>,
    v: PyReadonlyArray1<'py, f64>,
    dt: PyReadonlyArray1<'py, f64>,
    model: &Bound<'py, PyAny>,
    z0: f64,
    return_z: bool,
    scale: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<ArrayPair<'py>> {
    let m = model_of(py, model)?;
    let p = m.friction;
    let exponent = m.stribeck_exponent();
    let vs = slice("v", &v).map_err(|e| to_py(py, e))?;
    let dts = slice("dt", &dt).map_err(|e| to_py(py, e))?;
    let sc = match &scale {
        None => None,
        Some(a) => Some(slice("scale", a).map_err(|e| to_py(py, e))?),
    };
    (|| -> Result<(), Error> {
        check_finite("v", vs)?;
        if dts.is_empty() {
            return Err(Error::input("dt", "is empty: give the hold interval [s]"));
        }
        if dts.len() != 1 {
            lugre::error::check_len("dt", dts, vs.len(), "v")?;
        }
        check_finite("dt", dts)?;
        if let Some(k) = dts.iter().position(|&h| h < 0.0) {
            return Err(Error::input(
                "dt",
                format!("element {k} is {}: hold intervals must be >= 0", dts[k]),
            ));
        }
        if !z0.is_finite() {
            return Err(Error::parameter("z0", z0, "must be finite"));
        }
        if let Some(sc) = sc {
            lugre::error::check_scale(sc, vs.len(), "v")?;
        }
        Ok(())
    })()
    .map_err(|e| to_py(py, e))?;
    let (f, z) = py.detach(|| {
        let mut f = vec![0.0; vs.len()];
        let mut z = if return_z {
            vec![0.0; vs.len()]
        } else {
            Vec::new()
        };
        let zo = if return_z { Some(&mut z[..]) } else { None };
        if sc.is_some() || exponent.is_some() {
            friction_force_general_into(&p, vs, dts, z0, sc, exponent, &mut f, zo);
        } else if dts.len() == 1 {
            friction_force_into(&p, vs, dts[0], z0, &mut f, zo);
        } else {
            friction_force_varstep_into(&p, vs, dts, z0, &mut f, zo);
        }
        (f, z)
    });
    Ok((f.into_pyarray(py), z.into_pyarray(py)))
}

type ArrayQuad<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
);

/// The load behind the `resonance` coupling driven by the motor motion `x`, `v`;
/// returns `(force, x_load, v_load, z)` at the samples.
#[pyfunction]
#[pyo3(signature = (x, v, dt, model, scale=None, extra=None, z0=0.0, substeps=1))]
#[allow(clippy::too_many_arguments)]
fn load_coupling<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    v: PyReadonlyArray1<'py, f64>,
    dt: f64,
    model: &Bound<'py, PyAny>,
    scale: Option<PyReadonlyArray1<'py, f64>>,
    extra: Option<PyReadonlyArray1<'py, f64>>,
    z0: f64,
    substeps: usize,
) -> PyResult<ArrayQuad<'py>> {
    let m = model_of(py, model)?;
    let r = (|| -> Result<servo::LoadTrajectory, Error> {
        let xs = slice("x", &x)?;
        let vs = slice("v", &v)?;
        let sc = match &scale {
            None => None,
            Some(a) => Some(slice("scale", a)?),
        };
        let ex = match &extra {
            None => None,
            Some(a) => Some(slice("extra", a)?),
        };
        let opts = CouplingOptions {
            scale: sc,
            extra: ex,
            level: None,
            z0,
            substeps,
        };
        py.detach(|| servo::load_coupling(&m, xs, vs, dt, &opts))
    })()
    .map_err(|e| to_py(py, e))?;
    Ok((
        r.force.into_pyarray(py),
        r.x.into_pyarray(py),
        r.v.into_pyarray(py),
        r.z.into_pyarray(py),
    ))
}

fn parse_opts(
    integrator: &str,
    substeps: usize,
    z0: f64,
    x0: Option<f64>,
    v0: f64,
) -> Result<SimOptions, Error> {
    let integrator = match integrator {
        "exact" => Integrator::Exact,
        "rk4" => Integrator::Rk4,
        other => {
            return Err(Error::input(
                "integrator",
                format!("unknown integrator \"{other}\": use \"exact\" or \"rk4\""),
            ))
        }
    };
    Ok(SimOptions {
        integrator,
        substeps,
        z0,
        x0,
        v0,
    })
}

fn drive_of<'a>(kind: &str, a: &'a [f64]) -> Result<Drive<'a>, Error> {
    Ok(match kind {
        "x_ref" => Drive::Position(a),
        "v_ref" => Drive::Speed(a),
        "current" => Drive::Current(a),
        other => return Err(Error::input("drive", format!("unknown drive \"{other}\""))),
    })
}

/// Simulate the axis; returns a `SimulationResult` (arrays x, v, z, i, friction, force).
///
/// Runs with the interpreter released and checks for Ctrl-C about every 50 ms.
#[pyfunction]
#[pyo3(signature = (model, t, drive_kind, drive, integrator="exact", substeps=1, z0=0.0, x0=None, v0=0.0))]
#[allow(clippy::too_many_arguments)]
fn simulate<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    t: PyReadonlyArray1<'py, f64>,
    drive_kind: &str,
    drive: PyReadonlyArray1<'py, f64>,
    integrator: &str,
    substeps: usize,
    z0: f64,
    x0: Option<f64>,
    v0: f64,
) -> PyResult<SimulationResult> {
    let m = model_of(py, model)?;
    let run = || -> Result<SimResult, Error> {
        let opts = parse_opts(integrator, substeps, z0, x0, v0)?;
        let ts = slice("t", &t)?;
        let d = drive_of(drive_kind, slice(drive_kind, &drive)?)?;
        py.detach(|| {
            servo::simulate(&m, ts, d, &opts, &mut || {
                Python::attach(|py| py.check_signals().is_ok())
            })
        })
    };
    let r = run().map_err(|e| to_py(py, e))?;
    Ok(SimulationResult::new(py, r))
}

/// Simulate many models on the same input in parallel; returns a list of
/// `SimulationResult`s, one per model.
#[pyfunction]
#[pyo3(signature = (models, t, drive_kind, drive, integrator="exact", substeps=1, z0=0.0, x0=None, v0=0.0))]
#[allow(clippy::too_many_arguments)]
fn simulate_batch<'py>(
    py: Python<'py>,
    models: Vec<Bound<'py, PyAny>>,
    t: PyReadonlyArray1<'py, f64>,
    drive_kind: &str,
    drive: PyReadonlyArray1<'py, f64>,
    integrator: &str,
    substeps: usize,
    z0: f64,
    x0: Option<f64>,
    v0: f64,
) -> PyResult<Vec<SimulationResult>> {
    let models = models
        .iter()
        .map(|m| model_of(py, m).map(|m| (*m).clone()))
        .collect::<PyResult<Vec<_>>>()?;
    let results = (|| -> Result<Vec<SimResult>, Error> {
        let opts = parse_opts(integrator, substeps, z0, x0, v0)?;
        let ts = slice("t", &t)?;
        let d = drive_of(drive_kind, slice(drive_kind, &drive)?)?;
        interruptible(py, |cancel| {
            servo::simulate_batch_with(&models, ts, d, &opts, cancel)
        })
        .into_iter()
        .collect()
    })()
    .map_err(|e| to_py(py, e))?;
    Ok(results
        .into_iter()
        .map(|r| SimulationResult::new(py, r))
        .collect())
}

/// Number of worker threads used by batch functions.
#[pyfunction]
fn num_threads() -> usize {
    rayon::current_num_threads()
}

/// The compiled core of `lugre`.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<inverse::PyModel>()?;
    m.add_class::<inverse::PyInverseRecord>()?;
    m.add_class::<SimulationResult>()?;
    m.add_class::<results::StaticFitResult>()?;
    m.add_class::<results::DirectionFitResult>()?;
    m.add_class::<results::PlateauResult>()?;
    m.add_class::<results::DynamicFitResult>()?;
    m.add_class::<results::LinearFitResult>()?;
    m.add_class::<results::GridFitResult>()?;
    m.add_function(wrap_pyfunction!(check_model, m)?)?;
    m.add_function(wrap_pyfunction!(stribeck, m)?)?;
    m.add_function(wrap_pyfunction!(friction_force, m)?)?;
    m.add_function(wrap_pyfunction!(load_coupling, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_batch, m)?)?;
    m.add_function(wrap_pyfunction!(num_threads, m)?)?;
    m.add_function(wrap_pyfunction!(inverse::position_sums, m)?)?;
    m.add_function(wrap_pyfunction!(inverse::filtfilt, m)?)?;
    m.add_function(wrap_pyfunction!(inverse::moving_median, m)?)?;
    m.add_function(wrap_pyfunction!(estimate::fit_static_points, m)?)?;
    m.add_function(wrap_pyfunction!(estimate::plateaus, m)?)?;
    m.add_function(wrap_pyfunction!(estimate::fit_dynamic_record, m)?)?;
    m.add_function(wrap_pyfunction!(estimate::irls_linear, m)?)?;
    m.add_function(wrap_pyfunction!(estimate::irls_linear_grid, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add(
        "EFFECT_NAMES",
        PyTuple::new(m.py(), lugre::servo::EFFECT_NAMES)?,
    )?;
    Ok(())
}
