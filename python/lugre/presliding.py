"""The experiment that determines sigma0 and sigma1: presliding at standstill.

Below break-away the axis does not slide: an open-loop force ``F(t)`` well under ``fc``
deflects the bristles, and ``m x'' = F - sigma0 z - sigma1 z' - sigma2 v`` with
``z' = v (1 - sigma0 z sign(v)/g(v))``. At small deflection ``z' = v`` and only the sum
``sigma1 + sigma2`` damps the motion (the stick-slip record's confound); as the force
nears ``fc`` the factor ``1 - sigma0 |z|/g`` falls toward 0 during each stroke, so
sigma1's share of the damping changes over the cycle while sigma2's does not. A force
whose amplitude grows from a few newtons to about 0.8 fc, swept across the presliding
resonance ``sqrt(sigma0/m)/(2 pi)`` (about 10 Hz on the paper's axis), excites both
regimes; sigma0, sigma1 and the static parameters ``sigma2``, ``fs``, ``vs``, ``fc`` of
each direction are fitted together to the measured position (a difference between the
directions makes the position ratchet over the cycles, and the static step's errors in
the break-away parameters would bias sigma1), started from the static step's estimates.

The intervals rest on a sandwich covariance whose middle is the long-run (Newey-West)
covariance of the scores: the residual is the axis's response to force noise, coloured
by the presliding resonance. With a bandwidth of about a tenth of the record that
long-run covariance is itself uncertain, so the critical value is the fixed-b one of
the Bartlett kernel (Kiefer and Vogelsang 2005) rather than 1.96; with 1.96 the sigma0
interval held the truth in only about 80 % of seeds (``benches/presliding_coverage.py``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import units as U
from ._native import simulate
from .exceptions import DataError
from .identify import STATIC_NAMES, StaticFit
from .model import Model

__all__ = ["PreslidingFit", "fit_presliding", "presliding_force"]

NAMES = ("sigma0", "sigma1", "sigma2_positive", "sigma2_negative", "fs_positive",
         "fs_negative", "vs_positive", "vs_negative", "fc_positive", "fc_negative")
"""The fitted parameters."""

#: Bartlett bandwidth of the interval, in units of the residual's correlation length.
HAC_BANDWIDTH = 1.5


def presliding_force(t: np.ndarray, fc: float, *, f0: float = 2.0, f1: float = 25.0,
                     level: float = 0.8) -> np.ndarray:
    """The excitation: a sine sweep from ``f0`` to ``f1`` Hz (log in frequency) whose
    amplitude grows linearly from ``0.1*level*fc`` to ``level*fc`` over the record,
    repeated with the amplitude falling, so each frequency is seen at small and large
    deflection."""
    t = np.asarray(t, float)
    T = t[-1] - t[0]
    half = T / 2
    tau = np.where(t - t[0] < half, t - t[0], t - t[0] - half)
    k = np.log(f1 / f0) / half
    phase = 2 * np.pi * f0 * (np.exp(k * tau) - 1) / k
    ramp = np.where(t - t[0] < half, tau / half, 1 - tau / half)
    amp = level * fc * (0.1 + 0.9 * ramp)
    # a half-cosine fade over the first 50 ms keeps the start free of a step
    fade = np.clip((t - t[0]) / 0.05, 0, 1)
    return amp * np.sin(phase) * (0.5 - 0.5 * np.cos(np.pi * fade))


@dataclass
class PreslidingFit:
    """sigma0, sigma1 and the sigma2 of each direction from a presliding record."""

    estimate: dict[str, float]
    ci95: dict[str, tuple[float, float]]
    """95 % intervals (log-normal), noise and static-step uncertainty combined."""
    rel_half_width: dict[str, float]
    static_share: dict[str, float]
    """Share of each parameter's variance that comes from the static sets."""
    determined: dict[str, bool]
    rms_residual: float
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return {"estimate": self.estimate, "ci95": {k: list(v) for k, v in self.ci95.items()},
                "rel_half_width": self.rel_half_width, "static_share": self.static_share,
                "determined": self.determined, "rms_residual": self.rms_residual,
                "notes": list(self.notes)}


def _with(model: Model, theta: np.ndarray) -> Model:
    p = dict(zip(NAMES, map(float, np.exp(theta))))
    sets = {d: {**getattr(model, d), **{k: p[f"{k}_{d}"] for k in ("sigma2", "fs", "vs", "fc")
                                        if f"{k}_{d}" in p}}
            for d in ("positive", "negative")}
    for s in sets.values():
        s["fs"] = max(s["fs"], s["fc"])
    return model.with_friction(sigma0=p["sigma0"], sigma1=p["sigma1"], **sets)


def _sim_x(model: Model, t: np.ndarray, force: np.ndarray, theta: np.ndarray) -> np.ndarray:
    m = _with(model, theta)
    return simulate(m, t, current=force / model.force_constant).x


def _hac(score: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, float]:
    """Heteroscedasticity- and autocorrelation-consistent middle of the sandwich
    covariance (Newey and West 1987, Bartlett weights): the residual of a presliding
    record is the axis's response to force noise, coloured by the presliding
    resonance, so neighbouring samples are far from independent. The bandwidth is
    1.5 times the last lag at which the residual's autocorrelation exceeds 0.1 in
    magnitude (at most a quarter of the record). Returns the matrix and ``b``, the
    bandwidth as a share of the record."""
    n = r.size
    m = 1 << int(np.ceil(np.log2(2 * n)))
    R = np.fft.rfft(r - r.mean(), m)
    acf = np.fft.irfft(R * np.conj(R), m)[:n]
    acf = acf / acf[0] if acf[0] > 0 else acf
    big = np.flatnonzero(np.abs(acf[: n // 4]) > 0.1)
    L = int(min(n // 4, HAC_BANDWIDTH * (big[-1] if big.size else 1) + 1))
    w = np.clip(1 - np.arange(m) / (L + 1), 0, None)
    w[m // 2:] = 0
    w_full = w + np.concatenate([[0], w[1:][::-1]])   # lags -L..L on the circle
    S = np.fft.rfft(score, m, axis=0)
    p = score.shape[1]
    out = np.empty((p, p))
    for i in range(p):
        cc = np.fft.irfft(S[:, i:i + 1] * np.conj(S), m, axis=0)   # sum_t s_i(t+l) s_j(t)
        out[i] = w_full @ cc
    return 0.5 * (out + out.T), L / n


def fit_presliding(t: np.ndarray, x: np.ndarray, force: np.ndarray, model: Model, *,
                   static_fit: StaticFit | None = None,
                   start: dict[str, float] | None = None) -> PreslidingFit:
    """Fit sigma0, sigma1, sigma2 of each direction to a presliding record.

    The two viscous coefficients are fitted, not held: a difference between the
    directions makes the position drift over the cycles (ratcheting), so the static
    step's estimates (0.5 % apart) would bias sigma1.

    Parameters
    ----------
    t, x, force : arrays
        Sample times [s], measured position [m], applied force [N] (``K_F i``).
    model : Model
        Axis (mass, force constant) and the static sets (held).
    static_fit : StaticFit, optional
        The static step: its joint covariance is carried into the intervals.
    start : dict, optional
        Start values of ``sigma0``, ``sigma1``, ``sigma2_positive``, ``sigma2_negative``
        (default: the model's).

    Returns
    -------
    PreslidingFit
    """
    from scipy.optimize import least_squares

    t, x, force = (np.asarray(a, float) for a in (t, x, force))
    st = start or {}
    held = {"sigma0": model.sigma0, "sigma1": model.sigma1}
    for d in ("positive", "negative"):
        held.update({f"{k}_{d}": getattr(model, d)[k] for k in ("sigma2", "fs", "vs", "fc")})
    theta0 = np.log([st.get(k, held[k]) for k in NAMES])
    top = float(np.max(np.abs(force)))
    if top > 0.95 * min(model.positive["fc"], model.negative["fc"]):
        with U.axis(model.kind):
            raise DataError(U.words(f"the force reaches {top:.3g} {U.si('N')}, near or above "
                                    "fc: the record must stay below break-away "
                                    "(presliding); lower the amplitude"))
    xs = float(np.std(x)) or 1.0
    # sigma0 start from the quasi-static compliance x = F/sigma0 over the slow start of
    # the sweep (well below the presliding resonance)
    slow = (t - t[0]) < 0.15 * (t[-1] - t[0])
    if slow.sum() > 10 and float(np.dot(force[slow], x[slow] - x[0])) > 0:
        k0 = float(np.dot(force[slow], force[slow]) / np.dot(force[slow], x[slow] - x[0]))
        if np.isfinite(k0) and k0 > 0:
            theta0[0] = np.log(k0)
    wide = {"sigma0": (1e2, 1e9), "sigma1": (1e-3, 1e5)}
    lb = np.log([wide[k][0] if k in wide else held[k] / (30 if k.startswith("vs") else 3)
                 for k in NAMES])
    ub = np.log([wide[k][1] if k in wide else held[k] * (30 if k.startswith("vs") else 3)
                 for k in NAMES])
    theta0 = np.clip(theta0, lb + 1e-6, ub - 1e-6)

    def res(th: np.ndarray, mm: Model = model) -> np.ndarray:
        try:
            return (x - _sim_x(mm, t, force, th)) / xs
        except DataError:
            # a trial that makes the simulation diverge: a large, finite misfit
            return np.full(x.size, 1e3)

    sol = least_squares(res, theta0, bounds=(lb, ub), diff_step=1e-6, x_scale="jac",
                        xtol=1e-12, max_nfev=300,
                        ftol=1e-12)
    th = sol.x
    r = sol.fun * xs
    J = sol.jac * xs
    JtJ_inv = np.linalg.pinv(J.T @ J)
    H, b = _hac(J * r[:, None], r)
    cov = JtJ_inv @ H @ JtJ_inv
    # fixed-b critical value of the Bartlett kernel (Kiefer and Vogelsang 2005): a
    # bandwidth that is a sizeable share of the record leaves the long-run variance
    # itself uncertain, which the normal quantile 1.96 ignores
    q = 1.96 + 2.9694 * b + 0.4160 * b ** 2 - 0.5324 * b ** 3
    static_var = np.zeros(len(NAMES))
    contrib: dict[str, float] = {}
    if static_fit is not None:
        # implicit-function sensitivity of theta to each static parameter (one
        # simulation per parameter), combined with the static step's joint covariance
        for d in ("positive", "negative"):
            df = getattr(static_fit, d)
            C = np.asarray(df.cov, float)
            if not np.all(np.isfinite(C)):
                continue
            G = np.zeros((len(NAMES), 4))
            for j, k in enumerate(STATIC_NAMES):
                if f"{k}_{d}" in NAMES:
                    continue   # fitted here, not held
                h = 1e-3 * abs(getattr(model, d)[k])
                sets = {dd: dict(getattr(model, dd)) for dd in ("positive", "negative")}
                sets[d][k] += h
                if sets[d]["fs"] < sets[d]["fc"]:
                    h = -h
                    sets[d][k] += 2 * h
                dr = (_sim_x(model.with_friction(**sets), t, force, th)
                      - _sim_x(model, t, force, th)) / h
                # fc moved alone: the fitted fs must stay at or above it
                # r = x - x_sim, so d r/d p = -d x_sim/d p; d theta = -(J^T J)^-1 J^T d r
                G[:, j] = JtJ_inv @ (J.T @ dr)
            part = G @ C @ G.T
            static_var += np.diag(part)
            for j, k in enumerate(STATIC_NAMES):
                if f"{k}_{d}" not in NAMES:
                    contrib[f"{k} ({d})"] = float(np.max(np.abs(G[:, j]) * np.sqrt(C[j, j])))
    var = np.diag(cov) + static_var
    half = q * np.sqrt(var)
    est = np.exp(th)
    lo, hi = est * np.exp(-half), est * np.exp(half)
    rel = (hi - lo) / (2 * est)
    notes = []
    determined = {}
    for j, k in enumerate(NAMES):
        determined[k] = bool(rel[j] <= 0.25)
        if not determined[k]:
            notes.append(f"{k} is NOT determined by this presliding record (+-"
                         f"{100 * rel[j]:.0f} %): raise the largest "
                         f"{'torque' if model.is_rotary else 'force'} toward 0.9 fc or "
                         "lengthen the sweep")
    if contrib:
        top_k = max(contrib, key=lambda k: contrib[k])
        notes.append(f"largest static contribution: {top_k}")
    return PreslidingFit(
        estimate=dict(zip(NAMES, map(float, est))),
        ci95={k: (float(a), float(b)) for k, a, b in zip(NAMES, lo, hi)},
        rel_half_width=dict(zip(NAMES, map(float, rel))),
        static_share={k: float(static_var[j] / var[j]) for j, k in enumerate(NAMES)},
        determined=determined, rms_residual=float(np.sqrt(np.mean(r ** 2))), notes=notes)
