"""The dynamic step in Python: ``sigma0`` and ``sigma1`` from a closed-loop record
(``src/estimate/dynamic_fit.rs``, seed paper eq. 18), twin of :func:`lugre.fit_dynamic`.

The PID loop is simulated by :func:`lugre.reference.simulate` (bit for bit the core's)
for trial ``(ln sigma0, ln sigma1)``; eq. 18, ``c1*sum(w*e^2) + c2*max|e|``, is
minimised by Nelder-Mead inside IRLS: a 5 x 3 grid gives the start, a few Huber-weighted
Gauss-Newton steps refine it and give the coordinates in which the simplex works; the
intervals come from the weighted Jacobian, widened for serially correlated residuals.
The steps are the core's, in the same order (the core runs the grid and the Jacobian
columns in parallel; each simulation is the same). With ``static_fit`` the static
step's covariance is carried over by the facade's own Python
(:func:`lugre.identify._carry_static`: draws from the static covariance and refits at
the ends of its confidence region), called with this module's refits, so the twin
follows the facade wherever that handling goes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Callable

import numpy as np

from .._args import as_array as _array
from .._entry import table_or_same
from .._fits import DynamicFit, StaticFit
from ..exceptions import (
    DataError,
    InputError,
    LugreError,
    ModelError,
    ParameterError,
)
from ..identify import _dynamic_fit
from ..io import Recording
from ..model import Model, ModelLike
from .checks import _check_finite, _check_time, _parsed
from .nm import NmOptions, minimize
from .parsed import _Parsed
from .robust import Weighting, robust_scale
from .servo import _simulate
from .static import _usize
from .static_vp import _div

__all__ = ["DynamicFit", "fit_dynamic"]

Resid = Callable[[list[float]], "list[float] | None"]
_LN10 = math.log(10.0)


@dataclass(frozen=True)
class DynamicFitResult:
    """The fit of one record with the attributes of the core's
    ``_core.DynamicFitResult``, which :func:`lugre.identify._dynamic_fit` reads from
    either."""

    sigma0: float
    sigma1: float
    std_err: list[float]
    ci_low: list[float]
    ci_high: list[float]
    rel_ci_half_width: list[float]
    identifiable: list[bool]
    correlation: float
    residual_autocorrelation: float
    notes: list[str]
    residuals: np.ndarray
    weights: np.ndarray
    rms_error: float
    max_error: float
    objective: float
    scale: float
    iterations: int
    evaluations: int
    converged: bool


def _exp(x: float) -> float:
    """``f64::exp`` (inf on overflow, where ``math.exp`` raises)."""
    try:
        return math.exp(x)
    except OverflowError:
        return math.inf


def _fmt(x: float, spec: str) -> str:
    """Rust's ``{:.N}`` / ``{:.Ne}`` of an ``f64`` (``NaN``, ``inf``, ``1.0000e5``)."""
    if math.isnan(x):
        return "NaN"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    s = format(x, spec)
    if spec.endswith("e"):
        mant, ex = s.split("e")
        s = f"{mant}e{int(ex)}"
    return s


# ---- the outer IRLS loop (irls.rs) ------------------------------------------------------


def _irls(residuals: Resid, objective: Callable[[list[float], list[float]], float],
          theta0: list[float], weighting: Weighting, max_outer: int, tol: float,
          scale_floor: float, nm: NmOptions, step0: list[float]) -> dict[str, Any] | None:
    theta = list(theta0)
    e = residuals(theta)
    if e is None:
        return None
    evals = 1
    s = max(robust_scale(e), scale_floor)
    w = weighting.weights(e, s)
    converged = False
    iterations = 0
    step = list(step0)
    while iterations < max(max_outer, 1):
        iterations += 1
        wk = list(w)

        def f(th: list[float], wk: list[float] = wk) -> float:
            r = residuals(th)
            return math.inf if r is None else objective(r, wk)

        r = minimize(f, theta, step, nm)
        evals += r.evals
        dtheta = 0.0
        for a, b in zip(r.x, theta):
            dtheta = max(dtheta, abs(a - b))
        theta = r.x
        e = residuals(theta)
        if e is None:
            return None
        evals += 1
        s = max(robust_scale(e), scale_floor)
        w_new = weighting.weights(e, s)
        dw, dw_sum = 0.0, 0.0
        for a, b in zip(w_new, w):
            dw = max(dw, abs(a - b))
        for a, b in zip(w_new, w):
            dw_sum += abs(a - b)
        dw_mean = dw_sum / max(len(w), 1)
        w = w_new
        if dw <= 1e-3 or dw_mean <= 1e-5 or dtheta <= tol:
            converged = True
            break
        step = [s0 * 0.1 for s0 in step0]
    return {"theta": theta, "residuals": e, "weights": w, "scale": s,
            "iterations": iterations, "converged": converged, "evals": evals}


# ---- the Gauss-Newton start and its metric (local_metric) ---------------------------------


def _jacobian(resid: Resid, th: list[float], e: list[float],
              h: float) -> list[list[float]] | None:
    a = resid([th[0] + h, th[1]])
    b = resid([th[0], th[1] + h])
    if a is None or b is None:
        return None
    return [[(e0 - e1) / h for e0, e1 in zip(e, a)], [(e0 - e1) / h for e0, e1 in zip(e, b)]]


def _wss(e: list[float], w: list[float]) -> float:
    s = 0.0
    for a, b in zip(e, w):
        s += b * a * a
    return s


def _local_metric(resid: Resid, theta0: list[float], c1: float,
                  count: list[int]) -> dict[str, Any] | None:
    huber = Weighting.huber()
    th = [theta0[0], theta0[1]]
    e = resid(th)
    if e is None:
        return None
    count[0] += 1
    metric = None
    last_jac = None
    for _ in range(10):
        s = robust_scale(e)
        if math.isnan(s) or s <= 0.0:
            break
        w = huber.weights(e, s)
        j = _jacobian(resid, th, e, 1e-3)
        if j is None:
            return None
        count[0] += 2
        m00 = m01 = m11 = g0 = g1 = 0.0
        for k in range(len(e)):
            a, b, wk = j[0][k], j[1][k], w[k]
            m00 += wk * a * a
            m01 += wk * a * b
            m11 += wk * b * b
            g0 += wk * a * e[k]
            g1 += wk * b * e[k]
        det = m00 * m11 - m01 * m01
        if not (m00 > 0.0 and m11 > 0.0 and det > 1e-12 * m00 * m11):
            return None
        metric = (m00, m01, m11)
        last_jac = (list(th), j)
        d = [(m11 * g0 - m01 * g1) / det, (m00 * g1 - m01 * g0) / det]
        f = _wss(e, w)
        predicted = d[0] * g0 + d[1] * g1
        if math.isnan(predicted) or predicted <= f / len(e):
            break
        lam_ = 1.0
        accepted = False
        for _ in range(4):
            big = max(abs(lam_ * d[0]), abs(lam_ * d[1]))
            lam = lam_ / big if big > 1.0 else lam_
            trial = [th[0] + lam * d[0], th[1] + lam * d[1]]
            count[0] += 1
            et = resid(trial)
            if et is not None and _wss(et, w) < f:
                th, e, accepted = trial, et, True
                break
            lam_ = lam * 0.5
        if not accepted:
            break
    if metric is None or last_jac is None:
        return None
    f = 0.0
    for x in e:
        f += x * x
    f = c1 * f
    m00, m01, m11 = c1 * metric[0], c1 * metric[1], c1 * metric[2]
    l00 = math.sqrt(m00)
    l10 = m01 / l00
    l11 = math.sqrt(max(m11 - l10 * l10, 0.0))
    if not (l11 > 0.0 and f > 0.0 and math.isfinite(f)):
        return None
    r = math.sqrt(f)
    return {"centre": th, "t": [[r / l00, -r * l10 / (l00 * l11)], [0.0, r / l11]],
            "jac": last_jac}


# ---- the estimator (fit_dynamic_body) ----------------------------------------------------


def _fit_record(m: _Parsed, t: list[float], x_ref: list[float], x_meas: list[float],
                weighting: Weighting, c1: float, c2: float, sigma0_start: float | None,
                sigma1_start: float | None, grid: bool, max_iter: int, scale_floor: float,
                substeps: int, integrator: str) -> DynamicFitResult:
    """The core's ``fit_dynamic`` with default options but those given; the binding's
    result."""
    tol, max_evals, s2_rel = 1e-3, 200, 0.01
    _check_record(m, t, x_ref, x_meas, c1, c2, scale_floor, s2_rel, sigma0_start,
                  sigma1_start)
    ta = np.array(t, dtype=np.float64)
    xra = np.array(x_ref, dtype=np.float64)

    def sim(mm: _Parsed) -> list[float]:
        return _simulate(mm, ta, xra, integrator=integrator, substeps=substeps).x.tolist()

    sim(m)  # errors in the model or the inputs surface here

    def resid(th: list[float]) -> list[float] | None:
        s0, s1 = _exp(th[0]), _exp(th[1])
        if not (math.isfinite(s0) and math.isfinite(s1) and s0 > 0.0):
            return None
        mm = replace(m, friction=replace(m.friction, sigma0=s0, sigma1=s1))
        try:
            xs = sim(mm)
        except (LugreError, ArithmeticError, ValueError):
            return None
        return [a - b for a, b in zip(x_meas, xs)]

    def objective(e: list[float], w: list[float]) -> float:
        ss, mx = 0.0, 0.0
        for ei, wi in zip(e, w):
            ss += wi * ei * ei
            if wi > 0.0:
                mx = max(mx, abs(ei))
        return c1 * ss + c2 * mx

    s0_start = sigma0_start if sigma0_start is not None else m.friction.sigma0
    s1_start = max(sigma1_start if sigma1_start is not None else m.friction.sigma1, 1e-6)
    theta0 = [math.log(s0_start), math.log(s1_start)]
    evaluations = 0
    step = [0.2, 0.5]
    if grid:
        nodes = [[theta0[0] + _LN10 * (i - 2.0) / 2.0, theta0[1] + _LN10 * (j - 1.0)]
                 for i in range(5) for j in range(3)]
        ones = [1.0] * len(t)
        scores = []
        for th in nodes:
            e = resid(th)
            scores.append(math.inf if e is None else objective(e, ones))
        evaluations += len(nodes)
        finite = [k for k in range(len(nodes)) if math.isfinite(scores[k])]
        if finite:
            k = min(finite, key=lambda k: scores[k])
            theta0 = list(nodes[k])
            step = [_LN10 / 4.0, _LN10 / 2.0]
    nm = NmOptions(max_evals, max(tol, 1e-8), 1e-6, 1)

    def fail() -> DataError:
        return DataError("data: the closed loop could not be simulated at the start values: "
                         "give sigma0_start and sigma1_start near the expected values")

    count = [0]
    local = _local_metric(resid, list(theta0), c1, count)
    evaluations += count[0]
    reuse_jac = None
    if local is not None:
        reuse_jac = local["jac"]
        cen, tm = local["centre"], local["t"]

        def to_theta(z: list[float]) -> list[float]:
            return [cen[0] + tm[0][0] * z[0] + tm[0][1] * z[1],
                    cen[1] + tm[1][0] * z[0] + tm[1][1] * z[1]]

        def resid_z(z: list[float]) -> list[float] | None:
            return resid(to_theta(z))

        tnorm = max(abs(tm[0][0]) + abs(tm[0][1]), abs(tm[1][0]) + abs(tm[1][1]))
        n = float(len(t))
        out = _irls(resid_z, objective, [0.0, 0.0], weighting, max_iter,
                    tol / max(tnorm, 1e-300), scale_floor,
                    NmOptions(nm.max_evals, 1e-8, min(nm.ftol, 0.04 / n), nm.restarts),
                    [2.0 / math.sqrt(n)] * 2)
        if out is None:
            raise fail()
        out["theta"] = to_theta(out["theta"])
    else:
        out = _irls(resid, objective, theta0, weighting, max_iter, tol, scale_floor, nm,
                    step)
        if out is None:
            raise fail()
    evaluations += out["evals"]
    th = out["theta"]
    s0, s1 = _exp(th[0]), _exp(th[1])

    jac, probes = _final_jacobian(resid, th, reuse_jac)
    evaluations += probes
    e, w, unc = _intervals(out["residuals"], out["weights"], jac, s0, s1)
    return _verdicts(m, out, e, w, unc, s2_rel, objective(e, w), evaluations)


def _check_record(m: _Parsed, t: list[float], x_ref: list[float], x_meas: list[float],
                  c1: float, c2: float, scale_floor: float, s2_rel: float,
                  sigma0_start: float | None, sigma1_start: float | None) -> None:
    """The core's checks of a dynamic fit's inputs, in its order."""
    _check_time("t", t)
    for name, a in (("x_ref", x_ref), ("x_measured", x_meas)):
        if len(a) != len(t):
            raise InputError.at(name, f"has {len(a)} samples but t has {len(t)}: give "
                                "arrays of the same length")
    _check_finite("x_ref", x_ref)
    _check_finite("x_measured", x_meas)
    for name, v in (("c1", c1), ("c2", c2), ("scale_floor", scale_floor),
                    ("sigma2_rel_uncertainty", s2_rel)):
        if not (math.isfinite(v) and v >= 0.0):
            raise ParameterError.invalid(name, v, "must be finite and zero or greater")
    if c1 == 0.0 and c2 == 0.0:
        raise ParameterError.invalid("c1", 0.0, "c1 and c2 cannot both be zero")
    for name, x in (("sigma0_start", sigma0_start), ("sigma1_start", sigma1_start)):
        if x is not None and not (math.isfinite(x) and x > 0.0):
            raise ParameterError.invalid(name, x, "must be a finite number greater than zero")
    if m.controller is None or m.controller.law != "pid":
        raise ModelError.at("controller", 'fit_dynamic needs a "pid" position controller '
                            "(the loop of the record)")
    if len(t) < 10:
        raise DataError(f"data: {len(t)} samples: a dynamic fit needs a record of many "
                        "control periods")
    if max(x_meas) - min(x_meas) <= 0.0:
        raise DataError("data: x_measured is constant: record a motion (a slow ramp that "
                        "sticks and slips)")


def _final_jacobian(resid: Resid, th: list[float], reuse_jac: Any
                    ) -> tuple[list[list[float]] | None, int]:
    """The residuals' Jacobian at the estimate (central differences, or the local
    metric's when it was taken close enough) and the simulations it took."""
    h = 1e-3
    jac = None
    evaluations = 0
    if reuse_jac is not None and max(abs(reuse_jac[0][0] - th[0]),
                                     abs(reuse_jac[0][1] - th[1])) <= h:
        jac = reuse_jac[1]
    else:
        probes = [[th[0] + h, th[1]], [th[0] - h, th[1]], [th[0], th[1] + h],
                  [th[0], th[1] - h]]
        sims = [resid(p) for p in probes]
        evaluations = 4
        if all(x is not None for x in sims):
            a, b, c, d = sims
            jac = [[(p - q) / (2.0 * h) for p, q in zip(a, b)],
                   [(p - q) / (2.0 * h) for p, q in zip(c, d)]]
    return jac, evaluations


def _intervals(e: list[float], w: list[float], jac: list[list[float]] | None, s0: float,
               s1: float) -> tuple[list[float], list[float], dict[str, Any]]:
    """Standard errors and 95 % intervals of sigma0 and sigma1 from the Jacobian, widened
    for the residuals' serial correlation; what the record determines."""
    n_used = sum(1 for x in w if x > 0.0)
    notes: list[str] = []
    std_err = [math.nan, math.nan]
    ci_low = [math.nan, math.nan]
    ci_high = [math.nan, math.nan]
    rel = [math.inf, math.inf]
    correlation = math.nan
    num = den = 0.0
    for k in range(len(e)):
        if w[k] > 0.0:
            den += w[k] * e[k] * e[k]
            if k + 1 < len(e) and w[k + 1] > 0.0:
                num += math.sqrt(w[k] * w[k + 1]) * e[k] * e[k + 1]
    rho = min(max(num / den, 0.0), 0.999) if den > 0.0 else 0.0
    inflation = (1.0 + rho) / (1.0 - rho)
    singular = False
    if jac is not None:
        ja, jb = jac
        m00 = m01 = m11 = 0.0
        for k in range(len(e)):
            j0, j1 = ja[k], jb[k]
            m00 += w[k] * j0 * j0
            m01 += w[k] * j0 * j1
            m11 += w[k] * j1 * j1
        dof = n_used - 2.0
        ssq = _wss(e, w)
        s2 = ssq / dof if dof > 0.0 else math.nan
        det = m00 * m11 - m01 * m01
        scale = max(m00 * m11, 0.0)
        if scale > 0.0 and det > 1e-10 * scale and math.isfinite(s2):
            c00 = m11 / det * s2 * inflation
            c11 = m00 / det * s2 * inflation
            c01 = -m01 / det * s2 * inflation
            correlation = c01 / math.sqrt(c00 * c11)
            se_th = [math.sqrt(c00), math.sqrt(c11)]
            est = [s0, s1]
            for k in range(2):
                std_err[k] = est[k] * se_th[k]
                ci_low[k] = est[k] * _exp(-1.96 * se_th[k])
                ci_high[k] = est[k] * _exp(1.96 * se_th[k])
                rel[k] = _div(ci_high[k] - ci_low[k], 2.0 * est[k])
        else:
            singular = True
    else:
        singular = True
        notes.append("the simulation failed next to the estimate: no intervals")
    identifiable = [not singular and math.isfinite(r) and r <= 0.5 for r in rel]
    return e, w, {"std_err": std_err, "ci_low": ci_low, "ci_high": ci_high, "rel": rel,
                  "correlation": correlation, "rho": rho, "inflation": inflation,
                  "singular": singular, "identifiable": identifiable, "notes": notes}


def _verdicts(m: _Parsed, out: dict[str, Any], e: list[float], w: list[float],
              unc: dict[str, Any], s2_rel: float, objective: float, evaluations: int
              ) -> DynamicFitResult:
    """The plain-language notes and the binding's result."""
    th = out["theta"]
    s0, s1 = _exp(th[0]), _exp(th[1])
    notes = unc["notes"]
    rel, identifiable, singular = unc["rel"], unc["identifiable"], unc["singular"]
    rho, inflation, correlation = unc["rho"], unc["inflation"], unc["correlation"]
    if singular:
        notes.append("the objective is flat in at least one direction (near-singular "
                     "Hessian): sigma0 and sigma1 cannot be separated by this record")
    if identifiable[0]:
        notes.append(f"sigma0 = {_fmt(s0, '.4e')} N/m is determined by the record (95 % "
                     f"interval +-{_fmt(rel[0] * 100.0, '.2f')} %)")
    else:
        notes.append(f"sigma0 is NOT determined by this record (95 % interval "
                     f"+-{_fmt(rel[0] * 100.0, '.0f')} %): record small back-and-forth moves "
                     "below the break-away force (presliding), where the force-displacement "
                     "slope is sigma0")
    if identifiable[1]:
        notes.append(f"sigma1 = {_fmt(s1, '.4f')} N s/m is determined by the record (95 % "
                     f"interval +-{_fmt(rel[1] * 100.0, '.1f')} %)")
    else:
        r1 = rel[1] if rel[1] < 1e6 or math.isnan(rel[1]) else 1e6
        r1 = 1e6 if math.isnan(r1) else r1
        notes.append("sigma1 is NOT determined by this record: the objective is nearly flat "
                     f"in sigma1 (95 % interval +-{_fmt(r1 * 100.0, '.0f')} %). Break-away "
                     "tests with small displacements (force ramps or steps below fs, with "
                     "fast position sampling) excite the bristle damping; otherwise keep the "
                     "start value and report it as assumed")
    s2max = max(m.friction.positive.sigma2, m.friction.negative.sigma2)
    bias = s2max * s2_rel
    if bias > 0.1 * s1:
        notes.append(f"sigma1 is confounded with sigma2 (the presliding damping is sigma1 + "
                     f"sigma2): a {_fmt(s2_rel * 100.0, '.1f')} % error in sigma2 "
                     f"({_fmt(bias, '.3f')} N s/m) is {_fmt(_div(100.0 * bias, s1), '.0f')} % of "
                     "sigma1; reduce sigma2's uncertainty (more fast constant-velocity "
                     "points) before trusting sigma1")
    if rho > 0.5:
        notes.append(f"residuals are serially correlated (lag-one {_fmt(rho, '.3f')}); "
                     f"intervals widened by a factor {_fmt(math.sqrt(inflation), '.1f')}")
    if abs(correlation) > 0.95:
        notes.append(f"ln sigma0 and ln sigma1 are strongly correlated "
                     f"({_fmt(correlation, '.3f')})")
    if not out["converged"]:
        notes.append(f"IRLS stopped at the iteration limit ({out['iterations']}) before the "
                     "weights settled")
    wsum = 0.0
    for x in w:
        wsum += x
    ssq = _wss(e, w)
    max_error = 0.0
    for ei, wi in zip(e, w):
        if wi > 0.0:
            max_error = max(max_error, abs(ei))
    return DynamicFitResult(
        sigma0=s0, sigma1=s1, std_err=unc["std_err"], ci_low=unc["ci_low"],
        ci_high=unc["ci_high"], rel_ci_half_width=rel, identifiable=identifiable,
        correlation=correlation, residual_autocorrelation=rho, notes=notes,
        residuals=np.array(e, dtype=np.float64),
        weights=np.array(w, dtype=np.float64),
        rms_error=math.sqrt(ssq / wsum) if wsum > 0.0 else math.nan,
        max_error=max_error, objective=objective, scale=out["scale"],
        iterations=out["iterations"], evaluations=evaluations,
        converged=out["converged"],
    )


def _record_call(mm: Model, rec: Recording, weighting: str, c1: float, c2: float,
                 s0: float | None, s1: float | None, grid: bool, max_iter: Any,
                 scale_floor: float, substeps: Any, integrator: str) -> DynamicFitResult:
    """What the facade hands the core's binding, and the binding's own checks."""
    args = (str(weighting), float(c1), float(c2), s0, s1, bool(grid), _usize(max_iter),
            float(scale_floor), _usize(substeps), str(integrator))
    m = _parsed(mm)
    wt = Weighting.from_name(args[0])
    if args[9] not in ("exact", "rk4"):
        raise InputError.at("integrator",
                            f'unknown integrator "{args[9]}": use "exact" or "rk4"')
    t = _array("t", rec.t).tolist()
    xr = _array("x_ref", rec.x_ref).tolist()
    xm = _array("x", rec.x).tolist()
    return _fit_record(m, t, xr, xm, wt, args[1], args[2],
                       None if s0 is None else float(s0), None if s1 is None else float(s1),
                       args[5], args[6], args[7], args[8], args[9])


def fit_dynamic(recording: Recording | str, model: ModelLike, *, weighting: str = "igg",
                c1: float = 1.0, c2: float = 0.0, sigma0_start: float | None = None,
                sigma1_start: float | None = None, grid: bool = True, max_iter: int = 20,
                scale_floor: float = 0.0, substeps: int = 1, integrator: str = "exact",
                columns: dict[str, str] | None = None,
                static_fit: StaticFit | None = None, static_draws: int = 39) -> DynamicFit:
    """Estimate sigma0 and sigma1 from a closed-loop record (seed paper, eq. 18): NumPy
    twin of :func:`lugre.fit_dynamic`, with the same parameters, result, warnings and
    errors (see there).

    ``recording`` may also be a table with named columns, as for the facade.
    """
    def twin(mm: Model, rec: Recording, s0: float | None, s1: float | None,
             use_grid: bool) -> DynamicFitResult:
        return _record_call(mm, rec, weighting, c1, c2, s0, s1, use_grid, max_iter,
                            scale_floor, substeps, integrator)

    return _dynamic_fit(twin, table_or_same(recording), model, sigma0_start=sigma0_start,
                        sigma1_start=sigma1_start, grid=grid, columns=columns,
                        static_fit=static_fit, static_draws=static_draws)
