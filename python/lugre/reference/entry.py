""":func:`diagnose`, :func:`evaluate`, :func:`fit_inverse_dynamics` and :func:`fit_model` on
the NumPy twin of the inverse-dynamics kernel.

The diagnosis's orchestration (preparation, search, refit, evidence, wording) is shared
with :func:`lugre.diagnose`; every numeric kernel it calls comes from the reference:
the residual, model force, sensitivities and low-pass from
:class:`lugre.reference.InverseRecord` (twin of ``src/inverse``), the load behind a
resonance from :func:`lugre.reference.load_coupling`, the closed-loop comparison from
:func:`lugre.reference.simulate`.
"""

from __future__ import annotations

from typing import Any

from .. import _entry
from . import kernels

__all__ = ["diagnose", "evaluate", "fit_inverse_dynamics", "fit_model"]


def diagnose(recording: Any, model: Any, **kwargs: Any) -> Any:
    """Twin of :func:`lugre.diagnose` (same parameters, result and errors) on the NumPy
    kernels.

    Parameters
    ----------
    recording : Recording, path or table with named columns
        The recording to diagnose.
    model : Model, dict or path
        The model believed to describe the axis.
    **kwargs
        As :func:`lugre.diagnosis.diagnose` (``backend`` is fixed to
        :mod:`lugre.reference.kernels`).

    Returns
    -------
    Diagnosis
    """
    kwargs["backend"] = kernels
    return _entry.diagnose(recording, model, **kwargs)


def fit_inverse_dynamics(recording: Any, *args: Any, **kwargs: Any) -> Any:
    """Twin of :func:`lugre.fit_inverse_dynamics` on the NumPy kernels.

    Parameters
    ----------
    recording : Recording, path or table with named columns
        With motion in both directions.
    *args, **kwargs
        As :func:`lugre.diagnosis.fit_inverse_dynamics` (``backend`` fixed to
        :mod:`lugre.reference.kernels`).

    Returns
    -------
    Model
    """
    kwargs["backend"] = kernels
    return _entry.fit_inverse_dynamics(recording, *args, **kwargs)


def fit_model(recording: Any, **kwargs: Any) -> Any:
    """Twin of :func:`lugre.fit_model` on the NumPy kernels (the base fit of
    ``lugre._reference_basefit``; slow: for checking on short records).

    Parameters
    ----------
    recording : Recording, path or table with named columns
        With motion in both directions.
    **kwargs
        As :func:`lugre.diagnosis.fit_model` (``backend`` fixed to
        :mod:`lugre.reference.kernels`).

    Returns
    -------
    tuple
        ``(model, fit)``.
    """
    kwargs["backend"] = kernels
    return _entry.fit_model(recording, **kwargs)


def evaluate(recording: Any, model: Any, *, cutoff_hz: float | None = None) -> dict[str, Any]:
    """The inverse-dynamics force residual of ``model`` on ``recording``, on the NumPy
    kernel: twin of :func:`lugre.evaluate` (same parameters, result and errors).

    Parameters
    ----------
    recording : Recording, path or table with named columns
        The recording.
    model : Model, dict or path
        The model (its effects included).
    cutoff_hz : float, optional
        Low-pass cut-off (default ``fs/25``).

    Returns
    -------
    dict
        ``rms_force`` [N], ``nrmse_force``, ``noise_floor`` [N], ``samples``,
        ``cutoff_hz``.
    """
    return _entry.evaluate(recording, model, cutoff_hz=cutoff_hz, backend=kernels)
