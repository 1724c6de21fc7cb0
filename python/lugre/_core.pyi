"""Type stubs of the compiled core (``lugre._core``); use the ``lugre`` package instead."""

from typing import Any, TypeAlias, final

import numpy as np
import numpy.typing as npt

__all__ = [
    "EFFECT_NAMES",
    "DirectionFitResult",
    "DynamicFitResult",
    "GridFitResult",
    "InverseRecord",
    "LinearFitResult",
    "Model",
    "PlateauResult",
    "SimulationResult",
    "StaticFitResult",
    "__version__",
    "check_model",
    "filtfilt",
    "fit_dynamic_record",
    "fit_static_points",
    "friction_force",
    "irls_linear",
    "irls_linear_grid",
    "load_coupling",
    "moving_median",
    "num_threads",
    "plateaus",
    "position_sums",
    "simulate",
    "simulate_batch",
    "stribeck",
]

__version__: str
#: The effect names of the model file, in the order of the CONTRACT.
EFFECT_NAMES: tuple[str, ...]

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
    def filt_columns(self, y: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...
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
    def fit_base(
        self, starts: list[_ModelArg], mask: list[bool], names: list[str],
        max_iter: int = 60, keep: int = 3, scouts: int = 12,
        weighting: str = "huber", tol: float = 1e-6, information: bool = True,
    ) -> dict[str, Any]: ...

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

@final
class DirectionFitResult:
    @property
    def fc(self) -> float: ...
    @property
    def fs(self) -> float: ...
    @property
    def sigma2(self) -> float: ...
    @property
    def vs(self) -> float: ...
    @property
    def std_err(self) -> list[float]: ...
    @property
    def cov(self) -> list[float]: ...
    @property
    def ci_low(self) -> list[float]: ...
    @property
    def ci_high(self) -> list[float]: ...
    @property
    def indices(self) -> list[int]: ...
    @property
    def weights(self) -> _F64: ...
    @property
    def residuals(self) -> _F64: ...
    @property
    def scale(self) -> float: ...
    @property
    def sigma(self) -> float: ...
    @property
    def iterations(self) -> int: ...
    @property
    def converged(self) -> bool: ...
    @property
    def evaluations(self) -> int: ...

@final
class StaticFitResult:
    @property
    def positive(self) -> DirectionFitResult: ...
    @property
    def negative(self) -> DirectionFitResult: ...
    @property
    def weights(self) -> _F64: ...
    @property
    def rejected(self) -> list[int]: ...
    @property
    def n_zero_speed(self) -> int: ...
    @property
    def weighting(self) -> str: ...
    @property
    def notes(self) -> list[str]: ...

@final
class PlateauResult:
    @property
    def v(self) -> _F64: ...
    @property
    def F(self) -> _F64: ...
    @property
    def F_std(self) -> _F64: ...
    @property
    def n_samples(self) -> list[int]: ...
    @property
    def plateau(self) -> list[int]: ...
    @property
    def segment_start(self) -> list[int]: ...
    @property
    def segment_end(self) -> list[int]: ...
    @property
    def segment_velocity(self) -> list[float]: ...
    @property
    def segment_first_used(self) -> list[int]: ...
    @property
    def segment_settled(self) -> list[bool]: ...
    @property
    def used(self) -> list[bool]: ...
    @property
    def notes(self) -> list[str]: ...

@final
class DynamicFitResult:
    @property
    def sigma0(self) -> float: ...
    @property
    def sigma1(self) -> float: ...
    @property
    def std_err(self) -> list[float]: ...
    @property
    def ci_low(self) -> list[float]: ...
    @property
    def ci_high(self) -> list[float]: ...
    @property
    def rel_ci_half_width(self) -> list[float]: ...
    @property
    def identifiable(self) -> list[bool]: ...
    @property
    def correlation(self) -> float: ...
    @property
    def residual_autocorrelation(self) -> float: ...
    @property
    def notes(self) -> list[str]: ...
    @property
    def residuals(self) -> _F64: ...
    @property
    def weights(self) -> _F64: ...
    @property
    def rms_error(self) -> float: ...
    @property
    def max_error(self) -> float: ...
    @property
    def objective(self) -> float: ...
    @property
    def scale(self) -> float: ...
    @property
    def iterations(self) -> int: ...
    @property
    def evaluations(self) -> int: ...
    @property
    def converged(self) -> bool: ...

@final
class LinearFitResult:
    @property
    def coef(self) -> _F64: ...
    @property
    def weights(self) -> _F64: ...
    @property
    def residuals(self) -> _F64: ...
    @property
    def sse(self) -> float: ...
    @property
    def scale(self) -> float: ...

@final
class GridFitResult:
    @property
    def chosen(self) -> int | None: ...
    @property
    def fit(self) -> LinearFitResult: ...
    @property
    def base_sse(self) -> float: ...
    @property
    def sse(self) -> _F64: ...

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
) -> StaticFitResult: ...
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
) -> PlateauResult: ...
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
) -> DynamicFitResult: ...

def filtfilt(
    y: npt.NDArray[np.float64],
    sos: npt.NDArray[np.float64],
    padlen: int,
) -> npt.NDArray[np.float64]: ...
def moving_median(y: npt.NDArray[np.float64], size: int) -> npt.NDArray[np.float64]: ...
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
) -> LinearFitResult: ...
def irls_linear_grid(
    x: npt.NDArray[np.float64],
    extras: list[npt.NDArray[np.float64]],
    y: npt.NDArray[np.float64],
    weighting: str = "igg",
    rounds: int = 8,
    ratio: float = 0.98,
) -> GridFitResult: ...
