"""The motor force arriving late: a delay or a current lag."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ...vocabulary import CURRENT_LAG, DELAY
from ..residual import Signals
from .base import Candidate, Context, FindingView, Said, Term
from .linear import Mass
from .probe import hide, rate_noise_power, refit_on, reversals, start_of, under

__all__ = ["TIMING_EXPERIMENT", "Lag", "effective_delay", "timing_parameters", "timing_words"]

#: The experiment that tells a pure delay from a first-order lag.
TIMING_EXPERIMENT = (
    "drive the axis at rest with a current step or a chirp up to a few hundred Hz and "
    "compare force (or acceleration) and current: a pure delay shifts the phase "
    "linearly with frequency at constant gain, a first-order lag attenuates the gain "
    "by 3 dB at its bandwidth")


class Lag(Candidate):
    """``delay`` and ``current_lag``: the same first-order signature, told apart later
    (:mod:`lugre.diagnosis.timing`)."""

    effect = DELAY
    signature = ("the motor force arrives late: the residual follows the rate of change of "
                 "the motor force")

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        return ctx.sig.dfm[:, None].copy()

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        tau = float(beta[0])
        if h == CURRENT_LAG:
            return [{"effect": CURRENT_LAG, "bandwidth": 1.0 / (2 * math.pi * max(tau, 1e-9))}]
        return [{"effect": DELAY, "seconds": max(tau, 0.0)}]

    def describe(self, h: Any, beta: np.ndarray, ctx: Context) -> str:
        tau = float(beta[0])
        hold = float(ctx.sig.info.get("hold_s", 0.0))
        if hold > 0.0:
            return (f"The force follows the recorded current by {tau * 1e3:.2g} ms on "
                    f"average (effective delay) beyond the {hold * 1e3:.2g} ms by which the "
                    "model's controller holds each command (half its period, which the "
                    "model already holds): the drive's own delay.")
        zoh = 0.5 * ctx.sig.info.get("dt_logged", ctx.sig.dt)
        return (f"The force follows the recorded current by {tau * 1e3:.2g} ms on average "
                f"(effective delay); if the current was logged at the rate the controller "
                f"updates it, {zoh * 1e3:.2g} ms of this is the zero-order hold of the "
                "logged command and the rest is the drive (the model has no controller "
                "whose hold would say).")

    def uncertainty(self, term: Any, beta: np.ndarray, ctx: Context, sig: Signals,
                    s2: float) -> dict[str, Any]:
        hold = float(sig.info.get("hold_s", 0.0))
        if hold > 0.0:  # the controller's hold is in the model: the delay is beyond it
            return {"effective_delay_s": float(beta[0]), "controller_hold_s": hold}
        zoh = 0.5 * sig.info.get("dt_logged", sig.dt)
        return {"effective_delay_s": float(beta[0]), "zero_order_hold_s": zoh}

    timing = True
    check_rank = 0

    def check(self, scorer: Any, terms: list[Any], k: int, ev: Any, ctx: Context
              ) -> dict[str, Any] | None:
        return lag_at_reversals(scorer, terms, k, ev, ctx)

    def refusal(self, chk: dict[str, Any]) -> str | None:
        if not chk["reversals_only"]:
            return None
        return (f"between the reversals the lag is {chk['lag_away_s'] * 1e3:.2g} ms, "
                f"not {chk['lag_s'] * 1e3:.2g} ms (lost motion, not timing)")

    def finding(self, term: Any, beta: np.ndarray, effect: dict[str, Any],
                view: FindingView) -> Said:
        return Said(parameters=timing_parameters(effect, view.alternatives))

    def limit(self, ctx: Context, sizes: Any) -> dict[str, Any] | None:
        b = float(sizes([ctx.sig.dfm])[0])
        return hide("delay/current_lag", b, "s",
                    f"a delay or current lag {under(b * 1e3, '{:.2g} ms')}")


def lag_at_reversals(scorer: Any, terms: list[Any], k: int, ev: Any,
                     ctx: Any) -> dict[str, Any] | None:
    """Is the lag term ``terms[k]`` a time shift of the whole force, or a mismatch at
    the reversals only?

    A delay or a current lag shifts the motor force everywhere: between reversals too,
    wherever the force changes (accelerations). Lost motion (backlash between motor
    and load, a presliding stage the model does not hold) fits a lag at the reversals
    alone. The lag is refitted, jointly with the base and the other terms, on the
    samples more than 50 ms from any reversal; when that record determines it (its
    standard error a quarter of the full fit's lag or less) and it is under half the
    full fit's, more than four standard errors below, the lag is a reversal mismatch.
    A mass error is fitted beside it there when no mass term is in (the believed mass
    is never exact, and between reversals the force changes with the acceleration).
    Returns the figures, or None when the record cannot tell.
    """
    sig = ctx.sig
    rev, nrev = reversals(sig)
    away = scorer.mask & ~rev
    if nrev == 0 or away.sum() < 0.2 * scorer.mask.sum():
        return None
    tau = float(ev.beta[start_of(scorer, terms, k)])
    nuisance = None
    if not any(isinstance(t.cand, Mass) for t in terms if t.cand is not None):
        nuisance = [Term(cand=Mass(), h=None, X=Mass().columns(None, ctx))]
    fit = refit_on(scorer, terms, k, away, nuisance) if tau > 0 else None
    if fit is None:
        return None
    tau_away, se = fit
    # the lag's column is the recorded force's rate of change, and the current's own
    # noise in it pulls the fitted lag toward zero by the noise's share of the column
    # (errors in variables): little at the reversals, where the force changes fast,
    # much between them. Both fits are corrected; where the noise is most of the
    # column there, those samples cannot tell
    nn = rate_noise_power(sig)

    def share(sel: np.ndarray) -> float:  # the noise's share of the column there
        sxx = float(np.sum(sig.dfm[sel] ** 2))
        return sel.sum() * nn / sxx if sxx > 0 else 1.0

    if nn > 0.0:
        s_away = share(away)
        if s_away > 0.75:
            return None
        tau = float(tau / (1.0 - min(share(scorer.mask), 0.75)))
        tau_away, se = float(tau_away / (1.0 - s_away)), float(se / (1.0 - s_away))
    return {"lag_s": tau, "lag_away_s": tau_away, "se_s": se, "reversals": nrev,
            "reversals_only": bool(se < 0.25 * tau and tau_away < 0.5 * tau
                                   and tau - tau_away > 4.0 * se)}


def effective_delay(effect: dict[str, Any]) -> float:
    """Mean delay [s] of the force behind the recorded current for a timing effect."""
    if effect["effect"] == DELAY:
        return float(effect["seconds"])
    return 1.0 / (2.0 * math.pi * float(effect["bandwidth"]))


def timing_parameters(effect: dict[str, Any],
                      alternatives: list[dict[str, Any]]) -> dict[str, float]:
    """A timing finding's parameters in both of its readings.

    ``seconds`` is always the effective delay (for a lag, its mean delay); a lag's
    ``bandwidth`` is given when the finding is a lag, or a delay whose lag reading the
    record does not rule out (the lag is then among the alternatives, and its fitted
    bandwidth is the one given). The augmented model holds the named form only.
    """
    out = {"seconds": effective_delay(effect)}
    if effect["effect"] == CURRENT_LAG:
        out["bandwidth"] = float(effect["bandwidth"])
    else:
        lag = next((a for a in alternatives if a.get("effect") == CURRENT_LAG), None)
        if lag is not None:
            out["bandwidth"] = float(lag["parameters"]["bandwidth"])
    return out


def timing_words(effect: str, parameters: dict[str, Any]) -> str:
    """A timing finding's parameters in words: "effective delay 1.3 ms, or a current lag
    of 125 Hz" for a delay the record does not tell from a lag."""
    sec = parameters.get("seconds")
    bw = parameters.get("bandwidth")
    d = f"effective delay {sec * 1e3:.3g} ms" if isinstance(sec, (int, float)) else ""
    if effect == CURRENT_LAG and isinstance(bw, (int, float)):
        return f"bandwidth {bw:.3g} Hz" + (f", {d}" if d else "")
    if isinstance(bw, (int, float)):
        return d + f", or a current lag of {bw:.3g} Hz"
    return d
