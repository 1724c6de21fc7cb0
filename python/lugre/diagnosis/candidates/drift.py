"""A trend in time of the friction level."""

from __future__ import annotations

from typing import Any

import numpy as np

from ...vocabulary import DRIFT
from .base import Candidate, Context, FindingView, Said
from .probe import hide, share, under

__all__ = ["Drift"]


class Drift(Candidate):
    effect = DRIFT
    signature = ("a trend in time of the Coulomb/static friction level (its sign follows "
                 "the direction of motion)")

    def _grid(self, ctx: Context) -> np.ndarray:
        # from a trend that spans two held-out blocks (3 tau = 2 T/K; one that is over
        # within one block is a start-up transient the other blocks cannot check, and
        # its column is nearly a rescaling of the friction levels) to 3 T
        T = float(ctx.sig.t[-1] - ctx.sig.t[0])
        K = int(ctx.extra.get("blocks", 10))
        return T * np.geomspace(2.0 / (3.0 * K), 3.0, 20)

    def _col(self, tau: float, ctx: Context) -> np.ndarray:
        return (1.0 - np.exp(-ctx.sig.t / tau)) * ctx.fcs

    def grid(self, ctx: Context) -> np.ndarray | None:
        # tau is chosen with the base levels re-fitted alongside (a level shift and a
        # slow trend trade off), by the held-out score over this grid
        return self._grid(ctx)

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        return ctx.sig.filt(self._col(h, ctx))[:, None]

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        return [{"effect": DRIFT, "gain": float(min(-beta[0], 0.95)),
                 "time_constant": float(h)}]

    def where(self, h: Any, beta: np.ndarray, ctx: Context) -> dict[str, Any]:
        T = float(ctx.sig.t[-1])
        return {"position": None, "time": [0.0, float(min(3.0 * h, T))], "velocity": None}

    def finding(self, term: Any, beta: np.ndarray, effect: dict[str, Any],
                view: FindingView) -> Said:
        unc, txt = drift_identifiability(term, float(view.sig.t[view.sig.mask][-1]),
                                         thr=view.min_gain)
        return Said(uncertainty=unc, evidence=txt)

    def limit(self, ctx: Context, sizes: Any) -> dict[str, Any] | None:
        sig = ctx.sig
        b = share(float(sizes([(sig.t / max(sig.t[-1], 1e-9)) * ctx.fcs])[0]))
        return hide(self.effect, b, "-",
                    f"a friction drift {under(100 * b, '{:.2g} %')} over the record")


def drift_identifiability(term: Any, T: float, thr: float = 10.0
                           ) -> tuple[dict[str, Any], str]:
    """What a record determines of a drift: intervals from the held-out profile over tau.

    Over a record short against the time constant, gain and time constant trade off and
    only the change over the record (a trend) is determined. The interval is the set of
    time constants whose held-out score lies within ``thr`` of the best (the selection
    threshold on the coloured chi-square scale, at the resolution of the grid); the time
    constant counts as determined when that interval closes inside the record.
    """
    pr = term.profile
    if pr is None:
        return {}, ""
    h, sc, beta = pr["h"], pr["score"], pr["beta"]
    ok = sc <= sc.min() + thr
    g = -beta[ok, 0]
    taus = h[ok]
    lo, hi = float(taus.min()), float(taus.max())
    open_hi = hi >= 0.999 * pr["grid_max"]
    open_lo = lo <= 1.001 * pr["grid_min"]
    determined = not open_hi and not open_lo and hi <= T
    rate = g / taus
    total = g * (1.0 - np.exp(-T / taus))
    unc = {"time_constant": [lo, None if open_hi else hi],
           "gain": [float(g.min()), float(g.max())],
           "initial_rate_per_s": [float(rate.min()), float(rate.max())],
           "change_over_record": [float(total.min()), float(total.max())],
           "mean_rate_per_s": [float(total.min() / T), float(total.max() / T)],
           "time_constant_determined": bool(determined),
           "criterion": f"held-out score within {thr:g} of the best"}
    if not determined:
        txt = (f"Over the {T:.3g} s record the Coulomb/static level falls by "
               f"{100 * total.min():.2g} to {100 * total.max():.2g} % "
               f"({100 * total.min() / T:.2g} to {100 * total.max() / T:.2g} %/s on average); "
               f"the time constant is not determined (from {lo:.3g} s to "
               f"{'beyond the grid' if open_hi else f'{hi:.3g} s'}: gain and time constant "
               "trade off), the pair reported is the best on the grid.")
    else:
        txt = (f"Time constant {lo:.3g} to {hi:.3g} s and gain {g.min():.3g} to "
               f"{g.max():.3g} fit within {thr:g} of the best held-out score; the level "
               f"falls by {100 * total.min():.2g} to {100 * total.max():.2g} % over the "
               "record.")
    return unc, txt
