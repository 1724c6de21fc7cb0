"""Signatures of the effects of the vocabulary, as regressors of the force residual.

Every candidate turns into columns ``X`` such that the residual of the model without
the effect is ``r ~ X @ beta`` (to first order), and ``beta`` maps back to the
effect's parameters. The base LuGre parameters enter the same way through the Jacobian
of the model force (:func:`base_jacobian`), so that effects and base parameters are
fitted jointly.

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
from .residual import Signals, base_friction

__all__ = [
    "BASE_PARAMS",
    "Candidate",
    "Context",
    "apply_base",
    "base_jacobian",
    "candidates",
]

#: Base parameters re-estimated alongside, and their tolerance (relative std of the
#: prior: how far a parameter of a model that is "about right" may move).
BASE_PARAMS: tuple[tuple[str, float], ...] = (
    ("mass", 0.03),
    ("positive.fc", 0.03),
    ("positive.fs", 0.03),
    ("positive.sigma2", 0.03),
    ("positive.vs", 0.1),
    ("negative.fc", 0.03),
    ("negative.fs", 0.03),
    ("negative.sigma2", 0.03),
    ("negative.vs", 0.1),
    ("sigma0", 0.3),
    ("sigma1", 0.3),
)


def get_base(model: Model, name: str) -> float:
    """Value of a base parameter by its path (``mass``, ``positive.fc``, ``sigma0``)."""
    if name == "mass":
        return float(model.mass)
    f = model.friction
    if "." in name:
        d, k = name.split(".")
        return float(f[d][k])
    return float(f[name])


def apply_base(model: Model, values: dict[str, float]) -> Model:
    """A copy of ``model`` with base parameters set (kept valid: ``fs >= fc`` etc.).

    Parameters
    ----------
    model : Model
        The model.
    values : dict
        New values by path.

    Returns
    -------
    Model
    """
    d = model.to_dict()
    f = d["friction"]
    for name, val in values.items():
        val = float(val)
        if name == "mass":
            d["axis"]["mass"] = max(val, 1e-6)
        elif "." in name:
            a, k = name.split(".")
            f[a][k] = val
        else:
            f[name] = val
    for side in ("positive", "negative"):
        s = f[side]
        s["fc"] = max(float(s["fc"]), 1e-9)
        s["fs"] = max(float(s["fs"]), float(s["fc"]))
        s["vs"] = max(float(s["vs"]), 1e-6)
        s["sigma2"] = max(float(s["sigma2"]), 0.0)
    f["sigma0"] = max(float(f["sigma0"]), 1.0)
    f["sigma1"] = max(float(f["sigma1"]), 0.0)
    return Model(d)


def base_jacobian(model: Model, sig: Signals, fr0: np.ndarray | None = None
                  ) -> tuple[np.ndarray, list[str], np.ndarray, np.ndarray]:
    """Jacobian of the filtered model force with respect to the base parameters.

    Parameters
    ----------
    model : Model
        The model at which to linearise (its effects included).
    sig : Signals
        The prepared recording.
    fr0 : numpy.ndarray, optional
        ``base_friction(model, sig)`` if already computed.

    Returns
    -------
    J : numpy.ndarray
        ``(n, q)``, filtered.
    names : list of str
        Parameter paths (identifiable ones only).
    theta : numpy.ndarray
        Current values.
    tol : numpy.ndarray
        Prior standard deviations (absolute).
    """
    if fr0 is None:
        fr0 = base_friction(model, sig)
    cols: list[np.ndarray] = []
    names: list[str] = []
    theta: list[float] = []
    tol: list[float] = []
    mass_fixed = getattr(model, "_diagnose_mass_fixed", False)
    for name, rel in BASE_PARAMS:
        th = get_base(model, name)
        if name == "mass":
            if mass_fixed:
                continue
            col = sig.a.copy()
            cols.append(col)
        else:
            side, key = (name.split(".") + [""])[:2] if "." in name else ("", name)
            if key == "vs" and abs(model.friction[side]["fs"] - model.friction[side]["fc"]) < (
                1e-3 * model.friction[side]["fc"]
            ):
                continue  # no Stribeck hump: vs does nothing
            h = 1e-4 * max(abs(th), 1e-9)
            if key == "fc":
                h = -h  # keep fs >= fc
            m2 = apply_base(model, {name: th + h})
            col = (base_friction(m2, sig) - fr0) / h
            if not np.any(np.abs(col) > 0):
                continue
            cols.append(sig.filt(col))
        names.append(name)
        theta.append(th)
        tol.append(rel * max(abs(th), 1e-12))
    return np.column_stack(cols), names, np.array(theta), np.array(tol)


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

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        """The effect objects for coefficients ``beta``."""
        raise NotImplementedError

    def where(self, h: Any, beta: np.ndarray, ctx: Context) -> dict[str, Any]:
        """Position, time and velocity ranges where the effect lives (``None``: all)."""
        return {"position": None, "time": None, "velocity": None}


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
        sig = ctx.sig
        span = max(ctx.xrange[1] - ctx.xrange[0], 1e-9)
        moving = np.abs(sig.vf[sig.mask])
        moving = moving[moving > 0.05 * max(moving.max(), 1e-12)]
        vtyp = float(np.median(moving)) if moving.size else 1.0
        q = max(sig.info.get("quantum", 0.0), 1e-9)
        kmax = min(1.0 / (20.0 * q), 0.7 * sig.cutoff_hz / max(vtyp, 1e-9), 400.0 / span)
        kmin = 1.5 / span
        if kmax <= kmin:
            return np.array([])
        return np.arange(kmin, kmax, 0.25 / span)

    @staticmethod
    def _power(r: np.ndarray, x: np.ndarray, ks: np.ndarray) -> np.ndarray:
        ph = 2.0 * np.pi * np.outer(ks, x)
        s, c = np.sin(ph), np.cos(ph)
        ss, cc, sc = (s * s).sum(1), (c * c).sum(1), (s * c).sum(1)
        rs, rc = np.einsum("ij,j->i", s, r), np.einsum("ij,j->i", c, r)
        det = ss * cc - sc * sc
        bs = (cc * rs - sc * rc) / det
        bc = (ss * rc - sc * rs) / det
        return bs * rs + bc * rc

    def choose(self, r: np.ndarray, ctx: Context) -> Any:
        ks = self._kgrid(ctx)
        if ks.size == 0:
            return None
        m = ctx.sig.mask
        step = max(1, int(m.sum() // 6000))
        x = ctx.sig.x[m][::step]
        rr = r[m][::step] - np.mean(r[m])
        p = self._power(rr, x, ks)
        k0 = ks[int(np.argmax(p))]
        span = ctx.xrange[1] - ctx.xrange[0]
        fine = np.linspace(k0 - 0.3 / span, k0 + 0.3 / span, 31)
        pf = self._power(rr, x, fine)
        k1 = float(fine[int(np.argmax(pf))])
        self.spectrum = (ks, p)
        return 1.0 / k1

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


class Drift(Candidate):
    effect = "drift"
    signature = ("a trend in time of the Coulomb/static friction level (its sign follows "
                 "the direction of motion)")

    def _grid(self, ctx: Context) -> np.ndarray:
        T = float(ctx.sig.t[-1] - ctx.sig.t[0])
        return T * np.logspace(np.log10(1 / 40), np.log10(3.0), 24)

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
    """``delay`` and ``current_lag``: the same first-order signature, told apart later."""

    effect = "delay"
    signature = "a force proportional to the rate of change of the motor force (a lag)"

    def columns(self, h: Any, ctx: Context) -> np.ndarray:
        return ctx.sig.dfm[:, None].copy()

    def to_effects(self, h: Any, beta: np.ndarray, ctx: Context) -> list[dict[str, Any]]:
        tau = float(beta[0])
        if h == "current_lag":
            return [{"effect": "current_lag", "bandwidth": 1.0 / (2 * math.pi * max(tau, 1e-9))}]
        return [{"effect": "delay", "seconds": max(tau, 0.0)}]


def candidates() -> list[Candidate]:
    """A fresh list of every candidate of the vocabulary."""
    return [Offset(), Spring(), Mass(), Cogging(), PositionFriction(), Drift(), Lag()]
