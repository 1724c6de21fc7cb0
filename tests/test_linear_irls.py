"""The robust linear fit by IRLS (``_core.irls_linear`` / ``irls_linear_grid`` behind
``lugre._native``) against its NumPy twin (``lugre.reference``): the same numbers bit for
bit on random problems with gross errors, the same errors naming the argument, never a
panic; the robust fit rejects planted gross errors that pull least squares; the
inverse-dynamics fit it serves gives what the NumPy IRLS it replaced gave."""

from __future__ import annotations

import math

import lugre
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from lugre import _native
from lugre import reference as ref
from shared_data import shared_file

BACKENDS = (_native, ref)


def problem(seed, n, p, share, scale_spread=2.0):
    """``y = X b + noise`` with columns of very different scales and a share of gross
    errors (5 to 60 noise levels, either sign)."""
    rng = np.random.default_rng(seed)
    scales = 10.0 ** rng.uniform(-scale_spread, scale_spread, p)
    X = rng.standard_normal((n, p)) * scales
    X[:, 0] = 1.0 + 0.1 * rng.standard_normal(n)  # an offset-like column
    b = rng.standard_normal(p) / scales
    y = X @ b + 0.1 * rng.standard_normal(n)
    bad = rng.random(n) < share
    y[bad] += 0.1 * rng.uniform(5.0, 60.0, bad.sum()) * rng.choice([-1.0, 1.0], bad.sum())
    return X, y, b, bad


def assert_same_fit(a, b):
    assert type(a) is type(b)
    for k in ("coef", "weights", "residuals"):
        x, y = getattr(a, k), getattr(b, k)
        assert x.dtype == y.dtype == np.float64 and x.shape == y.shape, k
        np.testing.assert_array_equal(x, y, err_msg=k)
    assert a.sse == b.sse and a.scale == b.scale


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1),
       n=st.one_of(st.integers(1, 60), st.integers(200, 5000)), p=st.integers(1, 10),
       share=st.sampled_from([0.0, 0.05, 0.2, 0.4]),
       weighting=st.sampled_from(["igg", "huber", "tukey", "none"]),
       rounds=st.integers(1, 9), fortran=st.booleans())
def test_twins_agree_bit_for_bit(seed, n, p, share, weighting, rounds, fortran):
    """Random problems with gross errors, every weighting, 1 to 10 columns (the core's
    unrolled sums up to 8 and its general loop beyond): the same fit, bit for bit, or
    the same refusal."""
    X, y, _, _ = problem(seed, n, p, share)
    if fortran:
        X = np.asfortranarray(X)
    out = []
    for backend in BACKENDS:
        try:
            out.append(backend.irls_linear(X, y, weighting=weighting, rounds=rounds))
        except lugre.LugreError as e:
            out.append(["refused", type(e), str(e)])
    if isinstance(out[0], list):
        assert out[0] == out[1]
        # fewer rows than columns, or (tiny exact fits) weights that keep no row
        assert n < p or out[0][1] is lugre.DataError, out[0]
        return
    assert_same_fit(*out)
    a = out[0]
    assert a.coef.shape == (p,) and a.weights.shape == a.residuals.shape == (n,)
    np.testing.assert_allclose(a.residuals, y - X @ a.coef, rtol=0, atol=1e-9 * (
        1.0 + np.max(np.abs(y))))


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1),
       n=st.one_of(st.integers(20, 100), st.integers(500, 3000)), p=st.integers(1, 6),
       q=st.integers(1, 3), k=st.integers(0, 8), share=st.sampled_from([0.0, 0.1, 0.3]),
       ratio=st.sampled_from([0.98, 1.0, 0.5]))
def test_grid_twins_agree_bit_for_bit(seed, n, p, q, k, share, ratio):
    X, y, _, _ = problem(seed, n, p, share)
    rng = np.random.default_rng(seed + 1)
    # candidates: noise columns, and some that explain part of y with a positive sign
    extras = []
    for j in range(k):
        c = rng.standard_normal((n, q))
        if j % 2:
            y = y + 0.05 * c.sum(axis=1)
        extras.append(c)
    out = []
    for backend in BACKENDS:
        try:
            out.append(backend.irls_linear_grid(X, extras, y, ratio=ratio))
        except lugre.DataError as e:
            # few rows, many gross errors: the weights of the first fit can reject every
            # row (residuals are weighed about zero, not about their median)
            out.append(["refused", str(e)])
    if isinstance(out[0], list):
        assert out[0] == out[1]
        return
    a, b = out
    assert a.chosen == b.chosen and a.base_sse == b.base_sse
    np.testing.assert_array_equal(a.sse, b.sse)
    assert a.sse.shape == (k,)
    assert_same_fit(a.fit, b.fit)
    # the choice follows the rule: positive extra coefficients, SSE below ratio x best
    best, chosen = a.base_sse, None
    for j in range(k):
        f = ref.irls_linear(np.column_stack([X, extras[j]]), y)
        assert f.sse == a.sse[j]
        if np.all(f.coef[p:] > 0) and f.sse < ratio * best:
            best, chosen = f.sse, j
    assert chosen == a.chosen


def _old_irls(X, y):
    """The NumPy IRLS that ``diagnosis/inverse.py`` held before the core took it over,
    verbatim (einsum sums, LAPACK solve, IGG constants written in)."""
    w = np.ones(X.shape[0])
    b = np.zeros(X.shape[1])
    for _ in range(8):
        G = np.einsum("ij,ik,i->jk", X, X, w)
        b = np.linalg.solve(G + 1e-12 * np.trace(G) * np.eye(G.shape[0]),
                            np.einsum("ij,i->j", X, w * y))
        e = y - np.einsum("ij,j->i", X, b)
        s = 1.4826 * np.median(np.abs(e - np.median(e))) + 1e-12
        u = np.abs(e) / s
        w = np.where(u <= 1.5, 1.0, np.where(u <= 2.5, 1.5 / u, 0.0))
    e = y - np.einsum("ij,j->i", X, b)
    return b, float(np.sum(w * e * e))


@pytest.mark.parametrize("seed", range(6))
def test_same_answer_as_the_numpy_irls_it_replaces(seed):
    """Only the order of the sums and the solver differ: on well-conditioned problems
    the coefficients and SSE agree with the former NumPy code to rounding."""
    X, y, _, _ = problem(seed, 3000, 7, 0.1, scale_spread=1.0)
    b_old, sse_old = _old_irls(X, y)
    for backend in BACKENDS:
        f = backend.irls_linear(X, y)
        np.testing.assert_allclose(f.coef, b_old, rtol=1e-10, atol=1e-12 * np.max(np.abs(b_old)))
        assert f.sse == pytest.approx(sse_old, rel=1e-10)


def test_robust_fit_rejects_planted_gross_errors_that_pull_least_squares():
    """One-sided gross errors in 15 % of the rows: least squares is pulled by many
    standard errors, the IGG fit is not, and it gives every planted error weight 0."""
    rng = np.random.default_rng(3)
    n = 2000
    t = np.linspace(-1.0, 1.0, n)
    X = np.column_stack([np.ones(n), t, t * t])
    b = np.array([2.0, -1.0, 0.5])
    y = X @ b + 0.05 * rng.standard_normal(n)
    bad = rng.random(n) < 0.15
    y[bad] += rng.uniform(1.0, 3.0, bad.sum())  # 20 to 60 noise levels, all upwards
    se = 0.05 * np.sqrt(np.diag(np.linalg.inv(X.T @ X)))
    for backend in BACKENDS:
        robust = backend.irls_linear(X, y)
        plain = backend.irls_linear(X, y, weighting="none", rounds=1)
        assert np.all(np.abs(robust.coef - b) < 4 * se), (robust.coef - b) / se
        assert np.max(np.abs(plain.coef - b) / se) > 50, (plain.coef - b) / se
        assert np.all(robust.weights[bad] == 0.0)
        assert np.mean(robust.weights[~bad] > 0) > 0.97
        # the MAD of all residuals, gross errors included: above the noise level, not
        # near the size of the errors
        assert 0.05 < robust.scale < 0.08


def test_grid_picks_the_candidate_that_explains_the_data():
    """Three candidate humps, the true one second: it is chosen, its coefficient found
    through 10 % gross errors; a negative hump is never chosen."""
    rng = np.random.default_rng(5)
    n = 4000
    v = np.linspace(-0.2, 0.2, n)
    X = np.column_stack([np.sign(v), v])
    humps = [np.column_stack([np.sign(v) * np.exp(-(v / vs) ** 2)]) for vs in (0.002, 0.02, 0.1)]
    y = X @ [20.0, 300.0] + 8.0 * humps[1][:, 0] + 0.3 * rng.standard_normal(n)
    bad = rng.random(n) < 0.1
    y[bad] += rng.choice([-1.0, 1.0], bad.sum()) * rng.uniform(5.0, 15.0, bad.sum())
    for backend in BACKENDS:
        g = backend.irls_linear_grid(X, humps, y)
        assert g.chosen == 1
        assert g.fit.coef[2] == pytest.approx(8.0, rel=0.05)
        assert g.fit.sse < 0.98 * g.base_sse
        neg = backend.irls_linear_grid(X, [-h for h in humps], y)
        assert neg.chosen is None and neg.fit.coef.shape == (2,)


# ---- errors: the same class and message from both, naming the argument --------------------

X3 = np.column_stack([np.ones(6), np.arange(6.0)])
Y3 = np.arange(6.0) * 2.0 + 1.0 + 0.01 * np.sin(np.arange(6.0))


def _with(a, i, j, value):
    b = np.array(a, dtype=float)
    b[i, j] = value
    return b


BAD = [
    # (description, call(backend), exception class, name, words)
    ("x 1-D", lambda b: b.irls_linear(np.ones(6), Y3), lugre.InputError, "X", "2-D array"),
    ("x 3-D", lambda b: b.irls_linear(np.ones((6, 2, 1)), Y3), lugre.InputError, "X",
     "2-D array"),
    ("x text", lambda b: b.irls_linear([["a", "b"]], Y3), lugre.InputError, "X",
     "array of numbers"),
    ("no rows", lambda b: b.irls_linear(np.zeros((0, 2)), []), lugre.InputError, "X",
     "has no rows"),
    ("no columns", lambda b: b.irls_linear(np.zeros((6, 0)), Y3), lugre.InputError, "X",
     "has no columns"),
    ("fewer rows", lambda b: b.irls_linear(X3[:1], Y3[:1]), lugre.InputError, "X",
     "2 unknowns for 1 rows"),
    ("x nan", lambda b: b.irls_linear(_with(X3, 4, 1, math.nan), Y3), lugre.InputError, "X",
     "row 4, column 1 is NaN"),
    ("x inf", lambda b: b.irls_linear(_with(X3, 0, 0, -math.inf), Y3), lugre.InputError, "X",
     "row 0, column 0 is -inf"),
    ("y length", lambda b: b.irls_linear(X3, Y3[:5]), lugre.InputError, "y",
     "has 5 samples but X has 6 rows"),
    ("y 2-D", lambda b: b.irls_linear(X3, X3), lugre.InputError, "y", "1-D"),
    ("y nan", lambda b: b.irls_linear(X3, np.r_[Y3[:2], math.nan, Y3[3:]]), lugre.InputError,
     "y", "element 2 is NaN"),
    ("x zero", lambda b: b.irls_linear(np.zeros((6, 2)), Y3), lugre.InputError, "X",
     "zero in every row"),
    ("x overflows", lambda b: b.irls_linear(X3 * 1e200, Y3), lugre.InputError, "X",
     "normal matrix overflows"),
    ("y overflows", lambda b: b.irls_linear(X3, Y3 * 1e307), lugre.InputError, "y",
     "the fit overflows (X^T W y is inf in column 0)"),
    ("weighting", lambda b: b.irls_linear(X3, Y3, weighting="cauchy"), lugre.InputError,
     "weighting", 'unknown weighting "cauchy"'),
    ("rounds 0", lambda b: b.irls_linear(X3, Y3, rounds=0), lugre.ParameterError, "rounds",
     "must be at least 1"),
    ("rounds negative", lambda b: b.irls_linear(X3, Y3, rounds=-2), lugre.ParameterError,
     "rounds", "must be at least 1"),
    ("ratio 0", lambda b: b.irls_linear_grid(X3, [], Y3, ratio=0.0), lugre.ParameterError,
     "ratio", "must be a number in (0, 1]"),
    ("ratio nan", lambda b: b.irls_linear_grid(X3, [], Y3, ratio=math.nan),
     lugre.ParameterError, "ratio", "(0, 1]"),
    ("ratio text", lambda b: b.irls_linear_grid(X3, [], Y3, ratio="most"),
     lugre.ParameterError, "ratio", "finite number"),
    ("extras not a sequence", lambda b: b.irls_linear_grid(X3, 3.0, Y3), lugre.InputError,
     "extras", "sequence of 2-D arrays"),
    ("extras 1-D", lambda b: b.irls_linear_grid(X3, [np.ones(6)], Y3), lugre.InputError,
     "extras[0]", "2-D array"),
    ("extras rows", lambda b: b.irls_linear_grid(X3, [np.ones((6, 1)), np.ones((5, 1))], Y3),
     lugre.InputError, "extras[1]", "has 5 rows but X has 6"),
    ("extras no columns", lambda b: b.irls_linear_grid(X3, [np.ones((6, 0))], Y3),
     lugre.InputError, "extras[0]", "has no columns"),
    ("extras nan", lambda b: b.irls_linear_grid(X3, [_with(np.ones((6, 2)), 3, 1, math.nan)],
                                                Y3),
     lugre.InputError, "extras[0]", "row 3, column 1 is NaN"),
    ("extras too many", lambda b: b.irls_linear_grid(X3, [np.ones((6, 5))], Y3),
     lugre.InputError, "extras[0]", "7 unknowns for 6 rows"),
    ("extras overflow", lambda b: b.irls_linear_grid(X3, [np.full((6, 1), 1e200)], Y3),
     lugre.InputError, "extras[0]", "joined to X: its normal matrix overflows"),
]


@pytest.mark.parametrize("desc,call,cls,name,words", BAD, ids=[b[0] for b in BAD])
def test_bad_input_same_errors(desc, call, cls, name, words):
    msgs = []
    for backend in BACKENDS:
        with pytest.raises(cls) as e:
            call(backend)
        assert isinstance(e.value, lugre.LugreError) and isinstance(e.value, ValueError)
        assert e.value.name == name, (e.value.name, str(e.value))
        assert words in str(e.value), str(e.value)
        assert name in str(e.value)
        msgs.append(str(e.value))
    assert msgs[0] == msgs[1]


def test_weights_rejecting_every_nonzero_row_is_a_data_error():
    """The weights can leave only rows whose regressors are zero: a DataError from both,
    saying which weighting and round, not a LinAlgError or NaN coefficients."""
    n = 40
    X = np.zeros((n, 1))
    X[:5, 0] = 1.0  # five rows carry the regressor, 35 are zero
    y = np.zeros(n)
    y[5:] = 0.01 * np.sin(np.arange(n - 5))  # the zero rows fit to noise
    y[:5] = 1000.0 * np.array([1.0, 2.0, 3.0, 4.0, 6.0])  # unequal, none at the mean: rejected
    msgs = []
    for backend in BACKENDS:
        with pytest.raises(lugre.DataError) as e:
            backend.irls_linear(X, y)
        msgs.append(str(e.value))
    assert msgs[0] == msgs[1]
    assert "igg weights keep no row in which X is non-zero (round 2 of 8)" in msgs[0]


@pytest.mark.parametrize("call", [
    lambda b: b.irls_linear(X3, Y3, rounds=2.0),
    lambda b: b.irls_linear(X3, Y3, rounds=True),
    lambda b: b.irls_linear(X3, Y3, weighting=None),
], ids=["rounds float", "rounds bool", "weighting None"])
def test_wrong_types_are_type_errors(call):
    for backend in BACKENDS:
        with pytest.raises(TypeError):
            call(backend)


# ---- the inverse-dynamics fit that uses it -------------------------------------------------


@pytest.mark.parametrize("case", ["none", "drag"])
def test_inverse_dynamics_fit_same_on_both_backends(case):
    """``fit_inverse_dynamics`` on a shared record: the core and the twin give the same
    model, bit for bit (the filters and the robust fit are twins)."""
    from lugre.diagnosis import fit_inverse_dynamics

    path = shared_file("mismatch", case, "recording.csv")
    a = fit_inverse_dynamics(path, backend="core").to_dict()
    b = fit_inverse_dynamics(path, backend=ref.kernels).to_dict()
    assert a == b
    assert a["axis"]["mass"] > 0
