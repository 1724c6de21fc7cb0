"""The public simulation API over the Rust core (:mod:`lugre._core`).

Each function has the same name, signature and results as its twin in
:mod:`lugre.reference`; Python only normalises inputs (dtype, layout, dimensions; the
conversions of :mod:`lugre._args`, shared with the twin) and the core validates their
content, with the same errors. This module is also the diagnosis's default kernels
(with the core's ``InverseRecord``); :mod:`lugre.reference.kernels` offers the twins.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ._args import (
    as_array,
    check_substeps_type,
    frequency_count,
    grid_args,
    linear_args,
    select_drive,
)
from ._core import InverseRecord
from ._core import filtfilt as core_filtfilt
from ._core import friction_force as core_friction_force
from ._core import irls_linear as core_irls_linear
from ._core import irls_linear_grid as core_irls_linear_grid
from ._core import load_coupling as core_load_coupling
from ._core import moving_median as core_moving_median
from ._core import position_sums as core_position_sums
from ._core import simulate as core_simulate
from ._core import simulate_batch as core_simulate_batch
from ._core import stribeck as core_stribeck
from ._memory import one_heap_per_core
from ._result import CouplingResult, GridFit, LinearFit, SimResult
from .exceptions import InputError, ParameterError
from .model import ModelLike, _as_model

one_heap_per_core()  # (before the core's threads first allocate)

__all__ = ["InverseRecord", "filtfilt", "friction_force", "irls_linear", "irls_linear_grid", "load_coupling",
           "moving_median", "position_sums", "simulate", "simulate_batch", "stribeck"]


def _array(name: str, a: Any) -> np.ndarray:
    """The twins' 1-D float64 array (same checks, same messages: a scalar is refused by
    both), made contiguous for the core."""
    return np.ascontiguousarray(as_array(name, a))


def _core_model(model: ModelLike) -> Any:
    """The core's parsed model (``_core.Model``), built once per :class:`Model`."""
    return _as_model(model)._core_model()


def stribeck(v: Any, model: ModelLike) -> np.ndarray:
    """Steady-state (Stribeck) friction force for each velocity.

    ``F_ss(v) = sign(v)*g(v) + sigma2*v`` with the ``positive`` set for ``v >= 0`` and
    the ``negative`` set for ``v < 0``, and ``F_ss(0) = 0``.

    Parameters
    ----------
    v : array_like
        Velocities [m/s], 1-D.
    model : Model, dict or path
        The model (only its friction is used).

    Returns
    -------
    numpy.ndarray
        Forces [N], float64, same length as ``v``.

    Examples
    --------
    >>> import lugre
    >>> float(lugre.stribeck([0.4], lugre.Model.paper())[0])
    161.7
    """
    return core_stribeck(_array("v", v), _core_model(model))


def friction_force(
    v: Any,
    dt: Any,
    model: ModelLike,
    *,
    z0: float = 0.0,
    return_z: bool = False,
    scale: Any = None,
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """LuGre friction force driven by a sampled velocity signal (see the reference).

    For ``k = 0 .. n-1``: ``F[k]`` is the force at state ``z`` and ``v[k]``; then ``z``
    advances exactly over ``dt`` (or ``dt[k]``) with ``v[k]`` held. The model's
    ``stribeck_shape`` effect, if any, sets the exponent of ``g(v)``.

    Parameters
    ----------
    v : array_like
        Velocities [m/s], 1-D.
    dt : float or array_like
        Hold interval [s]: one value, or one per sample.
    model : Model, dict or path
        The model (only its friction is used).
    z0 : float, default 0.0
        Initial bristle deflection [m].
    return_z : bool, default False
        Also return ``z[k]``, the state at which ``F[k]`` was evaluated.
    scale : array_like, optional
        One positive factor per sample multiplying ``g(v[k])`` (position- or
        time-dependent friction levels).

    Returns
    -------
    F : numpy.ndarray
        Friction force [N].
    z : numpy.ndarray
        Only with ``return_z``.
    """
    vv = _array("v", v)
    sc = None if scale is None else _array("scale", scale)
    try:
        dta = np.ascontiguousarray(dt, dtype=np.float64).reshape(-1)
    except (TypeError, ValueError) as e:
        raise InputError.at("dt", f"must be a number or an array of numbers ({e})") from None
    f, z = core_friction_force(vv, dta, _core_model(model), _float("z0", z0), bool(return_z),
                                sc)
    return (f, z) if return_z else f


def load_coupling(
    x: Any,
    v: Any,
    dt: float,
    model: ModelLike,
    *,
    scale: Any = None,
    extra: Any = None,
    z0: float = 0.0,
    substeps: int = 1,
) -> CouplingResult:
    """The load behind the ``resonance`` coupling, driven by the measured motor motion.

    The load (``r*M``, carrying the friction and the effect forces) is simulated along
    the sampled motor position and velocity, interpolated linearly between samples, in
    ``substeps*max(1, ceil(4*w*dt), ceil(d*dt))`` substeps per interval with
    ``w = sqrt((k + sigma0)/(r*M))`` and ``d = (c + sigma1 + max(sigma2))/(r*M)``
    (leapfrog, the velocities at each substep's start and middle predicted from the
    last acceleration, exact bristle update; ``docs/DESIGN.md``). With ``a_m`` the motor's acceleration, the model's motor force
    is ``(1 - r)*M*a_m + force``. Runs in the Rust core; the parameters and results are
    those of :func:`lugre.reference.load_coupling`.

    Parameters
    ----------
    x, v : array_like
        Motor position [m] and velocity [m/s] at uniform samples, 1-D, same length.
    dt : float
        Sample interval [s], > 0.
    model : Model, dict or path
        The model; it must hold a ``resonance`` effect.
    scale : array_like, optional
        One positive factor per sample multiplying ``g(v)`` (``position_friction``,
        ``drift``).
    extra : array_like, optional
        Further force on the load per sample [N] (cogging, springs, offsets, drag).
    z0 : float, default 0.0
        Initial bristle deflection [m].
    substeps : int, default 1
        Multiplier (>= 1) of the automatic number of substeps per interval.

    Returns
    -------
    CouplingResult
        Named tuple ``(force, x_load, v_load, z)`` at each sample (state before the
        step that follows it): coupling force on the load [N], load position [m],
        load velocity [m/s], bristle deflection [m].

    Examples
    --------
    >>> import numpy as np, lugre
    >>> d = lugre.Model.paper().to_dict()
    >>> d["effects"] = [{"effect": "resonance", "frequency": 22.0, "damping_ratio": 0.04,
    ...                  "load_fraction": 0.75}]
    >>> r = lugre.load_coupling(np.zeros(5), np.zeros(5), 1e-4, d)
    >>> float(np.abs(r.force).max())
    0.0
    """
    mj = _core_model(model)
    xx = _array("x", x)
    vv = _array("v", v)
    sc = None if scale is None else _array("scale", scale)
    ex = None if extra is None else _array("extra", extra)
    dtf = _float("dt", dt)
    n_sub = _substeps(substeps)
    f, xl, vl, z = core_load_coupling(xx, vv, dtf, mj, sc, ex, _float("z0", z0), n_sub)
    return CouplingResult(f, xl, vl, z)


def filtfilt(y: Any, sos: Any, padlen: int) -> np.ndarray:
    """``y`` through the second-order sections ``sos`` (rows ``[b0, b1, b2, 1, a1, a2]``)
    forward and backward, odd extension of ``min(padlen, len(y) - 1)`` samples at each
    end: SciPy's ``sosfiltfilt(sos, y, padtype="odd", padlen=padlen)`` in the core (the
    low-pass of ``InverseRecord.filt``, states under 1e-270 flushed to zero), equal to
    it to about 1e-15 of the signal's scale; the same as
    :func:`lugre.reference.kernels.filtfilt`."""
    yy = _array("y", y)
    ss = np.ascontiguousarray(np.asarray(sos, dtype=float))
    if ss.ndim != 2:
        raise InputError.at("sos", "must be a matrix with one row [b0, b1, b2, 1, a1, a2] "
                            "per section")
    return core_filtfilt(yy, ss, int(padlen))


def moving_median(y: Any, size: int) -> np.ndarray:
    """The moving median of ``y`` over ``size`` samples centred on each, the ends
    extended by their edge values: SciPy's ``ndimage.median_filter(y, size=size,
    mode="nearest")``, value for value, in the core; the same as
    :func:`lugre.reference.kernels.moving_median`."""
    return core_moving_median(_array("y", y), int(size))


def position_sums(x: Any, r: Any, k0: float, dk: float, n: int, *, squares: bool = False
                  ) -> tuple[np.ndarray, ...]:
    """Sums of ``r`` against ``sin`` and ``cos`` of ``2*pi*k_j*x`` over a uniform grid of
    spatial frequencies ``k_j = k0 + j*dk``, ``j < n``: the periodogram of a signal over
    position. Runs in the Rust core (the angles advanced by rotation, re-started from
    exact values every 32 frequencies); the parameters, results and errors are those of
    :func:`lugre.reference.position_sums`, the results equal to about 1e-13 of their
    scale.

    Returns
    -------
    tuple of numpy.ndarray
        ``(S, C)``, with ``squares`` ``(S, C, SS, CC, SC)``: the sums of ``sin*r``,
        ``cos*r``, ``sin^2``, ``cos^2`` and ``sin*cos``, each of length ``n``.
    """
    xx = _array("x", x)
    rr = _array("r", r)
    k0f, dkf = _float("k0", k0), _float("dk", dk)
    nn = frequency_count(n)
    return tuple(core_position_sums(xx, rr, k0f, dkf, nn, bool(squares)))


def irls_linear(x: Any, y: Any, *, weighting: str = "igg", rounds: int = 8) -> LinearFit:
    """Robust linear least squares ``y ~ X b`` by IRLS, in the Rust core
    (``estimate::irls_linear``, the interpreter released). The parameters, results and
    errors are those of :func:`lugre.reference.irls_linear`, the results equal bit for
    bit.

    Returns
    -------
    LinearFit
        ``coef``, ``weights``, ``residuals``, ``sse`` and ``scale``.
    """
    xa, ya, name, nr = linear_args(x, y, weighting, rounds)
    return fit_result(core_irls_linear(np.asfortranarray(xa), np.ascontiguousarray(ya),
                                        name, nr))


def irls_linear_grid(x: Any, extras: Any, y: Any, *, weighting: str = "igg", rounds: int = 8,
                     ratio: float = 0.98) -> GridFit:
    """:func:`irls_linear` of ``x`` alone and joined by each candidate's extra columns,
    the best kept (``estimate::irls_linear_grid``, the candidates fitted in parallel).
    The parameters, results and errors are those of
    :func:`lugre.reference.irls_linear_grid`, the results equal bit for bit.

    Returns
    -------
    GridFit
        ``chosen``, ``fit``, ``base_sse`` and ``sse``.
    """
    xa, cands, ya, name, nr, rt = grid_args(x, extras, y, weighting, rounds, ratio)
    g = core_irls_linear_grid(np.asfortranarray(xa), [np.asfortranarray(c) for c in cands],
                               np.ascontiguousarray(ya), name, nr, rt)
    return GridFit(chosen=g.chosen, fit=fit_result(g.fit), base_sse=g.base_sse, sse=g.sse)


def fit_result(f: Any) -> LinearFit:
    """A :class:`LinearFit` from the core's ``_core.LinearFitResult``."""
    return LinearFit(coef=f.coef, weights=f.weights, residuals=f.residuals, sse=f.sse,
                     scale=f.scale)


def _float(name: str, value: Any) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        raise ParameterError.invalid(name, value, "must be a finite number") from None


def _drive(x_ref: Any, v_ref: Any, current: Any) -> tuple[str, np.ndarray]:
    kind, a = select_drive(x_ref, v_ref, current)
    return kind, _array(kind, a)


def simulate(
    model: ModelLike,
    t: Any,
    x_ref: Any = None,
    *,
    v_ref: Any = None,
    current: Any = None,
    integrator: str = "exact",
    substeps: int = 1,
    z0: float = 0.0,
    x0: float | None = None,
    v0: float = 0.0,
) -> SimResult:
    """Simulate the axis under its controller (or in open loop), sampled at ``t``.

    Runs in the Rust core with the interpreter released; Ctrl-C interrupts it. The
    parameters and results are those of :func:`lugre.reference.simulate`.

    Parameters
    ----------
    model : Model, dict or path
        The axis model. Closed loop needs its ``controller``.
    t : array_like
        Sample times [s], strictly increasing.
    x_ref, v_ref, current : array_like, optional
        Exactly one: position reference (pid), speed reference (pi_speed) or open-loop
        current command [A], each sampled at ``t``.
    integrator : {"exact", "rk4"}, default "exact"
        Plant integrator.
    substeps : int, default 1
        Plant steps per control period (per sample interval in open loop).
    z0, x0, v0 : float
        Initial bristle deflection, position (default ``x_ref[0]`` or 0) and velocity.

    Returns
    -------
    SimResult
        ``t``, ``x``, ``v``, ``z``, ``i``, ``friction`` and ``force`` at ``t``.
    """
    tt, args = _sim_args(t, x_ref, v_ref, current, integrator, substeps, z0, x0, v0)
    r = core_simulate(_core_model(model), tt, *args)
    return SimResult(tt.copy(), r.x, r.v, r.z, r.i, r.friction, r.force)


def _sim_args(t: Any, x_ref: Any, v_ref: Any, current: Any, integrator: Any, substeps: Any,
              z0: Any, x0: Any, v0: Any) -> tuple[np.ndarray, tuple[Any, ...]]:
    """Normalised ``t`` and the core's positional arguments after the model."""
    tt = _array("t", t)
    kind, d = _drive(x_ref, v_ref, current)
    args = (kind, d, str(integrator), _substeps(substeps), _float("z0", z0),
            None if x0 is None else _float("x0", x0), _float("v0", v0))
    return tt, args


def _substeps(substeps: Any) -> int:
    """Integer check as in the reference; the core checks the range (>= 1)."""
    check_substeps_type(substeps)
    return max(int(substeps), 0)


def simulate_batch(
    models: Sequence[ModelLike],
    t: Any,
    x_ref: Any = None,
    *,
    v_ref: Any = None,
    current: Any = None,
    integrator: str = "exact",
    substeps: int = 1,
    z0: float = 0.0,
    x0: float | None = None,
    v0: float = 0.0,
) -> list[SimResult]:
    """Simulate many models on the same input, in parallel on all cores.

    Parameters are those of :func:`simulate`, with a sequence of models.

    Returns
    -------
    list of SimResult
        One per model, in order.
    """
    tt, args = _sim_args(t, x_ref, v_ref, current, integrator, substeps, z0, x0, v0)
    rs = core_simulate_batch([_core_model(m) for m in models], tt, *args)
    return [SimResult(tt.copy(), r.x, r.v, r.z, r.i, r.friction, r.force) for r in rs]


