"""Type stubs of the compiled core (``lugre._core``); use the ``lugre`` package instead."""

from typing import Any

import numpy as np
import numpy.typing as npt

__all__ = [
    "__version__",
    "check_model",
    "fit_dynamic_record",
    "fit_static_points",
    "friction_force",
    "load_coupling",
    "num_threads",
    "plateaus",
    "simulate",
    "simulate_batch",
    "stribeck",
]

__version__: str

def check_model(model_json: str) -> bool: ...
def stribeck(v: npt.NDArray[np.float64], model_json: str) -> npt.NDArray[np.float64]: ...
def friction_force(
    v: npt.NDArray[np.float64],
    dt: npt.NDArray[np.float64],
    model_json: str,
    z0: float = 0.0,
    return_z: bool = False,
    scale: npt.NDArray[np.float64] | None = None,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def load_coupling(
    x: npt.NDArray[np.float64],
    v: npt.NDArray[np.float64],
    dt: float,
    model_json: str,
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
    model_json: str,
    t: npt.NDArray[np.float64],
    drive_kind: str,
    drive: npt.NDArray[np.float64],
    integrator: str = "exact",
    substeps: int = 1,
    z0: float = 0.0,
    x0: float | None = None,
    v0: float = 0.0,
) -> dict[str, npt.NDArray[np.float64]]: ...
def simulate_batch(
    model_jsons: list[str],
    t: npt.NDArray[np.float64],
    drive_kind: str,
    drive: npt.NDArray[np.float64],
    integrator: str = "exact",
    substeps: int = 1,
    z0: float = 0.0,
    x0: float | None = None,
    v0: float = 0.0,
) -> list[dict[str, npt.NDArray[np.float64]]]: ...
def num_threads() -> int: ...
def fit_static_points(
    v: npt.NDArray[np.float64],
    f: npt.NDArray[np.float64],
    weighting: str = "igg",
    max_iter: int = 20,
    scale_floor: float = 0.0,
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
    model_json: str,
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
