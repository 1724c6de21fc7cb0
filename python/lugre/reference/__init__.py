"""The NumPy reference: the algorithms of ``docs/DESIGN.md`` in plain Python.

Same names, signatures, results and errors as the Rust-backed :mod:`lugre` API, written
with NumPy alone (no SciPy) as loops over Python floats that repeat the core's
(``src/friction/mod.rs``, ``src/servo/sim.rs``, ``src/estimate/``) operations in the
same order, so that the two agree bit for bit. It is slow (a few microseconds per plant
step) and meant for checking the core and for reading. Never calls :mod:`lugre._core`.

- kernels: :func:`stribeck`, :func:`friction_force` (``friction``), :func:`simulate`,
  :func:`simulate_batch` (``servo``, the plant in ``plant``), :func:`load_coupling`
  (``coupling``), the input checks in ``checks``;
- estimators, imported on first use: :func:`fit_static` (``static``, its start values
  in ``static_starts``), :func:`fit_dynamic` (``dynamic``), built on Nelder-Mead as
  the core runs it (``nm``) and the robust weights (``robust``); their results are the
  facade's :class:`StaticFit` and :class:`DynamicFit`; :func:`steady_state_points`
  (``plateaus``), the plateau detection, returns the facade's
  :class:`~lugre.identify.SteadyStatePoints`;
- :func:`evaluate`, :func:`diagnose`, :func:`fit_inverse_dynamics` and
  :func:`fit_model` (``entry``) run the diagnosis's orchestration on the twin's kernels
  (:mod:`lugre.reference.kernels`): the residual from :class:`InverseRecord`, the NumPy
  twin of the inverse-dynamics kernel (``inverse``, its base fit in ``basefit``), and
  :func:`irls_linear_grid` (``linear``, with :func:`irls_linear`), the robust linear
  fit of the inverse dynamics;
- :func:`load_model` and :func:`save_model` are the facade's own (Python) functions.

Examples
--------
>>> from lugre import reference
>>> from lugre.model import Model
>>> m = Model.paper()
>>> float(reference.stribeck([0.01], m)[0])  # doctest: +ELLIPSIS
43.613...
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .._result import CouplingResult, SimResult
from ..model import load_model, save_model
from .coupling import load_coupling
from .friction import friction_force, stribeck
from .inverse import InverseRecord
from .servo import simulate, simulate_batch

if TYPE_CHECKING:  # pragma: no cover
    from .dynamic import DynamicFit, fit_dynamic
    from .entry import diagnose, evaluate, fit_inverse_dynamics, fit_model
    from .plateaus import steady_state_points
    from .static import StaticFit, fit_static

__all__ = [
    "CouplingResult",
    "DynamicFit",
    "InverseRecord",
    "SimResult",
    "StaticFit",
    "diagnose",
    "evaluate",
    "fit_dynamic",
    "fit_inverse_dynamics",
    "fit_model",
    "fit_static",
    "friction_force",
    "load_coupling",
    "load_model",
    "save_model",
    "simulate",
    "simulate_batch",
    "steady_state_points",
    "stribeck",
]

#: Names imported on first use, with the module that defines them: the estimators and
#: the diagnosis need SciPy, which ``import lugre.reference`` does not load.
_LAZY = {
    "DirectionFit": ".static",
    "StaticFit": ".static",
    "fit_static": ".static",
    "DynamicFit": ".dynamic",
    "fit_dynamic": ".dynamic",
    "evaluate": ".entry",
    "diagnose": ".entry",
    "fit_inverse_dynamics": ".entry",
    "fit_model": ".entry",
    "steady_state_points": ".plateaus",
    # the kernels the diagnosis takes (lugre.reference.kernels: twin of lugre._native)
    "kernels": ".kernels",
    # the periodogram of the diagnosis (twin of lugre._native.position_sums)
    "position_sums": ".inverse",
    # the robust linear fit of the inverse dynamics (twins of lugre._native.irls_linear*)
    "irls_linear": ".linear",
    "irls_linear_grid": ".linear",
}


def __getattr__(name: str) -> Any:
    mod = _LAZY.get(name)
    if mod is None:
        raise AttributeError(f"module 'lugre.reference' has no attribute {name!r}")
    from importlib import import_module

    module = import_module(mod, __name__)
    value = module if name == "kernels" else getattr(module, name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
