"""Type stubs of the compiled core (``lugre._core``); use the ``lugre`` package instead."""

from typing import Any, TypeAlias, final

import numpy as np
import numpy.typing as npt

__all__ = [
    "InverseRecord",
    "Model",
    "SimulationResult",
    "__version__",
    "check_model",
    "fit_dynamic_record",
    "fit_static_points",
    "friction_force",
    "irls_linear",
    "irls_linear_grid",
    "load_coupling",
    "num_threads",
    "plateaus",
    "position_sums",
    "simulate",
    "simulate_batch",
    "stribeck",
]

__version__: str

@final
class Model:
    def __new__(cls, model_json: str) -> Model: ...
    def is_passive(self) -> bool: ...

# a _core.Model, the model's JSON text, or a lugre.Model (its cached _core.Model)
_ModelArg: TypeAlias = Model | str | Any

@final
class InverseRecord:
    def __new__(
        cls,
        t: npt.NDArray[np.float64],
        x: npt.NDArray[np.float64],
        x_drive: npt.NDArray[np.float64],
        v: npt.NDArray[np.float64],
        a: npt.NDArray[np.float64],
        fm: npt.NDArray[np.float64],
        fm_f: npt.NDArray[np.float64],
        dt: float,
        sos: npt.NDArray[np.float64] | None = None,
        padlen: int = 0,
    ) -> InverseRecord: ...
    def __len__(self) -> int: ...
    def filt(self, y: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
    def friction_scale(self, model: _ModelArg) -> npt.NDArray[np.float64] | None: ...
    def base_friction(self, model: _ModelArg) -> npt.NDArray[np.float64]: ...
    def effect_force(self, model: _ModelArg) -> npt.NDArray[np.float64]: ...
    def coupling_force(self, model: _ModelArg) -> npt.NDArray[np.float64]: ...
    def model_force(self, model: _ModelArg) -> npt.NDArray[np.float64]: ...
    def motor_force(self, model: _ModelArg) -> npt.NDArray[np.float64]: ...
    def residual(self, model: _ModelArg) -> npt.NDArray[np.float64]: ...
    def residuals(self, models: list[_ModelArg]) -> npt.NDArray[np.float64]: ...
    def base_sensitivities(
        self, model: _ModelArg, names: list[str]
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], list[bool]]: ...

_F64: TypeAlias = npt.NDArray[np.float64]

# Results: frozen, every attribute read-only; no constructor (the core makes them).
@final
class SimulationResult:
    @property
    def x(self) -> _F64: ...
    @property
    def v(self) -> _F64: ...
    @property
    def z(self) -> _F64: ...
    @property
    def i(self) -> _F64: ...
    @property
    def friction(self) -> _F64: ...
    @property
    def force(self) -> _F64: ...

def check_model(model: _ModelArg) -> bool: ...
def stribeck(v: npt.NDArray[np.float64], model: _ModelArg) -> npt.NDArray[np.float64]: ...
def friction_force(
    v: npt.NDArray[np.float64],
    dt: npt.NDArray[np.float64],
    model: _ModelArg,
    z0: float = 0.0,
    return_z: bool = False,
    scale: npt.NDArray[np.float64] | None = None,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def load_coupling(
    x: npt.NDArray[np.float64],
    v: npt.NDArray[np.float64],
    dt: float,
    model: _ModelArg,
    scale: npt.NDArray[np.float64] | None = None,
    extra: npt.NDArray[np.float64] | None = None,
    z0: float = 0.0,
    substeps: int = 1,
) -> tuple[
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
]: ...
def simulate(
    model: _ModelArg,
    t: npt.NDArray[np.float64],
    drive_kind: str,
    drive: npt.NDArray[np.float64],
    integrator: str = "exact",
    substeps: int = 1,
    z0: float = 0.0,
    x0: float | None = None,
    v0: float = 0.0,
) -> SimulationResult: ...
def simulate_batch(
    models: list[_ModelArg],
    t: npt.NDArray[np.float64],
    drive_kind: str,
    drive: npt.NDArray[np.float64],
    integrator: str = "exact",
    substeps: int = 1,
    z0: float = 0.0,
    x0: float | None = None,
    v0: float = 0.0,
) -> list[SimulationResult]: ...
def num_threads() -> int: ...
def fit_static_points(
    v: npt.NDArray[np.float64],
    f: npt.NDArray[np.float64],
    weighting: str = "igg",
    max_iter: int = 20,
    scale_floor: float = 0.0,
    max_start_points: int = 400,
) -> dict[str, Any]: ...
def plateaus(
    t: npt.NDArray[np.float64],
    x: npt.NDArray[np.float64],
    force: npt.NDArray[np.float64],
    v_ref: npt.NDArray[np.float64] | None = None,
    settle_fraction: float = 0.3,
    velocity_tolerance: float = 0.02,
    window: int = 0,
    min_samples: int = 20,
    chunks: int = 1,
) -> dict[str, Any]: ...
def fit_dynamic_record(
    model: _ModelArg,
    t: npt.NDArray[np.float64],
    x_ref: npt.NDArray[np.float64],
    x: npt.NDArray[np.float64],
    weighting: str = "igg",
    c1: float = 1.0,
    c2: float = 0.0,
    sigma0_start: float | None = None,
    sigma1_start: float | None = None,
    grid: bool = True,
    max_iter: int = 20,
    scale_floor: float = 0.0,
    substeps: int = 1,
    integrator: str = "exact",
) -> dict[str, Any]: ...

def position_sums(
    x: npt.NDArray[np.float64],
    r: npt.NDArray[np.float64],
    k0: float,
    dk: float,
    n: int,
    squares: bool = False,
) -> list[npt.NDArray[np.float64]]: ...
def irls_linear(
    x: npt.NDArray[np.float64],
    y: npt.NDArray[np.float64],
    weighting: str = "igg",
    rounds: int = 8,
) -> dict[str, Any]: ...
def irls_linear_grid(
    x: npt.NDArray[np.float64],
    extras: list[npt.NDArray[np.float64]],
    y: npt.NDArray[np.float64],
    weighting: str = "igg",
    rounds: int = 8,
    ratio: float = 0.98,
) -> dict[str, Any]: ...
