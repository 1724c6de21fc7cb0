"""Experiment design for the static (Stribeck) step: which speeds, how many runs each.

From a first fit, the Fisher information of a constant-velocity run at speed ``a`` is
``r(a) r(a)^T / sigma^2`` with ``r`` the gradient of the Stribeck curve in
``(fc, fs, sigma2, vs)``:
``r = (1 - phi, phi, a, 2 (fs - fc) phi a^2 / vs^3)``, ``phi = exp(-(a/vs)^2)``.
Runs are added one at a time (a greedy, exchange-free design; Fedorov 1972) at the
candidate speed that most lowers the worst relative variance of the four parameters
(the minimax criterion: the issue is the worst parameter, usually ``vs``), until the
predicted relative standard error of every parameter is at most ``target`` or the
budget is spent. Every chosen speed gets at least ``min_repeats`` runs, so that a gross
error stands out against its replicates instead of bending the curve through itself.
The design depends on the first fit's parameters (a locally optimal design): repeat it
with the new fit when the parameters moved.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .exceptions import DataError, ParameterError
from .identify import STATIC_NAMES, StaticFit

__all__ = ["StaticDesign", "design_static"]


@dataclass
class StaticDesign:
    """Speeds and runs per speed for one or both directions."""

    speeds: dict[str, np.ndarray]
    """Speed magnitudes [m/s] per direction (``"positive"``, ``"negative"``)."""
    repeats: dict[str, np.ndarray]
    """Runs at each speed."""
    predicted_rel_std: dict[str, dict[str, float]]
    """Predicted relative standard error of each parameter after the design's runs."""
    reached: dict[str, bool]
    """True when every parameter reaches the target within the budget."""
    target: float
    notes: list[str] = field(default_factory=list)

    def points(self) -> np.ndarray:
        """The signed speeds of every run (negative for ``v < 0``), in run order."""
        out = []
        for d, s in (("positive", 1.0), ("negative", -1.0)):
            out.append(s * np.repeat(self.speeds[d], self.repeats[d]))
        return np.concatenate(out)

    def to_dict(self) -> dict[str, Any]:
        return {d: {"speeds": self.speeds[d].tolist(), "repeats": self.repeats[d].tolist(),
                    "points": int(self.repeats[d].sum()),
                    "predicted_rel_std": self.predicted_rel_std[d],
                    "reached": self.reached[d]}
                for d in ("positive", "negative")} | {"target": self.target,
                                                      "notes": list(self.notes)}

    def summary(self) -> str:
        lines = [(f"static experiment design (target: relative standard error <= "
                  f"{100 * self.target:.2g} % for every parameter)")]
        for d, tag in (("positive", "v > 0"), ("negative", "v < 0")):
            n = int(self.repeats[d].sum())
            runs = ", ".join(f"{1e3 * a:.4g} mm/s x{k}"
                             for a, k in zip(self.speeds[d], self.repeats[d]))
            pred = ", ".join(f"{k} {100 * v:.2f} %"
                             for k, v in self.predicted_rel_std[d].items())
            lines.append(f"  {tag}: {n} runs at {len(self.speeds[d])} speeds"
                         f"{'' if self.reached[d] else ' (target NOT reached in the budget)'}")
            lines.append(f"    {runs}")
            lines.append(f"    predicted relative standard errors: {pred}")
        lines += [f"  note: {n}" for n in self.notes]
        return "\n".join(lines)


def _gradient(a: np.ndarray, p: dict[str, float]) -> np.ndarray:
    """Rows ``r(a)``: gradient of the Stribeck curve, scaled by the parameters (so the
    covariance is that of the relative errors)."""
    fc, fs, s2, vs = (p[k] for k in STATIC_NAMES)
    phi = np.exp(-(a / vs) ** 2)
    r = np.stack([1 - phi, phi, a, 2 * (fs - fc) * phi * a ** 2 / vs ** 3], axis=1)
    return r * np.array([fc, fs, s2, vs])


def _design_one(p: dict[str, float], sigma: float, lo: float, hi: float, target: float,
                budget: int, min_repeats: int, min_speeds: int,
                candidates: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    grid = np.geomspace(lo, hi, candidates)
    R = _gradient(grid, p)
    # a start that determines all four parameters: min_speeds speeds spread in log
    # speed over the range, min_repeats runs each
    start = np.unique(np.round(np.linspace(0, candidates - 1, min_speeds)).astype(int))
    counts = np.zeros(candidates, int)
    counts[start] = min_repeats
    eps = 1e-12 * np.eye(4)

    def rel_var(c: np.ndarray) -> np.ndarray:
        M = (R.T * c) @ R / sigma ** 2
        return np.diag(np.linalg.inv(M + eps * np.trace(M)))

    v = rel_var(counts)
    while counts.sum() < budget and np.sqrt(v.max()) > target:
        # one more run at the speed that lowers the worst relative variance most;
        # a new speed opens with min_repeats runs (when the budget allows)
        best: tuple[float, int, int] | None = None
        worst = v.max()
        for k in range(candidates):
            step = 1 if counts[k] > 0 else min_repeats
            if counts.sum() + step > budget:
                continue
            c = counts.copy()
            c[k] += step
            gain = (worst - rel_var(c).max()) / step   # per run
            if best is None or gain > best[0]:
                best = (gain, k, step)
        if best is None or best[0] <= 0:
            break
        counts[best[1]] += best[2]
        v = rel_var(counts)
    used = counts > 0
    return grid[used], counts[used], np.sqrt(v), bool(np.sqrt(v).max() <= target)


def design_static(fit: StaticFit, *, target: float = 0.003, budget: int = 96,
                  speed_range: tuple[float, float] | None = None, min_repeats: int = 3,
                  min_speeds: int = 6, noise: float | None = None,
                  candidates: int = 48) -> StaticDesign:
    """Speeds and runs per speed that bring every static parameter to a precision.

    Parameters
    ----------
    fit : StaticFit
        A first fit (its parameters and residual scale set the design).
    target : float
        Relative standard error wanted for every parameter (0.003: 0.3 %).
    budget : int
        Most constant-velocity runs per direction.
    speed_range : (lo, hi), optional
        Speeds the axis can hold [m/s] (default: ``vs/50`` to ``40 vs`` of the fit).
    min_repeats : int
        Runs at least at each chosen speed (3: a gross error is outvoted by its
        replicates, so it stays detectable).
    min_speeds : int
        Speeds at least (the start of the greedy design).
    noise : float, optional
        Force noise [N] (default: the fit's residual scale).
    candidates : int
        Log-spaced candidate speeds.

    Returns
    -------
    StaticDesign
    """
    if not (0 < target < 1):
        raise ParameterError.invalid("target", target, "must be a relative standard error "
                                     "between 0 and 1, e.g. 0.003")
    if min_repeats < 1 or min_speeds < 4:
        raise ParameterError.invalid("min_speeds", min_speeds, "must be 4 or more, with "
                                     "min_repeats 1 or more (four parameters per direction)")
    if budget < min_repeats * min_speeds:
        raise ParameterError.invalid("budget", budget, "must hold min_repeats x min_speeds "
                                     f"= {min_repeats * min_speeds} runs")
    speeds, repeats, rel, reached = {}, {}, {}, {}
    notes = []
    for d in ("positive", "negative"):
        df = getattr(fit, d)
        p = df.params
        sigma = float(noise) if noise is not None else float(df.scale)
        if not (np.isfinite(sigma) and sigma > 0):
            raise DataError(f"{d} direction: the first fit has no residual scale; give "
                            "noise= (the force noise in N)")
        lo, hi = speed_range if speed_range is not None else (p["vs"] / 50, 40 * p["vs"])
        if not (0 < lo < hi):
            raise ParameterError.invalid("speed_range", (lo, hi), "must satisfy 0 < lo < hi")
        s, c, r, ok = _design_one(p, sigma, lo, hi, target, budget, min_repeats,
                                  min_speeds, candidates)
        speeds[d], repeats[d], reached[d] = s, c, ok
        rel[d] = dict(zip(STATIC_NAMES, map(float, r)))
        if not ok:
            worst = max(rel[d], key=lambda k: rel[d][k])
            notes.append(f"{d} direction: {budget} runs reach {100 * rel[d][worst]:.2g} % "
                         f"on {worst}, not {100 * target:.2g} %; raise the budget or lower "
                         "the force noise (longer plateaus average it down)")
    return StaticDesign(speeds=speeds, repeats=repeats, predicted_rel_std=rel,
                        reached=reached, target=float(target), notes=notes)
