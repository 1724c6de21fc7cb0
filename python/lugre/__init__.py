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

from ._native import friction_force, simulate, simulate_batch, stribeck
from ._result import SimResult
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
    from .diagnosis import Diagnosis, fit_inverse_dynamics
    from .identify import (
        DynamicFit,
        StaticFit,
        SteadyStatePoints,
        fit_dynamic,
        fit_static,
        steady_state_points,
    )

__version__ = "0.1.0"

#: Names imported on first use, with the module that defines them.
_LAZY = {
    "Diagnosis": ".diagnosis",
    "fit_inverse_dynamics": ".diagnosis",
    "DynamicFit": ".identify",
    "StaticFit": ".identify",
    "SteadyStatePoints": ".identify",
    "fit_dynamic": ".identify",
    "fit_static": ".identify",
    "steady_state_points": ".identify",
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

    rec = require_plausible(as_recording(recording))
    hold = kwargs.get("holdout")
    if hold is not None:
        kwargs["holdout"] = require_plausible(as_recording(hold, "holdout"))
    return _diagnose(rec, model, **kwargs)


def evaluate(recording: Any, model: Any, **kwargs: Any) -> Any:
    """The inverse-dynamics force residual of ``model`` on ``recording`` (``rms_force``
    [N], ``nrmse_force``, ...). ``recording`` is taken as by :func:`diagnose`; see
    :func:`lugre.diagnosis.evaluate`."""
    from .checks import require_plausible
    from .diagnosis import evaluate as _evaluate
    from .tabular import as_recording

    return _evaluate(require_plausible(as_recording(recording)), model, **kwargs)


__all__ = [
    "ConvergenceWarning",
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
    "StaticFit",
    "SteadyStatePoints",
    "UnitsWarning",
    "diagnose",
    "evaluate",
    "fit_dynamic",
    "fit_inverse_dynamics",
    "fit_static",
    "friction_force",
    "load_model",
    "read_points",
    "read_recording",
    "save_model",
    "simulate",
    "simulate_batch",
    "steady_state_points",
    "stribeck",
    "write_recording",
]
