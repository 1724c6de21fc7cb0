"""Input checks of the twin (``src/error.rs``), raising the same information as the core,
in the same order."""

from __future__ import annotations

import math
from typing import Any

from ..exceptions import InputError, ParameterError, _fmt_f64
from ..model import ModelLike, _as_model
from .parsed import _parse, _Parsed

__all__: list[str] = []


def _parsed(model: ModelLike) -> _Parsed:
    """The model's numbers, checked here from its document as the core checks its JSON:
    a :class:`~lugre.Model` built around the checks is refused by both backends alike."""
    return _parse(_as_model(model)._data)


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


def _ceil_f(q: float) -> float:
    """``f64::ceil`` (``math.ceil`` returns an int and fails on inf)."""
    return float(math.ceil(q)) if math.isfinite(q) else q


def _finite_option_any(name: str, value: Any) -> float:
    """``float(value)`` or ParameterError (finiteness is checked by the caller)."""
    try:
        return float(value)
    except (TypeError, ValueError):
        raise ParameterError.invalid(name, value, "must be a finite number") from None
