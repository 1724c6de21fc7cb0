"""Type stubs of the compiled core (``lugre._core``); use the ``lugre`` package instead."""

import numpy as np
import numpy.typing as npt

__all__ = [
    "__version__",
    "check_model",
    "friction_force",
    "num_threads",
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
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
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
