"""Signatures of the effects of the vocabulary, as regressors of the force residual.

Every candidate turns into columns ``X`` such that the residual of the model without
the effect is ``r ~ X @ beta`` (to first order), and ``beta`` maps back to the
effect's parameters. The base LuGre parameters enter the same way through the Jacobian
of the model force, so that effects and base parameters are
fitted jointly (:mod:`lugre.diagnosis.base`).

========================  =================================================================
candidate                 signature (column)
========================  =================================================================
``offset``                constant
``spring``                linear in position (and constant: ``x0``)
``mass``                  proportional to acceleration
``cogging``               ``sin``/``cos`` of ``2*pi*x/pitch``, pitch from a periodogram over
                          position
``position_friction``     hat functions of position times the Coulomb/static part of the
                          friction (the sign follows the direction of motion)
``drift``                 ``(1 - exp(-t/tau))`` times the Coulomb/static part, ``tau`` by the
                          held-out score of the joint fit over a grid (profile)
``delay``/``current_lag`` time derivative of the motor force (a lag against the command);
                          the two are told apart afterwards by their exact forms
``gravity``               ``sin``/``cos`` of the angle (rotary axes only)
``force_ripple``          the motor force times ``sin``/``cos`` of ``2*pi*x/pitch``
``current_limit``         the change of the residual a clipped current makes (secant),
                          over the percentiles of the current
``load_friction``         the change of the residual that friction levels growing with
                          the drive's force make (secant)
========================  =================================================================

One module per family; :func:`candidates` lists them all.
"""

from __future__ import annotations

from .base import Candidate, Context, FindingView, Said, Term
from .drift import Drift
from .drive import CurrentLimit, ForceRipple, LoadFriction
from .lag import Lag
from .linear import Drag, Mass, Offset, Spring
from .position import Cogging, Gravity, PositionFriction
from .resonance import Resonance
from .secant import Deadband, StribeckShape

__all__ = ["Candidate", "Cogging", "Context", "CurrentLimit", "Deadband", "Drag", "Drift",
           "FindingView", "ForceRipple", "Gravity", "Lag", "LoadFriction", "Mass", "Offset",
           "PositionFriction", "Resonance", "Said", "Spring", "StribeckShape", "Term",
           "candidates"]


def candidates(axis_kind: str = "linear") -> list[Candidate]:
    """A fresh list of every candidate of the vocabulary that acts on a ``axis_kind``
    axis (``gravity`` on a rotary one only: a linear axis's weight is an offset)."""
    rotary = [Gravity()] if axis_kind == "rotary" else []
    return [Offset(), Spring(), *rotary, Mass(), Cogging(), PositionFriction(), Drift(),
            Lag(), Drag(), StribeckShape(), Deadband(), Resonance(), ForceRipple(),
            CurrentLimit(), LoadFriction()]
