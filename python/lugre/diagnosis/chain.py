"""The chain from a user's own recording: the base identified at the record's limit,
the effects the user names diagnosed against it, and the base refitted with them held."""

from __future__ import annotations

import warnings
from dataclasses import replace
from typing import Any

from ..exceptions import InputError
from ..model import Model
from ..vocabulary import DRAG, GRAVITY, NAMES, SPRING, kind
from . import residual as R
from .basefit import fit_base, identify
from .core import diagnose
from .evaluation import as_recording, evaluate
from .fitreport import identification
from .options import IDENTIFY_TOLERANCE

__all__ = ["fit_model"]


def fit_model(
    recording: Any,
    *,
    effects: list[str] | None = None,
    mass: float | None = None,
    force_constant: float = 1.0,
    cutoff_hz: float | None = None,
    screw_lead: float | None = None,
    backend: Any = "core",
) -> tuple[Model, Any]:
    """Identify an axis model from a recording, with extra physics when asked.

    The base (mass and per-direction LuGre friction) by
    :func:`lugre.diagnosis.basefit.identify`: the robust inverse-dynamics levels as the
    start of a robust Levenberg-Marquardt fit of every base parameter on the residual
    with the bristle state driven by the measured motion, from starts over the Stribeck
    hump and the bristle stiffness, with each parameter's interval from its profile.
    Then, when ``effects`` names some, the diagnosis searches those with the base
    re-estimated alongside; an effect the record does not support is left out and said
    so in the returned diagnosis (its trials and notes).

    Parameters
    ----------
    recording : Recording or path
        With motion in both directions.
    effects : list of str, optional
        Effects to identify with the base (e.g. ``["resonance", "drag"]``); default none.
    mass : float, optional
        Known moving mass [kg]; estimated otherwise.
    force_constant : float, default 1.0
        K_F [N/A] (needed when the recording holds the current).
    cutoff_hz : float, optional
        Low-pass cut-off (default ``fs/25``).
    screw_lead : float, optional
        Ball-screw lead [m] (tried for cogging).
    backend : "core" or module, default "core"
        The kernels (:func:`lugre.diagnosis.residual.kernels`) of the compiled core, or
        the NumPy twins (:mod:`lugre.reference.kernels`).

    Returns
    -------
    model : Model
        The identified model (base and the effects the record supports).
    fit : BaseFitResult
        The base fit: intervals, what the record determines, the residual against its
        noise floor; ``fit.diagnosis`` the search for ``effects`` (None without).
    """
    wanted = list(effects or [])
    for e in wanted:
        if e not in NAMES:
            raise InputError.at("effects", f'unknown effect "{e}": use some of '
                                f'{", ".join(sorted(NAMES))}')
    # one candidate a kind (the timing's form is chosen by the record)
    wanted = list(dict.fromkeys(kind(e) for e in wanted))
    rec = as_recording(recording)
    res = identify(rec, mass=mass, force_constant=force_constant, cutoff_hz=cutoff_hz,
                   backend=backend)
    # (the fit holds a joint's weight, a spring or a drag already when the record
    # needs one: fitted beside the base, which cannot be had without them, and set
    # aside for the diagnosis to name, unless asked for)
    held = {e["effect"] for e in res.model.effects} & set(LOADS)
    res = _set_aside(res, held - set(wanted))
    wanted = [e for e in wanted if e not in held]
    if not wanted:
        return _identified(rec, res.model, res, cutoff_hz, backend), res
    dg = diagnose(rec, res.model, candidates=wanted, free_mass=mass is None,
                  cutoff_hz=cutoff_hz, screw_lead=screw_lead, closed_loop=False,
                  tolerance=IDENTIFY_TOLERANCE, backend=backend)
    model = dg.augmented_model()
    if mass is not None:
        model = model.with_axis(mass=float(mass))
    if not dg.findings:
        return (_identified(rec, res.model, res, cutoff_hz, backend),
                replace(res, diagnosis=dg))
    # the base fitted again with the effects found held in it: the search refits the
    # levels only near the base it was given, which the effects had pulled astray (a
    # cogging on the slow samples doubles a hump)

    sig = R.prepare(rec, model, cutoff_hz=cutoff_hz, backend=backend)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        final = fit_base(sig, model, free_mass=mass is None)  # (model: the first start)
    return (_identified(rec, final.model, final, cutoff_hz, backend),
            replace(final, diagnosis=dg))


def _identified(rec: Any, model: Model, fit: Any, cutoff_hz: float | None,
                backend: Any) -> Model:
    """The model with its ``identification`` section (the fit against the record's
    noise floor, every parameter with its interval): the file says that ``lugre fit``
    made it, so that ``diagnose`` takes its base as an estimate from the record."""
    nrmse = evaluate(rec, model, cutoff_hz=cutoff_hz, backend=backend)["nrmse_force"]
    ident = identification(fit, model, nrmse)
    return model.replace(identification={**ident, "record": as_recording(rec).fingerprint()})


#: Loads the fit's linear start takes up beside the base when the record needs them.
LOADS = (GRAVITY, SPRING, DRAG)


def _set_aside(res: Any, effects: set[str]) -> Any:
    """The fit without the ``effects`` its linear start took up beside the base (a
    joint's weight, a spring, a drag, which the friction levels and the mass would
    otherwise absorb), unless asked for: ``lugre diagnose`` names them with their evidence and
    the augmented model holds them."""
    out = [e for e in res.model.effects if e["effect"] in effects]
    if not out:
        return res
    rest = [e for e in res.model.effects if e["effect"] not in effects]
    return replace(res, model=res.model.replace(effects=rest), set_aside=tuple(out))
