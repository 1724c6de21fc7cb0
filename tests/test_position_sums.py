"""The periodogram kernel over position (``_core.position_sums`` behind
``lugre._native.position_sums``) against its NumPy twin
(``lugre.reference.position_sums``): the same sums to 1e-12 of their scale (the core
advances the angles by rotation, re-started from exact values every 32 frequencies;
measured: a few 1e-15), the same errors naming the argument, never a panic; and the
diagnosis's two users of it unchanged against the NumPy code they replaced."""

from __future__ import annotations

import importlib

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from lugre import _native, reference
from lugre.diagnosis import candidates as E
from lugre.diagnosis import residual as R
from lugre.diagnosis.synth import concealed
from lugre.exceptions import InputError, ParameterError

BACKENDS = (_native.position_sums, reference.position_sums)


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300))


@settings(max_examples=40, deadline=None)
@given(m=st.integers(0, 700), n=st.integers(1, 150), k0=st.floats(-500.0, 2000.0),
       dk=st.floats(0.01, 20.0), stroke=st.floats(1e-3, 2.0), squares=st.booleans(),
       seed=st.integers(0, 2**16))
def test_twins_agree(m, n, k0, dk, stroke, squares, seed):
    rng = np.random.default_rng(seed)
    x = stroke * (rng.random(m) - 0.3)
    r = rng.standard_normal(m)
    a = _native.position_sums(x, r, k0, dk, n, squares=squares)
    b = reference.position_sums(x, r, k0, dk, n, squares=squares)
    assert len(a) == len(b) == (5 if squares else 2)
    for u, w in zip(a, b):
        assert u.shape == w.shape == (n,)
        # each sum against the scale of its terms (sum |r| or the sample count)
        scale = max(float(np.abs(r).sum()), float(m), 1.0)
        assert np.max(np.abs(u - w), initial=0.0) <= 1e-12 * scale


def test_sums_of_a_sinusoid():
    x = np.linspace(0.0, 0.3, 3001)
    r = 2.0 * np.sin(2 * np.pi * 40.0 * x + 0.3)
    for f in BACKENDS:
        s, c, ss, cc, sc = f(x, r, 10.0, 2.5, 25, squares=True)
        det = ss * cc - sc * sc
        bs, bc = (cc * s - sc * c) / det, (ss * c - sc * s) / det
        j = int(np.argmax(np.hypot(bs, bc)))
        assert j == 12  # 10 + 12*2.5 = 40 periods per metre
        assert abs(np.hypot(bs[j], bc[j]) - 2.0) < 1e-9
        assert abs(np.arctan2(bc[j], bs[j]) - 0.3) < 1e-9


BAD = {
    "x nan": ({"x": [0.0, np.nan]}, InputError, "x"),
    "x 2-D": ({"x": np.zeros((2, 2))}, InputError, "x"),
    "x scalar": ({"x": 1.0}, InputError, "x"),
    "r length": ({"r": [0.0]}, InputError, "r"),
    "r inf": ({"r": [0.0, np.inf]}, InputError, "r"),
    "k0 nan": ({"k0": np.nan}, ParameterError, "k0"),
    "k0 text": ({"k0": "a"}, ParameterError, "k0"),
    "dk zero": ({"dk": 0.0}, ParameterError, "dk"),
    "dk negative": ({"dk": -1.0}, ParameterError, "dk"),
    "dk inf": ({"dk": np.inf}, ParameterError, "dk"),
    "n zero": ({"n": 0}, ParameterError, "n"),
    "n negative": ({"n": -3}, ParameterError, "n"),
    "n huge": ({"n": 2**40}, ParameterError, "n"),
    "n float": ({"n": 2.5}, ParameterError, "n"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_input_same_errors(case):
    kw, cls, name = BAD[case]
    args = {"x": [0.0, 1.0], "r": [1.0, 2.0], "k0": 1.0, "dk": 1.0, "n": 3} | kw
    msgs = []
    for f in BACKENDS:
        with pytest.raises(cls) as e:
            f(args["x"], args["r"], args["k0"], args["dk"], args["n"], squares=True)
        assert e.value.name == name
        msgs.append(str(e.value))
    assert msgs[0] == msgs[1]


def test_numpy_integer_count_and_empty_samples():
    for f in BACKENDS:
        s, c = f(np.zeros(0), np.zeros(0), 1.0, 1.0, np.int64(3))
        assert np.array_equal(s, np.zeros(3)) and np.array_equal(c, np.zeros(3))


@pytest.fixture(scope="module")
def record():
    rec, model, _ = concealed("cogging", duration=6.0)
    sig = R.prepare(rec, model)
    sigr = R.prepare(rec, model, backend=reference.kernels)
    return sig, sigr, sig.kernel.residual(model), model


def _old_power(r, x, ks):
    ph = 2.0 * np.pi * np.outer(ks, x)
    s, c = np.sin(ph), np.cos(ph)
    ss, cc, sc = (s * s).sum(1), (c * c).sum(1), (s * c).sum(1)
    rs, rc = np.einsum("ij,j->i", s, r), np.einsum("ij,j->i", c, r)
    det = ss * cc - sc * sc
    bs = (cc * rs - sc * rc) / det
    bc = (ss * rc - sc * rs) / det
    return bs * rs + bc * rc


def test_cogging_power_as_the_numpy_code(record):
    """``Cogging._power`` on the kernel against the outer products it replaced."""
    sig, sigr, r, model = record
    ctx = E.Context.build(sig, model, R.base_friction(model, sig))
    cog = E.Cogging()
    ks = cog._kgrid(ctx)
    assert ks.size > 50
    x = sig.x[sig.mask][::2]
    rr = r[sig.mask][::2] - np.mean(r[sig.mask])
    want = _old_power(rr, x, ks)
    dk = 0.25 / max(ctx.xrange[1] - ctx.xrange[0], 1e-9)
    for s in (sig, sigr):
        got = cog._power(rr, x, float(ks[0]), dk, ks.size, s)
        assert np.max(np.abs(got - want) / want) <= 1e-10


def test_position_spectrum_as_the_numpy_code(record):
    sig, sigr, r, _ = record
    locate = importlib.import_module("lugre.diagnosis.locate")
    m = sig.mask
    step = max(1, int(m.sum() // 4000))
    x = sig.x[m][::step]
    rr = r[m][::step] - np.mean(r[m])
    span = max(float(np.ptp(x)), 1e-9)
    ks = np.arange(1.0 / span, min(200.0 / span, 2000.0), 0.5 / span)
    ph = 2 * np.pi * np.outer(ks, x)
    want = 2 * np.hypot(np.sin(ph) @ rr, np.cos(ph) @ rr) / x.size
    for s in (sig, sigr):
        k, got = locate.position_spectrum(r, s)
        assert np.array_equal(k, ks)
        assert np.max(np.abs(got - want) / want) <= 1e-10
