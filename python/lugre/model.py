"""The axis model: a validated JSON document (``docs/DESIGN.md``, a superset of CONTRACT).

A :class:`Model` keeps the document as a plain ``dict`` (unknown keys included, so that
they are written back on save) and checks it on construction with the same rules, in
the same order and with the same parameter paths as the Rust core
(``src/servo/model.rs``): a value out of range raises :class:`~lugre.exceptions.ParameterError`
naming its path (``friction.negative.vs``, ``axis.mass``, ``effects[2].pitch``), a
structural problem (missing key, wrong type, unknown effect) raises
:class:`~lugre.exceptions.ModelError`.

Examples
--------
>>> m = Model.paper()
>>> m.mass, m.positive["fs"]
(25.0, 60.2)
>>> m2 = m.with_friction(sigma1=40.0)
>>> m2.sigma1, m.sigma1
(40.0, 31.62)
"""

from __future__ import annotations

import copy as _copy
import json
import math
import numbers
import os
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Union

from .exceptions import InputError, ModelError, ParameterError, PassivityWarning

__all__ = ["Model", "ModelLike", "load_model", "save_model"]

_TWO_PI = 2.0 * math.pi
_EFFECTS = (
    "cogging, spring, offset, position_friction, drift, mass, delay, current_lag, "
    "resonance, deadband, drag, stribeck_shape"
)
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
        dm = sum(e.params["delta"] for e in self.effects if e.kind == "mass")
        return self.axis.mass + dm

    @property
    def stribeck_exponent(self) -> float | None:
        """Exponent of a ``stribeck_shape`` effect, ``None`` without one."""
        for e in self.effects:
            if e.kind == "stribeck_shape":
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
    e = _obj(e, path)
    kind = _get(e, "effect", path)
    if not isinstance(kind, str):
        raise ModelError.at(_join(path, "effect"), "must be a string")

    def n(k: str) -> float:
        return _num(e, k, path)

    def p(k: str) -> str:
        return _join(path, k)

    if kind == "cogging":
        harmonics: list[tuple[float, float]] = []
        h = e.get("harmonics")
        if h is not None:
            hp = p("harmonics")
            if not isinstance(h, (list, tuple)):
                raise ModelError.at(hp, "must be a list of [amplitude, phase] pairs")
            for k, pair in enumerate(h):
                q = _num_list(pair, f"{hp}[{k}]")
                if len(q) != 2:
                    raise ModelError.at(f"{hp}[{k}]", "must be [amplitude, phase]")
                harmonics.append((q[0], q[1]))
        amplitude = n("amplitude")
        pitch = _positive(n("pitch"), p("pitch"))
        phase = _opt_num(e, "phase", path)
        return _Effect(kind, {
            "amplitude": amplitude, "pitch": pitch,
            "phase": 0.0 if phase is None else phase, "harmonics": tuple(harmonics),
        })
    if kind == "spring":
        stiffness = n("stiffness")
        x0 = _opt_num(e, "x0", path)
        return _Effect(kind, {"stiffness": stiffness, "x0": 0.0 if x0 is None else x0})
    if kind == "offset":
        return _Effect(kind, {"force": n("force")})
    if kind == "position_friction":
        positions = _num_list(_get(e, "positions", path), p("positions"))
        scale = _num_list(_get(e, "scale", path), p("scale"))
        if not positions or len(positions) != len(scale):
            raise ModelError.at(
                p("scale"),
                f"has {len(scale)} values for {len(positions)} positions: "
                "give one scale per position",
            )
        for k in range(len(positions) - 1):
            if positions[k + 1] <= positions[k]:
                raise ModelError.at(
                    f"{p('positions')}[{k + 1}]", "positions must be strictly increasing"
                )
        for k, s in enumerate(scale):
            _positive(s, f"{p('scale')}[{k}]")
        return _Effect(kind, {"positions": tuple(positions), "scale": tuple(scale)})
    if kind == "drift":
        gain = n("gain")
        if gain >= 1.0:
            raise ParameterError.invalid(
                p("gain"), gain, "must be below 1 (friction would vanish or turn negative)"
            )
        tc = _positive(n("time_constant"), p("time_constant"))
        return _Effect(kind, {"gain": gain, "time_constant": tc})
    if kind == "mass":
        return _Effect(kind, {"delta": n("delta")})
    if kind == "delay":
        return _Effect(kind, {"seconds": _nonneg(n("seconds"), p("seconds"))})
    if kind == "current_lag":
        return _Effect(kind, {"bandwidth_hz": _positive(n("bandwidth"), p("bandwidth"))})
    if kind == "resonance":
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
    if kind == "deadband":
        return _Effect(kind, {"current": _nonneg(n("current"), p("current"))})
    if kind == "drag":
        return _Effect(kind, {"coefficient": _nonneg(n("coefficient"), p("coefficient"))})
    if kind == "stribeck_shape":
        return _Effect(kind, {"exponent": _positive(n("exponent"), p("exponent"))})
    raise ModelError.at(p("effect"), f'unknown effect "{kind}": use one of {_EFFECTS}')


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


def _parse(v: Mapping[str, Any]) -> _Parsed:
    """Validate a model document exactly as ``Model::from_value`` does."""
    v = _obj(v, "")
    a = _obj(_get(v, "axis", ""), "axis")
    cl = a.get("current_loop")
    current_loop = None if cl is None else _parse_current_loop(cl)
    mass = _positive(_num(a, "mass", "axis"), "axis.mass")
    kf = _positive(_num(a, "force_constant", "axis"), "axis.force_constant")
    lim = _opt_num(a, "current_limit", "axis")
    if lim is not None:
        lim = _positive(lim, "axis.current_limit")
    axis = _Axis(mass, kf, current_loop, lim)
    friction = _parse_friction(_get(v, "friction", ""), "friction")
    effects = _parse_effects(v, mass)
    c = v.get("controller")
    controller = None if c is None else _parse_controller(c, friction)
    return _Parsed(axis, friction, effects, controller)


def _parse_effects(v: Mapping[str, Any], mass: float) -> tuple[_Effect, ...]:
    """Validate the ``effects`` of a model document whose axis has ``mass`` (the part
    of :func:`_parse` that depends on them, in its order)."""
    effects: list[_Effect] = []
    ev = v.get("effects")
    if ev is not None:
        if not isinstance(ev, (list, tuple)):
            raise ModelError.at("effects", "must be a list")
        effects = [_parse_effect(x, f"effects[{k}]") for k, x in enumerate(ev)]
    n_delay = sum(e.kind == "delay" for e in effects)
    n_lag = sum(e.kind == "current_lag" for e in effects)
    if n_delay > 1 or n_lag > 1:
        raise ModelError.at(
            "effects", "holds more than one delay or current_lag: merge them into one"
        )
    n_res = sum(e.kind == "resonance" for e in effects)
    n_shape = sum(e.kind == "stribeck_shape" for e in effects)
    if n_res > 1 or n_shape > 1:
        raise ModelError.at(
            "effects", "holds more than one resonance or stribeck_shape: keep one of each"
        )
    dm = sum(e.params["delta"] for e in effects if e.kind == "mass")
    if mass + dm <= 0.0:
        raise ParameterError.invalid(
            "effects.mass.delta", float(dm), "makes the total mass zero or negative"
        )
    return tuple(effects)


def _plain(obj: Any, path: str = "") -> Any:
    """A JSON-ready deep copy: mappings to dicts, sequences and arrays to lists,
    NumPy scalars to Python numbers."""
    if isinstance(obj, Mapping):
        out = {}
        for k, val in obj.items():
            if not isinstance(k, str):
                raise ModelError.at(path or "(model)", f"key {k!r} is not a string")
            out[k] = _plain(val, _join(path, k))
        return out
    if isinstance(obj, (list, tuple)):
        return [_plain(x, f"{path}[{k}]") for k, x in enumerate(obj)]
    if hasattr(obj, "tolist") and callable(obj.tolist):  # NumPy arrays and scalars
        return _plain(obj.tolist(), path)
    return obj


# --------------------------------------------------------------------------------------
# Public API
# --------------------------------------------------------------------------------------


class Model:
    """A validated axis model (mass, force constant, LuGre friction, effects, controller).

    Parameters
    ----------
    data : Mapping or Model
        The model document, as in ``docs/DESIGN.md`` (a superset of CONTRACT's model
        JSON). It is deep-copied; unknown keys are kept and written back by
        :meth:`to_dict`, :meth:`to_json` and :func:`save_model`.

    Raises
    ------
    ParameterError
        A value is out of range; ``name`` holds its path, e.g. ``"friction.negative.vs"``.
    ModelError
        A key is missing, has the wrong type, or names an unknown effect or controller;
        ``path`` holds where, e.g. ``"effects[2].effect"``.

    Warns
    -----
    PassivityWarning
        When ``sigma1 > 4*sigma2*fc/(fs - fc)`` for a direction (the map v -> F is then
        not passive; Barabanov & Ortega 2000). The model is accepted.

    Notes
    -----
    A ``Model`` does not change after construction: the properties return copies, and
    :meth:`with_friction` and :meth:`replace` return new models.
    """

    __slots__ = ("_core", "_data", "_parsed")

    def __init__(self, data: Mapping[str, Any] | Model) -> None:
        self._core: Any = None
        if isinstance(data, Model):
            self._data: dict[str, Any] = _copy.deepcopy(data._data)
            self._parsed: _Parsed = data._parsed
            self._core = data._core
            return
        if not isinstance(data, Mapping):
            raise ModelError.at(
                "(model)",
                f"must be a mapping (the model JSON object), found {type(data).__name__}",
            )
        self._data = _plain(data)
        self._parsed = _parse(self._data)
        self._warn_passivity()

    def _warn_passivity(self) -> None:
        fr = self._parsed.friction
        for d in ("positive", "negative"):
            bound = getattr(fr, d).passivity_bound()
            if fr.sigma1 > bound:
                warnings.warn(
                    f"friction.sigma1 = {fr.sigma1} exceeds the passivity bound "
                    f"4*sigma2*fc/(fs - fc) = {bound:.6g} of the {d} set: the friction "
                    "map is not passive (Barabanov & Ortega 2000); lower sigma1 or "
                    "check sigma2, fc and fs",
                    PassivityWarning,
                    stacklevel=3,
                )

    # ---- construction ---------------------------------------------------------------

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Model:
        """Validate a model document.

        Parameters
        ----------
        data : Mapping
            The model JSON as a dict.

        Returns
        -------
        Model
        """
        return cls(data)

    @classmethod
    def from_json(cls, text: str) -> Model:
        """Parse and validate a model from its JSON text.

        Parameters
        ----------
        text : str
            JSON text.

        Returns
        -------
        Model

        Raises
        ------
        ModelError
            The text is not valid JSON (path ``"(file)"``), or see :class:`Model`.
        """
        try:
            data = json.loads(text)
        except json.JSONDecodeError as e:
            raise ModelError.at("(file)", f"is not valid JSON: {e}") from None
        return cls(data)

    @classmethod
    def paper(cls) -> Model:
        """The seed paper's linear-motor axis with its PID position controller.

        m = 25 kg, K_F = 25 N/A, sigma0 = 1e5 N/m, sigma1 = 31.62 N s/m; positive set
        fc 28.7 N, fs 60.2 N, sigma2 332.5 N s/m, vs 0.01 m/s; negative set 28.5, 60.1,
        333.0, 0.01; PID kp 5e4, ki 5e5, kd 1500 at 10 kHz.

        Returns
        -------
        Model
        """
        return cls({
            "axis": {"mass": 25.0, "force_constant": 25.0},
            "friction": {
                "model": "lugre", "sigma0": 1e5, "sigma1": 31.62,
                "positive": {"fc": 28.7, "fs": 60.2, "sigma2": 332.5, "vs": 0.01},
                "negative": {"fc": 28.5, "fs": 60.1, "sigma2": 333.0, "vs": 0.01},
            },
            "effects": [],
            "controller": {"type": "pid", "kp": 5e4, "ki": 5e5, "kd": 1500.0,
                           "rate_hz": 10000.0},
        })

    # ---- export -----------------------------------------------------------------------

    def to_dict(self) -> dict[str, Any]:
        """The model document (a deep copy, unknown keys included).

        Returns
        -------
        dict
        """
        return _copy.deepcopy(self._data)

    def to_json(self, indent: int | None = 2) -> str:
        """The model document as JSON text.

        Parameters
        ----------
        indent : int or None, default 2
            Passed to :func:`json.dumps`.

        Returns
        -------
        str
        """
        return json.dumps(self._data, indent=indent, allow_nan=False)

    def _core_model(self) -> Any:
        """The model parsed by the compiled core (``lugre._core.Model``), built on first
        use and kept: a model does not change, so every call of the core takes this one
        instead of parsing the JSON again."""
        if self._core is None:
            from ._core import Model as CoreModel

            self._core = CoreModel(self.to_json(indent=None))
        return self._core

    def copy(self) -> Model:
        """An independent copy.

        Returns
        -------
        Model
        """
        return Model(self)

    __copy__ = copy

    def __deepcopy__(self, memo: dict[int, Any]) -> Model:
        return Model(self)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Model):
            return NotImplemented
        return self._data == other._data

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        fr = self._parsed.friction
        kinds = [e.kind for e in self._parsed.effects]
        c = self._parsed.controller
        return (
            f"Model(mass={self.mass}, force_constant={self.force_constant}, "
            f"sigma0={fr.sigma0}, sigma1={fr.sigma1}, effects={kinds}, "
            f"controller={None if c is None else c.law!r})"
        )

    def __reduce__(self) -> tuple[Any, ...]:
        return (Model, (self._data,))

    # ---- access -----------------------------------------------------------------------

    @property
    def mass(self) -> float:
        """Moving mass ``axis.mass`` [kg] (without ``mass`` effects)."""
        return self._parsed.axis.mass

    @property
    def total_mass(self) -> float:
        """Mass including the ``delta`` of ``mass`` effects [kg]."""
        return self._parsed.total_mass

    @property
    def force_constant(self) -> float:
        """Force constant K_F ``axis.force_constant`` [N/A]."""
        return self._parsed.axis.force_constant

    @property
    def sigma0(self) -> float:
        """Bristle stiffness [N/m]."""
        return self._parsed.friction.sigma0

    @property
    def sigma1(self) -> float:
        """Bristle damping [N s/m]."""
        return self._parsed.friction.sigma1

    @property
    def positive(self) -> dict[str, Any]:
        """Static set for ``v >= 0`` (``fc``, ``fs``, ``sigma2``, ``vs``), a copy."""
        return _copy.deepcopy(self._data["friction"]["positive"])

    @property
    def negative(self) -> dict[str, Any]:
        """Static set for ``v < 0`` (``fc``, ``fs``, ``sigma2``, ``vs``), a copy."""
        return _copy.deepcopy(self._data["friction"]["negative"])

    @property
    def axis(self) -> dict[str, Any]:
        """The ``axis`` object, a copy."""
        return _copy.deepcopy(self._data["axis"])

    @property
    def friction(self) -> dict[str, Any]:
        """The ``friction`` object, a copy."""
        return _copy.deepcopy(self._data["friction"])

    @property
    def effects(self) -> list[dict[str, Any]]:
        """The ``effects`` list (empty without effects), a copy."""
        return _copy.deepcopy(self._data.get("effects") or [])

    @property
    def controller(self) -> dict[str, Any] | None:
        """The ``controller`` object, a copy, or ``None`` without a controller."""
        c = self._data.get("controller")
        return None if c is None else _copy.deepcopy(c)

    def passivity_bound(self) -> tuple[float, float]:
        """The largest passive sigma1, ``4*sigma2*fc/(fs - fc)``, per direction.

        Returns
        -------
        (float, float)
            Bounds of the positive and the negative set (``inf`` when ``fs == fc``).
        """
        fr = self._parsed.friction
        return fr.positive.passivity_bound(), fr.negative.passivity_bound()

    @property
    def is_passive(self) -> bool:
        """True when sigma1 satisfies the passivity bound of both directions."""
        return all(self.sigma1 <= b for b in self.passivity_bound())

    # ---- derived models ---------------------------------------------------------------

    def with_friction(
        self,
        *,
        sigma0: float | None = None,
        sigma1: float | None = None,
        positive: Mapping[str, float] | None = None,
        negative: Mapping[str, float] | None = None,
    ) -> Model:
        """A new model with some friction parameters changed.

        Parameters
        ----------
        sigma0, sigma1 : float, optional
            New bristle stiffness and damping.
        positive, negative : Mapping, optional
            Entries to update in the static sets, e.g. ``{"fc": 30.0}``; the others
            are kept.

        Returns
        -------
        Model
            Validated like any model.

        Examples
        --------
        >>> Model.paper().with_friction(negative={"vs": 0.02}).negative["vs"]
        0.02
        """
        d = self.to_dict()
        f = d["friction"]
        if sigma0 is not None:
            f["sigma0"] = sigma0
        if sigma1 is not None:
            f["sigma1"] = sigma1
        if positive is not None:
            f["positive"].update(positive)
        if negative is not None:
            f["negative"].update(negative)
        return Model(d)

    def replace(self, **sections: Any) -> Model:
        """A new model with whole top-level sections replaced.

        Parameters
        ----------
        **sections
            ``axis=...``, ``friction=...``, ``effects=[...]``, ``controller=...`` (or any
            other top-level key); ``None`` removes the key (e.g. ``controller=None``
            gives an axis without a controller).

        Returns
        -------
        Model
        """
        # the untouched sections are shared, not copied: a model never changes its
        # document in place (every accessor hands out copies)
        d = dict(self._data)
        for k, val in sections.items():
            if not isinstance(k, str):  # pragma: no cover - keywords are strings
                raise ModelError.at("(model)", f"key {k!r} is not a string")
            if val is None:
                d.pop(k, None)
            else:
                d[k] = _plain(val, k)
        if set(sections) == {"effects"}:
            # only the effects change: the axis, friction and controller as parsed (the
            # grids of the diagnosis build a hundred such models)
            return Model._checked(d, self._parsed)
        return Model._checked(d)

    @classmethod
    def _checked(cls, plain: dict[str, Any], same: _Parsed | None = None) -> Model:
        """A model of a JSON-ready document (validated, not copied again); ``same``: the
        parsed model whose document differs from ``plain`` in its effects only."""
        m = cls.__new__(cls)
        m._core = None
        m._data = plain
        if same is None:
            m._parsed = _parse(plain)
        else:
            m._parsed = _Parsed(same.axis, same.friction,
                                _parse_effects(plain, same.axis.mass), same.controller)
        m._warn_passivity()
        return m


ModelLike = Union[Model, Mapping[str, Any], str, "os.PathLike[str]"]


def _as_model(m: ModelLike) -> Model:
    """Turn a :class:`Model`, a model dict or the path of a model file into a Model.

    Parameters
    ----------
    m : Model, Mapping, str or os.PathLike
        A model, its document, or a JSON file to load.

    Returns
    -------
    Model
        ``m`` itself when it already is one.
    """
    if isinstance(m, Model):
        return m
    if isinstance(m, Mapping):
        return Model(m)
    if isinstance(m, (str, os.PathLike)):
        return load_model(m)
    raise ModelError.at(
        "model", f"got {type(m).__name__}: give a lugre.Model, a model dict or the path "
        "of a model JSON file (e.g. lugre.Model.paper() or lugre.load_model('model.json'))"
    )


def load_model(path: str | os.PathLike[str]) -> Model:
    """Read and validate a model JSON file.

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    Model

    Raises
    ------
    FileNotFoundError
        No such file.
    ModelError, ParameterError
        Invalid JSON or an invalid model; the message starts with the file name.
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise FileNotFoundError(
            2, f"model file {str(p)!r} does not exist", str(p)
        ) from None
    except UnicodeDecodeError as e:
        raise ModelError(
            f"{p}: model: (file): is not UTF-8 text ({e}); save it as UTF-8 JSON",
            path="(file)",
        ) from None
    try:
        return Model.from_json(text)
    except ModelError as e:
        raise ModelError(f"{p}: {e}", path=e.path) from None
    except ParameterError as e:
        raise ParameterError(
            f"{p}: {e}", name=e.name, value=e.value, requirement=e.requirement
        ) from None


def save_model(model: ModelLike, path: str | os.PathLike[str]) -> None:
    """Write a model as JSON, atomically (whole or not at all).

    The text goes to a temporary file in the same directory, which then replaces
    ``path`` with :func:`os.replace`.

    Parameters
    ----------
    model : Model or Mapping
        The model (a dict is validated first).
    path : str or os.PathLike
        Destination file.
    """
    from ._atomic import _atomic_write

    if isinstance(model, (str, os.PathLike)) and not isinstance(path, (str, os.PathLike)):
        raise InputError.at("model", f"got the path {os.fspath(model)!r} first: save_model "
                            "takes the model first, then the path: save_model(model, path)")
    m = _as_model(model)
    text = m.to_json(indent=2) + "\n"
    _atomic_write(path, text.encode("utf-8"))

