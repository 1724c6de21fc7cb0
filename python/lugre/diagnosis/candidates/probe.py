"""What the candidates' own checks share: one term refitted on part of a record, the
reversals of the motion, and the words of what a record could hide."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from ... import units as U
from .. import residual as R

__all__ = ["AT_ONCE", "amps", "currents", "hide", "in_batches", "rate_noise_power", "refit_on",
           "reversals", "share", "start_of", "two_ways", "under"]


#: Columns of a limit built and judged at once: each is 8 MB a million samples, and its
#: size is its own (the same numbers in any grouping).
AT_ONCE = 4


def in_batches(judge: Any, pts: list[Any], at_once: int = AT_ONCE) -> np.ndarray:
    """``judge(pts)`` (one size per point, from columns it builds) a few points at a
    time, so that only a few whole columns live at once."""
    out = [np.asarray(judge(pts[i:i + at_once]), float) for i in range(0, len(pts), at_once)]
    return np.concatenate(out) if out else np.array([])


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


def currents(ctx: Any) -> np.ndarray:
    """The magnitude of the logged current [A] on the samples in motion."""
    return np.abs(ctx.sig.fm[ctx.sig.mask]) / ctx.model.force_constant


def amps(a: float) -> str:
    """A current in words, mA below one ampere."""
    return f"{a * 1e3:.3g} mA" if abs(a) < 1 else f"{a:.3g} A"


#: A force fixed in position read where the axis hardly accelerates and where it
#: accelerates hard: readings apart by more than this share of the larger (or of
#: opposite signs) are no such force (an inertia varying by 30 % over a joint's turn
#: read its weight-like part 0.56 and 0.92).
STEADY_APART = 0.3


def same_at_any_acceleration(scorer: Any, terms: list[Any], k: int, ev: Any,
                             ctx: Any) -> dict[str, Any] | None:
    """Is the position-fixed force ``terms[k]`` (a spring, a weight, a cogging) the same
    where the axis hardly accelerates and where it accelerates hard? Such a force
    depends on the position alone; an inertia that changes with the position (a joint
    with the arm behind it) adds a force periodic in position that grows with the
    acceleration, which a weight or a spring fits in part. The term, as fitted (its
    columns combined by its coefficients, so that one coefficient of 1 stands for it),
    is refitted jointly with the base and the other terms on the samples under and over
    the median acceleration; when both determine it and differ by more than four combined
    standard errors and by more than 30 % of the larger (or in sign), it is no force
    fixed in position. Returns the figures, or None when the record
    cannot tell."""

    m = scorer.mask
    j = start_of(scorer, terms, k)
    t = terms[k]
    col = t.X @ ev.beta[j:j + t.X.shape[1]]
    if not np.any(col[m]):
        return None
    tt = list(terms[:k]) + [replace(t, X=col[:, None], prior=None, center=None)] + list(
        terms[k + 1:])
    acc = np.abs(ctx.sig.a)
    cut = float(np.median(acc[m]))
    out = two_ways(scorer, tt, k, scorer.evaluate(tt),
                   {"calm": m & (acc <= cut), "accelerating": m & (acc > cut)})
    if out is None:
        return None
    a, b = out["calm"], out["accelerating"]
    unlike = a * b <= 0 or abs(a - b) > STEADY_APART * max(abs(a), abs(b))
    out["not_fixed"] = bool(out.pop("apart") and unlike)
    return out


class FixedInPosition:
    """The check of a force fixed in position (:func:`same_at_any_acceleration`)."""

    check_rank = 1

    def check(self, scorer: Any, terms: list[Any], k: int, ev: Any, ctx: Any
              ) -> dict[str, Any] | None:
        return same_at_any_acceleration(scorer, terms, k, ev, ctx)

    def refusal(self, chk: dict[str, Any]) -> str | None:
        if not chk["not_fixed"]:
            return None
        return (f"it reads {chk['calm']:.2g} of its size where the axis hardly "
                f"accelerates and {chk['accelerating']:.2g} where it accelerates hard: a "
                "force fixed in position is the same at any acceleration (an inertia that "
                "changes with the position is not)")
