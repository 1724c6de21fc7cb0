""":func:`evaluate` on the NumPy twin of the inverse-dynamics kernel.

The same pipeline as :func:`lugre.evaluate` (the diagnosis's preparation of the record:
the spike filter, the zero-phase low-pass and the derivatives; then the residual
``K_F*i - m*a - F_friction - sum(F_effect)`` and its scores), with the residual computed
by :class:`lugre.reference.InverseRecord`, the NumPy twin of ``src/inverse``, instead of
the compiled kernel.
"""

from __future__ import annotations

from typing import Any

__all__ = ["evaluate"]


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
    from .diagnosis import evaluate as _evaluate
    from .tabular import as_recording

    return _evaluate(as_recording(recording), model, cutoff_hz=cutoff_hz, backend="reference")
