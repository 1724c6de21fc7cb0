"""A fitted model's mass that the record moves beyond its interval, named as a ``mass``
finding: the base a ``lugre fit`` identified is re-estimated freely (its mass among
its parameters), and a moved mass would otherwise pass as a base move. Across two
records of one axis that is a payload or, on a joint, another configuration of the
arm behind it: a change to name, with its size and its unit. Only when the record,
identified alone, also puts the mass there: on the record the model was fitted on, a
mass that moves is what the findings took back from it (a spring in the mass)."""

from __future__ import annotations

from typing import Any

import numpy as np

from .. import units as U
from ..model import Model
from ..vocabulary import MASS
from . import evidence as V
from . import residual as R
from .basefit import identify
from .report import Diagnosis, Finding

__all__ = ["MASS_CHANGE_SHARE", "MASS_CHANGE_WIDTHS", "name_mass_change"]

#: The move must exceed this many half-widths of the fit's 95 % interval ...
MASS_CHANGE_WIDTHS = 3.0
#: ... and this share of the mass.
MASS_CHANGE_SHARE = 0.05


def name_mass_change(dg: Diagnosis, given: Model, rec: Any, *, cutoff_hz: float | None,
                     backend: Any) -> Diagnosis:
    """``dg`` with the move of a fitted mass beyond its interval named as a ``mass``
    finding, and the augmented model holding it as an effect on the given mass."""
    ident = (given.to_dict().get("identification") or {}).get("parameters") or {}
    interval = (ident.get("mass") or {}).get("ci95") or [None, None]
    new = dg.augmented.total_mass
    delta = new - given.total_mass
    if None in interval or any(f.effect == MASS for f in dg.findings):
        return dg
    half = 0.5 * (float(interval[1]) - float(interval[0]))
    within = max(MASS_CHANGE_WIDTHS * half, MASS_CHANGE_SHARE * given.mass)
    if abs(delta) <= within:
        return dg
    # the record identified alone, as lugre fit would: a mass where the model's is means
    # the move is the findings' (a spring the fit had taken into the mass), not the axis's
    own = identify(rec, force_constant=given.force_constant, cutoff_hz=cutoff_hz,
                   backend=backend, profiles=False).model.mass
    if abs(own - given.mass) <= within:
        return dg
    explained = _explained(rec, given, new, cutoff_hz, backend)  # (new: a total mass)
    u = U.si("kg")
    text = (f"The {U.mass_words()} the record supports is {new:.4g} {u} where the fitted "
            f"model holds {given.mass:.4g} {u} (95 % interval {float(interval[0]):.4g} to "
            f"{float(interval[1]):.4g} {u}): {100 * delta / given.mass:+.0f} %, a payload"
            + (" or another configuration of the arm behind the joint" if U.is_rotary()
               else "") + " since the record the model was fitted on.")
    dg.findings.append(Finding(MASS, {"delta": float(delta)},
                               {"position": None, "time": None, "velocity": None},
                               explained, text))
    effects = dg.augmented.effects + [{"effect": MASS, "delta": float(delta)}]
    dg.augmented = dg.augmented.with_axis(mass=given.mass).replace(effects=effects)
    dg.base_moves = [m for m in dg.base_moves if m.get("parameter") != "mass"]
    dg.could_not_reveal = [h for h in dg.could_not_reveal if h.get("effect") != MASS]
    dg.verdict = V.verdict(dg)
    return dg


def _explained(rec: Any, given: Model, mass: float, cutoff_hz: float | None,
               backend: Any) -> float:
    """Share of the given model's residual variance that the mass alone accounts for."""
    sig = R.prepare(rec, given, cutoff_hz=cutoff_hz, backend=backend)
    r0 = np.asarray(sig.kernel.residual(given))[sig.mask]
    moved = given.with_axis(mass=given.mass + mass - given.total_mass)
    r1 = np.asarray(sig.kernel.residual(moved))[sig.mask]
    v0 = float(np.var(r0))
    return float(np.clip(1.0 - float(np.var(r1)) / v0, 0.0, 1.0)) if v0 > 0 else 0.0
