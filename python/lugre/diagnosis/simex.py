"""Gains the readings' own noise makes: a check of each finding by simulation and
extrapolation (SIMEX).

The inverse dynamics reads the acceleration from the position twice differentiated,
and a finding's column is built from the same readings. A term that smooths what it is
given (a compliant load low-passes the acceleration) then also "explains" part of the
readings' noise that the residual holds: the errors-in-variables gain. It is the same
in every held-out block, so the block test cannot tell it from physics; on a clean
17 kg axis logged at 5 kHz with a 0.1 um encoder it named a damped 76 Hz resonance.

SIMEX (Cook and Stefanski, 1994) measures it, for the terms whose column smooths a
reading (``Candidate.smooths_readings``; the timing terms' smoothing of the current's
noise is corrected in :mod:`.timing`): noise like the record's own is added to the
readings and the gain read again. Physics keeps its gain; a gain made by the noise
grows by what the added noise makes, and is extrapolated back to readings without
noise: ``g0 - ((g(+e) + g(-e))/2 - g0)``. The surrogate pair ``+e, -e`` (antithetic)
cancels the added noise's cross-products with the signal, so one pair measures the
noise's own share. The force's noise is white at its level above the motion's band.
The position's is made as the encoder makes it: the smoothed motion quantised again at
the record's resolution on a grid at a random offset (it stops at rest and sweeps
slowly at slow speeds, as the record's own does; white noise at that level would
overstate it: 2846 against 1180 on the 5 kHz record), plus white noise for what the
reading holds beyond its resolution.

What it cannot see: a distortion that is not noise. A 1 um encoder on a 6.7 kg axis
logged at 2 kHz distorts the velocity that drives the bristles alike at every reversal;
the presliding pair is freed and a damped resonance takes up what it does wrong, and
noise added to the record changes neither.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..io import Recording
from ..model import Model
from . import residual as R
from .scoring import accept, block_evidence

__all__ = ["NOISE_SHARE", "SIMEX_MARK", "SURROGATE_SEED", "gains", "noise_made", "surrogates"]

#: Seed of the surrogate noise (a diagnosis gives the same answer every time).
SURROGATE_SEED = 20_240_611

#: A term whose gain the added noise raises by more than this share of it is the
#: readings' noise more than physics. Physical resonances of the generator and the
#: public case: 0.0002-0.004 (the gain does not move with the noise); damped resonances
#: on clean records logged at 2-5 kHz: 0.60-0.65 (session 9: the linear extrapolation
#: left 35-40 % of their gain standing, enough to pass).
NOISE_SHARE = 0.5

#: What every reason this check gives for dropping a term says (the search's log keeps
#: it, and later stages read it there).
SIMEX_MARK = "(SIMEX)"


def surrogates(rec: Recording, model: Model, sig: R.Signals
               ) -> list[R.Signals]:
    """The record with noise like its own added, and subtracted, prepared as ``sig``
    (same band and time origin): ``[sig(+e), sig(-e)]``; empty when the record is too
    short to measure its noise."""
    fs = 1.0 / rec.dt
    force = rec.force(model)
    x = np.asarray(rec.x, float)
    level, q, sq, read_ = R.reading_noises(x, R.hampel(force)[0], fs)
    sf, read = level or 0.0, read_ or 0.0
    if not (sf > 0.0 or read > 0.0):
        return []
    rng = np.random.default_rng(SURROGATE_SEED)
    ex = np.zeros_like(x)
    if q > 0.0 and sq >= 0.5 * read:  # the reading is its resolution: quantise again
        xs = R.lowpass(x, fs / 6.0, fs)
        u = float(rng.uniform(0.0, q))
        ex = np.round((xs + u) / q) * q - u - xs
    white = read - (sq if np.any(ex) else 0.0)
    if white > 0.0:
        ex = ex + np.sqrt(white * 0.5 * fs) * rng.standard_normal(x.size)
    ef = np.sqrt(sf * 0.5 * fs) * rng.standard_normal(x.size)
    backend = sig.backend  # the kernels the record was prepared with
    out = []
    for sgn in (1.0, -1.0):
        r = Recording(t=rec.t, x=x + sgn * ex, F=force + sgn * ef)
        out.append(R.prepare(r, model, cutoff_hz=sig.cutoff_hz, backend=backend))
    return out


def _sse(m: Model, s: R.Signals, blocks: list[np.ndarray]) -> np.ndarray:
    rr = R.residual(m, s)[s.mask]
    return np.array([np.sum(rr[b] ** 2) for b in blocks])


def _without(model: Model, aug: Model, terms: list[Any], betas: list[np.ndarray], ctx: Any,
             k: int) -> Model:
    """``aug`` without term ``k`` (nothing refitted)."""
    from .refit import effects_of

    return aug.replace(effects=list(model.effects) + effects_of(
        [t for j, t in enumerate(terms) if j != k],
        [b for j, b in enumerate(betas) if j != k], ctx))


def gains(model: Model, fit: tuple[Any, ...], s: R.Signals, ks: list[int],
          blocks: list[np.ndarray], s2: float) -> list[np.ndarray]:
    """Per-block gain of each finding ``ks`` of a fit ``(aug, terms, betas, ctx)`` on
    the signals ``s``: the squared residual it saves, nothing else refitted, in units
    of ``s2``."""
    aug, terms, betas, ctx = fit
    full = _sse(aug, s, blocks)
    return [(_sse(_without(model, aug, terms, betas, ctx, k), s, blocks) - full) / s2
            for k in ks]


def noise_made(sig: R.Signals, sur: list[R.Signals], model: Model, fit: tuple[Any, ...],
               ks: list[int], blocks: list[np.ndarray], s2: float, min_gain: float,
               alpha: float) -> dict[int, str]:
    """The findings (indices ``ks`` of the fit's terms) whose gain the readings' noise
    makes, with why: its per-block gains pass the acceptance rule of the search
    (:func:`~lugre.diagnosis.search.accept`) but not once the noise's part is taken
    out.

    ``fit`` is ``(aug, terms, betas, ctx)`` on ``sig``, ``sur`` the surrogates
    (:func:`surrogates`). The models are not refitted on
    the surrogates: the gain grows linearly with the added noise's variance, and
    refitting the terms there changes the noise's part by under 1 % (a false 76 Hz
    resonance: 2838 refitted, 2846 not; a 33 Hz one: 2200 both ways).
    """
    if not sur:
        return {}
    g0 = gains(model, fit, sig, ks, blocks, s2)
    gs = [gains(model, fit, s, ks, blocks, s2) for s in sur]

    def passes(d: np.ndarray) -> bool:
        ev = block_evidence(d)
        return accept(ev, alpha=alpha, min_gain=min_gain)[0]

    out = {}
    for j, k in enumerate(ks):
        noise = np.mean([g[j] for g in gs], axis=0) - g0[j]
        if not passes(g0[j]):
            continue
        if not passes(g0[j] - noise):
            out[k] = (f"its gain ({g0[j].sum():.0f} in squared-error units of the noise) is "
                      f"what the readings' own noise makes: noise like the record's added "
                      f"to them raises it by {noise.sum():.0f} {SIMEX_MARK}")
        elif noise.sum() > NOISE_SHARE * g0[j].sum():
            out[k] = (f"noise like the record's added to its readings raises its gain "
                      f"({g0[j].sum():.0f} in squared-error units of the noise) by "
                      f"{noise.sum():.0f} {SIMEX_MARK}: most of it is the readings' own noise, "
                      "and what would remain rests on how well the added noise copies the "
                      "record's")
    return out
