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

from . import _entry
from ._entry import table_or_same
from ._native import friction_force, load_coupling, simulate, simulate_batch, stribeck
from ._result import CouplingResult, SimResult
from ._version import __version__ as __version__
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
    return _entry.diagnose(recording, model, **kwargs)


def evaluate(recording: Any, model: Any, **kwargs: Any) -> Any:
    """The inverse-dynamics force residual of ``model`` on ``recording`` (``rms_force``
    [N], ``nrmse_force``, ...). ``recording`` is taken as by :func:`diagnose`; see
    :func:`lugre.diagnosis.evaluate`."""
    return _entry.evaluate(recording, model, **kwargs)


def fit_inverse_dynamics(recording: Any, *args: Any, **kwargs: Any) -> Any:
    """Mass and LuGre friction by robust inverse dynamics; ``recording`` may be a table
    with named columns. See :func:`lugre.diagnosis.fit_inverse_dynamics`."""
    return _entry.fit_inverse_dynamics(recording, *args, **kwargs)


def fit_model(recording: Any, **kwargs: Any) -> Any:
    """Identify an axis model from a recording: ``(model, fit)``, the fit with every
    parameter's interval, what the record leaves open and how far the fit is from the
    record's noise floor; ``recording`` may be a table with named columns. See
    :func:`lugre.diagnosis.fit_model`."""
    return _entry.fit_model(recording, **kwargs)


def fit_dynamic(recording: Any, *args: Any, **kwargs: Any) -> Any:
    """sigma0 and sigma1 from a closed-loop record; ``recording`` may be a table with
    named columns. See :func:`lugre.identify.fit_dynamic`."""
    from .identify import fit_dynamic as _fit

    return _fit(table_or_same(recording), *args, **kwargs)


def steady_state_points(recording: Any, *args: Any, **kwargs: Any) -> Any:
    """Steady-state (v, F) points of a plateau record; ``recording`` may be a table with
    named columns. See :func:`lugre.identify.steady_state_points`."""
    from .identify import steady_state_points as _points

    return _points(table_or_same(recording), *args, **kwargs)


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
