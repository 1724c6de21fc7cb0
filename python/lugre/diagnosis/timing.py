"""Timing of the motor force against the recorded current: a pure delay or a first-order
lag (current loop, inductance).

Both have the same first-order signature (the force follows the command by an effective
delay ``tau``); they are told apart by their exact forms, each refitted jointly with the
base: a delay shifts the phase linearly with frequency at constant gain, a lag also
attenuates. The lag is discretised for a command interpolated linearly between samples
(its mean delay is then exactly ``1/(2*pi*bandwidth)``), so that the two forms name the
same delay and the choice between them rests on their shapes alone.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..model import Model
from ..vocabulary import CURRENT_LAG, DELAY
from . import candidates as E
from . import residual as R
from .candidates import Term
from .candidates.lag import (
    TIMING_EXPERIMENT,
    effective_delay,
    timing_parameters,
    timing_words,
)
from .refit import refine
from .scoring import told_apart

__all__ = ["choose_timing", "effective_delay", "smoothing_gain", "timing_parameters",
           "timing_words"]


def smoothing_gain(sig: R.Signals, bandwidth: float, n: int, s2: float) -> float:
    """Expected drop of the squared residual, in units of ``s2``, that a first-order lag
    of ``bandwidth`` [Hz] gives by smoothing the measurement noise of the recorded
    current alone.

    The noise is taken white at the level of the motor force's spectrum between 0.5
    and 0.9 of the Nyquist frequency (a median over the band, corrected for the
    chi-square spread of the Welch estimate; the drive's own activity there can only
    raise it, which errs toward the delay), and passed through the lag's
    ``1 - |H|^2`` and the residual's zero-phase low-pass. On a clean record logged with
    white current noise this is what the lag fits better than a delay (a 1 ms dead
    time: 19 units of 15 measured; a 90 Hz lag on the generator: 46 of 41): the
    forms are told apart by what remains.
    """
    if bandwidth <= 0:
        return 0.0
    power = R.force_noise_power(
        sig, lambda ff: (ff / bandwidth) ** 2 / (1.0 + (ff / bandwidth) ** 2))
    return n * power / s2


def choose_timing(model: Model, sig: R.Signals, terms: list[Term], k: int,
                  base: dict[str, float], betas: list[np.ndarray], s2: float,
                  names: list[str], blocks: list[slice], min_gain: float,
                  tolerance: float = 1.0
                  ) -> tuple[Model, dict[str, float], list[np.ndarray], E.Context, list[Term],
                             dict[str, Any] | None]:
    """Refit with the timing term as a delay and as a current lag; keep the better.

    Returns the refit of the better form and, when the held-out blocks do not separate
    the two (t < 3 or a total difference under ``min_gain``), the delay (what the record
    shows: a time shift) with the lag as an alternative and the experiment that
    separates them.
    """
    fits = {}
    for form in (DELAY, CURRENT_LAG):
        tt = list(terms)
        tt[k] = Term(cand=terms[k].cand, h=form, X=terms[k].X)
        out = refine(model, sig, tt, dict(base), [b.copy() for b in betas], s2, names,
                     tolerance=tolerance)
        fits[form] = (*out, R.residual(out[0], sig))
    sse = {f: np.array([np.sum(v[5][sig.mask][b] ** 2) for b in blocks])
           for f, v in fits.items()}
    dd = (sse[DELAY] - sse[CURRENT_LAG]) / s2
    # the lag also smooths the measurement noise of the recorded current, which a
    # delay passes unchanged: that much of its advantage says nothing about the drive
    lag = next(e for e in fits[CURRENT_LAG][0].effects if e["effect"] == CURRENT_LAG)
    n_b = sum(b.stop - b.start for b in blocks)
    noise_gain = smoothing_gain(sig, float(lag["bandwidth"]), n_b, s2)
    dd = dd - noise_gain / len(blocks)
    # told apart as a term is accepted: consistently, or confined (a feed's starts and
    # stops) and overwhelming there
    separated, _ = told_apart(dd, min_gain)
    # not separated: the record shows a time shift and nothing of the attenuation a lag
    # would add, so the pure delay is named and the lag given beside it
    better = CURRENT_LAG if separated and dd.sum() > 0 else DELAY
    other = DELAY if better == CURRENT_LAG else CURRENT_LAG
    aug, base_f, betas_f, ctx, terms_f, _ = fits[better]
    alt = None
    if not separated:
        ao = fits[other]
        eff = ao[4][k].cand.to_effects(other, ao[2][k], ao[3])[0]
        alt = {"effect": other,
               "parameters": {a: v for a, v in eff.items() if a != "effect"},
               "effective_delay_s": effective_delay(eff),
               "note": (f"fits the held-out blocks about as well (difference "
                        f"{abs(dd.sum()):.0f} in squared-error units of the noise)"),
               "experiment": TIMING_EXPERIMENT}
    return aug, base_f, betas_f, ctx, terms_f, alt
