"""The load behind the resonance coupling (``src/servo/coupling.rs``), driven by the
measured motor motion: :func:`load_coupling`."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._args import as_array as _array
from .._args import check_substeps_type as _check_substeps_type
from .._result import CouplingResult
from ..exceptions import DataError, InputError, ModelError, ParameterError, _fmt_f64
from ..model import ModelLike
from ..vocabulary import RESONANCE
from .checks import (
    _ceil_f,
    _check_finite,
    _check_len,
    _check_scale,
    _finite_option,
    _finite_option_any,
    _parsed,
)
from .friction import _advance_z, _eval, _eval_loaded, _eval_shaped
from .parsed import _Friction
from .plant import _TwoMass

__all__ = ["load_coupling"]


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
    return _load_coupling(x, v, dt, model, scale=scale, extra=extra, z0=z0,
                          substeps=substeps)


def _load_coupling(x: Any, v: Any, dt: float, model: ModelLike, *, scale: Any = None,
                   extra: Any = None, level: Any = None, z0: float = 0.0,
                   substeps: int = 1) -> CouplingResult:
    """:func:`load_coupling` with ``level``: the rise of both friction levels per sample
    [N] (a ``load_friction``'s ``coefficient*|F_m|``, ``CouplingOptions::level``), which
    the inverse dynamics gives and the facade does not offer."""
    # the facade's conversions, then the core's checks in the core's order
    parsed = _parsed(model)
    xa = _array("x", x).tolist()
    va = _array("v", v).tolist()
    sc = None if scale is None else _array("scale", scale).tolist()
    ex = None if extra is None else _array("extra", extra).tolist()
    lv = None if level is None else _array("level", level).tolist()
    dtf = _finite_option_any("dt", dt)
    _check_substeps_type(substeps)
    res = next((e.params for e in parsed.effects if e.kind == RESONANCE), None)
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
    if lv is not None:
        _check_len("level", lv, n, "x")
        _check_finite("level", lv)
        for k, u in enumerate(lv):
            if u < 0.0:
                raise InputError.at(
                    "level", f"element {k} is {_fmt_f64(u)}: give levels of zero or more")
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
    return _drive_load(xa, va, sc, ex, lv, dtf, int(nsub_f), z, tm, p, exponent)


def _drive_load(xa: list[float], va: list[float], sc: list[float] | None,
                ex: list[float] | None, lv: list[float] | None, dtf: float, nsub: int,
                z: float, tm: _TwoMass, p: _Friction, exponent: float | None
                ) -> CouplingResult:
    """The load driven along the checked motor motion, ``nsub`` substeps per interval
    (the friction levels raised by ``lv[i]`` over interval ``i`` when given)."""
    n = len(xa)
    kc, c, ml = tm.k, tm.c, tm.ml
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
        lvi = None if lv is None else lv[i]
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
            if lvi is not None:
                g, ff, _ = _eval_loaded(p, z, vt, s, lvi, exponent)
            elif exponent is None:
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
