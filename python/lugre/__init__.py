"""lugre: LuGre friction, servo-axis simulation and robust friction identification.

The public API runs on the Rust core; :mod:`lugre.reference` offers the same functions
written in NumPy alone, for checking and reading.

>>> import lugre
>>> m = lugre.Model.paper()
>>> r = lugre.simulate(m, t, x_ref)          # doctest: +SKIP
"""

from __future__ import annotations

from ._native import friction_force, simulate, simulate_batch, stribeck
from ._result import SimResult
from .design import StaticDesign, design_static
from .diagnosis import Diagnosis, diagnose, evaluate, fit_inverse_dynamics
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
from .identify import (
    DynamicFit,
    StaticFit,
    SteadyStatePoints,
    fit_dynamic,
    fit_static,
    steady_state_points,
    stribeck_determinacy,
)
from .io import Recording, read_points, read_recording, write_recording
from .model import Model, load_model, save_model

__version__ = "0.1.0"

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
    "StaticDesign",
    "StaticFit",
    "SteadyStatePoints",
    "UnitsWarning",
    "design_static",
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
    "stribeck_determinacy",
    "write_recording",
]
