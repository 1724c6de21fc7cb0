"""Robust linear least squares by IRLS (``src/estimate/linear.rs``) in NumPy.

The twin of ``_core.irls_linear`` and ``_core.irls_linear_grid``: the same rounds and
the same floating-point operations in the same order, vectorised over the rows, so that
the two agree bit for bit. Sums over rows are taken with ``np.add.accumulate`` (in row
order from the first row's term, as the core sums; ``np.sum`` adds pairwise); the
medians of the robust scale are the same order statistics; the small linear solve is
the core's Gaussian elimination over Python floats. Exported by :mod:`lugre.reference`
as :func:`irls_linear` and :func:`irls_linear_grid`.

The argument conversions in front of both backends are :mod:`lugre._args`'s, so that
``lugre._native`` refuses what this module refuses with the same message.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._args import grid_args, linear_args
from .._result import GridFit, LinearFit
from ..exceptions import DataError, InputError, ParameterError, _fmt_f64
from .robust import Weighting

__all__ = ["DEFAULT_ROUNDS", "irls_linear", "irls_linear_grid"]

#: Rounds of reweighting by default (``DEFAULT_ROUNDS`` in linear.rs).
DEFAULT_ROUNDS = 8
_RIDGE = 1e-12
_SCALE_FLOOR = 1e-12


# --------------------------------------------------------------------------------------
# The core's checks, in the core's order
# --------------------------------------------------------------------------------------


def _check_design(name: str, a: np.ndarray, rows: int | None) -> None:
    n, p = a.shape
    if rows is not None and n != rows:
        raise InputError.at(name, f"has {n} rows but X has {rows}: give the candidate's "
                            "columns on the rows of X")
    if n == 0:
        raise InputError.at(name, "has no rows: give one row per sample")
    if p == 0:
        raise InputError.at(name, "has no columns: give at least one regressor")
    bad = np.flatnonzero(~np.isfinite(a.T))  # column by column, as the core reads it
    if bad.size:
        k = int(bad[0])
        i, j = k % n, k // n
        raise InputError.at(name, f"row {i}, column {j} is {_fmt_f64(float(a[i, j]))} : "
                            "remove or interpolate non-finite samples")


def _check_unknowns(name: str, rows: int, unknowns: int) -> None:
    if rows < unknowns:
        raise InputError.at(name, f"gives {unknowns} unknowns for {rows} rows: give at least "
                            "as many rows (samples) as columns (unknowns)")


def _check_target(y: np.ndarray, rows: int) -> None:
    if y.size != rows:
        raise InputError.at("y", f"has {y.size} samples but X has {rows} rows: give one "
                            "target per row of X")
    bad = np.flatnonzero(~np.isfinite(y))
    if bad.size:
        k = int(bad[0])
        raise InputError.at("y", f"element {k} is {_fmt_f64(float(y[k]))} : remove or "
                            "interpolate non-finite samples")


def _check_ratio(ratio: float) -> None:
    if not (math.isfinite(ratio) and 0.0 < ratio <= 1.0):
        raise ParameterError.invalid(
            "ratio", ratio, "must be a number in (0, 1]: the fraction of the best weighted "
            "sum of squares a candidate must get below")


# --------------------------------------------------------------------------------------
# The rounds (fit_rows in linear.rs)
# --------------------------------------------------------------------------------------


def _row_sum(a: np.ndarray) -> np.ndarray:
    """Sums along the last axis in order from the first element (the core's sums)."""
    return np.add.accumulate(a, axis=-1)[..., -1]


def _solve(a: list[list[float]], b: list[float]) -> list[float] | None:
    """Gaussian elimination with partial pivoting, as ``solve`` in linear.rs."""
    p = len(b)
    for k in range(p):
        piv, big = k, abs(a[k][k])
        for i in range(k + 1, p):
            v = abs(a[i][k])
            if v > big:
                big, piv = v, i
        if not (big > 0.0 and math.isfinite(big)):
            return None
        if piv != k:
            a[k], a[piv] = a[piv], a[k]
            b[k], b[piv] = b[piv], b[k]
        d = a[k][k]
        rk = a[k]
        for i in range(k + 1, p):
            ri = a[i]
            f = ri[k] / d
            for j in range(k + 1, p):
                ri[j] -= f * rk[j]
            b[i] -= f * b[k]
    x = [0.0] * p
    for k in range(p - 1, -1, -1):
        s = b[k]
        for j in range(k + 1, p):
            s -= a[k][j] * x[j]
        x[k] = s / a[k][k]
    return x if all(math.isfinite(v) for v in x) else None


def _median(a: np.ndarray) -> float:
    """The median as ``robust.rs`` takes it: the middle order statistic, or half the
    sum of the two middle ones."""
    n = a.size
    h = n // 2
    if n % 2 == 1:
        return float(np.partition(a, h)[h])
    part = np.partition(a, (h - 1, h))
    return 0.5 * (float(part[h - 1]) + float(part[h]))


def _robust_scale(e: np.ndarray) -> float:
    """``robust_scale`` of finite residuals (``1.4826*MAD``; ``1.2533*mean|e - median|``
    when the MAD is zero)."""
    m = _median(e)
    dev = np.abs(e - m)
    mad = _median(dev)
    if mad > 0.0 and math.isfinite(mad):
        return 1.4826 * mad
    finite = dev[np.isfinite(dev)]
    if finite.size == 0:
        return 0.0
    return 1.2533 * float(_row_sum(finite)) / finite.size


def _weights(wt: Weighting, e: np.ndarray, s: float) -> np.ndarray:
    """``Weighting::weights`` over an array."""
    if not s > 0.0:
        return np.where(e == 0.0, 1.0, wt.weight(math.inf))
    a = np.abs(e / s)
    with np.errstate(divide="ignore", invalid="ignore"):
        if wt.kind == "igg":
            w = np.where(a <= wt.k0, 1.0, np.where(a <= wt.k1, wt.k0 / a, 0.0))
        elif wt.kind == "huber":
            w = np.where(a <= wt.c, 1.0, wt.c / a)
        elif wt.kind == "tukey":
            r = a / wt.c
            q = 1.0 - r * r
            w = np.where(a < wt.c, q * q, 0.0)
        else:
            w = np.ones_like(a)
    return np.where(np.isnan(a), 0.0, w)


def _fit_rows(xt: np.ndarray, y: np.ndarray, wt: Weighting, rounds: int) -> LinearFit:
    """The IRLS rounds on a checked design given by columns (``xt`` is ``p x n``)."""
    p, n = xt.shape
    w = np.ones(n)
    coef = [0.0] * p
    e = np.zeros(n)
    s = 0.0
    for rnd in range(rounds):
        g = [[0.0] * p for _ in range(p)]
        with np.errstate(over="ignore", invalid="ignore"):  # overflow is checked below
            wx = xt * w
            for j in range(p):
                row = _row_sum(wx[j] * xt[j:]).tolist()
                for k in range(j, p):
                    g[j][k] = g[k][j] = row[k - j]
            rhs = _row_sum(wx * y).tolist()
        trace = g[0][0]
        for j in range(1, p):
            trace += g[j][j]
        if not math.isfinite(trace):
            raise InputError.at("X", f"its normal matrix overflows (trace {_fmt_f64(trace)}): "
                                "scale the columns of X to moderate values")
        if trace == 0.0:
            if rnd == 0:
                raise InputError.at("X", "is zero in every row: give at least one non-zero "
                                    "regressor")
            raise DataError(f"data: the {wt.name} weights keep no row in which X is non-zero "
                            f"(round {rnd + 1} of {rounds}): check y for gross errors in "
                            'most rows, or use weighting "huber"')
        bad_rhs = [j for j, v in enumerate(rhs) if not math.isfinite(v)]
        if bad_rhs:
            j = bad_rhs[0]
            raise InputError.at("y", f"the fit overflows (X^T W y is {_fmt_f64(rhs[j])} in "
                                f"column {j}): scale y and the columns of X to moderate values")
        lam = _RIDGE * trace
        for j in range(p):
            g[j][j] += lam
        sol = _solve(g, rhs)
        if sol is None:
            raise DataError(f"data: the weighted normal matrix of X is singular (round "
                            f"{rnd + 1} of {rounds}): drop columns of X that are "
                            "combinations of others")
        coef = sol
        with np.errstate(over="ignore", invalid="ignore"):
            f = xt[0] * coef[0]
            for j in range(1, p):
                f = f + xt[j] * coef[j]
            e = y - f
        bad = np.flatnonzero(~np.isfinite(e))
        if bad.size:
            k = int(bad[0])
            raise InputError.at("y", f"the fit overflows (residual {k} is "
                                f"{_fmt_f64(float(e[k]))}): scale y and the columns of X "
                                "to moderate values")
        s = _robust_scale(e) + _SCALE_FLOOR
        w = _weights(wt, e, s)
    sse = float(_row_sum((w * e) * e))
    return LinearFit(coef=np.array(coef, dtype=np.float64), weights=w, residuals=e, sse=sse,
                     scale=s)


# --------------------------------------------------------------------------------------
# The public twins
# --------------------------------------------------------------------------------------


def irls_linear(x: Any, y: Any, *, weighting: str = "igg", rounds: int = DEFAULT_ROUNDS
                ) -> LinearFit:
    """Robust linear least squares ``y ~ X b`` by iteratively reweighted least squares.

    Starting from unit weights, each of ``rounds`` rounds solves the weighted normal
    equations ``(X^T W X + 1e-12*trace(X^T W X)*I) b = X^T W y``, then takes the
    residuals ``e = y - X b``, the scale ``s = 1.4826*MAD(e) + 1e-12`` and the weights
    ``w_i = weighting(e_i/s)`` (IGG: 1 up to 1.5 scales, ``1.5/|u|`` up to 2.5, 0
    beyond). NumPy twin of :func:`lugre._native.irls_linear` (``src/estimate/linear.rs``);
    the two agree bit for bit.

    Parameters
    ----------
    x : array_like
        Design matrix, 2-D (rows x columns), finite, at least as many rows as columns.
    y : array_like
        Target, 1-D, one value per row of ``x``, finite.
    weighting : {"igg", "huber", "tukey", "none"}, default "igg"
        Weight function (the seed paper's IGG by default).
    rounds : int, default 8
        Rounds of reweighting (no early stop), at least 1.

    Returns
    -------
    LinearFit
        ``coef`` (the last round's), ``weights`` and ``residuals`` of ``coef``, ``sse``
        (``sum w*e^2``) and the ``scale`` of the weights.

    Raises
    ------
    InputError
        ``x`` not 2-D, without rows or columns, fewer rows than columns or not finite;
        ``y`` of another length or not finite; values so large that the fit overflows.
    ParameterError
        ``rounds`` below 1.
    DataError
        The weights keep no row with a non-zero regressor, or the normal matrix is
        singular.

    Examples
    --------
    >>> import numpy as np
    >>> from lugre import reference
    >>> t = np.linspace(0.0, 1.0, 30)
    >>> y = 2.0 + 3.0 * t + 0.01 * np.sin(40 * t)
    >>> y[4] += 10.0                       # a gross error
    >>> fit = reference.irls_linear(np.column_stack([np.ones(30), t]), y)
    >>> bool(abs(fit.coef[1] - 3.0) < 0.05), float(fit.weights[4])
    (True, 0.0)
    """
    xa, ya, name, nr = linear_args(x, y, weighting, rounds)
    wt = Weighting.from_name(name)
    _check_design("X", xa, None)
    _check_unknowns("X", xa.shape[0], xa.shape[1])
    _check_target(ya, xa.shape[0])
    return _fit_rows(np.ascontiguousarray(xa.T), ya, wt, nr)


def irls_linear_grid(x: Any, extras: Any, y: Any, *, weighting: str = "igg",
                     rounds: int = DEFAULT_ROUNDS, ratio: float = 0.98) -> GridFit:
    """:func:`irls_linear` of ``x`` alone and of ``x`` joined by each candidate's extra
    columns; the best fit.

    The base fit is the first best. Candidates are taken in order; one replaces the best
    when every coefficient of its extra columns is greater than zero and its weighted
    sum of squares is below ``ratio`` times the best's. NumPy twin of
    :func:`lugre._native.irls_linear_grid`; the two agree bit for bit.

    Parameters
    ----------
    x : array_like
        Base design, 2-D, as in :func:`irls_linear`.
    extras : sequence of array_like
        Per candidate, its extra columns: 2-D, the rows of ``x``.
    y : array_like
        Target, 1-D, one value per row.
    weighting : {"igg", "huber", "tukey", "none"}, default "igg"
        Weight function.
    rounds : int, default 8
        Rounds of reweighting of every fit.
    ratio : float, default 0.98
        In (0, 1]: how far below the best's weighted sum of squares a candidate must get.

    Returns
    -------
    GridFit
        ``chosen`` (index into ``extras``, None for the base alone), its ``fit``
        (coefficients of ``x``'s columns, then of the candidate's), ``base_sse`` and the
        ``sse`` of every candidate.

    Raises
    ------
    InputError, ParameterError, DataError
        As :func:`irls_linear`, for ``ratio`` out of range, and naming ``extras[k]`` for
        a candidate of another number of rows, without columns, not finite or with too
        many columns for the rows.
    """
    xa, cands, ya, name, nr, rt = grid_args(x, extras, y, weighting, rounds, ratio)
    wt = Weighting.from_name(name)
    _check_ratio(rt)
    n, p0 = xa.shape
    _check_design("X", xa, None)
    _check_unknowns("X", n, p0)
    _check_target(ya, n)
    for k, c in enumerate(cands):
        _check_design(f"extras[{k}]", c, n)
        _check_unknowns(f"extras[{k}]", n, p0 + c.shape[1])
    xt = np.ascontiguousarray(xa.T)
    base = _fit_rows(xt, ya, wt, nr)
    best: tuple[int | None, LinearFit] = (None, base)
    sse = []
    for k, c in enumerate(cands):
        try:
            f = _fit_rows(np.concatenate([xt, c.T]), ya, wt, nr)
        except DataError as e:
            raise DataError(f"data: with extras[{k}]: {str(e).removeprefix('data: ')}") from None
        except InputError as e:
            if e.name != "X":
                raise
            msg = str(e).removeprefix("input X: ")
            raise InputError.at(f"extras[{k}]", f"joined to X: {msg}") from None
        sse.append(f.sse)
        if all(c > 0.0 for c in f.coef[p0:].tolist()) and f.sse < rt * best[1].sse:
            best = (k, f)
    return GridFit(chosen=best[0], fit=best[1], base_sse=base.sse,
                   sse=np.array(sse, dtype=np.float64))
