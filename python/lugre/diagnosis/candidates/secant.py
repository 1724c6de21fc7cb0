"""Effects with a nonlinear parameter searched over a grid, by the change of the residual
the effect makes: a Stribeck shape and a dead-band."""

from __future__ import annotations

from typing import Any

import numpy as np

from ... import units as U
from ...model import Model
from ...vocabulary import DEADBAND, STRIBECK_SHAPE, is_timing
from .. import residual as R
from ..residual import Signals
from .base import Candidate, Context, by, by_current, grid_interval
from .probe import AT_ONCE, amps, currents, hide, refit_on, start_of

__all__ = ["Deadband", "StribeckShape", "_Secant"]


class _Secant(Candidate):
    """An effect with a nonlinear parameter ``h``, searched over a grid.

    Its column is the change of the residual that the effect at ``h`` makes (the
    secant), with a coefficient near 1 when ``h`` is right; :meth:`from_secant` maps a
    coefficient to the parameter it stands for, and the joint refit re-linearises there.
    """

    needs_grid = True

    def effect_at(self, h: Any) -> dict[str, Any]:
        raise NotImplementedError

    def from_secant(self, h: Any, b: float) -> Any:
        return h

    def _signals(self, ctx: Context) -> Signals:
        """The signals the columns are computed on: the record's own."""
        return ctx.sig

    def _r_base(self, ctx: Context) -> np.ndarray:
        sig = self._signals(ctx)
        key = ("r_base", id(ctx.model), id(sig))
        if key not in ctx.extra:
            ctx.extra[key] = R.residual(ctx.model, sig)
        return ctx.extra[key]

    def _with(self, h: Any, ctx: Context) -> Model:
        return ctx.model.replace(effects=list(ctx.model.effects) + [self.effect_at(h)])

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        return (self._r_base(ctx) - R.residual(self._with(h, ctx), self._signals(ctx))
                )[:, None]

    def columns_many(self, hs: list[Any], ctx: Context, step: int = 1
                     ) -> list[np.ndarray] | None:
        """The columns of several grid points at once (the kernel runs them in
        parallel), or None when this candidate builds its columns otherwise; with
        ``step``, every ``step``-th row only (:func:`~.base.rows_of`, the same numbers)."""
        if type(self).columns is not _Secant.columns:
            return None
        r0 = self._r_base(ctx)[::step]
        rs = self._signals(ctx).kernel.residuals([self._with(h, ctx) for h in hs])
        return [(r0 - rs[::step, j])[:, None] for j in range(len(hs))]

    def columns_of(self, hs: list[Any], ctx: Context) -> list[np.ndarray]:
        """The single columns of grid points ``hs`` (in parallel when the kernel can)."""
        cols = self.columns_many(hs, ctx) or [self.columns(h, ctx) for h in hs]
        return [X[:, 0] for X in cols]

    def parameter(self, h: Any, beta: np.ndarray, ctx: Context) -> Any:
        """The parameter a coefficient ``beta`` on the secant at ``h`` stands for, on
        this record (:meth:`from_secant` unless the record itself sets the map)."""
        return self.from_secant(h, float(beta[0]))

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        return [self.effect_at(self.parameter(h, beta, ctx))]

    def recenter(self, h: Any, beta: np.ndarray, ctx: Context) -> tuple[Any, np.ndarray]:
        return self.parameter(h, beta, ctx), np.ones(1)

    def uncertainty(self, term: Any, beta: np.ndarray, ctx: Context, sig: Signals,
                    s2: float) -> dict[str, Any]:
        pr = term.profile
        if pr is None:
            return {}
        ok = pr["score"] <= pr["score"].min() + 10.0
        out: dict[str, Any] = {"criterion": "held-out score within 10 of the best"}
        hs = [self.parameter(h, np.atleast_1d(b), ctx) for h, b in zip(pr["h_obj"], pr["beta"])]
        for name, vals in self.interval_params(hs, ok).items():
            out[name] = vals
        return out

    def interval_params(self, hs: list[Any], ok: np.ndarray) -> dict[str, list[float]]:
        return grid_interval({self.param: np.array([float(h) for h in hs])}, ok)

    param = ""


class StribeckShape(_Secant):
    effect = STRIBECK_SHAPE
    param = "exponent"
    signature = ("a Stribeck curve of another shape: the friction falls from its static to "
                 "its Coulomb level more gradually (exponent under 2) or more abruptly")

    def grid(self, ctx: Context) -> np.ndarray | None:
        return np.array([0.5, 0.65, 0.8, 1.0, 1.25, 1.55, 2.6, 3.3, 4.2])

    def effect_at(self, h: Any) -> dict[str, Any]:
        return {"effect": STRIBECK_SHAPE, "exponent": float(h)}

    def from_secant(self, h: Any, b: float) -> Any:
        return float(np.clip(2.0 + b * (float(h) - 2.0), 0.2, 10.0))

    def describe(self, h: Any, beta: np.ndarray, ctx: Context) -> str:
        return "It lives at slow speeds, where the friction falls from static to Coulomb."

    def limit(self, ctx: Context, sizes: Any) -> dict[str, Any] | None:
        sig, m = ctx.sig, ctx.model
        hump = min(m.positive["fs"] / m.positive["fc"], m.negative["fs"] / m.negative["fc"])
        slow = float(np.mean(np.abs(sig.vf[sig.mask]) < 3 * min(m.positive["vs"],
                                                                  m.negative["vs"])))
        exp = ("steady slow feeds at 0.3 to 3 times the Stribeck velocity in both directions "
               "would show it")
        if hump < 1.02:
            return hide(self.effect, float("inf"), "-", "the shape of the Stribeck curve (the "
                        "model has no static level above the Coulomb level, fs = fc)",
                        experiment=exp)
        lo, hi = self._hidden_exponents(ctx, sizes)
        if lo is None and hi is None:
            return hide(self.effect, float("inf"), "-", "the shape of the Stribeck curve",
                        experiment=exp)
        b = max(2.0 - (lo if lo is not None else self.BELOW[-1]),
                (hi if hi is not None else self.ABOVE[-1]) - 2.0)
        if lo is not None and hi is not None:
            what = f"a Stribeck exponent between {lo:.3g} and {hi:.3g} (2 in the model)"
        elif lo is not None:
            what = (f"a Stribeck exponent over {lo:.3g} (2 in the model; tried up to "
                    f"{self.ABOVE[-1]:.3g})")
        else:
            what = (f"a Stribeck exponent under {hi:.3g} (2 in the model; tried down to "
                    f"{self.BELOW[-1]:.3g})")
        return hide(self.effect, b, "-", what, rng=[lo, hi],
                    experiment=exp if slow < 0.05 else "")

    #: Exponents tried each side of the model's 2 for the limit.
    BELOW = (1.85, 1.7, 1.55, 1.4, 1.25, 1.1, 0.95, 0.8, 0.65, 0.5)
    ABOVE = (2.2, 2.45, 2.75, 3.1, 3.5, 4.0, 4.7, 5.5, 6.5, 8.0)

    def _hidden_exponents(self, ctx: Context, sizes: Any
                          ) -> tuple[float | None, float | None]:
        """The exponents each side of 2 from which the search would name the shape,
        each judged by the exact change of the residual that it makes (the shape is far
        from linear in the exponent: 2 -> 3 changes the curve less than 2 -> 1)."""
        first: list[float | None] = [None, None]
        left = [list(self.BELOW), list(self.ABOVE)]
        # outwards from 2 a few exponents each side at a time, until each side has the
        # first it would name (the later ones are not read)
        while any(left):
            batch = [(s, h) for s in (0, 1) for h in left[s][:AT_ONCE // 2]]
            left = [rest[AT_ONCE // 2:] for rest in left]
            sz = np.asarray(sizes(self.columns_of([h for _, h in batch], ctx)), float)
            for (s, h), size in zip(batch, sz):  # (1: the whole change)
                if first[s] is None and np.isfinite(size) and size <= 1.0:
                    first[s], left[s] = h, []
        return first[0], first[1]

    figure = by("v", "velocity [m/s]")


class Deadband(_Secant):
    effect = DEADBAND
    param = "current"
    signature = ("a dead-band of the drive: small currents give no force, so the motor "
                 "force lags the command at every change of the current's sign")

    def grid(self, ctx: Context) -> np.ndarray | None:
        ia = currents(ctx)
        top = float(np.percentile(ia, 50))
        if not top > 0:
            return None
        return top * np.geomspace(0.01, 0.8, 12)

    def effect_at(self, h: Any) -> dict[str, Any]:
        return {"effect": DEADBAND, "current": float(h)}

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        if any(is_timing(e["effect"]) or e["effect"] == self.effect
               for e in ctx.model.effects):
            return super().columns(h, ctx)
        sig = ctx.sig
        # r(without) - r(with): only the motor force changes
        return (sig.fm_f - sig.filt(R.deadband(sig.fm, float(h) * ctx.model.force_constant))
                )[:, None]

    def from_secant(self, h: Any, b: float) -> Any:
        return float(max(b * float(h), 0.0))

    def describe(self, h: Any, beta: np.ndarray, ctx: Context) -> str:
        d = self.from_secant(h, float(beta[0]))
        force = d * ctx.model.force_constant
        n = U.si("N")
        if _force_recorded(ctx):  # (no current was logged: the band reads as a force)
            return (f"Motor forces under {force:.3g} {n} give no force at the axis (lost at "
                    "each sign change of the drive's force).")
        return (f"Currents under {d * 1e3:.3g} mA give no force ({force:.3g}"
                f" {n} of motor force lost at each sign change of the current).")

    figure = by_current

    check_rank = 2

    def check(self, scorer: Any, terms: list[Any], k: int, ev: Any, ctx: Context
              ) -> dict[str, Any] | None:
        return deadband_braking(scorer, terms, k, ev, ctx)

    def refusal(self, chk: dict[str, Any]) -> str | None:
        if not chk["not_deadband"]:
            return None
        return (f"where the drive brakes the axis it reads {chk['braking']:.2g} "
                f"times the band it reads overall ({chk['coefficient']:.2g}): no one "
                "dead-band explains both")

    def limit(self, ctx: Context, sizes: Any) -> dict[str, Any] | None:
        d0 = 0.02
        b = d0 * float(sizes([self.columns(d0, ctx)[:, 0]])[0])
        kf, n = ctx.model.force_constant, U.si("N")
        if _force_recorded(ctx):  # (no current was logged: the band reads as a force)
            return hide(self.effect, b * kf, "N", (f"a dead-band under {b * kf:.2g} {n} of "
                                                   "motor force" if np.isfinite(b)
                                                   else "a dead-band of any size"))
        return hide(self.effect, b, "A", (f"a dead-band under {amps(b)} ({b * kf:.2g} {n} of "
                                          "motor force)" if np.isfinite(b)
                                          else "a dead-band of any size"))


def deadband_braking(scorer: Any, terms: list[Any], k: int, ev: Any,
                     ctx: Any) -> dict[str, Any] | None:
    """Is the dead-band term ``terms[k]`` a dead-band, the same where the drive brakes?

    A dead-band takes force away along the current: wherever the current is over the
    band, the logged force is ``b`` more than what acts, in the current's direction.
    More friction than the model holds also needs more force, but along the motion.
    The two agree while the drive pushes the axis along (force and velocity of one
    sign, most of a record) and part while it brakes: there a dead-band still takes
    force along the current, against the motion. The term is refitted, jointly with
    the base and the other terms, on the samples where the drive brakes the moving axis
    (``F*v < 0``); when they determine it (standard error under a quarter of the full
    fit's) and it differs from the full fit by more than four standard errors and by
    more than half, no one dead-band explains both: the term stands for something else
    (a friction bump on part of the stroke read 0.56 of its band overall and 2.0 +- 0.13
    braking; dead-bands of 2-150 mA on the generator read within 0.35 and 5 standard
    errors). Returns the figures, or None when the record cannot tell.
    """
    sig = ctx.sig
    m = scorer.mask
    vmax = float(np.max(np.abs(sig.vf[m])))
    brake = m & (sig.fm_f * sig.vf < 0) & (np.abs(sig.vf) > 0.02 * vmax)
    full = float(ev.beta[start_of(scorer, terms, k)])
    # (braking is rare where friction stops the axis: the standard error decides)
    fit = refit_on(scorer, terms, k, brake) if full > 0 and brake.sum() >= 20 else None
    if fit is None:
        return None
    b, se = fit
    return {"coefficient": full, "braking": b, "braking_se": se,
            "not_deadband": bool(se < 0.25 * full and abs(b - full) > 4.0 * se
                                 and abs(b - full) > 0.5 * full)}


def _force_recorded(ctx: Context) -> bool:
    """Whether the record logged the motor force itself (``F``), not the current."""
    rec = getattr(ctx.sig, "recording", None)
    return rec is not None and rec.i is None
