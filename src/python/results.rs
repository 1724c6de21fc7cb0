//! The results the bindings return: frozen classes with typed, read-only attributes
//! (`lugre._core.SimulationResult`), in place of dicts whose keys the facade had to spell
//! right. Arrays are NumPy arrays made once from the core's
//! vectors (no copy on access); lists and numbers convert on access. Each has a `__repr__`
//! that says what the result holds. No numerics here.

use crate::servo::SimResult;
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
