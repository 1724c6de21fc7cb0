"""The entry points that take a recording as a file, a :class:`~lugre.io.Recording` or a
table with named columns, shared by :mod:`lugre` and its NumPy twin
:mod:`lugre.reference` (which passes its kernels as ``backend``)."""

from __future__ import annotations

from typing import Any

from .io import Recording
from .tabular import as_recording, table_columns

__all__ = ["diagnose", "evaluate", "fit_inverse_dynamics", "fit_model", "table_or_same"]


def table_or_same(recording: Any) -> Any:
    """A table with named columns as a :class:`Recording`; anything else unchanged (paths
    and recordings are read and checked where they are used)."""
    if (isinstance(recording, (Recording, str, bytes)) or hasattr(recording, "__fspath__")
            or table_columns(recording) is None):
        return recording
    return as_recording(recording)


def diagnose(recording: Any, model: Any, **kwargs: Any) -> Any:
    """:func:`lugre.diagnosis.diagnose` of a recording-like object (see
    :func:`lugre.diagnose`)."""
    from .checks import require_plausible
    from .diagnosis import diagnose as _diagnose

    # the recording is checked first thing by the diagnosis; the hold-out only at its
    # end, so it is checked here, before the work
    hold = kwargs.get("holdout")
    if hold is not None:
        kwargs["holdout"] = require_plausible(as_recording(hold, "holdout"))
    return _diagnose(as_recording(recording), model, **kwargs)


def evaluate(recording: Any, model: Any, **kwargs: Any) -> Any:
    """:func:`lugre.diagnosis.evaluate` of a recording-like object."""
    from .diagnosis import evaluate as _evaluate

    return _evaluate(as_recording(recording), model, **kwargs)  # checked by the diagnosis


def fit_inverse_dynamics(recording: Any, *args: Any, **kwargs: Any) -> Any:
    """:func:`lugre.diagnosis.fit_inverse_dynamics`, a table taken as a recording."""
    from .diagnosis import fit_inverse_dynamics as _fit

    return _fit(table_or_same(recording), *args, **kwargs)


def fit_model(recording: Any, **kwargs: Any) -> Any:
    """:func:`lugre.diagnosis.fit_model`, a table taken as a recording."""
    from .diagnosis import fit_model as _fit

    return _fit(table_or_same(recording), **kwargs)
