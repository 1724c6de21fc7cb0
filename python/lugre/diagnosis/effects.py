"""Signatures of the effects of the vocabulary, as regressors of the force residual.

Every candidate turns into columns ``X`` such that the residual of the model without
the effect is ``r ~ X @ beta`` (to first order), and ``beta`` maps back to the
effect's parameters. The base LuGre parameters enter the same way through the Jacobian
of the model force, so that effects and base parameters are
fitted jointly (:mod:`lugre.diagnosis.base`).

========================  =================================================================
candidate                 signature (column)
========================  =================================================================
``offset``                constant
``spring``                linear in position (and constant: ``x0``)
``mass``                  proportional to acceleration
``cogging``               ``sin``/``cos`` of ``2*pi*x/pitch``, pitch from a periodogram over
                          position
``position_friction``     hat functions of position times the Coulomb/static part of the
                          friction (the sign follows the direction of motion)
``drift``                 ``(1 - exp(-t/tau))`` times the Coulomb/static part, ``tau`` by the
                          held-out score of the joint fit over a grid (profile)
``delay``/``current_lag`` time derivative of the motor force (a lag against the command);
                          the two are told apart afterwards by their exact forms
========================  =================================================================
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..model import Model
from .residual import Signals, base_friction, position_sums

__all__ = ["Candidate", "Context", "candidates"]

@dataclass
class Context:
    """What the candidates need: the prepared signals and the current base model.

    Attributes
    ----------
    sig : Signals
    model : Model
        Current base model.
    fcs : numpy.ndarray
        Unfiltered Coulomb/static part of the friction (``F - sigma2*v``) [N].
    xrange : tuple of float
        Position range of the samples used [m].
    """

    sig: Signals
    model: Model
    fcs: np.ndarray
    xrange: tuple[float, float]
    extra: dict[str, Any] = field(default_factory=dict)

    @classmethod
    def build(cls, sig: Signals, model: Model, fr: np.ndarray | None = None) -> Context:
        """Build the context for ``model`` (computes the friction parts)."""
        if fr is None:
            fr = base_friction(model, sig)
        s2 = np.where(sig.v >= 0, model.positive["sigma2"], model.negative["sigma2"])
        fcs = fr - s2 * sig.v
        xm = sig.x[sig.mask]
        return cls(sig=sig, model=model, fcs=fcs, xrange=(float(xm.min()), float(xm.max())))


class Candidate:
    """One effect of the vocabulary as a block of regressors.

    Subclasses set ``effect`` (the vocabulary name), and implement :meth:`columns` and
    :meth:`to_effects`; those with a nonlinear parameter (pitch, time constant)
    implement :meth:`choose`.
    """

    effect: str = ""
    #: names of candidates this one contains (selecting it removes them)
    supersedes: tuple[str, ...] = ()
    #: signature in words, for the evidence
    signature: str = ""
    #: its column low-passes a reading (the acceleration, noise and all), so that it
    #: also takes up part of the noise the residual holds: checked by SIMEX
    #: (:mod:`lugre.diagnosis.simex`)
    smooths_readings: bool = False
    #: its nonlinear parameters are profiled again once later terms are in
    #: (:func:`lugre.diagnosis.search.forward_select`)
    reprofile: bool = False

    def choose(self, r: np.ndarray, ctx: Context) -> Any:
        """Pick the nonlinear parameter against the current residual ``r`` (filtered)."""
        return None

    def grid(self, ctx: Context) -> np.ndarray | None:
        """Values of the nonlinear parameter to profile by the held-out score of the
        joint fit (``None``: :meth:`choose` picks it)."""
        return None

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        """Filtered regressors ``(n, p)``."""
        raise NotImplementedError

    def prior_tol(self, h: Any, ctx: Context) -> np.ndarray | None:
        """Prior standard deviation of each coefficient (``None``: flat)."""
        return None

    def prior_center(self, h: Any, ctx: Context) -> np.ndarray | None:
        """Prior mean of each coefficient (``None``: 0)."""
        return None

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        """The effect objects for coefficients ``beta``."""
        raise NotImplementedError

    def where(self, h: Any, beta: np.ndarray, ctx: Context) -> dict[str, Any]:
        """Position, time and velocity ranges where the effect lives (``None``: all)."""
        return {"position": None, "time": None, "velocity": None}

    def recenter(self, h: Any, beta: np.ndarray, ctx: Context) -> tuple[Any, np.ndarray]:
        """Re-linearise a nonlinear parameter at the fitted point (identity for linear
        terms)."""
        return h, beta

    def next_grid(self, rows: list[tuple[Any, float]], grid: np.ndarray, stage: int
                  ) -> np.ndarray | None:
        """The points to score after ``rows`` (``(h, score)`` so far), or None when the
        profile is done; ``stage`` counts from 1. Default: :meth:`fine_grid` around the
        best point of :meth:`grid`, once."""
        if stage > 1:
            return None
        return self.fine_grid(min(rows, key=lambda r: r[1])[0], grid)

    def fine_grid(self, best: Any, grid: np.ndarray) -> np.ndarray | None:
        """Second, finer grid around the best point of :meth:`grid` (log-spaced default)."""
        j = int(np.argmin(np.abs(grid - best)))
        lo = grid[max(j - 1, 0)]
        hi = grid[min(j + 1, grid.size - 1)]
        return np.geomspace(lo, hi, 11)[1:-1] if hi > lo else None

    def describe(self, h: Any, beta: np.ndarray, ctx: Context) -> str:
        """A sentence on the fitted effect for the evidence (may be empty)."""
        return ""

    def uncertainty(self, term: Any, beta: np.ndarray, ctx: Context, sig: Signals,
                    s2: float) -> dict[str, Any]:
        """Intervals of the parameters the record determines (empty: none stated)."""
        return {}

    def figure(self, residual: np.ndarray, contrib: np.ndarray, ctx: Context
               ) -> dict[str, Any]:
        """Data of the figure of the fitted effect over the residual it explains."""
        m = ctx.sig.mask
        return {"x": ctx.sig.t[m], "xlabel": "time [s]", "residual": residual[m],
                "effect": contrib[m]}


def _by(key: str, xlabel: str):  # figure against position or velocity
    def figure(self: Candidate, residual: np.ndarray, contrib: np.ndarray, ctx: Context
               ) -> dict[str, Any]:
        m = ctx.sig.mask
        x = (ctx.sig.x if key == "x" else ctx.sig.vf)[m]
        o = np.argsort(x, kind="stable")
        return {"x": x[o], "xlabel": xlabel, "residual": residual[m][o],
                "effect": contrib[m][o]}
    return figure


class Offset(Candidate):
    effect = "offset"
    signature = "a constant force, the same in both directions of motion and at rest"

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        return np.ones((len(ctx.sig), 1))

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        return [{"effect": "offset", "force": float(beta[0])}]


class Spring(Candidate):
    effect = "spring"
    supersedes = ("offset",)
    signature = "a force linear in position, the same in both directions"

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        xm = 0.5 * (ctx.xrange[0] + ctx.xrange[1])
        return np.column_stack([ctx.sig.x - xm, np.ones(len(ctx.sig))])

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        xm = 0.5 * (ctx.xrange[0] + ctx.xrange[1])
        k = float(beta[0])
        out = [{"effect": "spring", "stiffness": k, "x0": xm}]
        if abs(k) * (ctx.xrange[1] - ctx.xrange[0]) > 1e-9 and abs(beta[1]) < 1e3 * abs(k):
            out[0]["x0"] = float(xm - beta[1] / k)
        else:
            out.append({"effect": "offset", "force": float(beta[1])})
        return out

    def where(self, h: Any, beta: np.ndarray, ctx: Context) -> dict[str, Any]:
        return {"position": list(ctx.xrange), "time": None, "velocity": None}

    figure = _by("x", "position [m]")


class Mass(Candidate):
    effect = "mass"
    signature = "a force proportional to the acceleration"

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        return ctx.sig.a[:, None].copy()

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        return [{"effect": "mass", "delta": float(beta[0])}]


class Cogging(Candidate):
    effect = "cogging"
    signature = "a force periodic in position, independent of the direction of motion"

    def _kgrid(self, ctx: Context) -> np.ndarray:
        """Spatial frequencies [1/m] the record resolves.

        Up to what the slow, well-moving fifth of the record passes within the filter
        band (a pitch ``p`` crossed at speed ``v`` is a force at ``v/p`` Hz), and at
        least 20 encoder counts a period; down to 1.5 periods over the stroke.
        """
        span = max(ctx.xrange[1] - ctx.xrange[0], 1e-9)
        kmax = self.kmax(ctx)
        kmin = 1.5 / span
        if kmax <= kmin:
            return np.array([])
        return np.arange(kmin, kmax, 0.25 / span)

    @staticmethod
    def kmax(ctx: Context) -> float:
        """Highest spatial frequency [1/m] the record resolves (see :meth:`_kgrid`)."""
        sig = ctx.sig
        moving = np.abs(sig.vf[sig.mask])
        moving = moving[moving > 0.05 * max(float(moving.max()), 1e-12)]
        v_slow = float(np.percentile(moving, 20)) if moving.size else 1.0
        q = max(sig.info.get("quantum", 0.0), 1e-9)
        return min(1.0 / (20.0 * q), 0.7 * sig.cutoff_hz / max(v_slow, 1e-9))

    @staticmethod
    def _power(r: np.ndarray, x: np.ndarray, k0: float, dk: float, n: int,
               sig: Any) -> np.ndarray:
        """Power of the best sinusoid of ``r`` over ``x`` at ``k0 + j*dk``, ``j < n``
        (least squares on sin and cos)."""
        rs, rc, ss, cc, sc = position_sums(sig, x, r, k0, dk, n, squares=True)
        det = ss * cc - sc * sc
        bs = (cc * rs - sc * rc) / det
        bc = (ss * rc - sc * rs) / det
        return bs * rs + bc * rc

    def choose(self, r: np.ndarray, ctx: Context) -> Any:
        ks = self._kgrid(ctx)
        lead = ctx.extra.get("screw_lead")
        if ks.size == 0:
            return None
        m = ctx.sig.mask
        step = max(1, int(m.sum() // 6000))
        x = ctx.sig.x[m][::step]
        rr = r[m][::step] - np.mean(r[m])
        dk = 0.25 / max(ctx.xrange[1] - ctx.xrange[0], 1e-9)  # the step of _kgrid
        p = self._power(rr, x, float(ks[0]), dk, ks.size, ctx.sig)
        k0 = ks[int(np.argmax(p))]
        span = ctx.xrange[1] - ctx.xrange[0]
        lo, hi = k0 - 0.3 / span, k0 + 0.3 / span
        fine = np.linspace(lo, hi, 31)
        pf = self._power(rr, x, lo, (hi - lo) / 30, 31, ctx.sig)
        if lead:  # one revolution of the screw and its harmonics: always tried
            fine = np.concatenate([fine, np.arange(1, 5) / float(lead)])
            kl = abs(1.0 / float(lead))  # (the power is even in k)
            pf = np.concatenate([pf, self._power(rr, x, kl, kl, 4, ctx.sig)])
        k1 = float(fine[int(np.argmax(pf))])
        self.spectrum = (ks, p)
        return 1.0 / k1

    def describe(self, h: Any, beta: np.ndarray, ctx: Context) -> str:
        return (f"The residual's spectrum over position peaks at a pitch of {h * 1e3:.4g} mm "
                f"(searched from {1e3 / self.kmax(ctx):.3g} mm, what the slowest fifth of "
                "the motion resolves in the filter band, to the stroke).")

    figure = _by("x", "position [m]")

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        ph = 2.0 * np.pi * ctx.sig.x / h
        return ctx.sig.filt(np.column_stack([np.sin(ph), np.cos(ph)]))

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        amp = float(math.hypot(beta[0], beta[1]))
        phase = float(math.atan2(beta[1], beta[0]))
        return [{"effect": "cogging", "amplitude": amp, "pitch": float(h), "phase": phase}]

    def where(self, h: Any, beta: np.ndarray, ctx: Context) -> dict[str, Any]:
        return {"position": list(ctx.xrange), "time": None, "velocity": None}


class PositionFriction(Candidate):
    effect = "position_friction"
    signature = ("a change of the Coulomb/static friction level along the guideway: it "
                 "changes sign with the direction of motion and depends on position")

    def knots(self, ctx: Context) -> np.ndarray:
        lo, hi = ctx.xrange
        n = int(np.clip(round((hi - lo) / 0.01), 8, 24)) + 1
        return np.linspace(lo, hi, n)

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        kn = self.knots(ctx)
        x = np.clip(ctx.sig.x, kn[0], kn[-1])
        eye = np.eye(kn.size)
        hats = np.column_stack([np.interp(x, kn, eye[j]) for j in range(kn.size)])
        return ctx.sig.filt(hats * ctx.fcs[:, None])

    def prior_tol(self, h: Any, ctx: Context) -> np.ndarray | None:
        return np.full(self.knots(ctx).size, 0.3)

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        kn = self.knots(ctx)
        scale = np.maximum(1.0 + np.asarray(beta, float), 0.05)
        return [{"effect": "position_friction", "positions": [float(p) for p in kn],
                 "scale": [float(s) for s in scale]}]

    def where(self, h: Any, beta: np.ndarray, ctx: Context) -> dict[str, Any]:
        kn = self.knots(ctx)
        dev = np.abs(np.asarray(beta, float))
        big = np.flatnonzero(dev >= 0.25 * dev.max()) if dev.max() > 0 else np.array([])
        if big.size == 0:
            return {"position": None, "time": None, "velocity": None}
        lo = kn[max(big[0] - 1, 0)]
        hi = kn[min(big[-1] + 1, kn.size - 1)]
        return {"position": [float(lo), float(hi)], "time": None, "velocity": None}


PositionFriction.figure = _by("x", "position [m]")  # type: ignore[method-assign]


class Drift(Candidate):
    effect = "drift"
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
        return [{"effect": "drift", "gain": float(min(-beta[0], 0.95)),
                 "time_constant": float(h)}]

    def where(self, h: Any, beta: np.ndarray, ctx: Context) -> dict[str, Any]:
        T = float(ctx.sig.t[-1])
        return {"position": None, "time": [0.0, float(min(3.0 * h, T))], "velocity": None}


class Lag(Candidate):
    """``delay`` and ``current_lag``: the same first-order signature, told apart later
    (:mod:`lugre.diagnosis.timing`)."""

    effect = "delay"
    signature = ("the motor force arrives late: the residual follows the rate of change of "
                 "the motor force")

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        return ctx.sig.dfm[:, None].copy()

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        tau = float(beta[0])
        if h == "current_lag":
            return [{"effect": "current_lag", "bandwidth": 1.0 / (2 * math.pi * max(tau, 1e-9))}]
        return [{"effect": "delay", "seconds": max(tau, 0.0)}]

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


class Drag(Candidate):
    effect = "drag"
    signature = ("a force growing with the square of the speed, opposing the motion "
                 "(seals, churning lubricant)")

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        v = ctx.sig.v
        return ctx.sig.filt(np.abs(v) * v)[:, None]

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        return [{"effect": "drag", "coefficient": float(beta[0])}]

    def where(self, h: Any, beta: np.ndarray, ctx: Context) -> dict[str, Any]:
        vm = float(np.max(np.abs(ctx.sig.vf[ctx.sig.mask])))
        return {"position": None, "time": None, "velocity": [-vm, vm]}

    figure = _by("v", "velocity [m/s]")


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

    def _r_base(self, ctx: Context) -> np.ndarray:
        from . import residual as R

        key = ("r_base", id(ctx.model))
        if key not in ctx.extra:
            ctx.extra[key] = R.residual(ctx.model, ctx.sig)
        return ctx.extra[key]

    def _with(self, h: Any, ctx: Context) -> Model:
        return ctx.model.replace(effects=list(ctx.model.effects) + [self.effect_at(h)])

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        from . import residual as R

        return (self._r_base(ctx) - R.residual(self._with(h, ctx), ctx.sig))[:, None]

    def columns_many(self, hs: list[Any], ctx: Context) -> list[np.ndarray] | None:
        """The columns of several grid points at once (the kernel runs them in
        parallel), or None when this candidate builds its columns otherwise."""
        if type(self).columns is not _Secant.columns:
            return None
        r0 = self._r_base(ctx)
        rs = ctx.sig.kernel.residuals([self._with(h, ctx) for h in hs])
        return [(r0 - rs[:, j])[:, None] for j in range(len(hs))]

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        return [self.effect_at(self.from_secant(h, float(beta[0])))]

    def recenter(self, h: Any, beta: np.ndarray, ctx: Context) -> tuple[Any, np.ndarray]:
        return self.from_secant(h, float(beta[0])), np.ones(1)

    def uncertainty(self, term: Any, beta: np.ndarray, ctx: Context, sig: Signals,
                    s2: float) -> dict[str, Any]:
        pr = term.profile
        if pr is None:
            return {}
        ok = pr["score"] <= pr["score"].min() + 10.0
        out: dict[str, Any] = {"criterion": "held-out score within 10 of the best"}
        hs = [self.from_secant(h, float(b[0])) for h, b in zip(pr["h_obj"], pr["beta"])]
        for name, vals in self.interval_params(hs, ok).items():
            out[name] = vals
        return out

    def interval_params(self, hs: list[Any], ok: np.ndarray) -> dict[str, list[float]]:
        return _grid_interval({self.param: np.array([float(h) for h in hs])}, ok)

    param = ""


class StribeckShape(_Secant):
    effect = "stribeck_shape"
    param = "exponent"
    signature = ("a Stribeck curve of another shape: the friction falls from its static to "
                 "its Coulomb level more gradually (exponent under 2) or more abruptly")

    def grid(self, ctx: Context) -> np.ndarray | None:
        return np.array([0.5, 0.65, 0.8, 1.0, 1.25, 1.55, 2.6, 3.3, 4.2])

    def effect_at(self, h: Any) -> dict[str, Any]:
        return {"effect": "stribeck_shape", "exponent": float(h)}

    def from_secant(self, h: Any, b: float) -> Any:
        return float(np.clip(2.0 + b * (float(h) - 2.0), 0.2, 10.0))

    def describe(self, h: Any, beta: np.ndarray, ctx: Context) -> str:
        return "It lives at slow speeds, where the friction falls from static to Coulomb."

    figure = _by("v", "velocity [m/s]")


class Deadband(_Secant):
    effect = "deadband"
    param = "current"
    signature = ("a dead-band of the drive: small currents give no force, so the motor "
                 "force lags the command at every change of the current's sign")

    def grid(self, ctx: Context) -> np.ndarray | None:
        ia = np.abs(ctx.sig.fm[ctx.sig.mask]) / ctx.model.force_constant
        top = float(np.percentile(ia, 50))
        if not top > 0:
            return None
        return top * np.geomspace(0.01, 0.8, 12)

    def effect_at(self, h: Any) -> dict[str, Any]:
        return {"effect": "deadband", "current": float(h)}

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        if any(e["effect"] in ("delay", "current_lag", "deadband") for e in ctx.model.effects):
            return super().columns(h, ctx)
        from .residual import deadband

        sig = ctx.sig
        # r(without) - r(with): only the motor force changes
        return (sig.fm_f - sig.filt(deadband(sig.fm, float(h) * ctx.model.force_constant))
                )[:, None]

    def from_secant(self, h: Any, b: float) -> Any:
        return float(max(b * float(h), 0.0))

    def describe(self, h: Any, beta: np.ndarray, ctx: Context) -> str:
        d = self.from_secant(h, float(beta[0]))
        return (f"Currents under {d * 1e3:.3g} mA give no force ({d * ctx.model.force_constant:.3g}"
                " N of motor force lost at each sign change of the current).")

    def figure(self, residual: np.ndarray, contrib: np.ndarray, ctx: Context
               ) -> dict[str, Any]:
        m = ctx.sig.mask
        i = ctx.sig.fm_f[m] / ctx.model.force_constant
        o = np.argsort(i, kind="stable")
        return {"x": i[o], "xlabel": "current [A]", "residual": residual[m][o],
                "effect": contrib[m][o]}


def _objects(items: list[Any]) -> np.ndarray:
    """A 1-D object array of tuples (grid points of several parameters)."""
    out = np.empty(len(items), dtype=object)
    out[:] = items
    return out


class Resonance(_Secant):
    effect = "resonance"
    signature = ("a compliant coupling: the load the encoder does not see swings against "
                 "the motor at the coupling's natural frequency")
    smooths_readings = True
    reprofile = True

    #: damping ratios and load fractions of the search
    ZETAS = (0.03, 0.1, 0.3)
    FRACTIONS = (0.3, 0.6, 0.85)

    def frequencies(self, ctx: Context) -> np.ndarray | None:
        """Natural frequencies searched [Hz]: 5 Hz to 0.8 of the filter's cut-off."""
        top = 0.8 * ctx.sig.cutoff_hz
        return None if top <= 5.0 else np.geomspace(5.0, top, 14)

    def grid(self, ctx: Context) -> np.ndarray | None:
        """First stage: every frequency at a middle damping and load fraction.

        Every point costs a simulation of the load along the whole record, so the
        search goes by stages (:meth:`next_grid`): the frequencies, then damping and
        load fraction at the best three, then a local search around the best point
        (40 to 140 simulations, 60-80 typically, where the full product of the three
        grids and its refinement took 171).
        """
        fs = self.frequencies(ctx)
        if fs is None:
            return None
        # the local search stays within what the first grids span (and a step beyond):
        # a resonance has a light damping and lies within the filter band
        self._box = ((0.88 * fs[0], 1.13 * fs[-1]),
                     (0.6 * min(self.ZETAS), 1.6 * max(self.ZETAS)))
        return _objects([(f, 0.1, 0.6) for f in fs])

    def next_grid(self, rows: list[tuple[Any, float]], grid: np.ndarray, stage: int
                  ) -> np.ndarray | None:
        """Stage 1: every damping and load fraction at the three best frequencies.
        Then a local search on the lattice of steps (frequency x0.94 or /0.94, damping
        x0.6 or /0.6, load fraction +-0.12, every combination: the three interact, a
        lightly damped load answers in a narrow band and the fraction moves where the
        motor sees it): the neighbours of the best point are scored until none is
        better, at most four times."""
        def key(h: Any) -> tuple[float, ...]:
            return tuple(float(f"{v:.9g}") for v in h)

        done = {key(r[0]) for r in rows}
        best = min(rows, key=lambda r: r[1])[0]
        if stage == 1:
            top: list[float] = []
            for h, _ in sorted(rows, key=lambda r: r[1]):
                if h[0] not in top:
                    top.append(h[0])
            g = [(fq, zz, rr) for fq in top[:3] for zz in self.ZETAS for rr in self.FRACTIONS]
        elif stage <= 5:
            f, z, r = best
            g = [(f * a, z * b, float(np.clip(r + c, 0.05, 0.95)))
                 for a in (0.94, 1.0, 1 / 0.94) for b in (0.6, 1.0, 1 / 0.6)
                 for c in (-0.12, 0.0, 0.12)]
        else:
            return None
        (f_lo, f_hi), (z_lo, z_hi) = getattr(self, "_box", ((0.0, np.inf), (0.0, np.inf)))
        g = [h for h in g if key(h) not in done
             and f_lo <= h[0] <= f_hi and z_lo <= h[1] <= z_hi]
        if not g:
            return None  # the best point has every neighbour scored: a local optimum
        return _objects(list(dict.fromkeys(g)))

    def prior_tol(self, h: Any, ctx: Context) -> np.ndarray | None:
        return np.full(1, 1e-6)  # the effect at h exactly: its parameters come from the grid

    def prior_center(self, h: Any, ctx: Context) -> np.ndarray | None:
        return np.ones(1)

    def effect_at(self, h: Any) -> dict[str, Any]:
        f, z, r = h
        return {"effect": "resonance", "frequency": float(f), "damping_ratio": float(z),
                "load_fraction": float(r)}

    def interval_params(self, hs: list[Any], ok: np.ndarray) -> dict[str, list[float]]:
        a = np.array([list(h) for h in hs], dtype=float)
        return _grid_interval({k: a[:, j] for j, k in
                               enumerate(("frequency", "damping_ratio", "load_fraction"))}, ok)

    def describe(self, h: Any, beta: np.ndarray, ctx: Context) -> str:
        f, z, r = h
        return (f"A load of {100 * r:.0f} % of the mass on a coupling of {f:.3g} Hz "
                f"(damping ratio {z:.2g}).")

    def figure(self, residual: np.ndarray, contrib: np.ndarray, ctx: Context
               ) -> dict[str, Any]:
        from scipy import signal

        m = ctx.sig.mask
        nper = int(min(m.sum(), 2048))
        f, pr = signal.welch(residual[m], fs=ctx.sig.fs, nperseg=nper)
        _, pe = signal.welch(contrib[m], fs=ctx.sig.fs, nperseg=nper)
        keep = f <= ctx.sig.cutoff_hz
        return {"x": f[keep], "xlabel": "frequency [Hz]", "residual": np.sqrt(pr[keep]),
                "effect": np.sqrt(pe[keep]), "ylabel": "force density [N/sqrt(Hz)]"}


def _grid_interval(values: dict[str, np.ndarray], ok: np.ndarray) -> dict[str, list[float]]:
    """Range of each parameter over the grid points whose held-out score is within the
    threshold of the best, widened to the neighbouring grid values: the grid's spacing
    bounds what the profile can say (one point alone is no interval)."""
    out = {}
    for name, v in values.items():
        grid = np.unique(v)
        lo, hi = float(v[ok].min()), float(v[ok].max())
        below, above = grid[grid < lo], grid[grid > hi]
        out[name] = [float(below.max()) if below.size else lo,
                     float(above.min()) if above.size else hi]
    return out


def candidates() -> list[Candidate]:
    """A fresh list of every candidate of the vocabulary."""
    return [Offset(), Spring(), Mass(), Cogging(), PositionFriction(), Drift(), Lag(),
            Drag(), StribeckShape(), Deadband(), Resonance()]
