"""The inverse-dynamics kernel of the diagnosis: the core (``_core.InverseRecord``)
against its NumPy twin (``lugre.reference.InverseRecord``), SciPy's filter, finite
differences, and the same errors from both.

The twins repeat the same operations in the same order: forces, residuals and
sensitivities agree to 1e-12 of their scale (measured: <= 1e-14), the filter to the
last bit.
"""

from __future__ import annotations

import lugre
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from lugre import _core, reference
from lugre.diagnosis import residual as R
from lugre.diagnosis.synth import concealed
from lugre.exceptions import InputError, LugreError
from scipy import signal
from shared_data import SHARED

MISMATCH = SHARED / "datasets" / "mismatch"

NAMES = ["positive.fc", "positive.fs", "positive.sigma2", "positive.vs", "negative.fc",
         "negative.fs", "negative.sigma2", "negative.vs", "sigma0", "sigma1"]

EFFECTS = {
    "plain": [],
    "cogging": [{"effect": "cogging", "amplitude": 2.0, "pitch": 0.025, "phase": 0.3,
                 "harmonics": [[0.5, 0.1]]}],
    "scales": [{"effect": "position_friction", "positions": [-0.1, 0.0, 0.1],
                "scale": [0.9, 1.1, 1.0]},
               {"effect": "drift", "gain": 0.1, "time_constant": 2.0}],
    "shape+forces": [{"effect": "stribeck_shape", "exponent": 0.8},
                     {"effect": "drag", "coefficient": 100.0},
                     {"effect": "spring", "stiffness": 30.0, "x0": 0.01},
                     {"effect": "offset", "force": 2.0}],
    "timing+band": [{"effect": "delay", "seconds": 7e-4},
                    {"effect": "deadband", "current": 0.1},
                    {"effect": "current_lag", "bandwidth": 150.0}],
    "resonance": [{"effect": "resonance", "frequency": 22.0, "damping_ratio": 0.04,
                   "load_fraction": 0.75},
                  {"effect": "mass", "delta": 1.5},
                  {"effect": "position_friction", "positions": [-0.1, 0.1],
                   "scale": [0.95, 1.05]}],
    # the actuator in its order (dead band, limit, lag, ripple) and the friction it raises
    "actuator+load": [{"effect": "force_ripple", "amplitude": 0.06, "pitch": 0.02,
                       "phase": 0.5},
                      {"effect": "current_limit", "current": 4.0},
                      {"effect": "deadband", "current": 0.1},
                      {"effect": "current_lag", "bandwidth": 150.0},
                      {"effect": "load_friction", "coefficient": 0.12},
                      {"effect": "force_ripple", "amplitude": -0.02, "pitch": 0.007}],
    "load+shape+scales": [{"effect": "load_friction", "coefficient": 0.2},
                          {"effect": "stribeck_shape", "exponent": 0.8},
                          {"effect": "drift", "gain": 0.1, "time_constant": 2.0},
                          {"effect": "delay", "seconds": 7e-4}],
    "limit": [{"effect": "current_limit", "current": 3.0}],
    "resonance+load": [{"effect": "resonance", "frequency": 22.0, "damping_ratio": 0.04,
                        "load_fraction": 0.75},
                       {"effect": "load_friction", "coefficient": 0.1},
                       {"effect": "force_ripple", "amplitude": 0.05, "pitch": 0.02},
                       {"effect": "cogging", "amplitude": 2.0, "pitch": 0.025}],
    # (on the record read as a joint's, in rad: gravity acts on rotary axes only)
    "rotary:gravity": [{"effect": "gravity", "torque": 30.0, "phase": 0.4},
                       {"effect": "offset", "force": 2.0}],
    "rotary:gravity+resonance": [{"effect": "resonance", "frequency": 22.0,
                                  "damping_ratio": 0.04, "load_fraction": 0.75},
                                 {"effect": "gravity", "torque": 30.0}],
}


def with_effects(model, case):
    """``model`` with the effects of ``case`` (a ``rotary:`` case on the same axis read
    as a joint's)."""
    if not case.startswith("rotary:"):
        return model.replace(effects=EFFECTS[case])
    axis = {"kind": "rotary", "inertia": model.mass, "torque_constant": model.force_constant}
    return model.replace(axis=axis, effects=EFFECTS[case])

KERNELS = ("base_friction", "effect_force", "model_force", "motor_force", "residual")


@pytest.fixture(scope="module")
def pair():
    rec, model, _ = concealed("cogging", duration=3.0)
    return (R.prepare(rec, model), R.prepare(rec, model, backend=reference.kernels), model)


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300))


@pytest.mark.parametrize("case", sorted(EFFECTS))
def test_kernels_twins(pair, case):
    sig, sigr, model = pair
    m = with_effects(model, case)
    for name in KERNELS:
        a = getattr(sig.kernel, name)(m)
        b = getattr(sigr.kernel, name)(m)
        assert a.shape == b.shape == (len(sig),)
        assert _rel(a, b) <= 1e-12, (case, name, _rel(a, b))
    if "resonance" in case:
        assert _rel(sig.kernel.coupling_force(m), sigr.kernel.coupling_force(m)) <= 1e-12
    fa, ja, na = sig.kernel.base_sensitivities(m, NAMES)
    fb, jb, nb = sigr.kernel.base_sensitivities(m, NAMES)
    assert na == nb
    assert _rel(fa, fb) <= 1e-12
    scale = np.maximum(np.max(np.abs(jb), axis=0), 1e-300)
    assert np.max(np.abs(ja - jb) / scale) <= 1e-12


def test_kernels_twins_on_independent_plant():
    """A record written by the independent plant of ../shared (a resonance case)."""
    case = MISMATCH / "resonance"
    rec = lugre.read_recording(case / "recording.csv")
    model = lugre.load_model(case / "model.json")
    n = 3000
    rec = lugre.Recording(t=rec.t[:n], x=rec.x[:n], i=rec.i[:n])
    sig, sigr = R.prepare(rec, model), R.prepare(rec, model, backend=reference.kernels)
    aug = model.replace(effects=[{"effect": "resonance", "frequency": 22.0,
                                  "damping_ratio": 0.04, "load_fraction": 0.75}])
    for m in (model, aug):
        # bit for bit: the load's stick-slip amplifies any difference in the last bit
        # (a parameter read one unit in the last place off gave 2e-11 N of 200 N)
        for name in KERNELS:
            a, b = getattr(sig.kernel, name)(m), getattr(sigr.kernel, name)(m)
            np.testing.assert_array_equal(a, b, err_msg=name)


@pytest.mark.parametrize("load", [[], EFFECTS["actuator+load"]], ids=["plain", "load"])
def test_sensitivities_are_derivatives(pair, load):
    """Each column against a central difference of the filtered LuGre force (the levels
    raised by a load_friction under the motor force included)."""
    sig, _, model = pair
    m = model.replace(effects=EFFECTS["scales"] + [{"effect": "stribeck_shape",
                                                      "exponent": 1.4}] + load)
    _, jac, _ = sig.kernel.base_sensitivities(m, NAMES)
    d = m.to_dict()
    for j, name in enumerate(NAMES):
        side, _, key = name.rpartition(".")
        obj = d["friction"][side] if side else d["friction"]
        h = 1e-6 * abs(obj[key])

        def f(delta: float, obj=obj, key=key) -> np.ndarray:
            old = obj[key]
            obj[key] = old + delta
            try:
                return sig.filt(sig.kernel.base_friction(lugre.Model(d)))
            finally:
                obj[key] = old

        fd = (f(h) - f(-h)) / (2 * h)
        scale = np.max(np.abs(jac[:, j]))
        assert scale > 0, name
        assert np.max(np.abs(fd - jac[:, j])) <= 1e-5 * scale, name


@settings(max_examples=25, deadline=None)
@given(n=st.integers(2, 400), order=st.sampled_from([2, 4, 6]),
       wn=st.floats(0.02, 0.9), padlen=st.integers(0, 100), seed=st.integers(0, 2**16))
def test_filter_as_scipy(n, order, wn, padlen, seed):
    y = np.random.default_rng(seed).standard_normal(n)
    sos = signal.butter(order, wn, output="sos")
    pl = min(padlen, n - 1)
    want = signal.sosfiltfilt(sos, y, padtype="odd", padlen=pl)
    z = np.zeros(n)
    a = _core.InverseRecord(z, z, z, z, z, z, z, 1e-3, sos, padlen).filt(y)
    b = reference.InverseRecord(z, z, z, z, z, z, z, 1e-3, sos, padlen).filt(y)
    np.testing.assert_array_equal(a, b)
    np.testing.assert_allclose(a, want, rtol=0, atol=1e-11 * max(np.max(np.abs(want)), 1.0))


def test_filter_columns_side_by_side_as_one_by_one():
    """``filt_columns`` filters several columns side by side in the core: each column
    to the last bit as ``filt`` alone and as the twin, a column that falls to zero
    (its states flushed, not left among the subnormal numbers) included."""
    n = 3000
    rng = np.random.default_rng(5)
    sos = signal.butter(4, 0.3, output="sos")
    z = np.zeros(n)
    hat = np.where(np.abs(np.arange(n) - 60) < 20, 1.0, 0.0)
    for m in (0, 1, 5, 9):
        Y = np.column_stack([hat] + [rng.standard_normal(n) for _ in range(m - 1)]
                            ) if m else np.zeros((n, 0))
        for cls in (_core.InverseRecord, reference.InverseRecord):
            k = cls(z, z, z, z, z, z, z, 1e-3, sos, 72)
            out = k.filt_columns(Y)
            assert out.shape == (n, m)
            for j in range(m):
                np.testing.assert_array_equal(out[:, j], k.filt(np.ascontiguousarray(Y[:, j])))
            if m:
                tail = out[1000:, 0]
                assert np.all((tail == 0) | (np.abs(tail) >= np.finfo(float).tiny))
                assert np.all(tail[-500:] == 0)
        a = _core.InverseRecord(z, z, z, z, z, z, z, 1e-3, sos, 72).filt_columns(Y)
        b = reference.InverseRecord(z, z, z, z, z, z, z, 1e-3, sos, 72).filt_columns(Y)
        np.testing.assert_array_equal(a, b)
    for cls in (_core.InverseRecord, reference.InverseRecord):
        with pytest.raises(InputError) as e:
            cls(z, z, z, z, z, z, z, 1e-3, sos, 72).filt_columns(np.zeros((n - 1, 2)))
        assert e.value.name == "y"


BAD = {
    "length": ({"x": np.zeros(5)}, InputError, "x"),
    "nan": ({"v": np.array([0.0, np.nan, 0, 0, 0, 0])}, InputError, "v"),
    "sos columns": ({"sos": np.ones((1, 5))}, InputError, "sos"),
    "sos a0": ({"sos": np.array([[1.0, 0, 0, 2.0, 0, 0]])}, InputError, "sos"),
    "sos pole": ({"sos": np.array([[1.0, 0, 0, 1.0, -2.0, 1.0]])}, InputError, "sos"),
    "dt": ({"dt": 0.0}, LugreError, "dt"),
}


@pytest.mark.parametrize("case", sorted(BAD))
@pytest.mark.parametrize("cls", [_core.InverseRecord, reference.InverseRecord])
def test_bad_input_same_errors(case, cls):
    kw, exc, name = BAD[case]
    z = np.zeros(6)
    args = {"t": np.arange(6) * 1e-3, "x": z, "x_drive": z, "v": z, "a": z, "fm": z,
            "fm_f": z, "dt": 1e-3, "sos": None, "padlen": 0}
    args.update(kw)
    with pytest.raises(exc) as e:
        cls(**args)
    assert e.value.name == name


@pytest.mark.parametrize("cls", [_core.InverseRecord, reference.InverseRecord])
def test_unknown_parameter_named(cls):
    z = np.zeros(6)
    k = cls(np.arange(6) * 1e-3, z, z, z, z, z, z, 1e-3)
    with pytest.raises(InputError, match="positive.fx"):
        k.base_sensitivities(lugre.Model.paper(), ["positive.fx"])


def test_core_refuses_a_non_model():
    z = np.zeros(6)
    k = _core.InverseRecord(np.arange(6) * 1e-3, z, z, z, z, z, z, 1e-3)
    with pytest.raises(InputError, match="model"):
        k.residual(42)


def test_diagnose_same_on_both_backends():
    """The whole diagnosis on the NumPy twin: the same finding and parameters."""
    rec, model, _ = concealed("cogging", duration=3.0)
    kw = {"closed_loop": False, "candidates": ["cogging", "offset", "spring", "drag"]}
    a = lugre.diagnose(rec, model, **kw)
    b = reference.diagnose(rec, model, **kw)
    assert [f.effect for f in a.findings] == [f.effect for f in b.findings] == ["cogging"]
    pa, pb = a.findings[0].parameters, b.findings[0].parameters
    for k in pa:
        if isinstance(pa[k], float):
            assert pa[k] == pytest.approx(pb[k], rel=1e-8, abs=1e-12), k


@pytest.mark.parametrize("case", ["plain", "load+shape+scales"])
def test_sensitivities_in_two_halves_as_one_by_one(pair, case):
    """The core carries the parameters in two halves on two threads: every column and
    the force the same, bit for bit, as each parameter's own pass."""
    sig, _, model = pair
    m = with_effects(model, case)
    force, jac, nonzero = sig.kernel.base_sensitivities(m, NAMES)
    for j, name in enumerate(NAMES):
        f1, j1, n1 = sig.kernel.base_sensitivities(m, [name])
        np.testing.assert_array_equal(jac[:, j], j1[:, 0], err_msg=name)
        np.testing.assert_array_equal(force, f1, err_msg=name)
        assert nonzero[j] == n1[0]


@pytest.mark.parametrize("backend", ["core", "reference"])
def test_residuals_batch_as_one_by_one(pair, backend):
    sig = pair[0] if backend == "core" else pair[1]
    model = pair[2]
    models = [model.replace(effects=EFFECTS[c]) for c in ("plain", "cogging", "resonance")]
    batch = sig.kernel.residuals(models)
    assert batch.shape == (len(sig), 3)
    for j, m in enumerate(models):
        np.testing.assert_array_equal(batch[:, j], sig.kernel.residual(m))
    assert sig.kernel.residuals([]).shape == (len(sig), 0)


def test_fit_inverse_dynamics_same_on_both_backends():
    rec, _, truth = concealed("none", duration=4.0)
    a = lugre.fit_inverse_dynamics(rec, force_constant=truth.force_constant)
    b = reference.fit_inverse_dynamics(rec, force_constant=truth.force_constant)
    da, db = a.to_dict(), b.to_dict()
    for side in ("positive", "negative"):
        for k in ("fc", "fs", "sigma2", "vs"):
            assert da["friction"][side][k] == pytest.approx(db["friction"][side][k],
                                                            rel=1e-9)
    assert da["axis"]["mass"] == pytest.approx(db["axis"]["mass"], rel=1e-9)
