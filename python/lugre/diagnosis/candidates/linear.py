"""Effects linear in their parameters: an offset, a spring, a payload, a drag."""

from __future__ import annotations

from typing import Any

import numpy as np

from ... import units as U
from ...vocabulary import DRAG, LOAD_FRICTION, MASS, OFFSET, SPRING
from .. import base as B
from .. import residual as R
from .base import Candidate, Context, FindingView, Said, by
from .probe import FixedInPosition, hide, two_ways, under

__all__ = ["ASYMMETRY_EXPERIMENT", "FORCE_FRICTION_EXPERIMENT", "Drag", "Mass", "Offset",
           "Spring"]

#: The experiment that tells a constant force from friction levels that differ by
#: direction.
ASYMMETRY_EXPERIMENT = (
    "hold the axis at rest under position control at several positions, approaching "
    "each from both sides: a constant force shows as a steady holding current whose "
    "mean over the two approaches is the offset, an asymmetric Coulomb level gives "
    "holding currents that average to zero")

#: The experiment that tells a payload from a friction growing with the drive force.
FORCE_FRICTION_EXPERIMENT = (
    "record moves whose decelerations the drive must brake (short strokes at high "
    "acceleration, or a vertical axis moving down): a payload is the same mass "
    "speeding up and braking, a friction that grows with the drive force reads as a "
    "heavier axis speeding up and a lighter one braking")

#: Coulomb/static levels an offset shifts: +F forward, -F backward (the friction of the
#: CONTRACT opposes the motion, the offset adds to the force the motor must give).
_OFFSET_LEVELS = {"positive.fc": 1.0, "positive.fs": 1.0, "negative.fc": -1.0,
                  "negative.fs": -1.0}


class Offset(Candidate):
    effect = OFFSET
    signature = "a constant force, the same in both directions of motion and at rest"

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        return np.ones((len(ctx.sig), 1))

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        return [{"effect": OFFSET, "force": float(beta[0])}]

    def limit(self, ctx: Context, sizes: Any) -> dict[str, Any] | None:
        b = float(sizes([np.ones(len(ctx.sig))])[0])
        return hide(self.effect, b, "N", f"a constant force {under(b, _u('{:.2g}', 'N'))}",
                    experiment=("per-direction friction levels absorb a constant force "
                                "while the axis moves; " + ASYMMETRY_EXPERIMENT.split(":")[0]
                                + " separates them"))

    def finding(self, term: Any, beta: np.ndarray, effect: dict[str, Any],
                view: FindingView) -> Said:
        alt, txt = offset_alternative(view)
        return Said(evidence=txt, alternatives=() if alt is None else (alt,))


class Spring(FixedInPosition, Candidate):
    effect = SPRING
    supersedes = (OFFSET,)
    signature = "a force linear in position, the same in both directions"

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        xm = 0.5 * (ctx.xrange[0] + ctx.xrange[1])
        return np.column_stack([ctx.sig.x - xm, np.ones(len(ctx.sig))])

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        xm = 0.5 * (ctx.xrange[0] + ctx.xrange[1])
        k = float(beta[0])
        out = [{"effect": SPRING, "stiffness": k, "x0": xm}]
        if abs(k) * (ctx.xrange[1] - ctx.xrange[0]) > 1e-9 and abs(beta[1]) < 1e3 * abs(k):
            out[0]["x0"] = float(xm - beta[1] / k)
        else:
            out.append({"effect": OFFSET, "force": float(beta[1])})
        return out

    def where(self, h: Any, beta: np.ndarray, ctx: Context) -> dict[str, Any]:
        return {"position": list(ctx.xrange), "time": None, "velocity": None}

    figure = by("x", "position [m]")

    def limit(self, ctx: Context, sizes: Any) -> dict[str, Any] | None:
        sig = ctx.sig
        b = float(sizes([sig.x - np.mean(sig.x[sig.mask])])[0])
        span = ctx.xrange[1] - ctx.xrange[0]
        return hide(self.effect, b, "N/m", f"a spring {under(b, _u('{:.3g}', 'N/m'))}"
                    + (f" ({b * span:.2g} {U.si('N')} over the stroke)" if np.isfinite(b)
                       else ""))


class Mass(Candidate):
    effect = MASS
    minor_when_consistent = True
    signature = "a force proportional to the acceleration"

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        return ctx.sig.a[:, None].copy()

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        return [{"effect": MASS, "delta": float(beta[0])}]

    check_rank = 1

    def check(self, scorer: Any, terms: list[Any], k: int, ev: Any, ctx: Context
              ) -> dict[str, Any] | None:
        return mass_both_ways(scorer, terms, k, ev, ctx)

    def refusal(self, chk: dict[str, Any]) -> str | None:
        if not chk["not_payload"]:
            return None
        kg = U.si("kg")
        return U.words(f"{chk['speeding_up']:+.2g} {kg} speeding up, {chk['braking']:+.2g} "
                       f"{kg} braking (no payload)")

    def finding(self, term: Any, beta: np.ndarray, effect: dict[str, Any],
                view: FindingView) -> Said:
        alt = mass_alternative(float(effect["delta"]), float(view.model.mass), view.sig,
                               view.scorer.mask)
        return Said(alternatives=() if alt is None else (alt,))

    def limit(self, ctx: Context, sizes: Any) -> dict[str, Any] | None:
        b = float(sizes([ctx.sig.a])[0])
        return hide(self.effect, b, "kg", f"a payload {under(b, _u('{:.2g}', 'kg'))}")


class Drag(Candidate):
    effect = DRAG
    signature = ("a force growing with the square of the speed, opposing the motion "
                 "(seals, churning lubricant)")

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        v = ctx.sig.v
        return ctx.sig.filt(np.abs(v) * v)[:, None]

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        return [{"effect": DRAG, "coefficient": float(beta[0])}]

    def where(self, h: Any, beta: np.ndarray, ctx: Context) -> dict[str, Any]:
        vm = float(np.max(np.abs(ctx.sig.vf[ctx.sig.mask])))
        return {"position": None, "time": None, "velocity": [-vm, vm]}

    figure = by("v", "velocity [m/s]")

    def limit(self, ctx: Context, sizes: Any) -> dict[str, Any] | None:
        sig = ctx.sig
        b = float(sizes([sig.filt(np.abs(sig.v) * sig.v)])[0])
        return hide(self.effect, b, "N s^2/m^2",
                    f"a drag {under(b, _u('{:.3g}', 'N s^2/m^2'))}")


def _u(number: str, unit: str) -> str:
    """A format for a number in the axis's unit for the linear SI ``unit``."""
    return f"{number} {U.si(unit)}"


def _moves(beta: np.ndarray, names: list[str], tol: np.ndarray) -> dict[str, float]:
    """Base changes in units of their tolerance (prior standard deviation)."""
    return {n: float(b / t) for n, b, t in zip(names, beta, tol)}


def offset_alternative(view: FindingView) -> tuple[dict[str, Any] | None, str]:
    """Weigh the offset against per-direction Coulomb/static levels (parsimony).

    The same data are fitted once with the offset and once without it (the base
    levels free); the held-out errors are compared, and the base moves of each story
    are counted in units of their tolerance. Returns the alternative (when the two fit
    about equally well on held-out data) and a sentence for the evidence.
    """
    scorer, terms, ev, names, tol = view.scorer, view.terms, view.ev, view.names, view.tol
    model, sig, min_gain = view.model, view.sig, view.min_gain
    k = next(j for j, t in enumerate(terms) if isinstance(t.cand, Offset))
    rest = [t for t in terms if not isinstance(t.cand, Offset)]
    # the alternative at its best: Coulomb/static levels free (flat prior)
    free_tol = np.array([t * (1e3 if n in _OFFSET_LEVELS else 1.0) for n, t in zip(names, tol)])
    alt = scorer.like(tol=free_tol).evaluate(rest)
    q = len(names)
    m_off = _moves(ev.beta[:q], names, tol)
    m_alt = _moves(alt.beta[:q], names, tol)
    cost_off = float(sum(v * v for v in m_off.values()))
    cost_alt = float(sum(v * v for v in m_alt.values()))
    big_alt = {n: v for n, v in m_alt.items() if abs(v) >= 1.0}
    big_off = {n: v for n, v in m_off.items() if abs(v) >= 1.0}
    d_fit = float((alt.sse_b.sum() - ev.sse_b.sum()) / scorer.s2)
    start = q + sum(t.X.shape[1] for t in terms[:k])
    force = float(ev.beta[start])
    levels = {n: B.get_base(model, n) + ev.beta[names.index(n)]
              for n in _OFFSET_LEVELS if n in names}
    alt_levels = {n: B.get_base(model, n) + alt.beta[names.index(n)]
                  for n in _OFFSET_LEVELS if n in names}
    n_u = U.si("N")
    alt_txt = ", ".join(f"{n} {v:.3g} {n_u}" for n, v in alt_levels.items())
    verdict = ("fit the held-out blocks about as well" if d_fit <= 3.0 * min_gain else
               f"fit the held-out blocks worse by {d_fit:.0f} (chi-square)")
    txt = (f"Parsimony: one parameter (offset {force:.3g} {n_u}, {len(big_off)} base parameters "
           f"moved by over one tolerance, sum of squared moves {cost_off:.0f}) against "
           f"asymmetric Coulomb/static levels ({alt_txt}), which move {len(big_alt)} base "
           f"parameters by over one tolerance (sum of squared moves {cost_alt:.0f}) and "
           f"{verdict}.")
    rest_txt = rest_evidence(sig)
    if rest_txt:
        txt += " " + rest_txt
    if d_fit > 3.0 * min_gain:
        return None, txt
    return {
        "effect": "asymmetric_friction",
        "parameters": {**{n: float(v) for n, v in alt_levels.items()},
                       "moves_in_tolerances": {n: round(v, 2) for n, v in big_alt.items()}},
        "note": (f"Coulomb/static levels shifted by direction ({alt_txt}, against "
                 f"{', '.join(f'{n} {v:.3g} {n_u}' for n, v in levels.items())} with the "
                 "offset) fit the motion about as well but move more parameters"),
        "experiment": U.words(ASYMMETRY_EXPERIMENT),
    }, txt


def rest_evidence(sig: R.Signals, min_s: float = 0.2) -> str:
    """Mean motor force in stretches at rest (entered from either side), if any."""
    still = (sig.v == 0.0) & sig.mask
    n_min = int(min_s * sig.fs)
    runs = []
    k = 0
    n = still.size
    while k < n:
        if still[k]:
            j = k
            while j < n and still[j]:
                j += 1
            if j - k >= n_min:
                runs.append((k, j))
            k = j
        else:
            k += 1
    if not runs:
        return ""
    means = [float(np.mean(sig.fm_f[a:b])) for a, b in runs]
    tot = sum(b - a for a, b in runs) / sig.fs
    return U.words(f"At rest ({len(runs)} stretches, {tot:.2g} s) the motor force averages "
                   f"{np.mean(means):.3g} {U.si('N')} (friction can hold any force up to the "
                   "static level there, so this bounds rather than measures the offset).")


def mass_both_ways(scorer: Any, terms: list[Any], k: int, ev: Any,
                   ctx: Any) -> dict[str, Any] | None:
    """Is the mass term ``terms[k]`` a payload, the same mass speeding up and braking?

    A payload adds ``delta*a`` whichever way the force points. A friction that grows
    with the force the drive transmits (a preloaded nut, a guide loaded by the drive)
    adds ``mu*|F|`` against the motion: like a heavier axis while the axis speeds up,
    like a lighter one while the drive brakes it. The term is refitted, jointly with the
    base and the other terms, on the samples where the drive speeds the axis up
    (``F*v > 0`` and ``a*v > 0``) and on those where it brakes (``F*v < 0``); when both
    determine it (standard errors under a quarter of the full fit's) and they differ by
    more than four combined standard errors and by more than half the full fit, the
    term is no payload. Returns the figures, or None when the record cannot tell.
    """
    sig = ctx.sig
    m = scorer.mask
    fv = sig.fm_f * sig.vf
    up = m & (fv > 0) & (sig.a * sig.vf > 0)
    brake = m & (fv < 0)
    if up.sum() < 0.05 * m.sum() or brake.sum() < 0.05 * m.sum():
        return None
    ways = two_ways(scorer, terms, k, ev, {"speeding_up": up, "braking": brake})
    if ways is None:
        return None
    full, apart = ways.pop("coefficient"), ways.pop("apart")
    a, b = ways["speeding_up"], ways["braking"]
    return {"delta_kg": full, **ways,
            "not_payload": bool(apart and abs(a - b) > 0.5 * abs(full))}


def mass_alternative(delta: float, mass: float, sig: R.Signals,
                     mask: np.ndarray) -> dict[str, Any] | None:
    """A named mass the record cannot tell from a friction growing with the drive force.

    Where the drive almost never brakes the axis (``F*v < 0`` on under 5 % of the
    samples), ``mu*|F|`` against the motion equals ``mu*F = mu*m*a + mu*friction``: a
    payload ``mu*m`` beside friction levels ``mu`` higher, which the base refit takes.
    :func:`mass_both_ways` cannot test it then; the finding says so. None when the
    record holds enough braking, or the term is a lighter axis (``mu`` would be < 0).
    """
    m = mask & np.isfinite(sig.fm_f)
    brake = float(np.mean((sig.fm_f * sig.vf)[m] < 0)) if m.any() else 0.0
    if brake >= 0.05 or delta <= 0:
        return None
    return {"effect": LOAD_FRICTION,
            "parameters": {"coefficient": float(delta / mass), "braking_share": brake},
            "experiment": U.words(FORCE_FRICTION_EXPERIMENT)}
