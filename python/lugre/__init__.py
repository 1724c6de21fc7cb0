"""lugre: LuGre friction, servo-axis simulation and robust friction identification.

The public API runs on the Rust core; :mod:`lugre.reference` offers the same functions
written in NumPy alone, for checking and reading.

>>> import lugre
>>> m = lugre.Model.paper()
>>> r = lugre.simulate(m, t, x_ref)          # doctest: +SKIP

``import lugre`` stays light (NumPy and the core only): the identification and the
diagnosis, which need SciPy, and the figures, which need matplotlib, are imported the
first time one of their names is used.
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

from ._native import friction_force, load_coupling, simulate, simulate_batch, stribeck
from ._result import CouplingResult, SimResult
from .exceptions import (
    ConvergenceWarning,
    DataError,
    FileFormatError,
    IdentifiabilityWarning,
    InputError,
    LugreError,
    LugreWarning,
    ModelError,
    ParameterError,
    PassivityWarning,
    UnitsWarning,
)
from .io import Recording, read_points, read_recording, write_recording
from .model import Model, load_model, save_model

if TYPE_CHECKING:  # pragma: no cover
    from .diagnosis import Diagnosis
    from .identify import DynamicFit, StaticFit, SteadyStatePoints, fit_static

__version__ = "0.1.0"

#: Names imported on first use, with the module that defines them.
_LAZY = {
    "Diagnosis": ".diagnosis",
    "DynamicFit": ".identify",
    "StaticFit": ".identify",
    "SteadyStatePoints": ".identify",
    "fit_static": ".identify",
    "stribeck_determinacy": ".identify",
    "StaticDesign": ".design",
    "design_static": ".design",
}


def __getattr__(name: str) -> Any:
    mod = _LAZY.get(name)
    if mod is None:
        raise AttributeError(f"module 'lugre' has no attribute {name!r}")
    value = getattr(import_module(mod, __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))


def diagnose(recording: Any, model: Any, **kwargs: Any) -> Any:
    """Diagnose the mismatch between ``model`` and ``recording``.

    ``recording`` may be a :class:`Recording`, a file name, or a table with named columns
    (a pandas DataFrame, a dict of arrays, a NumPy structured array). A recording whose
    sampling has gaps or whose units look wrong is refused with the fix
    (:func:`lugre.checks.require_plausible`). See :func:`lugre.diagnosis.diagnose` for
    the options and the result.
    """
    from .checks import require_plausible
    from .diagnosis import diagnose as _diagnose
    from .tabular import as_recording

    # the recording is checked first thing by the diagnosis; the hold-out only at its
    # end, so it is checked here, before the work
    hold = kwargs.get("holdout")
    if hold is not None:
        kwargs["holdout"] = require_plausible(as_recording(hold, "holdout"))
    return _diagnose(as_recording(recording), model, **kwargs)


def evaluate(recording: Any, model: Any, **kwargs: Any) -> Any:
    """The inverse-dynamics force residual of ``model`` on ``recording`` (``rms_force``
    [N], ``nrmse_force``, ...). ``recording`` is taken as by :func:`diagnose`; see
    :func:`lugre.diagnosis.evaluate`."""
    from .diagnosis import evaluate as _evaluate
    from .tabular import as_recording

    return _evaluate(as_recording(recording), model, **kwargs)  # checked by the diagnosis


def _table_or_same(recording: Any) -> Any:
    """A table with named columns as a :class:`Recording`; anything else unchanged (paths
    and recordings are read and checked where they are used)."""
    from .tabular import as_recording, table_columns

    if (isinstance(recording, (Recording, str, bytes)) or hasattr(recording, "__fspath__")
            or table_columns(recording) is None):
        return recording
    return as_recording(recording)


def fit_inverse_dynamics(recording: Any, *args: Any, **kwargs: Any) -> Any:
    """Mass and LuGre friction by robust inverse dynamics; ``recording`` may be a table
    with named columns. See :func:`lugre.diagnosis.fit_inverse_dynamics`."""
    from .diagnosis import fit_inverse_dynamics as _fit

    return _fit(_table_or_same(recording), *args, **kwargs)


def fit_model(recording: Any, **kwargs: Any) -> Any:
    """Identify an axis model from a recording: ``(model, fit)``, the fit with every
    parameter's interval, what the record leaves open and how far the fit is from the
    record's noise floor; ``recording`` may be a table with named columns. See
    :func:`lugre.diagnosis.fit_model`."""
    from .diagnosis import fit_model as _fit

    return _fit(_table_or_same(recording), **kwargs)


def fit_dynamic(recording: Any, *args: Any, **kwargs: Any) -> Any:
    """sigma0 and sigma1 from a closed-loop record; ``recording`` may be a table with
    named columns. See :func:`lugre.identify.fit_dynamic`."""
    from .identify import fit_dynamic as _fit

    return _fit(_table_or_same(recording), *args, **kwargs)


def steady_state_points(recording: Any, *args: Any, **kwargs: Any) -> Any:
    """Steady-state (v, F) points of a plateau record; ``recording`` may be a table with
    named columns. See :func:`lugre.identify.steady_state_points`."""
    from .identify import steady_state_points as _points

    return _points(_table_or_same(recording), *args, **kwargs)


__all__ = [
    "ConvergenceWarning",
    "CouplingResult",
    "DataError",
    "Diagnosis",
    "DynamicFit",
    "FileFormatError",
    "IdentifiabilityWarning",
    "InputError",
    "LugreError",
    "LugreWarning",
    "Model",
    "ModelError",
    "ParameterError",
    "PassivityWarning",
    "Recording",
    "SimResult",
    "StaticDesign",
    "StaticFit",
    "SteadyStatePoints",
    "UnitsWarning",
    "design_static",
    "diagnose",
    "evaluate",
    "fit_dynamic",
    "fit_inverse_dynamics",
    "fit_model",
    "fit_static",
    "friction_force",
    "load_coupling",
    "load_model",
    "read_points",
    "read_recording",
    "save_model",
    "simulate",
    "simulate_batch",
    "steady_state_points",
    "stribeck",
    "stribeck_determinacy",
    "write_recording",
]
