"""Units and number formatting for pages a person reads: one unit per quantity.

Positions are shown in millimetres, speeds in millimetres per second, times in seconds,
forces in newtons; every other parameter in the unit of the CONTRACT's vocabulary.
"""

from __future__ import annotations

import math
from typing import Any

from .vocabulary import EFFECTS

__all__ = ["BASE_UNITS", "EFFECT_UNITS", "display", "fmt", "fmt_range"]

#: Display unit and factor from SI for each quantity.
POSITION = ("mm", 1e3)
SPEED = ("mm/s", 1e3)

#: Units of the effects' parameters (CONTRACT vocabulary), as (unit, factor from SI).
EFFECT_UNITS: dict[str, dict[str, tuple[str, float]]] = {
    name: spec.display for name, spec in EFFECTS.items()}

#: Units of the base model's parameters.
BASE_UNITS: dict[str, tuple[str, float]] = {
    "mass": ("kg", 1.0), "force_constant": ("N/A", 1.0), "sigma0": ("N/m", 1.0),
    "sigma1": ("N s/m", 1.0), "fc": ("N", 1.0), "fs": ("N", 1.0), "sigma2": ("N s/m", 1.0),
    "vs": SPEED,
}

#: Units of the ``where`` ranges.
WHERE_UNITS: dict[str, tuple[str, float]] = {
    "position": POSITION, "time": ("s", 1.0), "velocity": SPEED,
}

#: Unit of a unit name used in reports (``m``, ``m/s``) turned into its display unit.
_DISPLAY = {"m": POSITION, "m/s": SPEED, "s": ("s", 1.0), "N": ("N", 1.0),
            "kg": ("kg", 1.0), "Hz": ("Hz", 1.0), "A": ("A", 1.0)}


def unit_of(effect: str | None, name: str) -> tuple[str, float]:
    """Display unit and factor of a parameter (``("", 1.0)`` when unknown)."""
    if effect and name in EFFECT_UNITS.get(effect, {}):
        return EFFECT_UNITS[effect][name]
    base = name.rsplit(".", 1)[-1]
    for suffix in ("_positive", "_negative"):
        base = base.removesuffix(suffix)
    return BASE_UNITS.get(base, ("", 1.0))


def display(unit: str | None) -> tuple[str, float]:
    """The display unit and factor for a value given in the SI ``unit``."""
    if not unit:
        return ("", 1.0)
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
