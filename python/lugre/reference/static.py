"""The static step in Python: the Stribeck curve of each direction from steady-state
points (``src/estimate/static_fit/``, ``docs/DESIGN.md``), twin of
:func:`lugre.fit_static`.

For a fixed ``vs`` the curve ``fc + (fs - fc)*phi + sigma2*a``, ``phi = exp(-(a/vs)^2)``,
is linear: the linear part comes from the 3x3 weighted normal equations (column-scaled
Cholesky, signs kept by an exhaustive active set), so every weighted problem is a
search over ``ln vs`` (a bracket, then Nelder-Mead). Starts: a Huber grid over
``ln vs`` and the two best least-trimmed-squares fits on each of three subset sizes;
IRLS with the chosen weights from each (from the trimmed fits at their high-breakdown
scale held fixed); the kept points refitted by least squares; the path of largest
Gaussian-plus-uniform mixture likelihood wins; covariance from the weighted Jacobian.
A direction with more than ``max_start_points`` points (FAST-LTS): the starts and the
paths on a subsample spread over the speeds (fixed-seed SplitMix64), the best two
distinct paths once more on all points, the larger likelihood on all points wins.

The operations follow the Rust code in the same order. Where the core's order is that
of an unstable selection (the subsets of the trimmed fits), sums may be taken in
another order, so the two agree to the precision of the optimiser's stopping rule,
not always bit for bit.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._args import as_array as _array
from .._fits import DirectionFit, StaticFit
from ..exceptions import ConvergenceWarning, DataError, InputError, ParameterError
from .checks import _check_finite
from .nm import NmOptions
from .robust import Weighting, median, robust_scale, t_quantile_975
from .static_starts import (
    _clamp_start,
    _fmax,
    _lts_scale,
    _lts_sizes,
    _refine_lts,
    _rescale,
    _start_values_huber,
    _start_values_lts,
    _subsample,
)
from .static_vp import P4, _div, _ln, _Sep, _vp_minimize

__all__ = ["DirectionFit", "StaticFit", "fit_static"]

MIN_POINTS_PER_DIRECTION = 5
STATIC_PARAM_NAMES = ("fc", "fs", "sigma2", "vs")
REFIT_REJECT_MIN = 4.685
MAX_START_POINTS = 400
FINISHED_PATHS = 2
_exp = math.exp



@dataclass(frozen=True)
class DirectionFitResult:
    """One direction's fit with the attributes of the core's
    ``_core.DirectionFitResult``, which :meth:`lugre.identify.DirectionFit._from_core`
    reads from either."""

    fc: float
    fs: float
    sigma2: float
    vs: float
    std_err: list[float]
    cov: list[float]
    ci_low: list[float]
    ci_high: list[float]
    indices: list[int]
    weights: np.ndarray
    residuals: np.ndarray
    scale: float
    sigma: float
    iterations: int
    converged: bool
    evaluations: int

# ---- IRLS and the refit of the kept points (reweight.rs) ---------------------------------


class _Cfg:
    def __init__(self, max_outer: int, tol: float, scale_floor: float, max_evals: int) -> None:
        self.max_outer, self.tol, self.scale_floor = max_outer, tol, scale_floor
        self.nm = NmOptions(max_evals, 1e-10, 1e-12, 0)
        self.nm_loose = NmOptions(max_evals, 1e-10, 1e-7, 0)
        self.nm_pre = NmOptions(max_evals, 1e-10, 1e-5, 0)
        self.obj_floor = 1e-6 * scale_floor * scale_floor


class _Outcome:
    def __init__(self, p: P4, residuals: list[float], weights: list[float], scale: float,
                 iterations: int, converged: bool, evals: int) -> None:
        self.p, self.residuals, self.weights, self.scale = p, residuals, weights, scale
        self.iterations, self.converged, self.evals = iterations, converged, evals


def _max_rel_change(p: P4, q: P4) -> float:
    m = 0.0
    for a, b in zip(p, q):
        m = max(m, abs(a - b) / max(abs(a), abs(b), 1e-300))
    return m


def _irls_vp(sep: _Sep, p0: P4, weighting: Weighting, cfg: _Cfg, stage: str,
             fixed: float | None = None) -> _Outcome:
    """IRLS (eqs. 19-24) over the profile; ``stage`` is ``pre``, ``refit`` or ``polish``;
    ``fixed``: a scale held through the rounds (an MM-estimate's M-step) instead of the
    MAD."""
    p = p0
    e = sep.residuals(p)

    def scale_of(e: list[float]) -> float:
        return _fmax(robust_scale(e) if fixed is None else fixed, cfg.scale_floor)

    s = scale_of(e)
    w = weighting.weights(e, s)
    evals = 1
    converged = False
    iterations = 0
    step = 0.3
    while iterations < max(cfg.max_outer, 1):
        iterations += 1
        nm = cfg.nm_pre if stage == "pre" else cfg.nm_loose
        pn, ev = _vp_minimize(sep, w, _ln(p[3]), step, nm, cfg.obj_floor)
        evals += ev
        dtheta = _max_rel_change(p, pn)
        d_ln_vs = abs(_ln(pn[3] / p[3]))
        p = pn
        e = sep.residuals(p)
        s = scale_of(e)
        w_new = weighting.weights(e, s)
        dw, dw_sum = 0.0, 0.0
        for a, b in zip(w_new, w):
            d = abs(a - b)
            dw, dw_sum = max(dw, d), dw_sum + d
        dw_mean = dw_sum / max(len(w), 1)
        w = w_new
        dw_tol = 1e-2 if stage == "pre" else 1e-3
        if dw <= dw_tol or dw_mean <= 1e-5 or dtheta <= cfg.tol:
            converged = True
            break
        step = min(max(3.0 * d_ln_vs, 1e-3), 0.1)
    if stage == "polish":
        pn, ev = _vp_minimize(sep, w, _ln(p[3]), 1e-3, cfg.nm, cfg.obj_floor)
        evals += ev
        p = pn
        e = sep.residuals(p)
        s = scale_of(e)
    return _Outcome(p, e, w, s, iterations, converged, evals)


def _refit_kept(sep: _Sep, out: _Outcome, k1: float, cfg: _Cfg) -> None:
    """Least squares on the kept points, rejections re-checked at ``k1`` times the kept
    points' scale until the kept set settles."""
    keep = [1.0 if w > 0.0 else 0.0 for w in out.weights]
    phi = _exp(-0.5 * k1 * k1) / math.sqrt(2.0 * math.pi)
    var_factor = 1.0 - 2.0 * k1 * phi / math.erf(k1 / math.sqrt(2.0))
    for _ in range(5):
        n_kept = 0.0
        for k in keep:
            n_kept += k
        if n_kept < MIN_POINTS_PER_DIRECTION:
            return
        p, ev = _vp_minimize(sep, keep, _ln(out.p[3]), 1e-3, cfg.nm, cfg.obj_floor)
        out.evals += ev
        e = sep.residuals(p)
        ss = 0.0
        for ei, wi in zip(e, keep):
            ss += wi * ei * ei
        s = max(math.sqrt(ss / (n_kept - 4.0) / var_factor), cfg.scale_floor)
        new_keep = [1.0 if abs(ei) <= k1 * s else 0.0 for ei in e]
        out.p, out.residuals, out.scale, out.weights = p, e, s, list(keep)
        if new_keep == keep:
            return
        keep = new_keep


# ---- covariance (intervals.rs) ----------------------------------------------------------


def _inverse4(a: list[list[float]]) -> list[list[float]] | None:
    """The inverse of a 4x4 matrix by cofactors, as nalgebra's ``try_inverse`` (MESA's
    unrolled formula; None when the determinant is zero)."""
    m = [a[k % 4][k // 4] for k in range(16)]  # column-major, as nalgebra stores it
    c00 = (m[5] * m[10] * m[15] - m[5] * m[11] * m[14] - m[9] * m[6] * m[15]
           + m[9] * m[7] * m[14] + m[13] * m[6] * m[11] - m[13] * m[7] * m[10])
    c01 = (-m[4] * m[10] * m[15] + m[4] * m[11] * m[14] + m[8] * m[6] * m[15]
           - m[8] * m[7] * m[14] - m[12] * m[6] * m[11] + m[12] * m[7] * m[10])
    c02 = (m[4] * m[9] * m[15] - m[4] * m[11] * m[13] - m[8] * m[5] * m[15]
           + m[8] * m[7] * m[13] + m[12] * m[5] * m[11] - m[12] * m[7] * m[9])
    c03 = (-m[4] * m[9] * m[14] + m[4] * m[10] * m[13] + m[8] * m[5] * m[14]
           - m[8] * m[6] * m[13] - m[12] * m[5] * m[10] + m[12] * m[6] * m[9])
    det = m[0] * c00 + m[1] * c01 + m[2] * c02 + m[3] * c03
    if det == 0.0:
        return None
    o = [[0.0] * 4 for _ in range(4)]
    o[0][0], o[0][1], o[0][2], o[0][3] = c00, c01, c02, c03
    o[1][0] = (-m[1] * m[10] * m[15] + m[1] * m[11] * m[14] + m[9] * m[2] * m[15]
               - m[9] * m[3] * m[14] - m[13] * m[2] * m[11] + m[13] * m[3] * m[10])
    o[2][0] = (m[1] * m[6] * m[15] - m[1] * m[7] * m[14] - m[5] * m[2] * m[15]
               + m[5] * m[3] * m[14] + m[13] * m[2] * m[7] - m[13] * m[3] * m[6])
    o[3][0] = (-m[1] * m[6] * m[11] + m[1] * m[7] * m[10] + m[5] * m[2] * m[11]
               - m[5] * m[3] * m[10] - m[9] * m[2] * m[7] + m[9] * m[3] * m[6])
    o[1][1] = (m[0] * m[10] * m[15] - m[0] * m[11] * m[14] - m[8] * m[2] * m[15]
               + m[8] * m[3] * m[14] + m[12] * m[2] * m[11] - m[12] * m[3] * m[10])
    o[2][1] = (-m[0] * m[6] * m[15] + m[0] * m[7] * m[14] + m[4] * m[2] * m[15]
               - m[4] * m[3] * m[14] - m[12] * m[2] * m[7] + m[12] * m[3] * m[6])
    o[3][1] = (m[0] * m[6] * m[11] - m[0] * m[7] * m[10] - m[4] * m[2] * m[11]
               + m[4] * m[3] * m[10] + m[8] * m[2] * m[7] - m[8] * m[3] * m[6])
    o[1][2] = (-m[0] * m[9] * m[15] + m[0] * m[11] * m[13] + m[8] * m[1] * m[15]
               - m[8] * m[3] * m[13] - m[12] * m[1] * m[11] + m[12] * m[3] * m[9])
    o[2][2] = (m[0] * m[5] * m[15] - m[0] * m[7] * m[13] - m[4] * m[1] * m[15]
               + m[4] * m[3] * m[13] + m[12] * m[1] * m[7] - m[12] * m[3] * m[5])
    o[3][2] = (-m[0] * m[5] * m[11] + m[0] * m[7] * m[9] + m[4] * m[1] * m[11]
               - m[4] * m[3] * m[9] - m[8] * m[1] * m[7] + m[8] * m[3] * m[5])
    o[1][3] = (m[0] * m[9] * m[14] - m[0] * m[10] * m[13] - m[8] * m[1] * m[14]
               + m[8] * m[2] * m[13] + m[12] * m[1] * m[10] - m[12] * m[2] * m[9])
    o[2][3] = (-m[0] * m[5] * m[14] + m[0] * m[6] * m[13] + m[4] * m[1] * m[14]
               - m[4] * m[2] * m[13] - m[12] * m[1] * m[6] + m[12] * m[2] * m[5])
    o[3][3] = (m[0] * m[5] * m[10] - m[0] * m[6] * m[9] - m[4] * m[1] * m[10]
               + m[4] * m[2] * m[9] + m[8] * m[1] * m[6] - m[8] * m[2] * m[5])
    inv_det = 1.0 / det
    return [[v * inv_det for v in row] for row in o]


def _covariance(a: list[float], weights: list[float], residuals: list[float],
                p: P4) -> tuple[list[float], list[float], float, int, float]:
    """``sigma^2 (J^T W J)^-1`` of the column-scaled matrix; std errors, covariance,
    sigma, points used, degrees of freedom (``intervals::covariance``)."""
    jtwj = [[0.0] * 4 for _ in range(4)]
    for ai, wi in zip(a, weights):
        if wi == 0.0:
            continue
        r0 = ai / p[3]
        phi = _exp(-(r0 * r0))
        r = (1.0 - phi, phi, ai, (p[1] - p[0]) * phi * 2.0 * ai * ai / (p[3] * p[3] * p[3]))
        for i in range(4):
            wr = wi * r[i]
            for j in range(4):
                jtwj[i][j] += wr * r[j]
    n_used = sum(1 for w in weights if w > 0.0)
    dof = n_used - 4.0
    ssq = 0.0
    for e, w in zip(residuals, weights):
        ssq += w * e * e
    sigma = math.sqrt(ssq / dof) if dof > 0.0 else math.nan
    d = [math.sqrt(jtwj[k][k]) if jtwj[k][k] >= 0.0 else math.nan for k in range(4)]
    std_err = [math.nan] * 4
    cov_out = [math.nan] * 16
    if all(x > 0.0 and math.isfinite(x) for x in d) and math.isfinite(sigma):
        dm = [1.0 / x for x in d]
        inv = _inverse4([[dm[i] * jtwj[i][j] * dm[j] for j in range(4)] for i in range(4)])
        if inv is not None:
            s2 = sigma * sigma
            cov = [[dm[i] * inv[i][j] * dm[j] * s2 for j in range(4)] for i in range(4)]
            for k in range(4):
                if cov[k][k] >= 0.0:
                    std_err[k] = math.sqrt(cov[k][k])
            if all(math.isfinite(s) for s in std_err):
                cov_out = [0.5 * (cov[i][j] + cov[j][i]) for i in range(4) for j in range(4)]
    return std_err, cov_out, sigma, n_used, dof


# ---- one direction, both directions (mod.rs) ---------------------------------------------


class _Paths:
    """The settings of one direction's paths (``Paths`` in mod.rs)."""

    def __init__(self, cfg: _Cfg, weighting: Weighting, scale_floor: float) -> None:
        self.cfg, self.weighting, self.scale_floor = cfg, weighting, scale_floor
        self.reject_at = weighting.rejects_at

    def run(self, sep: _Sep, p0: P4, pre: Weighting | None,
            fixed: float | None = None) -> _Outcome:
        """From a start: an optional IRLS pass, IRLS, the refit of the kept points."""
        evals = 0
        cfg = self.cfg
        if pre is not None:
            o = _irls_vp(sep, p0, pre, cfg, "pre", fixed)
            p0, evals = o.p, o.evals
        refit = self.reject_at is not None
        out = _irls_vp(sep, p0, self.weighting, cfg, "refit" if refit else "polish", fixed)
        out.evals += evals
        if self.reject_at is not None:
            _refit_kept(sep, out, max(self.reject_at, REFIT_REJECT_MIN), cfg)
        return out

    def ranked(self, sep: _Sep, fscale: float) -> list[tuple[_Outcome, bool]]:
        """The paths from the starts on ``sep``'s points, each with whether it held its
        scale (else the MAD), best first (first of equal costs)."""
        a, y, cfg = sep.a, sep.y, self.cfg
        huber_start = _clamp_start(_start_values_huber(sep), a, fscale)
        if self.reject_at is None:
            return [(self.run(sep, huber_start, None), False)]
        # seven starts as in MM-estimation: a Huber pass from the Huber grid (MAD
        # scale); from the two best trimmed fits of each subset size a Tukey pass and
        # IGG at the trimmed fit's scale held fixed
        paths: list[tuple[_Outcome, bool]] = [
            (self.run(sep, huber_start, Weighting.huber()), False)]
        for h in _lts_sizes(len(a)):
            refined = [_refine_lts(sep, _clamp_start(p0, a, fscale), h, cfg.nm_pre,
                                   cfg.obj_floor) for p0 in _start_values_lts(sep, h)]
            refined = [r for r in refined if math.isfinite(r[0])]
            refined.sort(key=lambda r: r[0])
            for _, p in refined[:2]:
                p = _clamp_start(p, a, fscale)
                s = _lts_scale(sep.residuals(p), h)
                fixed = s if math.isfinite(s) else None
                paths.append((self.run(sep, p, Weighting.tukey(), fixed), fixed is not None))
        width = self.width(y)
        costs = [self.cost(o, width) for o, _ in paths]
        # sort_by with total_cmp (stable): NaN above everything
        order = sorted(range(len(paths)),
                       key=lambda k: (math.isnan(costs[k]), 0.0 if math.isnan(costs[k])
                                      else costs[k]))
        return [paths[k] for k in order]

    def width(self, y: list[float]) -> float:
        return _fmax(max(y) - min(y), self.scale_floor)

    def cost(self, o: _Outcome, width: float) -> float:
        """The Gaussian-plus-uniform mixture's negative log-likelihood (each path at its
        own refit scale)."""
        half_ln_2pi_e = 0.5 * (1.0 + math.log(2.0 * math.pi))
        kept = float(sum(1 for w in o.weights if w > 0.0))
        out = len(o.weights) - kept
        return kept * (_ln(_fmax(o.scale, self.scale_floor)) + half_ln_2pi_e) + out * _ln(width)


def _fit_direction(a: list[float], y: list[float], sign: float, indices: list[int],
                   weighting: Weighting, max_iter: int, scale_floor: float,
                   max_start_points: int, notes: list[str], label: str) -> DirectionFitResult:
    fscale = max(median([abs(v) for v in y]), 1e-12)
    floor = max(scale_floor, 1e-6 * fscale)
    cfg = _Cfg(max_iter, 1e-7, floor, 4000)
    paths = _Paths(cfg, weighting, floor)
    n = len(a)
    if n > max_start_points:
        # FAST-LTS: the starts and their paths on a subsample spread over the speeds,
        # the best distinct ones (kept sets) once more on all points at their kind of
        # scale (the MAD, or held: all points' scale reweighted from the path's own),
        # the smallest cost on all points wins
        sub = _subsample(a, max_start_points)
        ranked = paths.ranked(_Sep([a[i] for i in sub], [y[i] for i in sub], fscale), fscale)
        evals = sum(o.evals for o, _ in ranked)
        sep = _Sep(a, y, fscale)
        kept_sets: list[list[bool]] = []
        finished: list[_Outcome] = []
        for o, held in ranked:
            kept = [w > 0.0 for w in o.weights]
            if kept in kept_sets:
                continue
            kept_sets.append(kept)
            p0 = _clamp_start(o.p, a, fscale)
            fixed = None
            if held:
                s = _rescale(sep.residuals(p0), o.scale)
                fixed = s if math.isfinite(s) and s > 0.0 else None
            f = paths.run(sep, p0, None, fixed)
            evals += f.evals
            finished.append(f)
            if len(finished) == FINISHED_PATHS:
                break
        width = paths.width(y)
        costs = [paths.cost(o, width) for o in finished]
        best = 0
        for k in range(1, len(finished)):
            # min_by with total_cmp: the first of equal costs, NaN above everything
            if costs[k] < costs[best] or (math.isnan(costs[best]) and not math.isnan(costs[k])):
                best = k
        out = finished[best]
    else:
        ranked = paths.ranked(_Sep(a, y, fscale), fscale)
        evals = sum(o.evals for o, _ in ranked)
        out = ranked[0][0]
    out.evals = evals
    if not all(math.isfinite(v) for v in out.p):
        raise DataError(
            f"data: {label} direction: the Stribeck curve could not be evaluated at the "
            "start values; check the data for extreme values")
    p = out.p
    std_err, cov, sigma, n_used, dof = _covariance(a, out.weights, out.residuals, p)
    if any(math.isnan(s) for s in std_err):
        notes.append(
            f"{label} direction: standard errors unavailable ({n_used} points kept for 4 "
            "parameters, or a singular Jacobian); add speeds around the Stribeck velocity")
    tq = t_quantile_975(dof)
    for k, name in enumerate(STATIC_PARAM_NAMES):
        rel = _div(std_err[k], p[k])
        if rel > 0.25:
            notes.append(
                f"{label} direction: {name} is poorly determined (standard error "
                f"{rel * 100.0:.0f} % of the estimate); add constant-velocity points where "
                "it acts (around vs for fs and vs, at high speed for sigma2)")
    if not out.converged:
        notes.append(f"{label} direction: IRLS stopped at the iteration limit "
                     f"({out.iterations}) before the weights settled")
    return DirectionFitResult(
        fc=p[0], fs=p[1], sigma2=p[2], vs=p[3],
        std_err=std_err, cov=cov,
        ci_low=[v - tq * s for v, s in zip(p, std_err)],
        ci_high=[v + tq * s for v, s in zip(p, std_err)],
        indices=indices,
        weights=np.array(out.weights, dtype=np.float64),
        residuals=np.array([sign * e for e in out.residuals], dtype=np.float64),
        scale=out.scale, sigma=sigma, iterations=out.iterations,
        converged=out.converged, evaluations=out.evals,
    )


def _usize(value: Any) -> int:
    """``int(value)`` as the binding takes a ``usize`` (negative: OverflowError)."""
    n = int(value)
    if n < 0:
        raise OverflowError("can't convert negative int to unsigned")
    return n


def fit_static(v: Any, F: Any, *, weighting: str = "igg", max_iter: int = 20,
               scale_floor: float = 0.0, max_start_points: int = MAX_START_POINTS) -> StaticFit:
    """Robust Stribeck fit of steady-state points, per direction (NumPy twin of
    :func:`lugre.fit_static`; same parameters, result, warnings and errors).

    Parameters
    ----------
    v : array_like
        Constant velocities [m/s]; zero speeds are ignored (and counted).
    F : array_like
        Steady-state forces [N] (negative for ``v < 0``).
    weighting : {"igg", "huber", "tukey", "none"}
        Robust weight function; ``"none"`` is plain least squares.
    max_iter : int
        IRLS iterations at most.
    scale_floor : float
        Lower bound of the residual scale [N] (e.g. the force resolution).
    max_start_points : int
        Most points of a direction on which the robust starts are searched; more are
        fitted from a subsample first (FAST-LTS).

    Returns
    -------
    StaticFit

    Raises
    ------
    DataError
        Fewer than 5 points in a direction, one direction only, only zero speeds.
    InputError
        NaN or inf, lengths differ, empty input, unknown weighting.
    ParameterError
        ``scale_floor`` negative or not finite, ``max_start_points`` below 5.
    """
    va = _array("v", v).tolist()
    fa = _array("F", F).tolist()
    wname = str(weighting)
    iters = _usize(max_iter)
    start_points = _usize(max_start_points)
    floor = float(scale_floor)
    wt = Weighting.from_name(wname)
    # the core's checks in the core's order (static_fit/mod.rs, fit_static)
    if len(fa) != len(va):
        raise InputError.at("f", f"has {len(fa)} samples but v has {len(va)}: give arrays "
                            "of the same length")
    if not va:
        raise InputError.at("v", "is empty: give steady-state (v, F) points")
    _check_finite("v", va)
    _check_finite("f", fa)
    if not (floor >= 0.0 and math.isfinite(floor)):
        raise ParameterError.invalid("scale_floor", floor, "must be finite and zero or greater")
    if start_points < MIN_POINTS_PER_DIRECTION:
        raise ParameterError.invalid("max_start_points", float(start_points),
                                     "must be at least 5 (the points a direction needs)")
    n_zero = sum(1 for x in va if x == 0.0)
    if n_zero == len(va):
        raise DataError("data: every speed is zero: the Stribeck curve needs "
                        "constant-velocity points in both directions")

    def split(pos: bool) -> tuple[list[float], list[float], list[int]]:
        a, y, idx = [], [], []
        for k, (vk, fk) in enumerate(zip(va, fa)):
            if (pos and vk > 0.0) or (not pos and vk < 0.0):
                a.append(abs(vk))
                y.append(fk if pos else -fk)
                idx.append(k)
        return a, y, idx

    ap, yp, ip = split(True)
    an, yn, in_ = split(False)
    if not ap or not an:
        have, miss = ("v < 0", "v > 0") if not ap else ("v > 0", "v < 0")
        raise DataError(f"data: only one direction of motion in the data ({have}): add "
                        f"constant-velocity points with {miss}, each direction has its own "
                        "friction parameters")
    for label, a in (("v > 0", ap), ("v < 0", an)):
        if len(a) < MIN_POINTS_PER_DIRECTION:
            raise DataError(f"data: {len(a)} points with {label}: at least "
                            f"{MIN_POINTS_PER_DIRECTION} are needed for the 4 Stribeck "
                            "parameters; add constant-velocity runs in that direction")
    notes: list[str] = []
    pos = _fit_direction(ap, yp, 1.0, ip, wt, iters, floor, start_points, notes,
                         "positive")
    neg = _fit_direction(an, yn, -1.0, in_, wt, iters, floor, start_points, notes,
                         "negative")
    weights = np.zeros(len(va))
    for d in (pos, neg):
        weights[d.indices] = d.weights
    rejected = [k for k in range(len(va)) if va[k] != 0.0 and weights[k] == 0.0]
    fit = StaticFit(
        positive=DirectionFit._from_core(pos),
        negative=DirectionFit._from_core(neg),
        weights=weights,
        rejected=rejected,
        n_zero_speed=n_zero,
        weighting=wt.name,
        notes=notes,
    )
    if not fit.converged:
        warnings.warn("static fit: IRLS reached its iteration limit before the weights "
                      "settled; check the rejected points", ConvergenceWarning, stacklevel=2)
    return fit
