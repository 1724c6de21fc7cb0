""":func:`diagnose` and :func:`fit_inverse_dynamics` on the NumPy twin of the
inverse-dynamics kernel.

The diagnosis's orchestration (preparation, search, refit, evidence, wording) is shared
with :func:`lugre.diagnose`; every numeric kernel it calls comes from the reference:
the residual, model force, sensitivities and low-pass from
:class:`lugre.reference.InverseRecord` (twin of ``src/inverse``), the load behind a
resonance from :func:`lugre.reference.load_coupling`, the closed-loop comparison from
:func:`lugre.reference.simulate`.
"""

from __future__ import annotations

from typing import Any

__all__ = ["diagnose", "fit_inverse_dynamics", "fit_model"]


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
        As :func:`lugre.diagnosis.diagnose` (``backend`` is fixed to ``"reference"``).

    Returns
    -------
    Diagnosis
    """
    from . import diagnose as _diagnose

    kwargs["backend"] = "reference"
    return _diagnose(recording, model, **kwargs)


def fit_inverse_dynamics(recording: Any, *args: Any, **kwargs: Any) -> Any:
    """Twin of :func:`lugre.fit_inverse_dynamics` on the NumPy kernels.

    Parameters
    ----------
    recording : Recording, path or table with named columns
        With motion in both directions.
    *args, **kwargs
        As :func:`lugre.diagnosis.fit_inverse_dynamics` (``backend`` fixed to
        ``"reference"``).

    Returns
    -------
    Model
    """
    from . import fit_inverse_dynamics as _fit

    kwargs["backend"] = "reference"
    return _fit(recording, *args, **kwargs)


def fit_model(recording: Any, **kwargs: Any) -> Any:
    """Twin of :func:`lugre.fit_model` on the NumPy kernels (the base fit of
    ``lugre._reference_basefit``; slow: for checking on short records).

    Parameters
    ----------
    recording : Recording, path or table with named columns
        With motion in both directions.
    **kwargs
        As :func:`lugre.diagnosis.fit_model` (``backend`` fixed to ``"reference"``).

    Returns
    -------
    tuple
        ``(model, fit)``.
    """
    from . import fit_model as _fit

    kwargs["backend"] = "reference"
    return _fit(recording, **kwargs)
