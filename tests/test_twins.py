"""Every public function of ``lugre`` (Rust core) against ``lugre.reference`` (NumPy).

Same inputs, same test: forces agree to 1e-9 relative, closed-loop trajectories to
1e-6 relative to their range; bad inputs raise the same exception class from both.
"""

from __future__ import annotations

import math

import lugre
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from lugre import reference as ref

BACKENDS = [lugre, ref]


def paper(**changes):
    d = lugre.Model.paper().to_dict()
    d.update(changes)
    return lugre.Model.from_dict(d)


def close(a, b, rel):
    a, b = np.asarray(a), np.asarray(b)
    scale = max(np.ptp(b), np.max(np.abs(b)), 1e-300)
    return np.max(np.abs(a - b)) <= rel * scale


def test_stribeck_twins():
    v = np.concatenate([-np.logspace(-5, 0, 50), [0.0], np.logspace(-5, 0, 50)])
    m = lugre.Model.paper()
    a, b = lugre.stribeck(v, m), ref.stribeck(v, m)
    assert a.dtype == np.float64 and a.shape == v.shape
    np.testing.assert_allclose(a, b, rtol=1e-12, atol=0)
    # lists are accepted
    np.testing.assert_allclose(lugre.stribeck(list(v), m), b, rtol=1e-12)


@settings(max_examples=40, deadline=None)
@given(
    v=st.lists(st.floats(-0.5, 0.5), min_size=1, max_size=300),
    dt=st.floats(1e-6, 1e-2),
    z0=st.floats(-5e-4, 5e-4),
)
def test_friction_force_twins(v, dt, z0):
    m = lugre.Model.paper()
    fa, za = lugre.friction_force(v, dt, m, z0=z0, return_z=True)
    fb, zb = ref.friction_force(v, dt, m, z0=z0, return_z=True)
    np.testing.assert_allclose(fa, fb, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(za, zb, rtol=1e-9, atol=1e-15)


def test_friction_force_per_sample_dt():
    rng = np.random.default_rng(1)
    v = 0.02 * np.sin(np.linspace(0, 20, 2000)) + 1e-3 * rng.standard_normal(2000)
    dt = rng.uniform(0.5e-4, 2e-4, 2000)
    m = lugre.Model.paper()
    a = lugre.friction_force(v, dt, m)
    b = ref.friction_force(v, dt, m)
    np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-9)


EFFECTS = {
    "none": [],
    "cogging": [{"effect": "cogging", "amplitude": 3.0, "pitch": 0.025, "phase": 0.4,
                 "harmonics": [[1.0, 0.2]]}],
    "spring": [{"effect": "spring", "stiffness": 500.0, "x0": 0.01}],
    "offset": [{"effect": "offset", "force": -4.0}],
    "position_friction": [{"effect": "position_friction", "positions": [-0.01, 0.0, 0.02],
                           "scale": [1.0, 1.3, 0.9]}],
    "drift": [{"effect": "drift", "gain": 0.2, "time_constant": 0.3}],
    "mass": [{"effect": "mass", "delta": 5.0}],
    "delay": [{"effect": "delay", "seconds": 3.5e-4}],
    "current_lag": [{"effect": "current_lag", "bandwidth": 200.0}],
}


@pytest.mark.parametrize("name", sorted(EFFECTS))
@pytest.mark.parametrize("integrator", ["exact", "rk4"])
def test_simulate_pid_twins(name, integrator):
    m = paper(effects=EFFECTS[name])
    t = np.arange(0, 0.6, 1e-4)
    x_ref = 0.02 * np.sin(2 * np.pi * 1.5 * t)
    a = lugre.simulate(m, t, x_ref, integrator=integrator)
    b = ref.simulate(m, t, x_ref, integrator=integrator)
    for f in lugre.SimResult.fields:
        assert close(getattr(a, f), getattr(b, f), 1e-6), f


@pytest.mark.parametrize(
    "axis_extra",
    [{"current_loop": {"bandwidth_hz": 800.0}},
     {"current_loop": {"resistance": 1.2, "inductance": 0.01874, "back_emf": 25.0,
                       "bandwidth_hz": 1000.0}, "current_limit": 8.0}],
)
@pytest.mark.parametrize("ff", [None, "static", "lugre"])
def test_simulate_speed_loop_twins(axis_extra, ff):
    d = lugre.Model.paper().to_dict()
    d["axis"].update(axis_extra)
    d["controller"] = {"type": "pi_speed", "kp": 1200.0, "ki": 12000.0, "rate_hz": 10000.0}
    if ff:
        d["controller"]["feedforward"] = {"type": ff}
    m = lugre.Model.from_dict(d)
    # output grid coarser than and offset from the control grid
    t = np.arange(0, 1.0, 3.3e-4)
    v_ref = np.sin(2 * np.pi * t)
    a = lugre.simulate(m, t, v_ref=v_ref, substeps=3)
    b = ref.simulate(m, t, v_ref=v_ref, substeps=3)
    for f in lugre.SimResult.fields:
        assert close(getattr(a, f), getattr(b, f), 1e-6), f


def test_open_loop_twins():
    m = lugre.Model.paper()
    t = np.arange(0, 0.3, 1e-3)
    i = 3.0 * np.sin(2 * np.pi * 4 * t)
    a = lugre.simulate(m, t, current=i, substeps=4)
    b = ref.simulate(m, t, current=i, substeps=4)
    for f in lugre.SimResult.fields:
        assert close(getattr(a, f), getattr(b, f), 1e-6), f


def test_batch_equals_single():
    t = np.arange(0, 0.2, 1e-4)
    xr = 0.01 * t
    models = [paper(effects=EFFECTS[k]) for k in ("none", "offset", "cogging")]
    rs = lugre.simulate_batch(models, t, xr)
    for m, r in zip(models, rs):
        s = ref.simulate(m, t, xr)
        assert close(r.x, s.x, 1e-6)


BAD = [
    # (description, call(backend), exception class, words in the message)
    ("nan velocity", lambda b: b.stribeck([0.1, math.nan], lugre.Model.paper()),
     lugre.InputError, ["v", "element 1"]),
    ("inf velocity", lambda b: b.friction_force([0.1, math.inf], 1e-3, lugre.Model.paper()),
     lugre.InputError, ["v", "element 1"]),
    ("negative dt", lambda b: b.friction_force([0.1, 0.2], -1e-3, lugre.Model.paper()),
     lugre.InputError, ["dt"]),
    ("dt length", lambda b: b.friction_force([0.1, 0.2, 0.3], [1e-3, 1e-3], lugre.Model.paper()),
     lugre.InputError, ["dt", "same length"]),
    ("time not increasing", lambda b: b.simulate(lugre.Model.paper(), [0, 1e-4, 1e-4], [0, 0, 0]),
     lugre.InputError, ["t", "strictly increasing"]),
    ("empty", lambda b: b.simulate(lugre.Model.paper(), [], []),
     lugre.InputError, ["t", "empty"]),
    ("lengths differ", lambda b: b.simulate(lugre.Model.paper(), [0, 1e-4, 2e-4], [0, 0]),
     lugre.InputError, ["x_ref", "same length"]),
    ("nan reference", lambda b: b.simulate(lugre.Model.paper(), [0, 1e-4], [0, math.nan]),
     lugre.InputError, ["x_ref", "element 1"]),
    ("wrong reference", lambda b: b.simulate(lugre.Model.paper(), [0, 1e-4], v_ref=[0, 0]),
     lugre.InputError, ["x_ref"]),
    ("bad integrator", lambda b: b.simulate(lugre.Model.paper(), [0, 1e-4], [0, 0],
                                            integrator="euler"),
     lugre.InputError, ["integrator"]),
    ("zero substeps", lambda b: b.simulate(lugre.Model.paper(), [0, 1e-4], [0, 0], substeps=0),
     lugre.ParameterError, ["substeps"]),
]


@pytest.mark.parametrize("desc,call,cls,words", BAD, ids=[b[0] for b in BAD])
@pytest.mark.parametrize("backend", BACKENDS, ids=["lugre", "reference"])
def test_bad_input_same_errors(desc, call, cls, words, backend):
    with pytest.raises(cls) as e:
        call(backend)
    assert isinstance(e.value, lugre.LugreError)
    assert isinstance(e.value, ValueError)
    for w in words:
        assert w in str(e.value), (w, str(e.value))


BAD_MODELS = [
    ("axis.mass", lambda d: d["axis"].update(mass=0.0)),
    ("axis.mass", lambda d: d["axis"].update(mass=-3.0)),
    ("friction.sigma0", lambda d: d["friction"].update(sigma0=0.0)),
    ("friction.positive.vs", lambda d: d["friction"]["positive"].update(vs=-0.01)),
    ("friction.negative.fs", lambda d: d["friction"]["negative"].update(fs=10.0)),
    ("friction.sigma1", lambda d: d["friction"].update(sigma1=math.nan)),
    ("friction.positive.fc", lambda d: d["friction"]["positive"].update(fc=math.inf)),
]


@pytest.mark.parametrize("path,edit", BAD_MODELS, ids=[f"{p}-{k}" for k, (p, _) in
                                                       enumerate(BAD_MODELS)])
@pytest.mark.parametrize("backend", BACKENDS, ids=["lugre", "reference"])
def test_bad_parameters_same_errors(path, edit, backend):
    d = lugre.Model.paper().to_dict()
    edit(d)
    with pytest.raises(lugre.ParameterError) as e:
        backend.stribeck([0.1], lugre.Model.from_dict(d))
    assert isinstance(e.value, ValueError)
    assert path in str(e.value)


def test_core_rejects_bad_model_json_directly():
    """The core validates on its own, whatever Python let through."""
    from lugre import _core

    d = lugre.Model.paper().to_dict()
    d["axis"]["mass"] = -1.0
    import json

    with pytest.raises(lugre.ParameterError) as e:
        _core.stribeck(np.zeros(1), json.dumps(d))
    assert "axis.mass" in str(e.value) and e.value.name == "axis.mass"
