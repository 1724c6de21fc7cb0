"""Stage 2: the base weighed. The friction levels are always refitted; the presliding
pair only when the record shows it (a held-out profile test); the mass as a base
parameter only when asked."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..model import Model
from . import base as B
from . import candidates as E
from . import residual as R
from .options import MIN_SHARE, Options
from .prepare import Prepared
from .scoring import Evaluation, Scorer, accept, compare

__all__ = ["BaseSet", "Weighing", "rms", "variance_unit", "weigh"]


def rms(y: np.ndarray, mask: np.ndarray) -> float:
    """The rms of ``y`` where ``mask`` holds."""
    return float(np.sqrt(np.mean(y[mask] ** 2)))


def variance_unit(r: np.ndarray, J: np.ndarray, tol: np.ndarray, sig: R.Signals,
                  blocks: int, step: int) -> tuple[dict[str, float], float]:
    """The noise floor of the base refit's residual and the scores' variance unit
    ``s2`` (its rms squared over the effective number of samples, in every sample)."""
    n_used = int(sig.mask.sum())
    noise = R.noise_floor(r, sig)
    s2 = noise["rms"] ** 2 * n_used / noise["n_eff"]
    ev = Scorer(r, J, tol, sig.mask, s2, blocks, step=step).evaluate([])
    noise = R.noise_floor(ev.resid, sig)
    return noise, noise["rms"] ** 2 * n_used / noise["n_eff"]


@dataclass(frozen=True)
class BaseSet:
    """The base parameters refitted beside the terms, with their scorer."""

    scorer: Scorer
    J: np.ndarray
    names: list[str]
    tol: np.ndarray


@dataclass(frozen=True)
class Weighing:
    """The model diagnosed (its contradicted effects out), its residual, the search's
    context, the base Jacobian with every base parameter (``J``, ``names``, ``tol``),
    the ones always refitted (``held``), the noise floor and variance unit ``s2``, and
    the scorers with the presliding pair held and free."""

    model: Model
    r0: np.ndarray
    ctx: E.Context
    J: np.ndarray
    names: list[str]
    tol: np.ndarray
    held: list[int]
    noise: dict[str, float]
    s2: float
    sc_held: Scorer
    sc_free: Scorer
    ev_held: Evaluation
    min_force: float
    presliding: dict[str, Any]

    def presliding_test(self, ev_h: Evaluation, ev_f: Evaluation, opts: Options
                        ) -> dict[str, Any]:
        """Whether the presliding pair is freed: it acts at every reversal, in every
        block, so only consistent held-out gains free it (a gain confined to a few
        blocks is some other mismatch at the reversals there, which sigma1 would absorb:
        -100 % on clean records)."""
        return presliding_test(ev_h, ev_f, self.s2, len(self.held) < len(self.names), opts)

    def base_set(self, free: bool) -> BaseSet:
        """The base refitted beside the terms: with the presliding pair when ``free``."""
        if free:
            return BaseSet(self.sc_free, self.J, self.names, self.tol)
        h = self.held
        # (the held scorer's columns: not taken again, a long record's are 60 MB)
        return BaseSet(self.sc_held, self.sc_held.J, [self.names[k] for k in h], self.tol[h])

    def block_sse(self, m: Model, sig: R.Signals) -> np.ndarray:
        """``m``'s squared residual summed over each held-out block."""
        rr = R.residual(m, sig)[sig.mask]
        return np.array([np.sum(rr[b] ** 2) for b in self.sc_held.used_blocks])


def presliding_test(ev_h: Evaluation, ev_f: Evaluation, s2: float, freeable: bool,
                    opts: Options) -> dict[str, Any]:
    """The block test of freeing the presliding pair (see :meth:`Weighing.presliding_test`)."""
    pt = compare(ev_h, ev_f, s2)
    pt["min_gain"], pt["alpha"] = opts.min_gain, opts.alpha
    pt["free"] = bool(freeable and accept(pt, **opts.test())[0] and pt["p"] < opts.alpha)
    return pt


def weigh(prep: Prepared, model: Model, r0: np.ndarray, opts: Options) -> Weighing:
    """The base weighed against ``model`` (the diagnosed model after questioning) and its
    residual ``r0``."""
    sig, step = prep.sig, prep.step
    ctx = E.Context.build(sig, model, R.base_friction(model, sig))
    lead = opts.screw_lead if opts.screw_lead is not None else model.axis.get("screw_lead")
    ctx.extra["screw_lead"] = float(lead) if lead else None
    ctx.extra["blocks"] = int(opts.blocks)
    wanted = B.LEVELS + B.PRESLIDING + (("mass",) if opts.free_mass else ())
    J, names, _, tol = B.base_jacobian(model, sig, names=wanted)
    tol = tol * float(opts.tolerance)
    held = [k for k, n in enumerate(names) if n not in B.PRESLIDING]
    ctx.extra["rows_step"] = step
    # (a view when the held columns are side by side: a long record's are 60 MB)
    j_held = J[:, held[0]:held[-1] + 1] if held == list(range(held[0], held[-1] + 1)) \
        else J[:, held]
    noise, s2 = variance_unit(r0, j_held, tol[held], sig, opts.blocks, step)
    sc_held = Scorer(r0, j_held, tol[held], sig.mask, s2, opts.blocks, step=step)
    sc_free = Scorer(r0, J, tol, sig.mask, s2, opts.blocks, step=step)
    ev_held = sc_held.evaluate([])
    pt = presliding_test(ev_held, sc_free.evaluate([]), s2, len(held) < len(names), opts)
    return Weighing(model=model, r0=r0, ctx=ctx, J=J, names=names, tol=tol, held=held,
                    noise=noise, s2=s2, sc_held=sc_held, sc_free=sc_free, ev_held=ev_held,
                    min_force=MIN_SHARE * rms(sig.fm_f, sig.mask), presliding=pt)
