"""The results of the identification (:mod:`lugre.identify`), shared with its NumPy
twin (:mod:`lugre.reference`): :class:`StaticFit` of both directions'
:class:`DirectionFit`, :class:`SteadyStatePoints` and :class:`DynamicFit`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import units as U
from .model import Model, ModelLike, _as_model

__all__ = ["STATIC_NAMES", "DirectionFit", "DynamicFit", "StaticFit", "SteadyStatePoints"]

STATIC_NAMES = ("fc", "fs", "sigma2", "vs")


@dataclass
class DirectionFit:
    """Stribeck fit of one direction (all parameters positive, also for ``v < 0``)."""

    params: dict[str, float]
    """``fc`` [N], ``fs`` [N], ``sigma2`` [N s/m], ``vs`` [m/s]."""
    std_err: dict[str, float]
    """Standard errors (NaN where they cannot be computed)."""
    ci95: dict[str, tuple[float, float]]
    """95 % confidence intervals."""
    indices: np.ndarray
    """Indices of this direction's points in the input."""
    weights: np.ndarray
    """Final IRLS weight of each of these points (0: rejected as a gross error)."""
    residuals: np.ndarray
    """``F - F_model`` at each of these points [N]."""
    scale: float
    """Robust residual scale (1.4826 MAD) [N]."""
    iterations: int
    converged: bool
    cov: np.ndarray = field(default_factory=lambda: np.full((4, 4), np.nan))
    """Joint covariance of ``fc, fs, sigma2, vs`` (NaN where it cannot be computed)."""

    @classmethod
    def _from_core(cls, d: Any) -> DirectionFit:
        """From a direction's result: the core's ``_core.DirectionFitResult`` or its
        twin's (same attributes)."""
        return cls(
            params={k: float(getattr(d, k)) for k in STATIC_NAMES},
            std_err=dict(zip(STATIC_NAMES, map(float, d.std_err))),
            ci95={k: (float(lo), float(hi))
                  for k, lo, hi in zip(STATIC_NAMES, d.ci_low, d.ci_high)},
            indices=np.asarray(d.indices, dtype=np.intp),
            weights=d.weights,
            residuals=d.residuals,
            scale=float(d.scale),
            iterations=int(d.iterations),
            converged=bool(d.converged),
            cov=np.asarray(d.cov, dtype=float).reshape(4, 4),
        )


@dataclass
class StaticFit:
    """Result of :func:`fit_static`."""

    positive: DirectionFit
    negative: DirectionFit
    weights: np.ndarray
    """Final weight of every input point (0 for rejected and zero-speed points)."""
    rejected: list[int]
    """Indices of the points rejected as gross errors."""
    n_zero_speed: int
    weighting: str
    notes: list[str] = field(default_factory=list)

    @property
    def converged(self) -> bool:
        """True when both directions converged."""
        return self.positive.converged and self.negative.converged

    def to_model(self, base: ModelLike | None = None, **axis: float) -> Model:
        """A model with these static sets.

        Parameters
        ----------
        base : Model, dict or path, optional
            Supplies the axis, sigma0, sigma1, effects and controller. Without it the
            paper's axis values are used for what the static step cannot tell, and the
            model is marked ``"identified": {"static": true, "dynamic": false}``.
        **axis
            ``mass=``, ``force_constant=`` override the axis.
        """
        d = (_as_model(base) if base is not None else Model.paper()).to_dict()
        d["friction"]["positive"] = dict(self.positive.params)
        d["friction"]["negative"] = dict(self.negative.params)
        d["axis"].update({k: float(v) for k, v in axis.items()})
        if base is None:
            d.pop("controller", None)
            d["identified"] = {"static": True, "dynamic": False}
        return Model.from_dict(d)

    def summary(self, truth: dict[str, dict[str, float]] | None = None) -> str:
        """A table a person reads: estimates, 95 % intervals, and errors against ``truth``
        (``{"positive": {...}, "negative": {...}}``) when given."""
        lines = [(f"static fit ({self.weighting} weights): {len(self.rejected)} points "
                 f"rejected as gross errors {self.rejected}")]
        for name, d in (("v > 0", self.positive), ("v < 0", self.negative)):
            lines.append(f"  {name}  (IRLS iterations {d.iterations}, "
                         f"{'converged' if d.converged else 'NOT converged'}, "
                         f"residual scale {d.scale:.3g} {U.si('N')})")
            for k in STATIC_NAMES:
                lo, hi = d.ci95[k]
                row = f"    {k:7s} {d.params[k]:12.6g}   95 % CI [{lo:.6g}, {hi:.6g}]"
                if truth is not None:
                    key = "positive" if d is self.positive else "negative"
                    tv = truth[key][k]
                    row += f"   truth {tv:.6g}  error {100 * (d.params[k] - tv) / tv:+.2f} %"
                lines.append(row)
        lines += [f"  note: {n}" for n in self.notes]
        return "\n".join(lines)


@dataclass
class SteadyStatePoints:
    """Steady-state points found in a raw constant-velocity record."""

    v: np.ndarray
    """Mean measured velocity of each point [m/s]."""
    F: np.ndarray
    """Mean force of each point [N]."""
    F_std: np.ndarray
    """Standard deviation of the force samples behind each point [N]."""
    plateaus: list[dict[str, Any]]
    """Every detected plateau: start/end sample, nominal velocity, first sample used,
    whether it settled."""
    used: np.ndarray
    """Boolean mask of the samples that went into a point."""
    notes: list[str]
    """What was skipped and why."""


@dataclass
class DynamicFit:
    """Result of :func:`fit_dynamic`."""

    sigma0: float
    sigma1: float
    std_err: dict[str, float]
    ci95: dict[str, tuple[float, float]]
    identifiable: dict[str, bool]
    """Whether the record determines each parameter (95 % interval within +-50 %, and
    within +-25 % once the static step's uncertainty is carried over)."""
    correlation: float
    """Correlation of the ln(sigma0) and ln(sigma1) estimates."""
    notes: list[str]
    """Plain-language verdicts and the experiments that would determine the rest."""
    residuals: np.ndarray
    """Measured minus simulated position [m]."""
    weights: np.ndarray
    rms_error: float
    max_error: float
    iterations: int
    evaluations: int
    converged: bool
    model: Model
    """The input model with the estimated sigma0 and sigma1."""

    def to_model(self) -> Model:
        """The model with the estimated sigma0 and sigma1."""
        return self.model.copy()

    def summary(self, truth: dict[str, float] | None = None) -> str:
        """Estimates, intervals, verdicts (and errors against ``truth`` when given)."""
        with U.axis(self.model.kind):
            u = U.si("m")
            lines = [(f"dynamic fit: {self.evaluations} closed-loop simulations, "
                      f"rms position error {self.rms_error:.3g} {u}, max {self.max_error:.3g} {u}")]
        for k in ("sigma0", "sigma1"):
            val = getattr(self, k)
            lo, hi = self.ci95[k]
            row = (f"  {k:7s} {val:12.6g}   95 % CI [{lo:.6g}, {hi:.6g}]   "
                   f"{'determined' if self.identifiable[k] else 'NOT determined by this record'}")
            if truth is not None and k in truth:
                row += f"   truth {truth[k]:.6g}  error {100 * (val - truth[k]) / truth[k]:+.2f} %"
            lines.append(row)
        lines += [f"  note: {n}" for n in self.notes]
        return "\n".join(lines)
