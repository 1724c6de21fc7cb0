//! Bindings of the model handed over once (`_core.Model`) and of the inverse-dynamics
//! kernel of the diagnosis (`_core.InverseRecord`). No numerics here.

use super::{slice, to_py};
use lugre::error::Error;
use lugre::estimate::Weighting;
use lugre::inverse::{
    fit_base as base_fit, moving_median as median, position_sums as sums, BaseFitOptions,
    BaseParam, Lanes, Lowpass, Record, LANES,
};
use lugre::servo::Model;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Arc;

/// A validated model, parsed once and passed to every call of the core.
#[pyclass(name = "Model", module = "lugre._core", frozen)]
pub(crate) struct PyModel {
    pub(crate) inner: Arc<Model>,
}

#[pymethods]
impl PyModel {
    /// Parse and validate a model from its JSON text.
    #[new]
    fn new(py: Python<'_>, model_json: &str) -> PyResult<Self> {
        let m = Model::from_json(model_json).map_err(|e| to_py(py, e))?;
        Ok(PyModel { inner: Arc::new(m) })
    }

    /// Whether the friction satisfies the passivity bound in both directions.
    fn is_passive(&self) -> bool {
        self.inner.friction.is_passive()
    }
}

/// The model of an argument: a `_core.Model` as it is, JSON text parsed.
pub(crate) fn model_of(py: Python<'_>, obj: &Bound<'_, PyAny>) -> PyResult<Arc<Model>> {
    if let Ok(m) = obj.downcast::<PyModel>() {
        return Ok(m.get().inner.clone());
    }
    if let Ok(text) = obj.extract::<String>() {
        return Model::from_json(&text)
            .map(Arc::new)
            .map_err(|e| to_py(py, e));
    }
    // a lugre.Model: its cached core model
    if let Ok(core) = obj.call_method0("_core_model") {
        if let Ok(m) = core.downcast::<PyModel>() {
            return Ok(m.get().inner.clone());
        }
    }
    let kind = obj.get_type().name().map_or("?".into(), |n| n.to_string());
    Err(to_py(
        py,
        Error::input(
            "model",
            format!(
                "must be a lugre.Model, a lugre._core.Model or the model's JSON text, \
                 got {kind}"
            ),
        ),
    ))
}

type F64Array<'py> = Bound<'py, PyArray1<f64>>;

/// A recording prepared for inverse dynamics (see `lugre.inverse` in the crate).
#[pyclass(name = "InverseRecord", module = "lugre._core", frozen)]
pub(crate) struct PyInverseRecord {
    rec: Record,
}

fn vec_of(name: &str, a: &PyReadonlyArray1<'_, f64>) -> Result<Vec<f64>, Error> {
    Ok(slice(name, a)?.to_vec())
}

impl PyInverseRecord {
    /// One signal of the record under `model`, computed with the interpreter released.
    fn signal<'py>(
        &self,
        py: Python<'py>,
        model: &Bound<'py, PyAny>,
        f: impl FnOnce(&Record, &Model) -> Result<Vec<f64>, Error> + Send,
    ) -> PyResult<F64Array<'py>> {
        let m = model_of(py, model)?;
        let r = py.detach(|| f(&self.rec, &m)).map_err(|e| to_py(py, e))?;
        Ok(r.into_pyarray(py))
    }
}

/// Columns of equal length `n` as an `(n, columns)` matrix.
fn columns(n: usize, cols: &[Vec<f64>]) -> Array2<f64> {
    Array2::from_shape_fn((n, cols.len()), |(k, j)| cols[j][k])
}

/// Columns of equal length `n` as an `(n, columns)` matrix stored column by column
/// (each column contiguous: the caller reads them one at a time).
fn columns_major(n: usize, cols: Vec<Vec<f64>>) -> Array2<f64> {
    let m = cols.len();
    let mut data: Vec<f64> = Vec::with_capacity(n * m);
    for c in cols {
        data.extend_from_slice(&c); // (each column freed once copied)
    }
    Array2::from_shape_vec((m, n), data)
        .expect("columns of equal length")
        .reversed_axes()
}

#[pymethods]
impl PyInverseRecord {
    #[new]
    #[pyo3(signature = (t, x, x_drive, v, a, fm, fm_f, dt, sos=None, padlen=0))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        t: PyReadonlyArray1<'_, f64>,
        x: PyReadonlyArray1<'_, f64>,
        x_drive: PyReadonlyArray1<'_, f64>,
        v: PyReadonlyArray1<'_, f64>,
        a: PyReadonlyArray1<'_, f64>,
        fm: PyReadonlyArray1<'_, f64>,
        fm_f: PyReadonlyArray1<'_, f64>,
        dt: f64,
        sos: Option<PyReadonlyArray2<'_, f64>>,
        padlen: usize,
    ) -> PyResult<Self> {
        let rec = (|| -> Result<Record, Error> {
            let filter = lowpass_of(sos.as_ref(), padlen)?;
            Record::new(
                vec_of("t", &t)?,
                vec_of("x", &x)?,
                vec_of("x_drive", &x_drive)?,
                vec_of("v", &v)?,
                vec_of("a", &a)?,
                vec_of("fm", &fm)?,
                vec_of("fm_f", &fm_f)?,
                dt,
                filter,
            )
        })()
        .map_err(|e| to_py(py, e))?;
        Ok(PyInverseRecord { rec })
    }

    fn __len__(&self) -> usize {
        self.rec.len()
    }

    /// The parallel low-pass of a signal of the record's length.
    fn filt<'py>(&self, py: Python<'py>, y: PyReadonlyArray1<'py, f64>) -> PyResult<F64Array<'py>> {
        let ys = slice("y", &y).map_err(|e| to_py(py, e))?;
        lugre::error::check_len("y", ys, self.rec.len(), "the record").map_err(|e| to_py(py, e))?;
        Ok(py.detach(|| self.rec.filt(ys)).into_pyarray(py))
    }

    /// The parallel low-pass of each column of an `(n, m)` matrix, several side by side.
    fn filt_columns<'py>(
        &self,
        py: Python<'py>,
        y: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let a = y.as_array();
        let n = self.rec.len();
        if a.nrows() != n {
            return Err(to_py(
                py,
                Error::input(
                    "y",
                    format!(
                        "has {} rows but the record has {n} samples: give one row per sample",
                        a.nrows()
                    ),
                ),
            ));
        }
        // LANES columns at a time read where they are and written into the result as
        // they are filtered, as many at once as there are threads: the matrix of a long
        // record is hundreds of MB, and copies of its columns in and out would triple
        // that (the same numbers: every column is filtered on its own)
        let m = a.ncols();
        let out = py.detach(|| {
            use rayon::prelude::*;
            let mut out = Array2::<f64>::zeros((n, m));
            let starts: Vec<usize> = (0..m).step_by(LANES).collect();
            for wave in starts.chunks(rayon::current_num_threads().max(1)) {
                let done: Vec<(usize, Lanes)> = wave
                    .par_iter()
                    .map(|&j0| {
                        let w = LANES.min(m - j0);
                        (j0, self.rec.filt_lanes(w, |l, k| a[[k, j0 + l]]))
                    })
                    .collect();
                for (j0, f) in done {
                    for l in 0..f.width() {
                        for (o, v) in out.column_mut(j0 + l).iter_mut().zip(f.lane(l)) {
                            *o = v;
                        }
                    }
                }
            }
            out
        });
        Ok(out.into_pyarray(py))
    }

    /// Product of the position and drift scales of friction, or None.
    fn friction_scale<'py>(
        &self,
        py: Python<'py>,
        model: &Bound<'py, PyAny>,
    ) -> PyResult<Option<F64Array<'py>>> {
        let m = model_of(py, model)?;
        Ok(py
            .detach(|| self.rec.friction_scale(&m))
            .map(|s| s.into_pyarray(py)))
    }

    /// Unfiltered LuGre force at the samples.
    fn base_friction<'py>(
        &self,
        py: Python<'py>,
        model: &Bound<'py, PyAny>,
    ) -> PyResult<F64Array<'py>> {
        self.signal(py, model, |r, m| Ok(r.base_friction(m)))
    }

    /// Unfiltered sum of the effect forces.
    fn effect_force<'py>(
        &self,
        py: Python<'py>,
        model: &Bound<'py, PyAny>,
    ) -> PyResult<F64Array<'py>> {
        self.signal(py, model, |r, m| Ok(r.effect_force(m)))
    }

    /// Unfiltered force of the resonance coupling on the load.
    fn coupling_force<'py>(
        &self,
        py: Python<'py>,
        model: &Bound<'py, PyAny>,
    ) -> PyResult<F64Array<'py>> {
        self.signal(py, model, Record::coupling_force)
    }

    /// Filtered force the model needs besides the motor.
    fn model_force<'py>(
        &self,
        py: Python<'py>,
        model: &Bound<'py, PyAny>,
    ) -> PyResult<F64Array<'py>> {
        self.signal(py, model, Record::model_force)
    }

    /// Filtered motor force after delay, dead-band and current lag.
    fn motor_force<'py>(
        &self,
        py: Python<'py>,
        model: &Bound<'py, PyAny>,
    ) -> PyResult<F64Array<'py>> {
        self.signal(py, model, |r, m| Ok(r.motor_force(m)))
    }

    /// Force residual.
    fn residual<'py>(&self, py: Python<'py>, model: &Bound<'py, PyAny>) -> PyResult<F64Array<'py>> {
        self.signal(py, model, Record::residual)
    }

    /// Residuals of several models (one column each), computed in parallel.
    fn residuals<'py>(
        &self,
        py: Python<'py>,
        models: Vec<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let ms = models
            .iter()
            .map(|m| model_of(py, m).map(|m| (*m).clone()))
            .collect::<PyResult<Vec<_>>>()?;
        let n = self.rec.len();
        let cols = py
            .detach(|| self.rec.residuals(&ms))
            .map_err(|e| to_py(py, e))?;
        Ok(columns_major(n, cols).into_pyarray(py))
    }

    /// The base parameters `names` fitted from `starts` by IGG-weighted
    /// Levenberg-Marquardt on the residual at the `mask`ed samples (see
    /// `lugre::inverse::fit_base`). A dict: `values` (every base parameter of the best
    /// model by path), `cost`, `scale`, `criterion`, `weights`, `information` (`q x q`;
    /// None unless `information`), `start`, `iterations`, `evaluations`. A start stops
    /// when the weighted sum of squares falls by less than `tol` (relative) twice in a row.
    #[pyo3(signature = (starts, mask, names, max_iter=60, keep=3, scouts=12, weighting="huber",
                        tol=1e-6, information=true))]
    #[allow(clippy::too_many_arguments)]
    fn fit_base<'py>(
        &self,
        py: Python<'py>,
        starts: Vec<Bound<'py, PyAny>>,
        mask: Vec<bool>,
        names: Vec<String>,
        max_iter: usize,
        keep: usize,
        scouts: usize,
        weighting: &str,
        tol: f64,
        information: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        if !(tol.is_finite() && tol >= 0.0) {
            let why = format!("must be a finite number >= 0, got {tol}");
            return Err(to_py(py, Error::input("tol", why)));
        }
        let ms = starts
            .iter()
            .map(|m| model_of(py, m).map(|m| (*m).clone()))
            .collect::<PyResult<Vec<_>>>()?;
        let opts = BaseFitOptions {
            max_iter,
            keep,
            scouts,
            weighting: Weighting::from_name(weighting).map_err(|e| to_py(py, e))?,
            tol,
            information,
            ..BaseFitOptions::default()
        };
        let fit = py
            .detach(|| base_fit(&self.rec, &ms, &mask, &names, &opts))
            .map_err(|e| to_py(py, e))?;
        let m = &fit.model;
        let f = &m.friction;
        let values = PyDict::new(py);
        values.set_item("mass", m.axis.mass)?;
        for (side, s) in [("positive", &f.positive), ("negative", &f.negative)] {
            for (k, v) in [
                ("fc", s.fc),
                ("fs", s.fs),
                ("sigma2", s.sigma2),
                ("vs", s.vs),
            ] {
                values.set_item(format!("{side}.{k}"), v)?;
            }
        }
        values.set_item("sigma0", f.sigma0)?;
        values.set_item("sigma1", f.sigma1)?;
        let q = names.len();
        let out = PyDict::new(py);
        out.set_item("values", values)?;
        out.set_item("cost", fit.cost)?;
        out.set_item("scale", fit.scale)?;
        out.set_item("criterion", fit.criterion)?;
        out.set_item("weights", fit.weights.into_pyarray(py))?;
        if information {
            let info =
                Array2::from_shape_vec((q, q), fit.information.clone()).expect("q x q information");
            out.set_item("information", info.into_pyarray(py))?;
        } else {
            out.set_item("information", py.None())?;
        }
        out.set_item("start", fit.start)?;
        out.set_item("iterations", fit.iterations)?;
        out.set_item("evaluations", fit.evaluations)?;
        Ok(out)
    }

    /// `(force, J, nonzero)`: the unfiltered LuGre force, its filtered derivatives with
    /// respect to the named parameters (one column each) and whether each unfiltered
    /// column is non-zero.
    #[allow(clippy::type_complexity)]
    fn base_sensitivities<'py>(
        &self,
        py: Python<'py>,
        model: &Bound<'py, PyAny>,
        names: Vec<String>,
    ) -> PyResult<(F64Array<'py>, Bound<'py, PyArray2<f64>>, Vec<bool>)> {
        let m = model_of(py, model)?;
        let params = names
            .iter()
            .map(|n| BaseParam::parse(n))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| to_py(py, e))?;
        let n = self.rec.len();
        let s = py.detach(|| self.rec.base_sensitivities(&m, &params));
        let jac = columns(n, &s.columns);
        Ok((s.force.into_pyarray(py), jac.into_pyarray(py), s.nonzero))
    }
}

/// The parallel low-pass of `sos` rows `[b0, b1, b2, 1, a1, a2]` (None: none).
fn lowpass_of(sos: Option<&PyReadonlyArray2<'_, f64>>, padlen: usize) -> Result<Lowpass, Error> {
    match sos {
        None => Ok(Lowpass::identity()),
        Some(s) => {
            let s = s.as_array();
            if s.ncols() != 6 {
                return Err(Error::input(
                    "sos",
                    format!(
                        "has {} columns: give one row [b0, b1, b2, 1, a1, a2] per section",
                        s.ncols()
                    ),
                ));
            }
            let rows = s
                .rows()
                .into_iter()
                .map(|r| [r[0], r[1], r[2], r[3], r[4], r[5]])
                .collect();
            Lowpass::new(rows, padlen)
        }
    }
}

/// `y` through the sections `sos` forward and backward, odd extension of `padlen`
/// samples (the diagnosis's low-pass of a signal before its kernel exists; see
/// `lugre::inverse::Lowpass::filtfilt`).
#[pyfunction]
#[pyo3(signature = (y, sos, padlen))]
pub(crate) fn filtfilt<'py>(
    py: Python<'py>,
    y: PyReadonlyArray1<'py, f64>,
    sos: PyReadonlyArray2<'py, f64>,
    padlen: usize,
) -> PyResult<F64Array<'py>> {
    let ys = slice("y", &y).map_err(|e| to_py(py, e))?;
    let filter = lowpass_of(Some(&sos), padlen).map_err(|e| to_py(py, e))?;
    Ok(py.detach(|| filter.filtfilt(ys)).into_pyarray(py))
}

/// The moving median of `y` over `size` samples, the ends extended by their edge values
/// (`lugre::inverse::moving_median`; SciPy's `ndimage.median_filter(mode="nearest")`).
#[pyfunction]
pub(crate) fn moving_median<'py>(
    py: Python<'py>,
    y: PyReadonlyArray1<'py, f64>,
    size: usize,
) -> PyResult<F64Array<'py>> {
    let ys = slice("y", &y).map_err(|e| to_py(py, e))?;
    Ok(py.detach(|| median(ys, size)).into_pyarray(py))
}

/// Sums of `r` against `sin` and `cos` of `2*pi*k_j*x` for `k_j = k0 + j*dk`, `j < n`:
/// `(S, C)`, with `squares` also `(SS, CC, SC)` (see `lugre::inverse::position_sums`).
#[pyfunction]
#[pyo3(signature = (x, r, k0, dk, n, squares=false))]
pub(crate) fn position_sums<'py>(
    py: Python<'py>,
    x: PyReadonlyArray1<'py, f64>,
    r: PyReadonlyArray1<'py, f64>,
    k0: f64,
    dk: f64,
    n: usize,
    squares: bool,
) -> PyResult<Vec<F64Array<'py>>> {
    let xs = slice("x", &x).map_err(|e| to_py(py, e))?;
    let rs = slice("r", &r).map_err(|e| to_py(py, e))?;
    let p = py
        .detach(|| sums(xs, rs, k0, dk, n, squares))
        .map_err(|e| to_py(py, e))?;
    let mut out = vec![p.s.into_pyarray(py), p.c.into_pyarray(py)];
    if squares {
        out.extend([p.ss, p.cc, p.sc].map(|a| a.into_pyarray(py)));
    }
    Ok(out)
}
