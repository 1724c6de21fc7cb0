"""A model diagnosed on the very record it was fitted on.

``lugre fit`` writes a fingerprint of its record into the model's ``identification``
section. When ``lugre diagnose`` is given that record again, what the fit took into the
base cannot come back out as a finding: a payload is inside the fitted mass, and a
constant force inside the fitted per-direction friction levels, whatever their size. The
report says so in its limits and in a note, rather than "nothing found" as if the record
had been searched for them; a later record, or one of another trajectory, diagnosed
against the same model shows them.
"""

from __future__ import annotations

from typing import Any

from .. import units as U
from ..recording import Recording
from ..vocabulary import MASS, OFFSET

__all__ = ["fitted_on_this_record", "say_fitted_here"]

_AGAIN = ("diagnose a later record of the axis, or one under another trajectory, against "
          "this model")


def fitted_on_this_record(identification: dict[str, Any], rec: Recording) -> bool:
    """Whether the model's ``identification`` names this record as its own."""
    own = identification.get("record")
    return isinstance(own, dict) and own == rec.fingerprint()


def _hidden(entry: dict[str, Any], mass_fitted: bool) -> dict[str, Any]:
    if entry.get("effect") == MASS and mass_fitted:
        what = ("a payload of any size cannot be seen in this record: the model's mass was "
                "fitted on this very record and holds it")
    elif entry.get("effect") == OFFSET:
        what = ("a constant force of any size cannot be seen in this record: the model's "
                "per-direction friction levels were fitted on this very record and hold it")
    else:
        return entry
    return {**entry, "smallest": None, "experiment": U.words(_AGAIN), "text": U.words(what)}


def say_fitted_here(dg: Any, mass_fitted: bool) -> Any:
    """The diagnosis ``dg`` of a model on the record it was fitted on: its limits for a
    payload and a constant force made infinite, and a note saying why."""
    dg.could_not_reveal = [_hidden(e, mass_fitted) for e in dg.could_not_reveal or []]
    dg.notes.append(U.words(
        "This model was fitted on this very record (its file's identification names the "
        "record): what the fit took into the base cannot come back out as a finding here, "
        + ("a payload into the fitted mass, " if mass_fitted else "")
        + "a constant force into the per-direction friction levels, whatever their size. "
        f"To see them, {_AGAIN}."))
    return dg
