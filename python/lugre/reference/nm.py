"""Nelder-Mead as the core runs it (``src/estimate/nelder_mead.rs`` over argmin 0.11).

The simplex method of argmin's ``NelderMead`` (reflection 1, expansion ``gamma``,
contraction 1/2, shrink ``sigma``; vertices sorted stably by cost; stop when the
standard deviation of the vertex costs falls below the tolerance, checked before each
iteration) inside the core's wrapper: the objective divided by its value at the start
of each run (so ``ftol`` is relative), non-finite values mapped to a large cost, an
evaluation budget, the best point ever seen kept, restarts from it. The operations are
those of the Rust code in the same order, so that the two runs take the same steps.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

__all__ = ["NmOptions", "NmResult", "minimize"]

#: Cost of a point where the objective is not finite (after normalisation).
_BIG = 1e150


@dataclass(frozen=True)
class NmOptions:
    """Stopping rules (``NmOptions`` in nelder_mead.rs)."""

    max_evals: int = 4000
    xtol: float = 1e-9
    ftol: float = 1e-12
    restarts: int = 1


@dataclass
class NmResult:
    x: list[float]
    f: float
    evals: int
    converged: bool


class _Budget(Exception):
    """The evaluation budget of a run is spent (argmin's run then returns an error)."""


def _clean(v: float) -> float:
    return v if math.isfinite(v) else math.inf


def _sd(costs: list[float]) -> float:
    """argmin's stopping statistic: the sample standard deviation of the costs."""
    n = float(len(costs))
    c0 = 0.0
    for c in costs:
        c0 += c
    c0 = c0 / n
    s = 0.0
    for c in costs:
        d = c - c0
        s += d * d
    return math.sqrt(1.0 / (n - 1.0) * s)


def _nelder_mead(cost: Callable[[list[float]], float], simplex: list[list[float]],
                 gamma: float, sigma: float, sd_tol: float, max_iters: int) -> bool:
    """argmin's ``NelderMead`` under its ``Executor``; True when it converged. Raises
    :class:`_Budget` from ``cost`` like the Rust objective's error."""
    params = [(x, cost(x)) for x in simplex]
    params.sort(key=lambda p: p[1])
    n_vec = len(params)
    num_param = n_vec - 1
    it = 0
    while True:
        if _sd([c for _, c in params]) < sd_tol:
            return True
        if it >= max_iters:
            return False
        # centroid of all but the worst
        acc = list(params[0][0])
        for p, _ in params[1:num_param]:
            acc = [a + b for a, b in zip(acc, p)]
        inv = 1.0 / float(num_param)
        x0 = [a * inv for a in acc]
        best_c = params[0][1]
        worst_x, worst_c = params[-1]
        second_c = params[-2][1]
        xr = [c + (c - w) * 1.0 for c, w in zip(x0, worst_x)]
        xr_c = cost(xr)
        if second_c > xr_c >= best_c:
            params[-1] = (xr, xr_c)
        elif xr_c < best_c:
            xe = [c + (r - c) * gamma for c, r in zip(x0, xr)]
            xe_c = cost(xe)
            params[-1] = (xe, xe_c) if xe_c < xr_c else (xr, xr_c)
        else:
            shrink = False
            if xr_c < worst_c:
                xc = [c + (r - c) * 0.5 for c, r in zip(x0, xr)]
                xc_c = cost(xc)
                if xc_c <= xr_c:
                    params[-1] = (xc, xc_c)
                else:
                    shrink = True
            else:
                xc = [c + (w - c) * 0.5 for c, w in zip(x0, worst_x)]
                xc_c = cost(xc)
                if xc_c < worst_c:
                    params[-1] = (xc, xc_c)
                else:
                    shrink = True
            if shrink:
                xb = params[0][0]
                for k in range(1, n_vec):
                    p = [b + (q - b) * sigma for b, q in zip(xb, params[k][0])]
                    params[k] = (p, cost(p))
        params.sort(key=lambda p: p[1])
        it += 1


def minimize(f: Callable[[list[float]], float], x0: Sequence[float],
             step: Sequence[float], opts: NmOptions) -> NmResult:
    """Minimise ``f`` from ``x0`` with an initial simplex ``x0 + step[k]*e_k``
    (``nelder_mead::minimize``)."""
    n = len(x0)
    f0 = _clean(f(list(x0)))
    evals = 1
    best_x = [float(v) for v in x0]
    best_f = f0
    if n == 0:
        return NmResult(best_x, best_f, evals, True)
    steps = []
    for k in range(n):
        h = float(step[k]) if k < len(step) else 0.0
        if not (h != 0.0 and math.isfinite(h)):
            h = 0.05 * max(abs(x0[k]), 1e-3)
        steps.append(math.copysign(max(abs(h), opts.xtol), h))
    nf = float(n)
    gamma, sigma = (1.0 + 2.0 / nf, 1.0 - 1.0 / nf) if n >= 2 else (2.0, 0.5)
    converged = False
    for rnd in range(opts.restarts + 1):
        if evals + n + 1 > opts.max_evals:
            break
        start_f = best_f
        simplex = [list(best_x)]
        for k, h in enumerate(steps):
            x = list(best_x)
            x[k] += h
            simplex.append(x)
        norm = abs(start_f) if math.isfinite(start_f) and start_f != 0.0 else 1.0
        track = {"evals": 0, "best_x": list(best_x), "best_f": best_f}
        budget = opts.max_evals - evals

        def cost(x: list[float], norm: float = norm, track: dict = track,
                 budget: int = budget) -> float:
            if track["evals"] >= budget:
                raise _Budget
            track["evals"] += 1
            v = _clean(f(x))
            if v < track["best_f"]:
                track["best_f"] = v
                track["best_x"] = list(x)
            c = v / norm
            return min(c, _BIG) if math.isfinite(c) else _BIG

        try:
            conv = _nelder_mead(cost, simplex, gamma, sigma, max(opts.ftol, 0.0),
                                opts.max_evals)
        except _Budget:
            conv = False
        evals += track["evals"]
        improved = track["best_f"] < start_f
        if track["best_f"] <= best_f:
            best_x = track["best_x"]
            best_f = track["best_f"]
        converged = conv
        if not conv or evals >= opts.max_evals or (rnd > 0 and not improved):
            break
    return NmResult(best_x, best_f, evals, converged)
