"""The minimum of a function of one variable on an interval, by golden section."""

from __future__ import annotations

import math
from collections.abc import Callable

__all__ = ["golden"]


def golden(f: Callable[[float], float], a: float, b: float, steps: int) -> float:
    """The minimum of ``f`` on ``[a, b]`` by golden-section search (``steps`` steps
    after the first two evaluations)."""
    g = (math.sqrt(5.0) - 1.0) / 2.0
    c, d = b - g * (b - a), a + g * (b - a)
    fc, fd = f(c), f(d)
    for _ in range(steps):
        if fc < fd:
            b, d, fd = d, c, fc
            c = b - g * (b - a)
            fc = f(c)
        else:
            a, c, fc = c, d, fd
            d = a + g * (b - a)
            fd = f(d)
    return c if fc < fd else d
