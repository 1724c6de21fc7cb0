"""Units and number formatting for pages a person reads: one unit per quantity.

On a linear axis positions are shown in millimetres, speeds in millimetres per second,
forces in newtons; on a rotary axis (CONTRACT, "Rotary axes") positions in rad, speeds
in rad/s, forces in N m, masses in kg m^2. Times are in seconds; every other parameter
in the unit of the CONTRACT's vocabulary.

The vocabulary and the code write units as a linear axis's SI units (``"N"``,
``"m/s"``); :func:`si` and :func:`display` turn them into the axis's own. Which axis is
set for a stretch of work by :func:`axis` (a context variable: the diagnosis, the fit
and the pages set it from the model they are given).
"""

from __future__ import annotations

import contextlib
import contextvars
import math
import re
from collections.abc import Iterator
from typing import Any

from .vocabulary import EFFECTS, canonical

__all__ = ["EFFECT_UNITS", "axis", "axis_kind", "axis_units", "base_unit", "constant_words",
           "display", "fmt", "fmt_range", "force_words", "is_rotary", "mass_words", "micro",
           "position_unit", "si", "where_unit", "words"]

#: A linear axis's SI units and a rotary axis's for the same quantity.
_ROTARY = {
    "m": "rad", "m/s": "rad/s", "m/s^2": "rad/s^2", "m/s²": "rad/s²", "N": "N m",
    "N/m": "N m/rad", "N s/m": "N m s/rad", "N s^2/m^2": "N m s^2/rad^2",
    "N s²/m²": "N m s²/rad²", "kg": "kg m^2", "N/A": "N m/A", "N/s": "N m/s",
}

_KIND: contextvars.ContextVar[str] = contextvars.ContextVar("lugre_axis_kind",
                                                            default="linear")


@contextlib.contextmanager
def axis(kind: str) -> Iterator[None]:
    """Speak ``kind``'s units (``"linear"`` or ``"rotary"``) inside the ``with``."""
    token = _KIND.set("rotary" if kind == "rotary" else "linear")
    try:
        yield
    finally:
        _KIND.reset(token)


def axis_kind() -> str:
    """The kind of axis whose units are spoken now (``"linear"`` unless set)."""
    return _KIND.get()


def is_rotary() -> bool:
    """Whether the units spoken now are a rotary axis's."""
    return _KIND.get() == "rotary"


def axis_units(kind: str) -> dict[str, str]:
    """What a report says of its axis: ``kind`` and the SI unit of each quantity."""
    with axis(kind):
        return {"kind": axis_kind(), **{q: si(u) for q, u in _QUANTITIES.items()}}


#: The quantities a report's numbers are in, with a linear axis's SI unit.
_QUANTITIES = {"position": "m", "velocity": "m/s", "force": "N", "mass": "kg",
               "force_constant": "N/A"}


def force_words() -> str:
    """``"force"``, or ``"torque"`` on a rotary axis."""
    return "torque" if is_rotary() else "force"


def mass_words() -> str:
    """``"mass"``, or ``"inertia"`` on a rotary axis."""
    return "inertia" if is_rotary() else "mass"


def constant_words() -> str:
    """``"force constant"``, or ``"torque constant"`` on a rotary axis."""
    return "torque constant" if is_rotary() else "force constant"


#: A linear axis's words and a rotary axis's, for :func:`words`.
_ROTARY_WORDS = {"force constant": "torque constant", "payloads": "load inertias",
                 "payload": "load inertia", "forces": "torques", "force": "torque",
                 "masses": "inertias", "a mass": "an inertia", "mass": "inertia",
                 "newtons": "newton metres",
                 "millimetres": "radians", "millimetre": "milliradian",
                 "micrometres": "microradians", "micrometre": "microradian"}
_WORDS_RE = re.compile(r"(?<![-\w])(" + "|".join(_ROTARY_WORDS) + r")\b", re.IGNORECASE)


def words(text: str) -> str:
    """``text``, written for a linear axis, in a rotary axis's words when one is spoken
    ("force" -> "torque", "mass" -> "inertia", "payload" -> "load inertia"); unchanged
    on a linear axis."""
    if not is_rotary():
        return text
    return _WORDS_RE.sub(_rotary_word, text)


def _rotary_word(m: re.Match[str]) -> str:
    w = _ROTARY_WORDS[m.group(0).lower()]
    return w[0].upper() + w[1:] if m.group(0)[0].isupper() else w


def micro(x: float, digits: int = 3) -> str:
    """A small position (SI) in micrometres, ``"3.2 um"``, or on a rotary axis in
    microradians, ``"3.2 µrad"``."""
    return f"{x * 1e6:.{digits}g} {'µrad' if is_rotary() else 'um'}"


def si(unit: str) -> str:
    """The axis's SI unit for a linear axis's SI ``unit`` (``"N"`` -> ``"N m"`` on a
    rotary axis; others unchanged)."""
    return _ROTARY.get(unit, unit) if is_rotary() else unit

#: Display unit and factor from SI for each quantity.
POSITION = ("mm", 1e3)
SPEED = ("mm/s", 1e3)

#: Units of the effects' parameters (CONTRACT vocabulary), as (unit, factor from SI).
EFFECT_UNITS: dict[str, dict[str, tuple[str, float]]] = {
    name: spec.display for name, spec in EFFECTS.items()}

#: SI units (of a linear axis) of the base model's parameters.
_BASE_SI = {"mass": "kg", "force_constant": "N/A", "sigma0": "N/m", "sigma1": "N s/m",
            "fc": "N", "fs": "N", "sigma2": "N s/m", "vs": "m/s"}

#: SI units (of a linear axis) of the ``where`` ranges.
_WHERE_SI = {"position": "m", "time": "s", "velocity": "m/s"}


def base_unit(name: str) -> tuple[str, float]:
    """Display unit and factor of a base parameter (``mass``, ``fc``, ``vs``, ...) on
    the axis spoken now; ``("", 1.0)`` when unknown."""
    unit = _BASE_SI.get(name)
    return ("", 1.0) if unit is None else display(unit)


def where_unit(key: str) -> tuple[str, float]:
    """Display unit and factor of a ``where`` range (``position``, ``time``,
    ``velocity``) on the axis spoken now."""
    return display(_WHERE_SI.get(key, ""))


def position_unit() -> tuple[str, float]:
    """Display unit and factor of a position on the axis spoken now."""
    return display("m")

#: Unit of a unit name used in reports (``m``, ``m/s``) turned into its display unit.
_DISPLAY = {"m": POSITION, "m/s": SPEED, "s": ("s", 1.0), "N": ("N", 1.0),
            "kg": ("kg", 1.0), "Hz": ("Hz", 1.0), "A": ("A", 1.0)}


def unit_of(effect: str | None, name: str) -> tuple[str, float]:
    """Display unit and factor of a parameter (``("", 1.0)`` when unknown)."""
    spec = EFFECTS.get(canonical(effect or ""))
    if spec is not None and name in spec.units:
        return _on_axis(spec.units[name], spec.display[name])
    base = name.rsplit(".", 1)[-1]
    for suffix in ("_positive", "_negative"):
        base = base.removesuffix(suffix)
    return base_unit(base)


def _on_axis(unit: str, linear_display: tuple[str, float]) -> tuple[str, float]:
    """A parameter's display unit on the axis spoken now: a rotary axis shows the SI
    unit of its own (rad, N m) where a linear one shows millimetres."""
    if is_rotary() and unit in _ROTARY:
        return (_ROTARY[unit], 1.0)
    return linear_display


def display(unit: str | None) -> tuple[str, float]:
    """The display unit and factor for a value given in the (linear) SI ``unit``, on
    the axis spoken now."""
    if not unit:
        return ("", 1.0)
    if is_rotary():
        return (_ROTARY.get(unit, unit), 1.0)
    return _DISPLAY.get(unit, (unit, 1.0))


def num(x: Any, digits: int = 4) -> str:
    """A number with ``digits`` significant digits, without exponent for usual sizes."""
    if x is None:
        return "–"
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        try:
            x = float(x)
        except (TypeError, ValueError):
            return str(x)
    x = float(x)
    if not math.isfinite(x):
        return "∞" if x > 0 else ("−∞" if x < 0 else "–")
    if x == 0.0:
        return "0"
    mag = math.floor(math.log10(abs(x)))
    if -4 <= mag < 7:
        decimals = max(0, digits - 1 - mag)
        s = f"{x:.{decimals}f}"
        if "." in s:
            s = s.rstrip("0").rstrip(".")
    else:
        s = f"{x:.{digits - 1}e}"
        mant, exp = s.split("e")
        mant = mant.rstrip("0").rstrip(".")
        s = f"{mant}×10^{int(exp)}"
    return s.replace("-", "−")


def fmt(x: Any, unit: tuple[str, float] | str = ("", 1.0), digits: int = 4) -> str:
    """``x`` (SI) in the display unit: ``fmt(0.0375, POSITION) == "37.5 mm"``."""
    u, k = display(unit) if isinstance(unit, str) else unit
    if isinstance(x, (list, tuple)):
        return "[" + ", ".join(num(k * float(v), digits) for v in x) + "]" + (f" {u}" if u else "")
    if x is None:
        return "–"
    v = num(k * float(x), digits)
    return f"{v} {u}" if u else v


def fmt_range(lo: Any, hi: Any, unit: tuple[str, float] | str = ("", 1.0),
              digits: int = 4) -> str:
    """``"12.1 to 13.4 mm"``; an open end is written as such."""
    u, k = display(unit) if isinstance(unit, str) else unit
    a = num(k * float(lo), digits) if lo is not None else "−∞"
    b = num(k * float(hi), digits) if hi is not None else "∞"
    return f"{a} to {b}" + (f" {u}" if u else "")


def percent(share: float, digits: int = 0) -> str:
    """A share as a percentage (a positive share that would round to zero: "under" the
    last digit's half)."""
    half = 0.5 * 10.0 ** -digits
    if 0.0 < 100 * share < half:
        return f"under {half:.{digits + 1}f} %"
    return f"{100 * share:.{digits}f} %"


def shares_that_add_up(shares: list[float], total: int = 100) -> list[int]:
    """Whole percentages of ``shares`` (which sum to 1) that add up to ``total`` exactly
    (largest remainders)."""
    raw = [max(0.0, s) * total for s in shares]
    base = [math.floor(r) for r in raw]
    left = total - sum(base)
    order = sorted(range(len(raw)), key=lambda i: raw[i] - base[i], reverse=True)
    for i in order[:max(0, left)]:
        base[i] += 1
    return base
