"""What the candidates' own checks share: one term refitted on part of a record, the
reversals of the motion, and the words of what a record could hide."""

from __future__ import annotations

from typing import Any

import numpy as np

from ... import units as U
from .. import residual as R

__all__ = ["amps", "hide", "rate_noise_power", "refit_on", "reversals", "share", "start_of",
           "two_ways", "under"]


def start_of(scorer: Any, terms: list[Any], k: int) -> int:
    """Index of the first coefficient of ``terms[k]`` in a fit's ``beta``."""
    return scorer.J.shape[1] + sum(t.X.shape[1] for t in terms[:k])


def refit_on(scorer: Any, terms: list[Any], k: int, sel: np.ndarray,
             nuisance: list[Any] | None = None) -> tuple[float, float] | None:
    """The first coefficient of ``terms[k]`` refitted, jointly with the base and the
    other terms (and the ``nuisance`` terms, whose share of its column it does not
    claim), on the samples ``sel`` alone, and its standard error; None when those
    samples hold nothing of its column."""
    x = terms[k].X[sel, 0]
    if nuisance:  # (their share of the column is not the term's)
        N = np.column_stack([t.X[sel, 0] for t in nuisance])
        x = x - N @ np.linalg.lstsq(N, x, rcond=None)[0]
        terms = list(terms) + list(nuisance)
    sxx = float(np.sum(x ** 2))
    if not sxx > 0:
        return None
    ev = scorer.like(mask=sel, center=None).evaluate(terms)
    return float(ev.beta[start_of(scorer, terms, k)]), float(np.sqrt(scorer.s2 / sxx))


def two_ways(scorer: Any, terms: list[Any], k: int, ev: Any,
             sets: dict[str, np.ndarray]) -> dict[str, Any] | None:
    """The first coefficient of ``terms[k]`` refitted (:func:`refit_on`) on each of two
    sets of samples, beside the full fit's: ``coefficient``, per set its value and
    ``<name>_se``, and ``apart``: both sets determine it (standard errors under a quarter
    of the full fit's) and they differ by more than four combined standard errors. None
    when a set holds nothing of the term's column."""
    full = float(ev.beta[start_of(scorer, terms, k)])
    out: dict[str, Any] = {"coefficient": full}
    for name, sel in sets.items():
        fit = refit_on(scorer, terms, k, sel)
        if fit is None:
            return None
        out[name], out[name + "_se"] = fit
    (a, sa), (b, sb) = ((out[n], out[n + "_se"]) for n in sets)
    out["apart"] = bool(max(sa, sb) < 0.25 * abs(full) and abs(a - b) > 4.0 * np.hypot(sa, sb))
    return out


def reversals(sig: R.Signals, window: float = 0.05) -> tuple[np.ndarray, int]:
    """Samples within ``window`` seconds of a reversal of the motion (a change of sign
    of the filtered velocity beyond 2 % of its peak), and the number of reversals."""
    vf = np.where(sig.mask, sig.vf, 0.0)
    vmax = float(np.max(np.abs(vf)))
    rev = np.zeros(vf.size, dtype=bool)
    s = np.sign(np.where(np.abs(vf) > 0.02 * vmax, vf, 0.0))
    nz = np.flatnonzero(s)
    flips = nz[1:][s[nz[1:]] != s[nz[:-1]]]
    w = max(int(window * sig.fs), 3)
    for j in flips:
        rev[max(j - w, 0):j + w] = True
    return rev & sig.mask, int(flips.size)


def rate_noise_power(sig: Any) -> float:
    """Mean square per sample of the recorded force's noise in its filtered rate of
    change (``sig.dfm``): the white level above the motion's band through the
    residual's low-pass and the central difference; 0 when it cannot be read."""
    # (the force is low-passed as the residual is; np.gradient's power response)
    return R.force_noise_power(sig, lambda ff: (np.sin(2 * np.pi * ff * sig.dt) / sig.dt) ** 2)


def share(b: float) -> float:
    """A relative size: one the friction itself would have to change sign to reach (100 %
    or more) is no size the record reveals."""
    return b if b < 1.0 else float("inf")


def under(b: float, fmt: str) -> str:
    """"under 0.3 N" for a finite size, "of any size" for none."""
    return "under " + fmt.format(b) if np.isfinite(b) else "of any size"


def hide(effect: str, b: float, unit: str, what: str, rng: Any = None,
         experiment: str = "") -> dict[str, Any]:
    """An entry of what the record could not have revealed (``unit`` a linear axis's SI
    unit, ``what`` and ``experiment`` in a linear axis's words: both said in the axis's
    own)."""
    verb = "would not be seen in" if np.isfinite(b) else "cannot be seen in"
    return {"effect": effect, "smallest": b if np.isfinite(b) else None, "unit": U.si(unit),
            "range": rng, "experiment": U.words(experiment),
            "text": U.words(f"{what} {verb} this record")}


def amps(a: float) -> str:
    """A current in words, mA below one ampere."""
    return f"{a * 1e3:.3g} mA" if abs(a) < 1 else f"{a:.3g} A"
