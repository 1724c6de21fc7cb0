"""The base as a starting point, not as the truth: after the search, the base is refitted
with the findings in; when that moves it far from the model as given (beyond three
tolerances) and lowers the residual by a fifth or more, the given base was far from what
the record supports, and the diagnosis is run again from the refitted base, so that no
finding stands in for a base parameter."""

from __future__ import annotations

from typing import Any

import numpy as np

from .. import units as U
from ..model import Model
from . import residual as R
from .base import BASE_PARAMS, apply_base, get_base
from .basefit import _run, _value, base_names, fit_base

__all__ = ["REBASE_GAIN", "REBASE_TOLERANCES", "STAND_IN", "far_base"]

#: Least share of the residual's rms the refit must remove ...
REBASE_GAIN = 0.2
#: ... while moving a base parameter by more than this many of its tolerances.
REBASE_TOLERANCES = 3.0

#: A base refitted without a finding that comes within this share of the residual with
#: it may have had it stand in for the base (the search from there decides).
STAND_IN = 0.05

#: The quick refit stops when its weighted sum of squares falls by less than this share
#: twice in a row: 1e-4 of the sum is 5e-5 of the rms, a thousandth of the smallest
#: margin it is weighed by (:data:`STAND_IN`).
QUICK_TOL = 1e-4

_TOL = dict(BASE_PARAMS)


def _tolerance(name: str) -> float:
    return _TOL.get(name.replace(".hump", ".fs"), 0.03)


def _rms(r: np.ndarray, mask: np.ndarray) -> float:
    return float(np.sqrt(np.mean(r[mask] ** 2)))


def far_base(rec: Any, given: Model, augmented: Model, *, cutoff_hz: float | None,
             backend: Any, free_mass: bool, held: str = "the findings",
             rms_before: float | None = None, against: Model | None = None
             ) -> dict[str, Any] | None:
    """Whether the given base is far from what the record supports.

    Returns None, or ``model`` (the given model, its own effects kept, with the base
    fitted from the grid of starts with the findings held in), ``moves`` (per parameter moved beyond the tolerances:
    ``name``, ``given``, ``refit``, ``change``), ``rms_given`` and ``rms_refit`` [N]
    (the augmented model's residual before and after the quick refit) and ``text``.
    ``rms_before`` [N], when given, is the residual the refit must beat instead of the
    augmented model's; ``held`` says in words what the refit held in. With ``against``
    (a model with more effects than ``augmented``), the refit must come within
    :data:`STAND_IN` of that model's residual, and need not move a parameter beyond its
    tolerances: the finding it lacks may have stood in for the base (the search from the
    refitted base decides, :func:`lugre.diagnosis.core.diagnose`).
    """
    sig = R.prepare(rec, augmented, cutoff_hz=cutoff_hz, backend=backend)
    names = base_names(free_mass)
    quick, _ = _run(sig, [augmented], names, keep=1, max_iter=30, tol=QUICK_TOL,
                    information=False)
    r1 = np.asarray(sig.kernel.residual(quick))
    rms1 = _rms(r1, sig.mask)
    rms0 = (_rms(np.asarray(sig.kernel.residual(against or augmented)), sig.mask)
            if rms_before is None else rms_before)
    if not rms1 < (1.0 + STAND_IN if against is not None else 1.0 - REBASE_GAIN) * rms0:
        return None
    moved = _moves(given, quick, names)
    if not moved and against is None:
        return None
    # the base fitted from the grid with the findings held in it (without them the
    # effects pull it astray: a cogging on the slow samples doubles a hump), then put
    # into the given model, whose search runs again
    full = fit_base(sig, augmented, free_mass=free_mass, extra=[quick], profiles=False)
    refit = apply_base(given, {n: get_base(full.model, n) for n, _ in BASE_PARAMS})
    moves = _moves(given, refit, names) or moved
    where = ("the base as given is far from what this record supports: "
             + ", ".join(_move_words(m) for m in moves)) if moves else (
        "the base as given is not where this record puts it")
    n = U.si("N")
    fall = (f"falls from {rms0:.3g} to {rms1:.3g} {n} rms" if against is None else
            f"is {rms1:.3g} {n} rms, against {rms0:.3g} {n} with that finding in as well")
    text = (where + f"; refitted with {held} in, the {U.force_words()} residual {fall}. "
            "The search was run again from the refitted base, so that no finding stands "
            "in for a base parameter")
    return {"model": refit, "moves": moves, "rms_given": rms0, "rms_refit": rms1,
            "text": text}


def _moves(given: Model, refit: Model, names: list[str]) -> list[dict[str, Any]]:
    out = []
    for n in names:
        a, b = _value(given, n), _value(refit, n)
        if n.endswith(".hump"):
            fc = _value(given, n.replace(".hump", ".fc"))
            change = (b - a) / max(fc, 1e-12)
        else:
            change = (b - a) / max(abs(a), 1e-12)
        if abs(change) > REBASE_TOLERANCES * _tolerance(n):
            out.append({"name": n, "given": a, "refit": b, "change": change})
    return out


def _move_words(m: dict[str, Any]) -> str:
    from .fitreport import fit_unit, label

    return f"{label(m['name'])} {m['given']:.4g} -> {m['refit']:.4g} {fit_unit(m['name'])}"
