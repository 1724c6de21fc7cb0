"""Joint refit: damped Gauss-Newton on the base parameters and the effects' coefficients,
on the exact residual."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from ..model import Model
from . import base as B
from . import candidates as E
from . import residual as R
from .candidates import Term
from .scoring import Scorer

__all__ = ["effects_of", "refine", "split"]


def effects_of(terms: list[Term], betas: list[np.ndarray], ctx: E.Context
                ) -> list[dict[str, Any]]:
    out: list[dict[str, Any]] = []
    for t, b in zip(terms, betas):
        out.extend(t.cand.to_effects(t.h, b, ctx))
    return out


def split(beta: np.ndarray, q: int, terms: list[Term]) -> tuple[np.ndarray, list[np.ndarray]]:
    k = q
    out = []
    for t in terms:
        p = t.X.shape[1]
        out.append(np.array(beta[k:k + p], dtype=float))
        k += p
    return np.array(beta[:q], dtype=float), out


#: Least share of the given mass a step may leave (a linearised step of a fitted
#: base beside a resonance went through zero, and the clamped mass of 1 mg made every
#: simulation of the coupling take seconds).
MASS_FLOOR = 0.1


def refine(model: Model, sig: R.Signals, terms: list[Term], base: dict[str, float],
           betas: list[np.ndarray], s2: float, names: tuple[str, ...] | list[str],
           iters: int = 3, tolerance: float = 1.0
           ) -> tuple[Model, dict[str, float], list[np.ndarray], E.Context, list[Term]]:
    """Damped Gauss-Newton on base parameters and effect coefficients (exact residual).

    Each step solves the linearised joint problem (base prior centred on the model as
    given) and is halved until the exact residual decreases. Effects with a nonlinear
    parameter are re-linearised at each step (:meth:`Candidate.recenter`).

    Parameters
    ----------
    model : Model
        The model as given (prior centre).
    sig : Signals
        The prepared recording.
    terms, betas : list
        Effect terms and their coefficients (start).
    base : dict
        Base parameter values (start), by path.
    s2 : float
        Variance unit of the prior (as in :class:`~lugre.diagnosis.scoring.Scorer`).
    names : sequence of str
        The base parameters that are free (the others are held at the model's values).
    iters : int, default 3
        Gauss-Newton steps at most.
    tolerance : float, default 1.0
        Scale of the base parameters' prior tolerances.

    Returns
    -------
    augmented : Model
    base : dict
    betas : list of numpy.ndarray
    ctx : Context
    terms : list of Term
        With their nonlinear parameters updated.
    """
    given = list(model.effects)
    theta0 = {n: B.get_base(model, n) for n, _ in B.BASE_PARAMS}
    tolrel = dict(B.BASE_PARAMS)
    terms = list(terms)

    def build(base: dict[str, float], betas: list[np.ndarray], terms: list[Term]
              ) -> tuple[Any, ...]:
        base = dict(base)
        betas = [b.copy() for b in betas]
        terms = list(terms)
        bm = B.apply_base(model, base)
        for k, t in enumerate(terms):  # keep the overall friction level in the base
            if t.cand.scales_levels:
                sc = 1.0 + betas[k]
                c = float(np.median(sc))
                betas[k] = sc / c - 1.0
                for side in ("positive", "negative"):
                    for key in ("fc", "fs"):
                        base[f"{side}.{key}"] = B.get_base(bm, f"{side}.{key}") * c
                bm = B.apply_base(model, base)
        ctx = E.Context.build(sig, bm)
        aug = bm.replace(effects=given + effects_of(terms, betas, ctx))
        for k, t in enumerate(terms):
            h, b = t.cand.recenter(t.h, betas[k], ctx)
            if h is not t.h:
                terms[k] = replace(t, h=h)
                betas[k] = b
        base = {n: B.get_base(aug, n) for n, _ in B.BASE_PARAMS}
        r = R.residual(aug, sig)
        return float(np.sum(r[sig.mask] ** 2)), aug, base, betas, ctx, r, terms

    # start from the linearised step of the selection, or from the model as given if
    # that is better (a step far outside the linear range can make things worse)
    def valid(base: dict[str, float], betas: list[np.ndarray], terms: list[Term]
              ) -> tuple[Any, ...] | None:
        if not base.get("mass", 1.0) > MASS_FLOOR * theta0.get("mass", 0.0):
            return None  # (a step through the mass's zero: no axis there)
        try:
            return build(base, betas, terms)
        except ValueError:  # a coefficient outside the effect's range: no model there
            return None

    starts = [o for o in (valid(base, betas, terms), valid(theta0, betas, terms))
              if o is not None]
    if not starts:
        build(base, betas, terms)  # raises, naming the parameter out of range
    sse, aug, base, betas, ctx, r, terms = min(starts, key=lambda o: o[0])
    for _ in range(iters):
        J, free, _, _ = B.base_jacobian(aug, sig, names=names)
        tol = np.array([tolerance * tolrel[n] * max(abs(theta0[n]), 1e-12) for n in free])
        center = np.array([theta0[n] - base[n] for n in free])
        cur_terms = [Term(cand=t.cand, h=t.h, X=t.cand.columns(t.h, ctx), prior=t.prior,
                          center=t.center) for t in terms]
        ev = Scorer(r, J, tol, sig.mask, s2, blocks=2, center=center).evaluate(cur_terms)
        d, dbs = split(ev.beta, len(free), cur_terms)
        lam = 1.0
        improved = False
        for _h in range(4):
            nb = dict(base)
            for n, dv in zip(free, d):
                nb[n] = base[n] + lam * dv
            nbetas = [b + lam * db for b, db in zip(betas, dbs)]
            out = valid(nb, nbetas, terms)
            if out is not None and out[0] < sse:
                sse, aug, base, betas, ctx, r, terms = out
                improved = True
                break
            lam *= 0.5
        if not improved or lam < 1.0:
            break
    return aug, base, betas, ctx, terms
