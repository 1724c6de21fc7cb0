"""The candidate of an effect: its context, its regressors, the term it makes once
selected, and the hooks through which the stages ask it what only it knows."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...model import Model
from ..residual import Signals, base_friction

__all__ = ["Candidate", "Context", "FindingView", "Said", "Term", "by", "by_current",
           "grid_interval", "objects", "rows_of"]


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


@dataclass(frozen=True)
class Said:
    """What a candidate adds to its finding: parameters, intervals or a sentence of
    evidence in place of the defaults (None: keep them), and alternatives beside it."""

    parameters: dict[str, Any] | None = None
    uncertainty: dict[str, Any] | None = None
    evidence: str | None = None
    alternatives: tuple[dict[str, Any], ...] = ()


@dataclass(frozen=True)
class FindingView:
    """What a candidate reads when its finding is written: the record, the model
    diagnosed, the search's scorer and evaluation with its base names and tolerances,
    the terms of the joint refit, the least gain, and the alternatives found so far."""

    sig: Signals
    model: Model
    scorer: Any
    ev: Any
    names: list[str]
    tol: np.ndarray
    terms: list[Any]
    min_gain: float
    alternatives: list[dict[str, Any]]


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

    #: a timing term: its findings need no least force (a lag is a time, not a force)
    #: and the search reads it in two forms (:mod:`lugre.diagnosis.timing`)
    timing: bool = False
    #: order of the own-physics checks (:meth:`check`) when several terms have one
    check_rank: int = 0
    #: :meth:`choose` picks a parameter the record may not resolve (None: not tried)
    chooses: bool = False
    #: its coefficients scale the friction levels: the joint refit keeps their median
    #: in the base levels (:func:`lugre.diagnosis.refit.refine`)
    scales_levels: bool = False
    #: the least force it must add to be named, in units of the search's practical size
    #: (0.3 % of the motor force), and why when more than one
    least_force: float = 1.0
    least_force_why: str = ""
    #: too small to name but consistent, it may enter the fit as a minor correction
    may_be_minor: bool = True
    #: a small correction nearly consistent over the blocks enters the fit as minor,
    #: never named (a mass error left out leaks into whatever follows the force)
    minor_when_consistent: bool = False

    def check(self, scorer: Any, terms: list[Any], k: int, ev: Any, ctx: Context
              ) -> dict[str, Any] | None:
        """The term ``terms[k]`` checked by its own physics (a lag between the reversals,
        a payload speeding up and braking); None when it has no such check or the record
        cannot tell."""
        return None

    def refusal(self, chk: dict[str, Any]) -> str | None:
        """Why the term is not named, from :meth:`check`'s figures; None: it stands."""
        return None

    def exact_refusal(self, h: Any, beta: np.ndarray, ctx: Context) -> str | None:
        """Why the term, as the joint refit left it in its exact form (``h``, ``beta``),
        is no finding of this physics; None: it stands (default)."""
        return None

    def finding(self, term: Any, beta: np.ndarray, effect: dict[str, Any],
                view: FindingView) -> Said:
        """What this effect adds to its finding beyond its parameters (default: nothing)."""
        return Said()

    def limit(self, ctx: Context, sizes: Any) -> dict[str, Any] | None:
        """What this record could hide of the effect: ``sizes(Xs)`` gives the smallest
        size of each column (per unit) that the search would name
        (:func:`lugre.diagnosis.evidence.revealed_sizes`); None: nothing to say."""
        return None

    def figure(self, residual: np.ndarray, contrib: np.ndarray, ctx: Context
               ) -> dict[str, Any]:
        """Data of the figure of the fitted effect over the residual it explains."""
        m = ctx.sig.mask
        return {"x": ctx.sig.t[m], "xlabel": "time [s]", "residual": residual[m],
                "effect": contrib[m]}


def by(key: str, xlabel: str):  # figure against position or velocity
    def figure(self: Candidate, residual: np.ndarray, contrib: np.ndarray, ctx: Context
               ) -> dict[str, Any]:
        m = ctx.sig.mask
        x = (ctx.sig.x if key == "x" else ctx.sig.vf)[m]
        o = np.argsort(x, kind="stable")
        return {"x": x[o], "xlabel": xlabel, "residual": residual[m][o],
                "effect": contrib[m][o]}
    return figure


def by_current(self: Candidate, residual: np.ndarray, contrib: np.ndarray, ctx: Context
               ) -> dict[str, Any]:
    """A candidate's figure against the motor current (the drive's own effects)."""
    m = ctx.sig.mask
    i = ctx.sig.fm_f[m] / ctx.model.force_constant
    o = np.argsort(i, kind="stable")
    return {"x": i[o], "xlabel": "current [A]", "residual": residual[m][o],
            "effect": contrib[m][o]}


def objects(items: list[Any]) -> np.ndarray:
    """A 1-D object array of tuples (grid points of several parameters)."""
    out = np.empty(len(items), dtype=object)
    out[:] = items
    return out


def rows_of(X: np.ndarray, step: int) -> np.ndarray:
    """Every ``step``-th row of ``X`` as its own array (the full one can be freed)."""
    return X if step <= 1 else np.ascontiguousarray(X[::step])


def grid_interval(values: dict[str, np.ndarray], ok: np.ndarray) -> dict[str, list[float]]:
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


@dataclass
class Term:
    """A selected effect: the candidate, its nonlinear parameter and its columns."""

    cand: Candidate
    h: Any
    X: np.ndarray
    prior: np.ndarray | None = None
    #: prior mean of the coefficients (default 0); with a tight ``prior`` it pins them
    center: np.ndarray | None = None
    #: held-out score over the nonlinear parameter (``h``, ``score``, ``beta``), when
    #: it was chosen by a profile
    profile: dict[str, np.ndarray] | None = None
    #: consistent on the held-out blocks but too small to matter: kept in the fit so
    #: that it does not leak into other terms, reported as a minor correction, never
    #: as a finding
    minor: bool = False
    #: set when ``X`` holds only the rows the scorers read (a trial of the search on a
    #: long record): the Gram matrix of all its columns over the samples used and that
    #: mask (:mod:`lugre.diagnosis.colcache`)
    gram: tuple[np.ndarray, np.ndarray] | None = None

    @property
    def effect(self) -> str:
        return self.cand.effect
