"""Robust weights, scale and quantiles of IRLS (``src/estimate/robust.rs``), in Python.

Weight functions of standardised residuals ``u = e/s``: IGG (``k0 = 1.5``, ``k1 = 2.5``,
the seed paper's), Huber (``c = 1.345``), Tukey's biweight (``c = 4.685``) and none;
the scale is ``1.4826*MAD``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from ..exceptions import InputError

__all__ = ["Weighting", "median", "robust_scale", "t_quantile_975"]


class Weighting:
    """A weight function with its constants (``Weighting`` in robust.rs)."""

    __slots__ = ("c", "k0", "k1", "kind")

    def __init__(self, kind: str, k0: float = 0.0, k1: float = 0.0, c: float = 0.0) -> None:
        self.kind, self.k0, self.k1, self.c = kind, k0, k1, c

    @classmethod
    def igg(cls) -> Weighting:
        return cls("igg", k0=1.5, k1=2.5)

    @classmethod
    def huber(cls) -> Weighting:
        return cls("huber", c=1.345)

    @classmethod
    def tukey(cls) -> Weighting:
        return cls("tukey", c=4.685)

    @classmethod
    def from_name(cls, name: str) -> Weighting:
        """The scheme named ``igg``, ``huber``, ``tukey`` or ``none`` (also ``ls``,
        ``least_squares``, ``biweight``), case-insensitive (``Weighting::from_name``)."""
        low = name.lower()
        if low == "igg":
            return cls.igg()
        if low == "huber":
            return cls.huber()
        if low in ("tukey", "biweight"):
            return cls.tukey()
        if low in ("none", "ls", "least_squares"):
            return cls("none")
        raise InputError.at(
            "weighting",
            f'unknown weighting "{low}": use "igg", "huber", "tukey" or "none"',
        )

    @property
    def name(self) -> str:
        return self.kind

    @property
    def rejects_at(self) -> float | None:
        """Where the weight falls to zero (IGG ``k1``, Tukey ``c``); None if never."""
        return {"igg": self.k1, "tukey": self.c}.get(self.kind)

    def weight(self, u: float) -> float:
        a = abs(u)
        if math.isnan(a):
            return 0.0
        if self.kind == "igg":
            if a <= self.k0:
                return 1.0
            return self.k0 / a if a <= self.k1 else 0.0
        if self.kind == "huber":
            return 1.0 if a <= self.c else self.c / a
        if self.kind == "tukey":
            if a < self.c:
                r = a / self.c
                q = 1.0 - r * r
                return q * q
            return 0.0
        return 1.0

    def weights(self, e: Sequence[float], s: float) -> list[float]:
        """Weights of residuals ``e`` at scale ``s``; with ``s == 0`` exact zeros get 1
        and the others the weight at infinity."""
        if s > 0.0:
            return [self.weight(x / s) for x in e]
        w_inf = self.weight(math.inf)
        return [1.0 if x == 0.0 else w_inf for x in e]


def median(a: Sequence[float]) -> float:
    """Median, NaNs ignored (NaN when nothing is left)."""
    b = sorted(x for x in a if not math.isnan(x))
    n = len(b)
    if n == 0:
        return math.nan
    return b[n // 2] if n % 2 == 1 else 0.5 * (b[n // 2 - 1] + b[n // 2])


def robust_scale(e: Sequence[float]) -> float:
    """``1.4826*MAD``; ``1.2533*mean|e - median|`` when the MAD is zero; 0 when every
    residual is equal."""
    m = median(e)
    if not math.isfinite(m):
        return 0.0
    dev = [abs(x - m) for x in e if not math.isnan(x)]
    mad = median(dev)
    if mad > 0.0 and math.isfinite(mad):
        return 1.4826 * mad
    finite = [d for d in dev if math.isfinite(d)]
    if not finite:
        return 0.0
    s = 0.0
    for d in finite:
        s += d
    return 1.2533 * s / len(finite)


def t_quantile_975(dof: float) -> float:
    """Two-sided 95 % quantile of Student's t (Cornish-Fisher, as the core)."""
    if math.isnan(dof) or dof < 1.0:
        return math.nan
    if dof == 1.0:
        return 12.706
    if dof == 2.0:
        return 4.303
    z = 1.959_963_984_540_054
    n = dof
    z3 = z * z * z
    z5 = z3 * z * z
    z7 = z5 * z * z
    return (z + (z3 + z) / (4.0 * n) + (5.0 * z5 + 16.0 * z3 + 3.0 * z) / (96.0 * n * n)
            + (3.0 * z7 + 19.0 * z5 + 17.0 * z3 - 15.0 * z) / (384.0 * n * n * n))
