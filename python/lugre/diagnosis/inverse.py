"""Base model by inverse dynamics: robust least squares on the filtered record."""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from ..exceptions import DataError
from ..model import Model, axis_document
from ..vocabulary import DRAG, GRAVITY, SPRING
from . import residual as R
from .evaluation import as_recording
from .options import IDENTIFY_TOLERANCE

__all__ = ["IDENTIFY_TOLERANCE", "fit_inverse_dynamics", "inverse_start", "inverse_starts"]


def fit_inverse_dynamics(
    recording: Any,
    *,
    mass: float | None = None,
    force_constant: float = 1.0,
    sigma0: float | None = None,
    cutoff_hz: float | None = None,
    controller: dict[str, Any] | None = None,
    backend: Any = "core",
    sliding: float | None = None,
    axis_kind: str | None = None,
) -> Model:
    """Fit a LuGre axis model by robust least squares on the inverse dynamics.

    ``F = m*a + sign(v)*g(v) + sigma2*v`` with per-direction ``fc``, ``fs``, ``vs``,
    ``sigma2``: linear in ``m``, ``fc`` and ``sigma2`` (and ``fs - fc`` for a given
    ``vs``, found on a grid of 15), on low-passed data, with IGG weights (robust to
    spikes): ``irls_linear_grid`` of the backend (the Rust core's IRLS or its NumPy
    twin). A ``vs`` is kept when both humps come out positive and it lowers the
    weighted sum of squares by 2 % or more.
    ``sigma0`` is a guess (the maximum friction over ten encoder counts, at least over
    10 um) and ``sigma1`` a damping guess; no offset is fitted (the diagnosis tests it
    as a candidate effect).

    Parameters
    ----------
    recording : Recording or path
        With motion in both directions.
    mass : float, optional
        Known mass [kg]; estimated otherwise.
    force_constant : float, default 1.0
        K_F [N/A] (needed when the recording holds the current).
    sigma0 : float, optional
        Bristle stiffness [N/m]; guessed otherwise.
    cutoff_hz : float, optional
        Low-pass cut-off (default ``fs/25``).
    controller : dict, optional
        Controller section to put in the model.
    backend : "core" or module, default "core"
        The kernels (:func:`lugre.diagnosis.residual.kernels`): the compiled
        inverse-dynamics kernel and robust fit, or their NumPy twins
        (:mod:`lugre.reference.kernels`).
    sliding : float, optional
        Use only the samples moving faster than this share of the largest speed (and
        than ten encoder counts per sample): where the axis slides, the static curve is
        the friction; where it sticks, the friction is whatever the drive pushes with.
        Default: every sample.
    axis_kind : {"linear", "rotary"}, optional
        The axis the model describes (CONTRACT, "Rotary axes"); default the
        recording's (``meta["axis_kind"]``, set when its positions were read in rad or
        deg), else linear.

    Returns
    -------
    Model
    """
    return inverse_start(recording, mass=mass, force_constant=force_constant, sigma0=sigma0,
                         cutoff_hz=cutoff_hz, controller=controller, backend=backend,
                         sliding=sliding, axis_kind=axis_kind)


def inverse_start(recording: Any, *, mass: float | None, force_constant: float,
                  sigma0: float | None = None, cutoff_hz: float | None,
                  controller: dict[str, Any] | None, backend: Any, sliding: float | None,
                  axis_kind: str | None = None, drag: bool = False) -> Model:
    """:func:`fit_inverse_dynamics`; with ``drag``, a quadratic drag beside the base
    whenever it is plausible (a positive coefficient, positive levels and mass), for a
    fit to compare against the one without it."""
    start, other = inverse_starts(
        recording, mass=mass, force_constant=force_constant, sigma0=sigma0,
        cutoff_hz=cutoff_hz, controller=controller, backend=backend, sliding=sliding,
        axis_kind=axis_kind)
    return other if drag and other is not None else start


def inverse_starts(recording: Any, *, mass: float | None, force_constant: float,
                   sigma0: float | None = None, cutoff_hz: float | None,
                   controller: dict[str, Any] | None, backend: Any,
                   sliding: float | None, axis_kind: str | None = None
                   ) -> tuple[Model, Model | None]:
    """The linear start (:func:`fit_inverse_dynamics`), and beside it, when the start
    holds no drag and one is plausible, the start with a quadratic drag (for a fit to
    compare against): one preparation of the record and one grid of fits for both."""
    rec = as_recording(recording)
    R.check_recording(rec)
    kind = axis_kind or rec.meta.get("axis_kind", "linear")
    proto = Model.paper().replace(
        axis=axis_document(kind, 1.0, force_constant), effects=[], controller=None)
    sig = R.prepare(rec, proto, cutoff_hz=cutoff_hz, backend=backend)
    m = sig.mask
    vmax = float(np.max(np.abs(sig.vf[m])))
    if sliding is not None:
        q = float(sig.info.get("quantum", 0.0))
        m = m & (np.abs(sig.vf) > max(sliding * vmax, 10 * q / sig.dt))
        if min(np.sum(m & (sig.vf > 0)), np.sum(m & (sig.vf < 0))) < 20:
            m = sig.mask
    v = sig.v
    pos, neg = (v > 0).astype(float), (v < 0).astype(float)
    y = sig.fm_f.copy()
    if mass is not None:
        y = y - float(mass) * sig.a

    base = ([] if mass is not None else [sig.a]) + [
        sig.filt(pos), sig.filt(pos * v), sig.filt(-neg), sig.filt(neg * v)]
    X = np.column_stack(base)[m]
    # one candidate per vs of the grid: the Stribeck hump of each direction
    # (sliding samples only: up to the largest speed, for a record that stays within
    # the Stribeck range)
    top = -0.5 if sliding is None else 0.0
    grid = vmax * np.logspace(-2.5, top, 15) if vmax > 0 else np.zeros(0)
    extras = []
    for vs_k in grid:
        e = np.exp(-(v / vs_k) ** 2)
        extras.append(np.column_stack([sig.filt(pos * e), sig.filt(-neg * e)])[m])
    # robust (IGG-weighted IRLS) fit of the base and of each candidate, the best kept:
    # the core's estimate::irls_linear_grid or its NumPy twin
    found = R.kernels(sig.backend).irls_linear_grid(X, extras, y[m])
    off = 0 if mass is not None else 1
    kept, forced = _with_loads(sig, kind, X, extras, y[m], m, found, off)
    args = (sig, kind, grid, vmax, off, mass, force_constant, sigma0, controller)
    start = _start(*args, *kept)
    return start, (_start(*args, *forced) if forced is not None else None)


def _start(sig: Any, kind: str, grid: np.ndarray, vmax: float, off: int,
           mass: float | None, force_constant: float, sigma0: float | None,
           controller: dict[str, Any] | None, found: Any, loads: list[str]) -> Model:
    """The model of one linear fit (``found``, with the ``loads``' columns after the
    base's)."""
    vs = float(grid[found.chosen]) if found.chosen is not None else None
    b = found.fit.coef
    mm = float(mass) if mass is not None else float(b[0])
    if not mm > 0:
        raise DataError(f"the inverse-dynamics fit gives a mass of {mm:.3g} "
                        f"{'kg m^2' if kind == 'rotary' else 'kg'}: the record does not "
                        "excite the inertia, or a force that grows with the position (a "
                        "spring, a cable, a weight) follows the acceleration against it; "
                        "give the mass (--mass)")
    fcp, s2p, fcn, s2n = (float(b[off + k]) for k in range(4))
    if SPRING in loads:  # (the spring's preload taken out of the levels' difference)
        fcp, fcn = 0.5 * (fcp + fcn), 0.5 * (fcp + fcn)
    ng = sum(LOAD_WIDTH[e] for e in loads)
    dp = float(b[off + 4 + ng]) if vs is not None else 0.0
    dn = float(b[off + 5 + ng]) if vs is not None else 0.0
    vs_val = float(vs) if vs is not None else 0.05 * max(vmax, 1e-6)
    fcp, fcn = max(fcp, 1e-3), max(fcn, 1e-3)
    fsmax = max(fcp + dp, fcn + dn)
    if sigma0 is None:
        q = max(sig.info.get("quantum", 0.0), 1e-6)
        sigma0 = fsmax / max(10 * q, 1e-5)
    sigma1 = 0.05 * math.sqrt(sigma0 * mm)
    doc = {
        "axis": axis_document(kind, mm, force_constant),
        "friction": {
            "model": "lugre", "sigma0": float(sigma0), "sigma1": float(sigma1),
            "positive": {"fc": fcp, "fs": fcp + max(dp, 0.0), "sigma2": max(s2p, 0.0),
                         "vs": vs_val},
            "negative": {"fc": fcn, "fs": fcn + max(dn, 0.0), "sigma2": max(s2n, 0.0),
                         "vs": vs_val},
        },
        "effects": _load_effects(b[off:off + 4 + ng], loads, sig),
    }
    if controller is not None:
        doc["controller"] = controller
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return Model(doc)


#: Least share of the robust scale that gravity's columns must take off to be kept (a
#: spring's column too when the mass comes out negative without it), and a spring's
#: column beside a positive mass (tried only with the mass fitted: springs of the
#: independent plant took 83-99.7 % off, a small stroke's cogging 40 %).
GRAVITY_GAIN = 0.2
SPRING_GAIN = 0.5

#: A quadratic drag's column is kept when a direction's Coulomb level comes out at or
#: below zero without it (the line through a force that grows faster than the speed
#: meets zero below the level) and with it both levels are positive, unless it raises
#: the robust scale by more than :data:`DRAG_BENT_RISE` (the scale moves with the IGG
#: weights: on drag records of the independent plant whose levels it brought back, it
#: took -8 % to +44 % off); with both levels positive, when it takes
#: :data:`DRAG_GAIN` of the scale off. Stress seed 17: a drag whose line had put one
#: level at -6.4 N took 44 % off (the level came back at 5.9 N for 5.8, the drag
#: within 0.1 % of its truth); on 38 clean records the column took at most 5.5 %, on a
#: friction change along the stroke 19 %.
DRAG_BENT_RISE = 0.1
DRAG_GAIN = 0.5

#: Columns of each load the linear start can take up beside the base.
LOAD_WIDTH = {GRAVITY: 2, SPRING: 1, DRAG: 1}


def _with_loads(sig: Any, kind: str, X: np.ndarray, extras: list[np.ndarray],
                y: np.ndarray, m: np.ndarray, found: Any, off: int
                ) -> tuple[tuple[Any, list[str]], tuple[Any, list[str]] | None]:
    """The linear fit with the loads the record needs beside the base (their columns
    after the base's, in the order of the names): a joint's weight or a spring
    (:func:`_load_columns`), then a quadratic drag; and beside it, when the drag was
    not kept but is plausible, the fit with it (None otherwise)."""
    fit = R.kernels(sig.backend).irls_linear_grid
    loads: list[str] = []
    load = _load_columns(sig, kind)
    with_g = fit(np.column_stack([X, load[m]]), extras, y)
    physical = _plausible(with_g.fit.coef, off, spring=kind != "rotary")
    # a spring only with the mass fitted: a force growing with the position
    # follows a sine's acceleration against it and the fitted mass takes it up
    # (negative, or a quarter off); with the mass given the diagnosis names it.
    # Unless the mass came out negative without it, the spring must take half of
    # the scale off: a small stroke's cogging took 40 % with a fivefold mass
    needed = kind == "rotary" or bool(off)
    no_axis = kind == "rotary" or not found.fit.coef[0] > 0
    gain = GRAVITY_GAIN if no_axis else SPRING_GAIN
    if needed and physical and with_g.fit.scale < (1.0 - gain) * found.fit.scale:
        found, X = with_g, np.column_stack([X, load[m]])
        loads.append(GRAVITY if kind == "rotary" else SPRING)
    with_d = fit(np.column_stack([X, sig.filt(sig.v * np.abs(sig.v))[m]]), extras, y)
    b0, b1 = found.fit.coef, with_d.fit.coef
    plausible = (b1[X.shape[1]] > 0 and b1[off] > 0 and b1[off + 2] > 0
                 and (not off or b1[0] > 0))
    bent = not (b0[off] > 0 and b0[off + 2] > 0)
    limit = (1.0 + DRAG_BENT_RISE) if bent else (1.0 - DRAG_GAIN)
    drag = (with_d, loads + [DRAG])
    if plausible and with_d.fit.scale < limit * found.fit.scale:
        return drag, None
    return (found, loads), (drag if plausible else None)


def _plausible(b: np.ndarray, off: int, spring: bool = False) -> bool:
    """Whether a linear start with a load is an axis: a positive mass (when fitted)
    and Coulomb levels of both directions positive and within a factor of three of
    each other (over a fraction of a turn with few reversals, sin and cos of the angle
    can stand in for the levels' difference, and a base axis read 1.1e4 N m of
    "gravity" with levels of 0 and 1e4 N m). A spring's preload and the levels'
    difference look alike while the axis moves: with a spring, a positive stiffness and
    mean level."""
    fcp, fcn = float(b[off]), float(b[off + 2])
    if off and not b[0] > 0:
        return False
    if spring:
        return fcp + fcn > 0 and float(b[off + 4]) > 0
    return fcp > 0 and fcn > 0 and max(fcp, fcn) < 3.0 * min(fcp, fcn)


def _load_columns(sig: Any, kind: str) -> np.ndarray:
    """A joint's weight, filtered ``sin(x)`` and ``cos(x)``; on a linear axis a spring,
    the filtered position about the record's middle."""
    if kind == "rotary":
        return np.column_stack([sig.filt(np.sin(sig.x)), sig.filt(np.cos(sig.x))])
    return sig.filt(sig.x - _middle(sig))[:, None]


def _middle(sig: Any) -> float:
    """The middle of the stroke [m]: a spring's rest position is taken there (a
    preload beyond it and a difference of the two directions' levels look alike)."""
    used = sig.x[sig.mask]
    return 0.5 * float(np.min(used) + np.max(used))


def _load_effects(b: np.ndarray, loads: list[str], sig: Any) -> list[dict[str, Any]]:
    """The effects of the loads' coefficients (``b``: the two directions' levels and
    slopes, then the loads' in the order of ``loads``)."""
    out = []
    width = sum(LOAD_WIDTH[e] for e in loads if e != DRAG)
    if width:
        out.append(_load_effect(b[:4 + width], sig))
    if DRAG in loads:
        out.append({"effect": DRAG, "coefficient": float(b[4 + width])})
    return out


def _load_effect(b: np.ndarray, sig: Any) -> dict[str, Any]:
    """The ``gravity`` effect of the coefficients of ``sin(x)`` and ``cos(x)``, or the
    ``spring`` of the position's (``b``: the two directions' levels and slopes, then
    the load's). The spring's rest position puts its preload where the levels are
    alike (:func:`lugre.diagnosis.basefit.identify` places it by the standstills)."""
    if b.size == 5:
        k = float(b[4])
        return {"effect": SPRING, "stiffness": k,
                "x0": _middle(sig) - 0.5 * (float(b[0]) - float(b[2])) / k}
    bs, bc = float(b[4]), float(b[5])
    return {"effect": GRAVITY, "torque": float(math.hypot(bs, bc)),
            "phase": float(math.atan2(bc, bs))}
