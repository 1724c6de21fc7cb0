"""LuGre friction (``src/friction/mod.rs``): the Stribeck curve, the bristle state and its
exact update, the observer of the feed-forward; :func:`stribeck` and
:func:`friction_force`."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._args import as_array as _array
from ..exceptions import InputError, _fmt_f64
from ..model import ModelLike
from .checks import _check_finite, _check_len, _check_scale, _finite_option, _parsed
from .parsed import _Friction, _StaticSet

__all__ = ["friction_force", "stribeck"]

_exp = math.exp


def _g(s: _StaticSet, v: float) -> float:
    """``g(v) = fc + (fs - fc)*exp(-(v/vs)^2)``."""
    r = v / s.vs
    return s.fc + (s.fs - s.fc) * _exp(-(r * r))


def _g_shaped(s: _StaticSet, v: float, exponent: float) -> float:
    """``g(v) = fc + (fs - fc)*exp(-|v/vs|^exponent)`` (``StaticSet::g_shaped``)."""
    r = abs(v / s.vs)
    return s.fc + (s.fs - s.fc) * _exp(-(r**exponent))


def _g_loaded(s: _StaticSet, v: float, level: float, exponent: float | None) -> float:
    """``g(v)`` with both levels raised by ``level`` (``effects::g_loaded``):
    ``(fc + level) + (fs - fc)*exp(-p)``, ``p`` as :func:`_g` (``exponent`` None) or
    :func:`_g_shaped` computes it."""
    if exponent is None:
        r = v / s.vs
        e = _exp(-(r * r))
    else:
        e = _exp(-(abs(v / s.vs) ** exponent))
    return (s.fc + level) + (s.fs - s.fc) * e


def _stribeck1(p: _Friction, v: float) -> float:
    """Steady-state friction ``sign(v)*g(v) + sigma2*v``, zero at ``v == 0``."""
    if v == 0.0:
        return 0.0
    s = p.positive if v >= 0.0 else p.negative
    return (1.0 if v > 0.0 else -1.0) * _g(s, v) + s.sigma2 * v


def _eval(p: _Friction, z: float, v: float, scale: float) -> tuple[float, float, float]:
    """``(g, F, zdot)`` at state ``z`` and velocity ``v`` (``LugreParams::eval``)."""
    s = p.positive if v >= 0.0 else p.negative
    g = scale * _g(s, v)
    zdot = v - p.sigma0 * abs(v) * z / g
    f = p.sigma0 * z + p.sigma1 * zdot + s.sigma2 * v
    return g, f, zdot


def _eval_shaped(
    p: _Friction, z: float, v: float, scale: float, exponent: float
) -> tuple[float, float, float]:
    """As :func:`_eval` with the generalised curve (``LugreParams::eval_shaped``)."""
    s = p.positive if v >= 0.0 else p.negative
    g = scale * _g_shaped(s, v, exponent)
    zdot = v - p.sigma0 * abs(v) * z / g
    f = p.sigma0 * z + p.sigma1 * zdot + s.sigma2 * v
    return g, f, zdot


def _eval_loaded(
    p: _Friction, z: float, v: float, scale: float, level: float, exponent: float | None
) -> tuple[float, float, float]:
    """As :func:`_eval` (or :func:`_eval_shaped`) with the levels raised by ``level``
    (``effects::eval_loaded``, a ``load_friction``)."""
    s = p.positive if v >= 0.0 else p.negative
    g = scale * _g_loaded(s, v, level, exponent)
    zdot = v - p.sigma0 * abs(v) * z / g
    f = p.sigma0 * z + p.sigma1 * zdot + s.sigma2 * v
    return g, f, zdot


def _advance_z(p: _Friction, z: float, v: float, g: float, h: float) -> float:
    """Exact bristle update over ``h`` with ``v`` held (``LugreParams::advance_z``)."""
    if v == 0.0:
        return z
    zss = (1.0 if v > 0.0 else -1.0) * g / p.sigma0
    return zss + (z - zss) * _exp(-(p.sigma0 * abs(v) * h / g))


class _Compensator:
    """LuGre observer (``friction::Compensator``)."""

    def __init__(self, p: _Friction) -> None:
        self.p = p
        self.z = 0.0

    def step(self, v: float, dt: float) -> float:
        if not math.isfinite(v) or not math.isfinite(dt) or dt < 0.0:
            return self.p.sigma0 * self.z
        g, f, _ = _eval(self.p, self.z, v, 1.0)
        self.z = _advance_z(self.p, self.z, v, g, dt)
        return f


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

    Raises
    ------
    InputError
        ``v`` is not 1-D or holds NaN or inf.
    """
    p = _parsed(model).friction
    vv = _array("v", v).tolist()
    _check_finite("v", vv)
    return np.array([_stribeck1(p, x) for x in vv], dtype=np.float64)


def friction_force(
    v: Any,
    dt: Any,
    model: ModelLike,
    *,
    z0: float = 0.0,
    return_z: bool = False,
    scale: Any = None,
) -> np.ndarray | tuple[np.ndarray, np.ndarray]:
    """LuGre friction force driven by a sampled velocity signal.

    For ``k = 0 .. n-1``: ``F[k]`` is the force at state ``z`` and ``v[k]``; then ``z``
    advances exactly over ``dt`` (or ``dt[k]``) with ``v[k]`` held. The model's
    ``stribeck_shape`` effect, if any, sets the exponent of ``g(v)``.

    Parameters
    ----------
    v : array_like
        Velocities [m/s], 1-D.
    dt : float or array_like
        Hold interval [s]: one value, or one per sample (``dt[k]`` follows ``v[k]``).
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

    Raises
    ------
    InputError
        ``v`` or ``dt`` not finite, ``dt`` negative or of the wrong length; ``scale``
        of the wrong length, not finite or not positive.
    ParameterError
        ``z0`` not finite.
    """
    parsed = _parsed(model)
    p = parsed.friction
    exponent = parsed.stribeck_exponent
    vv = _array("v", v).tolist()
    sc = None if scale is None else _array("scale", scale).tolist()
    _check_finite("v", vv)
    try:
        dta = np.asarray(dt, dtype=float).reshape(-1)
    except (TypeError, ValueError) as e:
        raise InputError.at("dt", f"must be a number or an array of numbers ({e})") from None
    # the same checks in the same order as the core's binding
    if dta.size == 0:
        raise InputError.at("dt", "is empty: give the hold interval [s]")
    dts = dta.tolist()
    scalar = len(dts) == 1
    if not scalar:
        _check_len("dt", dts, len(vv), "v")
    _check_finite("dt", dts)
    for k, h in enumerate(dts):
        if h < 0.0:
            raise InputError.at(
                "dt", f"element {k} is {_fmt_f64(h)}: hold intervals must be >= 0"
            )
    z = _finite_option("z0", z0)
    n = len(vv)
    if sc is not None:
        _check_scale(sc, n, "v")
    out = [0.0] * n
    zs = [0.0] * n
    h = dts[0]
    for k in range(n):
        vk = vv[k]
        s = 1.0 if sc is None else sc[k]
        if exponent is None:
            g, f, _ = _eval(p, z, vk, s)
        else:
            g, f, _ = _eval_shaped(p, z, vk, s, exponent)
        out[k] = f
        zs[k] = z
        z = _advance_z(p, z, vk, g, h if scalar else dts[k])
    F = np.array(out, dtype=np.float64)
    if return_z:
        return F, np.array(zs, dtype=np.float64)
    return F
