"""The NumPy reference: the algorithms of ``docs/DESIGN.md`` in plain Python.

Same names, signatures, results and errors as the Rust-backed :mod:`lugre` API, written
with NumPy alone (no SciPy) as loops over Python floats that repeat the core's
(``src/friction/mod.rs``, ``src/servo/sim.rs``, ``src/estimate/``) operations in the
same order, so that the two agree bit for bit. It is slow (a few microseconds per plant
step) and meant for checking the core and for reading. Never calls :mod:`lugre._core`.

- kernels here: :func:`stribeck`, :func:`friction_force`, :func:`simulate`,
  :func:`simulate_batch`, :func:`load_coupling`;
- estimators in their own modules, imported on first use: :func:`fit_static`
  (``_reference_static``), :func:`fit_dynamic` (``_reference_dynamic``), built on
  Nelder-Mead as the core runs it (``_reference_nm``) and the robust weights
  (``_reference_robust``); their results are the facade's :class:`StaticFit` and
  :class:`DynamicFit`; :func:`steady_state_points` (``_reference_plateaus``), the
  plateau detection, returns the facade's :class:`~lugre.identify.SteadyStatePoints`;
- :func:`evaluate` runs the diagnosis's preparation of the record (SciPy filters) with
  the residual from :class:`InverseRecord`, the NumPy twin of the inverse-dynamics
  kernel (``_reference_inverse``); :func:`diagnose` and :func:`fit_inverse_dynamics`
  (``_reference_diagnose``) share the diagnosis's orchestration and take every numeric
  kernel from here, among them :func:`irls_linear_grid` (``_reference_linear``, with
  :func:`irls_linear`), the robust linear fit of the inverse dynamics;
- :func:`load_model` and :func:`save_model` are the facade's own (Python) functions.

Examples
--------
>>> from lugre import reference
>>> from lugre.model import Model
>>> m = Model.paper()
>>> float(reference.stribeck([0.01], m)[0])  # doctest: +ELLIPSIS
43.613...
"""

from __future__ import annotations

import math
from bisect import bisect_right
from collections import deque
from collections.abc import Sequence
from numbers import Integral
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from ._reference_inverse import InverseRecord
from ._result import CouplingResult, SimResult
from .exceptions import DataError, InputError, ModelError, ParameterError, _fmt_f64
from .model import (
    ModelLike,
    _as_model,
    _CurrentLoop,
    _Friction,
    _parse,
    _Parsed,
    _StaticSet,
    load_model,
    save_model,
)

if TYPE_CHECKING:  # pragma: no cover
    from ._reference_diagnose import diagnose, fit_inverse_dynamics, fit_model
    from ._reference_dynamic import DynamicFit, fit_dynamic
    from ._reference_evaluate import evaluate
    from ._reference_plateaus import steady_state_points
    from ._reference_static import StaticFit, fit_static

__all__ = [
    "CouplingResult",
    "DynamicFit",
    "InverseRecord",
    "SimResult",
    "StaticFit",
    "diagnose",
    "evaluate",
    "fit_dynamic",
    "fit_inverse_dynamics",
    "fit_model",
    "fit_static",
    "friction_force",
    "load_coupling",
    "load_model",
    "save_model",
    "simulate",
    "simulate_batch",
    "steady_state_points",
    "stribeck",
]

#: Names defined in the ``_reference_*`` modules, imported on first use: the
#: identification imports the facade's result classes, whose module imports this one.
_LAZY = {
    "DirectionFit": "._reference_static",
    "StaticFit": "._reference_static",
    "fit_static": "._reference_static",
    "DynamicFit": "._reference_dynamic",
    "fit_dynamic": "._reference_dynamic",
    "evaluate": "._reference_evaluate",
    "diagnose": "._reference_diagnose",
    "fit_inverse_dynamics": "._reference_diagnose",
    "fit_model": "._reference_diagnose",
    "steady_state_points": "._reference_plateaus",
    # the periodogram of the diagnosis (twin of lugre._native.position_sums)
    "position_sums": "._reference_inverse",
    # the robust linear fit of the inverse dynamics (twins of lugre._native.irls_linear*)
    "irls_linear": "._reference_linear",
    "irls_linear_grid": "._reference_linear",
}


def __getattr__(name: str) -> Any:
    mod = _LAZY.get(name)
    if mod is None:
        raise AttributeError(f"module 'lugre.reference' has no attribute {name!r}")
    from importlib import import_module

    value = getattr(import_module(mod, __package__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))


_PI = math.pi
_exp = math.exp


# --------------------------------------------------------------------------------------
# Input checks (src/error.rs), raising the same information as the core
# --------------------------------------------------------------------------------------


def _parsed(model: ModelLike) -> _Parsed:
    """The model's numbers, checked here from its document as the core checks its JSON:
    a :class:`~lugre.Model` built around the checks is refused by both backends alike."""
    return _parse(_as_model(model)._data)


def _array(name: str, a: Any, ndim: int = 1) -> np.ndarray:
    """``np.asarray(a, float)`` as a 1-D array (2-D: rows x columns, with ``ndim=2``),
    or InputError naming the argument."""
    try:
        arr = np.asarray(a, dtype=float)
    except (TypeError, ValueError) as e:
        raise InputError.at(name, f"must be an array of numbers ({e})") from None
    if arr.ndim != ndim:
        what = "a 1-D array" if ndim == 1 else f"a {ndim}-D array (rows x columns)"
        raise InputError.at(name, f"must be {what}, got shape {arr.shape}")
    return arr


def _check_finite(name: str, a: list[float]) -> None:
    for k, x in enumerate(a):
        if not math.isfinite(x):
            raise InputError.at(
                name, f"element {k} is {_fmt_f64(x)} : remove or interpolate non-finite samples"
            )


def _check_time(name: str, t: list[float]) -> None:
    if not t:
        raise InputError.at(name, "is empty: give at least one sample")
    _check_finite(name, t)
    for k in range(len(t) - 1):
        if t[k + 1] <= t[k]:
            raise InputError.at(
                name,
                f"time is not strictly increasing at element {k + 1} "
                f"({_fmt_f64(t[k + 1])} after {_fmt_f64(t[k])}): sort the record and "
                "drop repeated samples",
            )


def _check_len(name: str, a: list[float], n: int, of: str) -> None:
    if len(a) != n:
        raise InputError.at(
            name, f"has {len(a)} samples but {of} has {n}: give arrays of the same length"
        )


def _check_scale(sc: list[float], n: int, of: str) -> None:
    """A per-sample friction ``scale``: as long as ``of``, finite, positive (``check_scale``
    in error.rs)."""
    _check_len("scale", sc, n, of)
    _check_finite("scale", sc)
    for k, x in enumerate(sc):
        if x <= 0.0:
            raise InputError.at(
                "scale",
                f"element {k} is {_fmt_f64(x)}: the friction scale must be greater than zero",
            )


def _finite_option(name: str, value: Any) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ParameterError.invalid(name, value, "must be a finite number") from None
    if not math.isfinite(x):
        raise ParameterError.invalid(name, x, "must be finite")
    return x


def _check_substeps_type(substeps: Any) -> None:
    """``substeps`` must be an integer (its range is checked with the other inputs)."""
    if isinstance(substeps, bool) or not isinstance(substeps, Integral):
        raise TypeError(f"substeps must be an integer, got {type(substeps).__name__}")


def _select_drive(x_ref: Any, v_ref: Any, current: Any) -> tuple[str, Any]:
    """The one drive given: ``("x_ref" | "v_ref" | "current", array_like)``."""
    drives = [(k, a) for k, a in (("x_ref", x_ref), ("v_ref", v_ref), ("current", current))
              if a is not None]
    if not drives:
        raise InputError.at(
            "x_ref",
            "nothing drives the axis: give a position reference x_ref, a speed reference "
            "v_ref, or an open-loop current",
        )
    if len(drives) > 1:
        raise InputError.at(
            drives[1][0],
            f"give only one of x_ref, v_ref and current (got {drives[0][0]} and "
            f"{drives[1][0]})",
        )
    return drives[0]


# --------------------------------------------------------------------------------------
# Friction (src/friction/mod.rs)
# --------------------------------------------------------------------------------------


def _g(s: _StaticSet, v: float) -> float:
    """``g(v) = fc + (fs - fc)*exp(-(v/vs)^2)``."""
    r = v / s.vs
    return s.fc + (s.fs - s.fc) * _exp(-(r * r))


def _g_shaped(s: _StaticSet, v: float, exponent: float) -> float:
    """``g(v) = fc + (fs - fc)*exp(-|v/vs|^exponent)`` (``StaticSet::g_shaped``)."""
    r = abs(v / s.vs)
    return s.fc + (s.fs - s.fc) * _exp(-(r**exponent))


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


# --------------------------------------------------------------------------------------
# Servo simulation (src/servo/sim.rs)
# --------------------------------------------------------------------------------------


class _Interp:
    """``np.interp`` with a forward-moving cursor (queries must not decrease)."""

    def __init__(self, t: list[float], y: list[float]) -> None:
        self.t, self.y, self.j, self.n = t, y, 0, len(t)

    def at(self, tq: float) -> float:
        t, y, n = self.t, self.y, self.n
        if tq <= t[0]:
            return y[0]
        if tq >= t[n - 1]:
            return y[n - 1]
        while self.j + 1 < n and t[self.j + 1] <= tq:
            self.j += 1
        j = self.j
        t0, t1 = t[j], t[j + 1]
        if tq == t0:
            return y[j]
        y0 = y[j]
        return y0 + (y[j + 1] - y0) * (tq - t0) / (t1 - t0)


def _interp_clamped(xp: tuple[float, ...], fp: tuple[float, ...], x: float) -> float:
    n = len(xp)
    if x <= xp[0]:
        return fp[0]
    if x >= xp[n - 1]:
        return fp[n - 1]
    j = bisect_right(xp, x)  # first index with xp[j] > x
    x0, x1 = xp[j - 1], xp[j]
    return fp[j - 1] + (fp[j] - fp[j - 1]) * (x - x0) / (x1 - x0)


class _State:
    __slots__ = ("fl", "ia", "q", "v", "vl", "x", "xl", "z")

    def __init__(self, x: float, v: float, z: float) -> None:
        self.x, self.v, self.z = x, v, z
        self.ia = self.q = self.fl = 0.0
        self.xl, self.vl = x, v  # load (resonance)


class _TwoMass:
    """The two bodies of the ``resonance`` effect (``TwoMass`` in sim.rs)."""

    def __init__(self, mass: float, frequency_hz: float, damping_ratio: float,
                 r: float) -> None:
        self.mm = (1.0 - r) * mass
        self.ml = r * mass
        w = 2.0 * _PI * frequency_hz
        self.k = self.ml * (w * w)
        self.c = 2.0 * damping_ratio * math.sqrt(self.k * self.ml)

    def free_mode(self) -> tuple[float, float]:
        """Angular frequency and damping ratio of the relative motor-load motion."""
        mu = self.mm * self.ml / (self.mm + self.ml)
        w = math.sqrt(self.k / mu)
        return w, self.c / (2.0 * mu * w)


class _Physics:
    """Extra physics flattened for the inner loop (``Physics`` in sim.rs)."""

    def __init__(self, m: _Parsed, t0: float) -> None:
        self.mass = m.total_mass
        self.kf = m.axis.force_constant
        self.fr = m.friction
        self.lin_a = 0.0
        self.lin_b = 0.0
        self.cogging: list[tuple[float, float, float]] = []
        self.pos_scale: list[tuple[tuple[float, ...], tuple[float, ...]]] = []
        self.drift: list[tuple[float, float]] = []
        self.current_loop: _CurrentLoop | None = m.axis.current_loop
        self.lag_w: float | None = None
        self.delay: float | None = None
        self.t0 = t0
        self.shape: float | None = None
        self.drag = 0.0
        self.deadband: float | None = None
        self.res: _TwoMass | None = None
        for e in m.effects:
            q = e.params
            if e.kind == "cogging":
                w = 2.0 * _PI / q["pitch"]
                self.cogging.append((q["amplitude"], w, q["phase"]))
                for k, (a, ph) in enumerate(q["harmonics"]):
                    self.cogging.append((a, w * (k + 2.0), ph))
            elif e.kind == "spring":
                self.lin_a += q["stiffness"]
                self.lin_b -= q["stiffness"] * q["x0"]
            elif e.kind == "offset":
                self.lin_b += q["force"]
            elif e.kind == "position_friction":
                self.pos_scale.append((q["positions"], q["scale"]))
            elif e.kind == "drift":
                self.drift.append((q["gain"], q["time_constant"]))
            elif e.kind == "delay":
                self.delay = q["seconds"]
            elif e.kind == "current_lag":
                self.lag_w = 2.0 * _PI * q["bandwidth_hz"]
            elif e.kind == "resonance":
                self.res = _TwoMass(self.mass, q["frequency_hz"], q["damping_ratio"],
                                    q["load_fraction"])
            elif e.kind == "deadband":
                self.deadband = q["current"]
            elif e.kind == "drag":
                self.drag += q["coefficient"]
            elif e.kind == "stribeck_shape":
                self.shape = q["exponent"]
        self.has_scale = bool(self.pos_scale) or bool(self.drift)

    def scale(self, x: float, time: float) -> float:
        if not self.has_scale:
            return 1.0
        s = 1.0
        for xp, fp in self.pos_scale:
            s *= _interp_clamped(xp, fp, x)
        for gain, tau in self.drift:
            s *= 1.0 - gain * (1.0 - _exp(-(time - self.t0) / tau))
        return s

    def load(self, s: _State) -> tuple[float, float]:
        """Position and velocity of the body carrying friction and effects."""
        return (s.xl, s.vl) if self.res is not None else (s.x, s.v)

    def friction(self, z: float, v: float, scale: float) -> tuple[float, float, float]:
        """``(g, F, zdot)`` of the plant's friction (``stribeck_shape`` applied)."""
        if self.shape is not None:
            return _eval_shaped(self.fr, z, v, scale, self.shape)
        return _eval(self.fr, z, v, scale)

    def deadband_of(self, i: float) -> float:
        """The current that produces force (``deadband``)."""
        c = self.deadband
        if c is None:
            return i
        if i > c:
            return i - c
        if i < -c:
            return i + c
        return 0.0

    def effect_force(self, x: float, v: float) -> float:
        f = self.lin_a * x + self.lin_b
        for a, w, ph in self.cogging:
            f += a * math.sin(w * x + ph)
        if self.drag != 0.0:
            f += self.drag * abs(v) * v
        return f

    def accel(
        self, fm: float, x: float, v: float, z: float, time: float
    ) -> tuple[float, float, float]:
        s = self.scale(x, time)
        g, f, zdot = self.friction(z, v, s)
        return (fm - f - self.effect_force(x, v)) / self.mass, g, zdot

    def motor(self, s: _State, ic: float, h: float) -> float:
        """Advance the current (loop) and the lagged force over ``h``; the motor force."""
        cl = self.current_loop
        if cl is None:
            s.ia = ic
        elif cl.kind == "first_order":
            s.ia = ic + (s.ia - ic) * _exp(-2.0 * _PI * cl.bandwidth_hz * h)
        else:
            r, ind, ke, kp, ki = cl.resistance, cl.inductance, cl.back_emf, cl.kp, cl.ki
            wc = kp / ind
            ns = max(math.ceil(h * wc * 4.0), 1)
            hs = h / ns
            v = s.v

            def d(ia: float, q: float) -> tuple[float, float]:
                return (kp * (ic - ia) + ki * q - r * ia - ke * v) / ind, ic - ia

            for _ in range(ns):
                a1, b1 = d(s.ia, s.q)
                a2, b2 = d(s.ia + 0.5 * hs * a1, s.q + 0.5 * hs * b1)
                a3, b3 = d(s.ia + 0.5 * hs * a2, s.q + 0.5 * hs * b2)
                a4, b4 = d(s.ia + hs * a3, s.q + hs * b3)
                s.ia += hs / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)
                s.q += hs / 6.0 * (b1 + 2.0 * b2 + 2.0 * b3 + b4)
        fm = self.kf * self.deadband_of(s.ia)
        if self.lag_w is None:
            return fm
        s.fl = fm + (s.fl - fm) * _exp(-self.lag_w * h)
        return s.fl

    def step_exact(self, s: _State, ic: float, h: float, time: float) -> None:
        fm = self.motor(s, ic, h)
        r = self.res
        if r is not None:
            # two bodies: semi-implicit Euler for both, exact bristle update on the load
            g, f, _ = self.friction(s.z, s.vl, self.scale(s.xl, time))
            fc = r.k * (s.x - s.xl) + r.c * (s.v - s.vl)
            am = (fm - fc) / r.mm
            al = (fc - f - self.effect_force(s.xl, s.vl)) / r.ml
            s.z = _advance_z(self.fr, s.z, s.vl, g, h)
            s.v += am * h
            s.vl += al * h
            s.x += s.v * h
            s.xl += s.vl * h
            return
        a, g, _ = self.accel(fm, s.x, s.v, s.z, time)
        s.z = _advance_z(self.fr, s.z, s.v, g, h)
        s.v += a * h
        s.x += s.v * h

    def step_rk4_two_mass(self, s: _State, fm: float, r: _TwoMass, h: float,
                          time: float) -> None:
        """RK4 on ``(x, v, xl, vl, z)`` of the two-mass axis, the motor force held."""

        def d(x: float, v: float, xl: float, vl: float, z: float,
              tm: float) -> tuple[float, float, float, float, float]:
            _, f, zdot = self.friction(z, vl, self.scale(xl, tm))
            fc = r.k * (x - xl) + r.c * (v - vl)
            return v, (fm - fc) / r.mm, vl, (fc - f - self.effect_force(xl, vl)) / r.ml, zdot

        x, v, xl, vl, z = s.x, s.v, s.xl, s.vl, s.z
        k1 = d(x, v, xl, vl, z, time)
        k2 = d(x + 0.5 * h * k1[0], v + 0.5 * h * k1[1], xl + 0.5 * h * k1[2],
               vl + 0.5 * h * k1[3], z + 0.5 * h * k1[4], time + 0.5 * h)
        k3 = d(x + 0.5 * h * k2[0], v + 0.5 * h * k2[1], xl + 0.5 * h * k2[2],
               vl + 0.5 * h * k2[3], z + 0.5 * h * k2[4], time + 0.5 * h)
        k4 = d(x + h * k3[0], v + h * k3[1], xl + h * k3[2], vl + h * k3[3], z + h * k3[4],
               time + h)
        s.x += h / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0])
        s.v += h / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1])
        s.xl += h / 6.0 * (k1[2] + 2.0 * k2[2] + 2.0 * k3[2] + k4[2])
        s.vl += h / 6.0 * (k1[3] + 2.0 * k2[3] + 2.0 * k3[3] + k4[3])
        s.z += h / 6.0 * (k1[4] + 2.0 * k2[4] + 2.0 * k3[4] + k4[4])

    def rk4_pieces(self, z: float, v: float, x: float, h: float, time: float) -> int:
        """Pieces of an RK4 step keeping ``sigma0*|v|*h/g`` under the limit
        (``Physics::rk4_pieces``)."""
        if v == 0.0:
            return 1
        g, _, _ = self.friction(z, v, self.scale(x, time))
        q = self.fr.sigma0 * abs(v) * h / g
        if math.isnan(q) or q <= _RK4_BRISTLE_LIMIT:  # (NaN: the divergence check)
            return 1
        return int(min(_ceil_f(q / _RK4_BRISTLE_LIMIT), _RK4_MAX_PIECES))

    def step_rk4(self, s: _State, ic: float, h_step: float, time: float) -> None:
        """One plant step of RK4, the motor force held, in equal pieces where the
        bristles would make it unstable (``Physics::step_rk4``)."""
        fm = self.motor(s, ic, h_step)
        x, v = (s.xl, s.vl) if self.res is not None else (s.x, s.v)
        p = self.rk4_pieces(s.z, v, x, h_step, time)
        h = h_step / float(p)
        for j in range(p):
            tj = time + float(j) * h
            if self.res is not None:
                self.step_rk4_two_mass(s, fm, self.res, h, tj)
            else:
                self.step_rk4_one_mass(s, fm, h, tj)

    def step_rk4_one_mass(self, s: _State, fm: float, h: float, time: float) -> None:
        """RK4 on ``(x, v, z)`` of the rigid axis, the motor force held."""

        def d(x: float, v: float, z: float, tm: float) -> tuple[float, float, float]:
            a, _, zdot = self.accel(fm, x, v, z, tm)
            return v, a, zdot

        x, v, z = s.x, s.v, s.z
        k1 = d(x, v, z, time)
        k2 = d(x + 0.5 * h * k1[0], v + 0.5 * h * k1[1], z + 0.5 * h * k1[2], time + 0.5 * h)
        k3 = d(x + 0.5 * h * k2[0], v + 0.5 * h * k2[1], z + 0.5 * h * k2[2], time + 0.5 * h)
        k4 = d(x + h * k3[0], v + h * k3[1], z + h * k3[2], time + h)
        s.x += h / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0])
        s.v += h / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1])
        s.z += h / 6.0 * (k1[2] + 2.0 * k2[2] + 2.0 * k3[2] + k4[2])


#: Largest ``sigma0*|v|*h/g`` of one RK4 step (``RK4_BRISTLE_LIMIT`` in sim.rs).
_RK4_BRISTLE_LIMIT = 1.0
#: Most pieces of one RK4 plant step (``RK4_MAX_PIECES``).
_RK4_MAX_PIECES = 1e4


def _ic_eff_peek(queue: deque[tuple[float, float]], current: float, time: float,
                 tol: float) -> float:
    """The delayed command that would act at ``time`` (for reporting the motor force)."""
    v = current
    for te, val in queue:
        if te <= time + tol:
            v = val
        else:
            break
    return v


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

    The digital controller runs at ``controller.rate_hz`` with its output held between
    updates; the plant is advanced in substeps between events (control instants and
    sample times), as fixed in ``docs/DESIGN.md``.

    Parameters
    ----------
    model : Model, dict or path
        The axis model. Closed loop needs its ``controller``.
    t : array_like
        Sample times [s], strictly increasing; the simulation starts at ``t[0]``.
    x_ref : array_like, optional
        Position reference [m] at ``t`` for a ``pid`` controller.
    v_ref : array_like, optional
        Speed reference [m/s] at ``t`` for a ``pi_speed`` controller.
    current : array_like, optional
        Open loop: current command [A] at ``t``, held between samples (the controller
        is not used). Give exactly one of ``x_ref``, ``v_ref`` and ``current``.
    integrator : {"exact", "rk4"}, default "exact"
        ``"exact"``: exact bristle update with the velocity held and semi-implicit Euler
        for x and v; ``"rk4"``: classic RK4 on (x, v, z), a plant step split in
        equal pieces where ``sigma0*|v|*h/g`` would exceed 1 at its start (beyond 2.78
        the bristles make RK4 unstable).
    substeps : int, default 1
        Plant steps per control period (per sample interval in open loop).
    z0 : float, default 0.0
        Initial bristle deflection [m].
    x0 : float, optional
        Initial position [m]; by default ``x_ref[0]`` (0 without a position reference).
    v0 : float, default 0.0
        Initial velocity [m/s].

    Returns
    -------
    SimResult
        ``t``, ``x``, ``v``, ``z``, ``i``, ``friction`` and ``force`` at the sample times.

    Raises
    ------
    InputError
        ``t`` empty, not finite or not strictly increasing; the drive of another length
        or not finite; the wrong drive for the controller; unknown integrator.
    ParameterError
        ``substeps`` below 1; ``z0``, ``x0`` or ``v0`` not finite.
    ModelError
        Closed loop without a controller.
    DataError
        The simulation diverged.
    """
    return _simulate(_parsed(model), t, x_ref, v_ref=v_ref, current=current,
                     integrator=integrator, substeps=substeps, z0=z0, x0=x0, v0=v0)


def _simulate(
    m: _Parsed,
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
    """:func:`simulate` of a parsed model (the estimators change its numbers directly,
    as the core does, without building and checking a document each time)."""
    if integrator not in ("exact", "rk4"):
        raise InputError.at(
            "integrator", f'unknown integrator "{integrator}": use "exact" or "rk4"'
        )
    _check_substeps_type(substeps)
    kind, drive_in = _select_drive(x_ref, v_ref, current)
    ta = _array("t", t)
    tl = ta.tolist()
    ref = _array(kind, drive_in).tolist()
    open_loop = kind == "current"

    # ---- check_inputs ---------------------------------------------------------------
    _check_time("t", tl)
    name = {"x_ref": "x_ref", "v_ref": "v_ref", "current": "i"}[kind]
    _check_len(name, ref, len(tl), "t")
    _check_finite(name, ref)
    if int(substeps) < 1:
        raise ParameterError.invalid("substeps", float(substeps), "must be at least 1")
    substeps = int(substeps)
    z_init = _finite_option("z0", z0)
    v_init = _finite_option("v0", v0)
    x_opt = None if x0 is None else _finite_option("x0", x0)
    if open_loop:
        if len(tl) < 2:
            raise InputError.at("t", "open-loop simulation needs at least two samples")
    else:
        c = m.controller
        if c is None:
            raise ModelError.at(
                "controller",
                "is missing: closed-loop simulation needs a controller (add one, or "
                "drive the axis with a current)",
            )
        if c.law == "pid" and kind == "v_ref":
            raise InputError.at(
                "v_ref", "the model's controller is a position PID: give x_ref instead"
            )
        if c.law == "pi_speed" and kind == "x_ref":
            raise InputError.at(
                "x_ref", "the model's controller is a PI speed loop: give v_ref instead"
            )

    # ---- check_resonance_step -------------------------------------------------------
    for e in m.effects:
        if e.kind == "resonance":
            q = e.params
            tm = _TwoMass(m.total_mass, q["frequency_hz"], q["damping_ratio"],
                          q["load_fraction"])
            w, zeta = tm.free_mode()
            limit = math.sqrt(1.0 + zeta * zeta) - zeta
            if not open_loop:
                assert m.controller is not None
                hh = 1.0 / (m.controller.rate_hz * substeps)
            else:
                hh = (tl[-1] - tl[0]) / (len(tl) - 1) / substeps
            if w * hh > limit:
                need = math.ceil(substeps * w * hh / limit)
                raise ParameterError.invalid(
                    "substeps", float(substeps),
                    "is too few for the resonance effect: its free motor-load mode at "
                    f"{w / (2.0 * _PI):.1f} Hz needs plant steps below "
                    f"{limit / (2.0 * _PI):.3f} of its period; use substeps >= {need} "
                    "(or a higher control rate)",
                )

    # ---- simulate -------------------------------------------------------------------
    n_out = len(tl)
    t0 = tl[0]
    phys = _Physics(m, t0)
    ctrl = None if open_loop else m.controller
    rate = ctrl.rate_hz if ctrl is not None else 0.0
    if open_loop:
        h_max = (tl[n_out - 1] - t0) / (n_out - 1) / substeps
        tol = 1e-9 * (tl[n_out - 1] - t0) / (n_out - 1)
    else:
        h_max = 1.0 / (rate * substeps)
        tol = 1e-9 / rate
    interp = _Interp(tl, ref)
    x_init = x_opt if x_opt is not None else (ref[0] if kind == "x_ref" else 0.0)
    s = _State(x_init, v_init, z_init)
    comp = (
        _Compensator(ctrl.ff_friction)
        if ctrl is not None and ctrl.ff_kind == "lugre" and ctrl.ff_friction is not None
        else None
    )
    step: Callable[[_State, float, float, float], None] = (
        phys.step_exact if integrator == "exact" else phys.step_rk4
    )
    lim = m.axis.current_limit
    out_x: list[float] = []
    out_v: list[float] = []
    out_z: list[float] = []
    out_i: list[float] = []
    out_f: list[float] = []
    out_fm: list[float] = []
    queue: deque[tuple[float, float]] = deque()
    xi = 0.0
    xr_prev = 0.0
    ic = 0.0  # latest command
    ic_eff = 0.0  # command acting on the drive (after delay)
    time = t0
    k = 0
    n = 0

    def ctrl_time(n: int) -> float:
        if open_loop:
            return tl[n] if n < n_out else math.inf
        return t0 + n / rate

    tc = ctrl_time(0)
    while True:
        if time >= tc - tol:
            # controller (or open-loop command) update
            if ctrl is not None:
                xr = interp.at(tc)
                if ctrl.law == "pid":
                    xr_dot = 0.0 if n == 0 else (xr - xr_prev) * rate
                    xr_prev = xr
                    e = xr - s.x
                    xi += e / rate
                    u = ctrl.kp * e + ctrl.ki * xi + ctrl.kd * (xr_dot - s.v)
                    vr = xr_dot
                else:
                    e = xr - s.v
                    xi += e / rate
                    u = ctrl.kp * e + ctrl.ki * xi
                    vr = xr
                if ctrl.ff_kind is None or ctrl.ff_friction is None:
                    f_ff = 0.0
                elif ctrl.ff_kind == "static":
                    f_ff = _stribeck1(ctrl.ff_friction, vr)
                else:
                    assert comp is not None
                    f_ff = comp.step(vr, 1.0 / rate)
                ic = (u + f_ff) / phys.kf
                if lim is not None:
                    ic = max(min(ic, lim), -lim)  # f64::clamp
            else:
                ic = ref[n]
            if phys.delay is None:
                ic_eff = ic
            else:
                queue.append((tc + phys.delay, ic))
            n += 1
            tc = ctrl_time(n)
        while k < n_out and tl[k] <= time + tol:
            xl, vl = phys.load(s)
            sc = phys.scale(xl, time)
            _, f, _ = phys.friction(s.z, vl, sc)
            out_x.append(s.x)
            out_v.append(s.v)
            out_z.append(s.z)
            out_i.append(s.ia if phys.current_loop is not None else ic)
            out_f.append(f)
            if phys.current_loop is not None:
                fm = phys.kf * phys.deadband_of(s.ia)
            elif phys.delay is not None:
                fm = phys.kf * phys.deadband_of(_ic_eff_peek(queue, ic_eff, time, tol))
            else:
                fm = phys.kf * phys.deadband_of(ic_eff)
            out_fm.append(s.fl if phys.lag_w is not None else fm)
            k += 1
        if k == n_out:
            break
        nxt = min(tc, tl[k])
        msteps = max(math.ceil((nxt - time) / h_max - 1e-6), 1)
        h = (nxt - time) / msteps
        for j in range(msteps):
            tj = time + j * h
            if phys.delay is not None:
                while queue and queue[0][0] <= tj + tol:
                    ic_eff = queue.popleft()[1]
            step(s, ic_eff, h, tj)
        if not (math.isfinite(s.x) and math.isfinite(s.v) and math.isfinite(s.z)
                and math.isfinite(s.xl) and math.isfinite(s.vl)):
            hint = ("check the current against the mass, or give more substeps" if open_loop
                    else "check the controller gains against the mass and the control rate, "
                    "or give more substeps")
            raise DataError(
                f"data: the simulation diverged at t = {_fmt_f64(time)}: {hint}"
            )
        time = nxt
    return SimResult(ta.copy(), out_x, out_v, out_z, out_i, out_f, out_fm)


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
    """Simulate many models on the same input: :func:`simulate` for each, in order.

    Parameters are those of :func:`simulate`, with a sequence of models. As in the core,
    the inputs are converted and every model is checked before the first simulation,
    and the first model that fails raises.

    Returns
    -------
    list of SimResult
        One per model, in order.
    """
    kind, drive = _select_drive(x_ref, v_ref, current)
    _array("t", t)
    _array(kind, drive)
    _check_substeps_type(substeps)
    models = list(models)
    for m in models:
        _parsed(m)
    return [simulate(m, t, integrator=integrator, substeps=substeps, z0=z0, x0=x0, v0=v0,
                     **{kind: drive}) for m in models]


# --------------------------------------------------------------------------------------
# The load behind the resonance coupling (src/servo/coupling.rs)
# --------------------------------------------------------------------------------------

#: Most substeps allowed per sample interval (``MAX_SUBSTEPS`` in coupling.rs).
_MAX_COUPLING_SUBSTEPS = 1e6


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

    The model's ``resonance`` joins the motor ``(1 - r)*M`` (measured by the encoder) to
    the load ``r*M`` (carrying the friction and the other effects) by a spring
    ``k = r*M*(2*pi*frequency)^2`` and a damper ``c = 2*damping_ratio*sqrt(k*r*M)``. The
    load starts at ``x[0]``, ``v[0]`` with ``z = z0`` and is driven by the motor position
    and velocity, interpolated linearly between samples, over
    ``substeps*max(1, ceil(4*w*dt), ceil(d*dt))`` equal substeps per interval,
    ``w = sqrt((k + sigma0)/(r*M))``, ``d = (c + sigma1 + max(sigma2))/(r*M)``. Each
    substep (length ``h``), at its start:
    ``F_s = k*(x_m - x_l) + c*(v_m - v_l)``, friction ``(g, F)`` at ``(z, v_l)`` with
    ``scale[k]`` and the model's Stribeck exponent,
    ``a_l = (F_s - F - extra[k])/(r*M)``; then the exact bristle update of ``z`` over
    ``h`` with ``v_l`` held, ``v_l += a_l*h``, ``x_l += v_l*h`` (``docs/DESIGN.md``).

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
        ``(force, x_load, v_load, z)`` at each sample, evaluated at the state before
        the step that follows it: the coupling force [N], the load's position [m] and
        velocity [m/s] and its bristle deflection [m].

    Raises
    ------
    ModelError
        The model has no ``resonance`` (path ``effects``).
    InputError
        ``x``, ``v``, ``scale`` or ``extra`` not 1-D, not finite or of another length
        than ``x``; ``scale`` not positive.
    ParameterError
        ``dt`` not finite or <= 0, or so long that an interval would need more than 1e6
        substeps; ``z0`` not finite; ``substeps`` below 1.
    DataError
        The load's state turned non-finite.
    """
    # the facade's conversions, then the core's checks in the core's order
    parsed = _parsed(model)
    xa = _array("x", x).tolist()
    va = _array("v", v).tolist()
    sc = None if scale is None else _array("scale", scale).tolist()
    ex = None if extra is None else _array("extra", extra).tolist()
    dtf = _finite_option_any("dt", dt)
    _check_substeps_type(substeps)
    res = next((e.params for e in parsed.effects if e.kind == "resonance"), None)
    if res is None:
        raise ModelError.at(
            "effects",
            "has no resonance: the load behind a coupling needs one; add "
            '{"effect": "resonance", "frequency": F, "damping_ratio": Z, '
            '"load_fraction": R} to the model\'s effects',
        )
    tm = _TwoMass(parsed.total_mass, res["frequency_hz"], res["damping_ratio"],
                  res["load_fraction"])
    p = parsed.friction
    exponent = parsed.stribeck_exponent
    # the same checks in the same order as the core (coupling.rs, check_inputs)
    _check_finite("x", xa)
    n = len(xa)
    _check_len("v", va, n, "x")
    _check_finite("v", va)
    if not (math.isfinite(dtf) and dtf > 0.0):
        raise ParameterError.invalid(
            "dt", dtf, "must be a finite sample interval greater than zero [s]"
        )
    z = _finite_option("z0", z0)
    if substeps < 1:
        raise ParameterError.invalid("substeps", 0.0, "must be at least 1")
    if sc is not None:
        _check_scale(sc, n, "x")
    if ex is not None:
        _check_len("extra", ex, n, "x")
        _check_finite("extra", ex)
    kc, c, ml = tm.k, tm.c, tm.ml
    w = math.sqrt((kc + p.sigma0) / ml)
    d = (c + p.sigma1 + max(p.positive.sigma2, p.negative.sigma2)) / ml
    q_stiff = 4.0 * w * dtf
    q_damp = d * dtf
    nsub_f = max(_ceil_f(q_stiff), _ceil_f(q_damp), 1.0) * float(int(substeps))
    if nsub_f > _MAX_COUPLING_SUBSTEPS:
        raise ParameterError.invalid(
            "dt", dtf,
            f"needs {_fmt_f64(nsub_f)} substeps per sample for the coupling and bristle "
            f"stiffness (at most {_fmt_f64(_MAX_COUPLING_SUBSTEPS)}): give samples at a "
            "shorter interval",
        )
    nsub = int(nsub_f)
    out_f = [0.0] * n
    out_x = [0.0] * n
    out_v = [0.0] * n
    out_z = [0.0] * n
    if n == 0:
        return CouplingResult(*(np.array(a, dtype=np.float64)
                                for a in (out_f, out_x, out_v, out_z)))
    h = dtf / nsub
    hh = 0.5 * h
    nf = float(nsub)
    # xl at the substep's start, vl at the middle of the substep before, al its
    # acceleration
    xl, vl, al = xa[0], va[0], 0.0
    for i in range(n):
        x0, v0 = xa[i], va[i]
        vt = vl + hh * al
        out_f[i] = kc * (x0 - xl) + c * (v0 - vt)
        out_x[i] = xl
        out_v[i] = vt
        out_z[i] = z
        if i + 1 == n:
            break
        s = 1.0 if sc is None else sc[i]
        fe = 0.0 if ex is None else ex[i]
        dx, dv = xa[i + 1] - x0, va[i + 1] - v0
        for j in range(nsub):
            if j == 0:
                xm, vm = x0, v0
            else:
                f = j / nf
                xm, vm = x0 + dx * f, v0 + dv * f
            vt = vl + hh * al
            vz = vl + h * al
            fs = kc * (xm - xl) + c * (vm - vt)
            if exponent is None:
                g, ff, _ = _eval(p, z, vt, s)
            else:
                g, ff, _ = _eval_shaped(p, z, vt, s, exponent)
            al = (fs - ff - fe) / ml
            z = _advance_z(p, z, vz, g, h)
            vl += al * h
            xl += vl * h
        if not (math.isfinite(xl) and math.isfinite(vl) and math.isfinite(z)):
            raise DataError(
                f"data: the load behind the coupling diverged after sample {i}: check "
                "the motor motion and the model's resonance"
            )
    return CouplingResult(*(np.array(a, dtype=np.float64)
                            for a in (out_f, out_x, out_v, out_z)))


def _ceil_f(q: float) -> float:
    """``f64::ceil`` (``math.ceil`` returns an int and fails on inf)."""
    return float(math.ceil(q)) if math.isfinite(q) else q


def _finite_option_any(name: str, value: Any) -> float:
    """``float(value)`` or ParameterError (finiteness is checked by the caller)."""
    try:
        return float(value)
    except (TypeError, ValueError):
        raise ParameterError.invalid(name, value, "must be a finite number") from None
