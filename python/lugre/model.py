"""The axis model: a validated JSON document (``docs/DESIGN.md``, a superset of CONTRACT).

A :class:`Model` keeps the document as a plain ``dict`` (unknown keys included, so that
they are written back on save) and has the compiled core check it on construction
(``src/servo/model.rs``, the one validation): a value out of range raises
:class:`~lugre.exceptions.ParameterError` naming its path (``friction.negative.vs``,
``axis.mass``, ``effects[2].pitch``), a structural problem (missing key, wrong type,
unknown effect) raises :class:`~lugre.exceptions.ModelError`.

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
import os
import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Union

from .exceptions import InputError, ModelError, ParameterError, PassivityWarning
from .vocabulary import ALIASES, EFFECTS, INERTIA, MASS, MASS_EFFECTS, canonical

__all__ = ["Model", "ModelLike", "load_model", "save_model"]



def _join(path: str, key: str) -> str:
    return key if not path else f"{path}.{key}"


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
    if isinstance(obj, float) and not math.isfinite(obj):
        raise ParameterError.invalid(path or "(model)", obj, "must be finite")
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

    __slots__ = ("_core", "_data")

    def __init__(self, data: Mapping[str, Any] | Model) -> None:
        if isinstance(data, Model):
            self._data: dict[str, Any] = _copy.deepcopy(data._data)
            self._core: Any = data._core
            return
        if not isinstance(data, Mapping):
            raise ModelError.at(
                "(model)",
                f"must be a mapping (the model JSON object), found {type(data).__name__}",
            )
        self._data = _canonical(_plain(data))
        self._core = _validated(self._data)
        self._warn_passivity()

    def _warn_passivity(self) -> None:
        s1 = self.sigma1
        for d, bound in zip(("positive", "negative"), self.passivity_bound()):
            if s1 > bound:
                warnings.warn(
                    f"friction.sigma1 = {s1} exceeds the passivity bound "
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
        return json.dumps(self._written(), indent=indent, allow_nan=False)

    def _written(self) -> dict[str, Any]:
        """The document as a file holds it: a rotary axis's ``mass`` effect written
        ``inertia`` (CONTRACT, "Rotary axes"; read back as ``mass``)."""
        effects = self._data.get("effects")
        if not self.is_rotary or not effects:
            return self._data
        return {**self._data, "effects": [
            {**e, "effect": INERTIA} if e.get("effect") == MASS else e for e in effects]}

    def _core_model(self) -> Any:
        """The model parsed by the compiled core (``lugre._core.Model``), built when the
        model was validated (or on first use) and kept: a model does not change, so every
        call of the core takes this one instead of parsing the JSON again."""
        if self._core is None:
            self._core = _validated(self._data)
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
        kinds = [e["effect"] for e in self._data.get("effects") or []]
        c = self._data.get("controller")
        law = None if c is None else c.get("type", "pid")
        return (
            f"Model(mass={self.mass}, force_constant={self.force_constant}, "
            f"sigma0={self.sigma0}, sigma1={self.sigma1}, effects={kinds}, "
            f"controller={law!r})"
        )

    def __reduce__(self) -> tuple[Any, ...]:
        return (Model, (self._data,))

    # ---- access -----------------------------------------------------------------------

    @property
    def kind(self) -> str:
        """``"linear"`` or ``"rotary"`` (``axis.kind``; CONTRACT, "Rotary axes")."""
        return "rotary" if self._data["axis"].get("kind") == "rotary" else "linear"

    @property
    def is_rotary(self) -> bool:
        """Whether the axis turns: positions in rad, forces in N m, inertia in kg m^2."""
        return self.kind == "rotary"

    @property
    def mass(self) -> float:
        """Moving mass ``axis.mass`` [kg], or a rotary axis's ``axis.inertia`` [kg m^2]
        (without ``mass`` effects)."""
        return float(self._data["axis"][_AXIS_KEYS[self.kind][0]])

    @property
    def total_mass(self) -> float:
        """Mass including the ``delta`` of ``mass`` effects [kg]."""
        return self.mass + sum(float(e[EFFECTS[e["effect"]].additive or ""])
                               for e in self._data.get("effects") or []
                               if e["effect"] in MASS_EFFECTS)

    @property
    def force_constant(self) -> float:
        """Force constant K_F ``axis.force_constant`` [N/A], or a rotary axis's
        ``axis.torque_constant`` [N m/A]."""
        return float(self._data["axis"][_AXIS_KEYS[self.kind][1]])

    def with_axis(self, *, mass: float | None = None,
                  force_constant: float | None = None) -> Model:
        """A new model with the mass (a rotary axis's inertia) or the force constant
        (torque constant) changed, written under the axis's own keys."""
        axis = self.axis
        for key, val in zip(_AXIS_KEYS[self.kind], (mass, force_constant)):
            if val is not None:
                axis[key] = float(val)
        return self.replace(axis=axis)

    @property
    def sigma0(self) -> float:
        """Bristle stiffness [N/m]."""
        return float(self._data["friction"]["sigma0"])

    @property
    def sigma1(self) -> float:
        """Bristle damping [N s/m]."""
        return float(self._data["friction"]["sigma1"])

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
        f = self._data["friction"]
        return _passivity_bound(f["positive"]), _passivity_bound(f["negative"])

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
        return Model._checked(d)

    @classmethod
    def _checked(cls, plain: dict[str, Any]) -> Model:
        """A model of a JSON-ready document (validated, not copied again)."""
        m = cls.__new__(cls)
        m._data = _canonical(plain)
        m._core = _validated(plain)
        m._warn_passivity()
        return m


#: The keys of the mass and the force constant of each kind of axis.
_AXIS_KEYS = {"linear": ("mass", "force_constant"), "rotary": ("inertia", "torque_constant")}


def axis_document(kind: str, mass: float, force_constant: float) -> dict[str, Any]:
    """The ``axis`` object of a ``kind`` axis (``"linear"`` or ``"rotary"``)."""
    keys = _AXIS_KEYS["rotary" if kind == "rotary" else "linear"]
    doc: dict[str, Any] = {"kind": "rotary"} if kind == "rotary" else {}
    return {**doc, keys[0]: float(mass), keys[1]: float(force_constant)}


def _canonical(doc: dict[str, Any]) -> dict[str, Any]:
    """The document with every effect under its vocabulary name (a rotary axis's
    ``inertia`` effect is a ``mass`` effect), so that the rest reads one name."""
    effects = doc.get("effects")
    if isinstance(effects, list) and any(
            isinstance(e, dict) and e.get("effect") in ALIASES for e in effects):
        doc = {**doc, "effects": [
            {**e, "effect": canonical(e["effect"])}
            if isinstance(e, dict) and e.get("effect") in ALIASES else e for e in effects]}
    return doc


def _passivity_bound(s: Mapping[str, Any]) -> float:
    """``4*sigma2*fc/(fs - fc)`` of a static set, infinite when ``fs == fc``."""
    d = float(s["fs"]) - float(s["fc"])
    return math.inf if d <= 0.0 else 4.0 * float(s["sigma2"]) * float(s["fc"]) / d


def _validated(plain: dict[str, Any]) -> Any:
    """The document checked by the compiled core, which says what is wrong and where
    (its errors are the package's ModelError and ParameterError); the core's model."""
    from ._core import Model as CoreModel

    return CoreModel(json.dumps(plain, allow_nan=False))


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

