"""The twin's model parser: the document checked with the same rules, in the same order
and with the same parameter paths as the Rust core (``src/servo/model.rs``), into the
numbers the NumPy simulators use. The product validates models with the core alone."""

from __future__ import annotations

import json
import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from ..exceptions import ModelError, ParameterError
from ..vocabulary import (
    COGGING,
    CURRENT_LAG,
    CURRENT_LIMIT,
    DEADBAND,
    DELAY,
    DRAG,
    DRIFT,
    FORCE_RIPPLE,
    GRAVITY,
    LOAD_FRICTION,
    MASS,
    NAMES,
    OFFSET,
    POSITION_FRICTION,
    RESONANCE,
    SPRING,
    STRIBECK_SHAPE,
)

__all__: list[str] = []

_TWO_PI = 2.0 * math.pi
_EFFECTS = ", ".join(NAMES)
_MISSING = "is missing: add it (see docs/DESIGN.md for the model format)"


# --------------------------------------------------------------------------------------
# Parsed form (private): the numbers the simulators use, built while validating.
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _StaticSet:
    """Stribeck parameters of one direction."""

    fc: float
    fs: float
    sigma2: float
    vs: float

    def passivity_bound(self) -> float:
        """``4*sigma2*fc/(fs - fc)``, infinite when ``fs == fc``."""
        d = self.fs - self.fc
        if d <= 0.0:
            return math.inf
        return 4.0 * self.sigma2 * self.fc / d


@dataclass(frozen=True)
class _Friction:
    """LuGre parameters."""

    sigma0: float
    sigma1: float
    positive: _StaticSet
    negative: _StaticSet


@dataclass(frozen=True)
class _CurrentLoop:
    """``kind`` is ``"first_order"`` (bandwidth_hz) or ``"rl"`` (R, L, Ke, kp, ki)."""

    kind: str
    bandwidth_hz: float = 0.0
    resistance: float = 0.0
    inductance: float = 0.0
    back_emf: float = 0.0
    kp: float = 0.0
    ki: float = 0.0


@dataclass(frozen=True)
class _Axis:
    kind: str
    mass: float
    force_constant: float
    current_loop: _CurrentLoop | None
    current_limit: float | None


@dataclass(frozen=True)
class _Effect:
    """One effect; ``params`` holds the parsed numbers (lists as tuples)."""

    kind: str
    params: dict[str, Any]


@dataclass(frozen=True)
class _Controller:
    law: str  # "pid" or "pi_speed"
    kp: float
    ki: float
    kd: float
    rate_hz: float
    ff_kind: str | None  # None, "static" or "lugre"
    ff_friction: _Friction | None


@dataclass(frozen=True)
class _Parsed:
    axis: _Axis
    friction: _Friction
    effects: tuple[_Effect, ...]
    controller: _Controller | None

    @property
    def total_mass(self) -> float:
        dm = sum(e.params["delta"] for e in self.effects if e.kind == MASS)
        return self.axis.mass + dm

    @property
    def stribeck_exponent(self) -> float | None:
        """Exponent of a ``stribeck_shape`` effect, ``None`` without one."""
        for e in self.effects:
            if e.kind == STRIBECK_SHAPE:
                return float(e.params["exponent"])
        return None


# --------------------------------------------------------------------------------------
# Validation helpers, one for one with src/servo/model.rs.
# --------------------------------------------------------------------------------------


def _join(path: str, key: str) -> str:
    return key if not path else f"{path}.{key}"


def _show(v: Any) -> str:
    try:
        return json.dumps(v)
    except (TypeError, ValueError):
        return repr(v)


def _obj(v: Any, path: str) -> Mapping[str, Any]:
    if not isinstance(v, Mapping):
        raise ModelError.at(path or "(model)", f"must be an object, found {_show(v)}")
    return v


def _get(obj: Mapping[str, Any], key: str, path: str) -> Any:
    if key not in obj:
        raise ModelError.at(_join(path, key), _MISSING)
    return obj[key]


def _as_num(v: Any, path: str) -> float:
    if isinstance(v, bool) or not isinstance(v, numbers.Real):
        raise ModelError.at(path, f"must be a number, found {_show(v)}")
    x = float(v)
    if not math.isfinite(x):
        raise ParameterError.invalid(path, x, "must be finite")
    return x


def _num(obj: Mapping[str, Any], key: str, path: str) -> float:
    return _as_num(_get(obj, key, path), _join(path, key))


def _opt_num(obj: Mapping[str, Any], key: str, path: str) -> float | None:
    v = obj.get(key)
    if v is None:
        return None
    return _as_num(v, _join(path, key))


def _positive(x: float, path: str) -> float:
    if x > 0.0:
        return x
    raise ParameterError.invalid(path, x, "must be greater than zero")


def _nonneg(x: float, path: str) -> float:
    if x >= 0.0:
        return x
    raise ParameterError.invalid(path, x, "must be zero or greater")


def _num_list(v: Any, path: str) -> list[float]:
    if not isinstance(v, (list, tuple)):
        raise ModelError.at(path, "must be a list of numbers")
    return [_as_num(x, f"{path}[{k}]") for k, x in enumerate(v)]


def _check_positive_f(name: str, x: float) -> None:
    if not (math.isfinite(x) and x > 0.0):
        raise ParameterError.invalid(name, x, "must be a finite number greater than zero")


def _check_nonnegative_f(name: str, x: float) -> None:
    if not (math.isfinite(x) and x >= 0.0):
        raise ParameterError.invalid(name, x, "must be a finite number, zero or greater")


def _validate_friction(p: _Friction, path: str) -> None:
    """``LugreParams::validate`` with the ``friction`` prefix replaced by ``path``."""
    _check_positive_f(f"{path}.sigma0", p.sigma0)
    _check_nonnegative_f(f"{path}.sigma1", p.sigma1)
    for d in ("positive", "negative"):
        s: _StaticSet = getattr(p, d)
        pre = f"{path}.{d}"
        _check_positive_f(f"{pre}.fc", s.fc)
        _check_positive_f(f"{pre}.fs", s.fs)
        _check_nonnegative_f(f"{pre}.sigma2", s.sigma2)
        _check_positive_f(f"{pre}.vs", s.vs)
        if s.fs < s.fc:
            raise ParameterError.invalid(
                f"{pre}.fs",
                s.fs,
                "must be at least fc (static friction below Coulomb friction); "
                "swap them or raise fs",
            )


def _parse_friction(f: Any, path: str) -> _Friction:
    f = _obj(f, path)
    if "model" in f and f["model"] != "lugre":
        raise ModelError.at(
            _join(path, "model"), f'is {_show(f["model"])}; only "lugre" is supported'
        )

    def static_set(d: str) -> _StaticSet:
        p = _join(path, d)
        s = _obj(_get(f, d, path), p)
        return _StaticSet(
            fc=_num(s, "fc", p), fs=_num(s, "fs", p),
            sigma2=_num(s, "sigma2", p), vs=_num(s, "vs", p),
        )

    fr = _Friction(
        sigma0=_num(f, "sigma0", path),
        sigma1=_num(f, "sigma1", path),
        positive=static_set("positive"),
        negative=static_set("negative"),
    )
    _validate_friction(fr, path)
    return fr


def _parse_effect(e: Any, path: str) -> _Effect:
    """One entry of ``effects`` (``parse_effect`` in effects.rs, checks in its order)."""
    e = _obj(e, path)
    kind = _get(e, "effect", path)
    if not isinstance(kind, str):
        raise ModelError.at(_join(path, "effect"), "must be a string")

    def n(k: str) -> float:
        return _num(e, k, path)

    def p(k: str) -> str:
        return _join(path, k)

    def phase() -> float:
        ph = _opt_num(e, "phase", path)
        return 0.0 if ph is None else ph

    if kind == COGGING:
        harmonics = _parse_harmonics(e, path)
        amplitude = n("amplitude")
        pitch = _positive(n("pitch"), p("pitch"))
        return _Effect(kind, {"amplitude": amplitude, "pitch": pitch, "phase": phase(),
                              "harmonics": harmonics})
    if kind == SPRING:
        stiffness = n("stiffness")
        x0 = _opt_num(e, "x0", path)
        return _Effect(kind, {"stiffness": stiffness, "x0": 0.0 if x0 is None else x0})
    if kind == OFFSET:
        return _Effect(kind, {"force": n("force")})
    if kind == POSITION_FRICTION:
        return _parse_position_friction(e, path)
    if kind == DRIFT:
        gain = n("gain")
        if gain >= 1.0:
            raise ParameterError.invalid(
                p("gain"), gain, "must be below 1 (friction would vanish or turn negative)"
            )
        tc = _positive(n("time_constant"), p("time_constant"))
        return _Effect(kind, {"gain": gain, "time_constant": tc})
    if kind == MASS:
        return _Effect(kind, {"delta": n("delta")})
    if kind == DELAY:
        return _Effect(kind, {"seconds": _nonneg(n("seconds"), p("seconds"))})
    if kind == CURRENT_LAG:
        return _Effect(kind, {"bandwidth_hz": _positive(n("bandwidth"), p("bandwidth"))})
    if kind == RESONANCE:
        frequency = _positive(n("frequency"), p("frequency"))
        zeta = _nonneg(n("damping_ratio"), p("damping_ratio"))
        r = n("load_fraction")
        if not (0.0 < r < 1.0):
            raise ParameterError.invalid(
                p("load_fraction"), r,
                "must lie strictly between 0 and 1 (the load's share of the total mass)",
            )
        return _Effect(kind, {"frequency_hz": frequency, "damping_ratio": zeta,
                              "load_fraction": r})
    if kind == DEADBAND:
        return _Effect(kind, {"current": _nonneg(n("current"), p("current"))})
    if kind == DRAG:
        return _Effect(kind, {"coefficient": _nonneg(n("coefficient"), p("coefficient"))})
    if kind == STRIBECK_SHAPE:
        return _Effect(kind, {"exponent": _positive(n("exponent"), p("exponent"))})
    if kind == GRAVITY:
        torque = n("torque")
        return _Effect(kind, {"torque": torque, "phase": phase()})
    if kind == LOAD_FRICTION:
        return _Effect(kind, {"coefficient": _nonneg(n("coefficient"), p("coefficient"))})
    if kind == FORCE_RIPPLE:
        a = n("amplitude")
        if abs(a) >= 1.0:
            raise ParameterError.invalid(
                p("amplitude"), a,
                "must lie strictly between -1 and 1 (a share of the force constant: at 1 the "
                "motor force would vanish at some positions)",
            )
        pitch = _positive(n("pitch"), p("pitch"))
        return _Effect(kind, {"amplitude": a, "pitch": pitch, "phase": phase()})
    if kind == CURRENT_LIMIT:
        return _Effect(kind, {"current": _positive(n("current"), p("current"))})
    raise ModelError.at(p("effect"), f'unknown effect "{kind}": use one of {_EFFECTS}')


def _parse_harmonics(e: Mapping[str, Any], path: str) -> tuple[tuple[float, float], ...]:
    """A cogging's optional ``harmonics``: ``[amplitude, phase]`` of harmonics 2, 3, ..."""
    harmonics: list[tuple[float, float]] = []
    h = e.get("harmonics")
    if h is not None:
        hp = _join(path, "harmonics")
        if not isinstance(h, (list, tuple)):
            raise ModelError.at(hp, "must be a list of [amplitude, phase] pairs")
        for k, pair in enumerate(h):
            q = _num_list(pair, f"{hp}[{k}]")
            if len(q) != 2:
                raise ModelError.at(f"{hp}[{k}]", "must be [amplitude, phase]")
            harmonics.append((q[0], q[1]))
    return tuple(harmonics)


def _parse_position_friction(e: Mapping[str, Any], path: str) -> _Effect:
    """A position_friction: breakpoints strictly increasing, one positive scale each."""
    pp, ps = _join(path, "positions"), _join(path, "scale")
    positions = _num_list(_get(e, "positions", path), pp)
    scale = _num_list(_get(e, "scale", path), ps)
    if not positions or len(positions) != len(scale):
        raise ModelError.at(
            ps, f"has {len(scale)} values for {len(positions)} positions: give one scale per "
            "position",
        )
    for k in range(len(positions) - 1):
        if positions[k + 1] <= positions[k]:
            raise ModelError.at(f"{pp}[{k + 1}]", "positions must be strictly increasing")
    for k, s in enumerate(scale):
        _positive(s, f"{ps}[{k}]")
    return _Effect(POSITION_FRICTION, {"positions": tuple(positions), "scale": tuple(scale)})


def _parse_current_loop(c: Any) -> _CurrentLoop:
    path = "axis.current_loop"
    c = _obj(c, path)
    if "inductance" in c or "resistance" in c:
        r = _nonneg(_num(c, "resistance", path), f"{path}.resistance")
        ind = _positive(_num(c, "inductance", path), f"{path}.inductance")
        ke = _opt_num(c, "back_emf", path)
        ke = _nonneg(0.0 if ke is None else ke, f"{path}.back_emf")
        bw = _opt_num(c, "bandwidth_hz", path)
        if bw is not None:
            bw = _positive(bw, f"{path}.bandwidth_hz")
            w = 2.0 * math.pi * bw
            kp, ki = w * ind, w * r
        else:
            kp = _positive(_num(c, "kp", path), f"{path}.kp")
            ki = _nonneg(_num(c, "ki", path), f"{path}.ki")
        return _CurrentLoop("rl", resistance=r, inductance=ind, back_emf=ke, kp=kp, ki=ki)
    bw = _positive(_num(c, "bandwidth_hz", path), f"{path}.bandwidth_hz")
    return _CurrentLoop("first_order", bandwidth_hz=bw)


def _parse_controller(c: Any, friction: _Friction) -> _Controller:
    path = "controller"
    c = _obj(c, path)
    kind = _get(c, "type", path)
    if not isinstance(kind, str):
        raise ModelError.at("controller.type", "must be a string")
    if kind == "pid":
        kp = _num(c, "kp", path)
        ki = _opt_num(c, "ki", path)
        kd = _opt_num(c, "kd", path)
    elif kind == "pi_speed":
        kp = _num(c, "kp", path)
        ki = _opt_num(c, "ki", path)
        kd = None
    else:
        raise ModelError.at(
            "controller.type", f'unknown controller "{kind}": use "pid" or "pi_speed"'
        )
    ki = 0.0 if ki is None else ki
    kd = 0.0 if kd is None else kd
    rate = _positive(_num(c, "rate_hz", path), "controller.rate_hz")
    ff_kind: str | None = None
    ff_friction: _Friction | None = None
    f = c.get("feedforward")
    if f is not None:
        f = _obj(f, "controller.feedforward")
        t = _get(f, "type", "controller.feedforward")
        if not isinstance(t, str) or t not in ("static", "lugre", "none"):
            raise ModelError.at(
                "controller.feedforward.type", 'must be "static", "lugre" or "none"'
            )
        if t != "none":
            ff_kind = t
            ff = f.get("friction")
            ff_friction = (
                friction if ff is None
                else _parse_friction(ff, "controller.feedforward.friction")
            )
    return _Controller(kind, kp, ki, kd, rate, ff_kind, ff_friction)


#: The keys of the axis's mass and force constant, by ``axis.kind``.
_AXIS_KEYS = {"linear": ("mass", "force_constant"), "rotary": ("inertia", "torque_constant")}


def _axis_kind(a: Mapping[str, Any]) -> str:
    """The axis's ``kind``, ``"linear"`` when absent (as ``parse_axis_kind``)."""
    k = a.get("kind")
    if k is None:
        return "linear"
    if not isinstance(k, str) or k not in _AXIS_KEYS:
        raise ModelError.at(
            "axis.kind",
            'must be "linear" (mass, force_constant) or "rotary" (inertia, torque_constant)')
    return k


def _parse(v: Mapping[str, Any]) -> _Parsed:
    """Validate a model document exactly as ``Model::from_value`` does."""
    v = _obj(v, "")
    a = _obj(_get(v, "axis", ""), "axis")
    cl = a.get("current_loop")
    current_loop = None if cl is None else _parse_current_loop(cl)
    kind = _axis_kind(a)
    mass_key, constant_key = _AXIS_KEYS[kind]
    mass = _positive(_num(a, mass_key, "axis"), "axis." + mass_key)
    kf = _positive(_num(a, constant_key, "axis"), "axis." + constant_key)
    lim = _opt_num(a, "current_limit", "axis")
    if lim is not None:
        lim = _positive(lim, "axis.current_limit")
    axis = _Axis(kind, mass, kf, current_loop, lim)
    friction = _parse_friction(_get(v, "friction", ""), "friction")
    effects = _parse_effects(v, mass, kind)
    c = v.get("controller")
    controller = None if c is None else _parse_controller(c, friction)
    return _Parsed(axis, friction, effects, controller)


def _parse_effects(v: Mapping[str, Any], mass: float, kind: str) -> tuple[_Effect, ...]:
    """Validate the ``effects`` of a model document whose axis has ``mass`` and ``kind``
    (the part of :func:`_parse` that depends on them, in its order)."""
    effects: list[_Effect] = []
    ev = v.get("effects")
    if ev is not None:
        if not isinstance(ev, (list, tuple)):
            raise ModelError.at("effects", "must be a list")
        effects = [_parse_effect(x, f"effects[{k}]") for k, x in enumerate(ev)]
    _check_effects(effects, kind)
    dm = sum(e.params["delta"] for e in effects if e.kind == MASS)
    if mass + dm <= 0.0:
        raise ParameterError.invalid(
            "effects.mass.delta", float(dm), "makes the total mass zero or negative"
        )
    return tuple(effects)


def _check_effects(effects: list[_Effect], kind: str) -> None:
    """The rules on the effects as a whole (``check_effects`` in model.rs): gravity only
    on a rotary axis, then at most one each of the one-of-a-kind effects."""
    if kind == "linear":
        for k, e in enumerate(effects):
            if e.kind == GRAVITY:
                raise ModelError.at(
                    f"effects[{k}].effect",
                    "is gravity, which acts on rotary axes only: on a linear axis a weight "
                    'is a constant force, give {"effect": "offset", "force": F} instead',
                )

    def count(name: str) -> int:
        return sum(e.kind == name for e in effects)

    if count(DELAY) > 1 or count(CURRENT_LAG) > 1:
        raise ModelError.at(
            "effects", "holds more than one delay or current_lag: merge them into one"
        )
    if count(RESONANCE) > 1 or count(STRIBECK_SHAPE) > 1:
        raise ModelError.at(
            "effects", "holds more than one resonance or stribeck_shape: keep one of each"
        )
    if count(GRAVITY) > 1 or count(LOAD_FRICTION) > 1 or count(CURRENT_LIMIT) > 1:
        raise ModelError.at(
            "effects",
            "holds more than one gravity, load_friction or current_limit: keep one of each",
        )
