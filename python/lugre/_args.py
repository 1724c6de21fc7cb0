"""Argument conversions in front of both backends: the Rust-backed facade
(:mod:`lugre._native`) and its NumPy twin (:mod:`lugre.reference`) refuse the same
inputs with the same messages because both convert them here first."""

from __future__ import annotations

from numbers import Integral
from typing import Any

import numpy as np

from .exceptions import InputError, ParameterError

__all__ = ["MAX_FREQUENCIES", "as_array", "candidate_matrices", "check_substeps_type",
           "design_matrix", "frequency_count", "grid_args", "linear_args", "ratio_value",
           "round_count", "select_drive", "weighting_name"]

#: Most frequencies in one call of ``position_sums`` (``MAX_FREQUENCIES`` in
#: src/inverse/mod.rs).
MAX_FREQUENCIES = 1 << 26


def as_array(name: str, a: Any, ndim: int = 1) -> np.ndarray:
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


def check_substeps_type(substeps: Any) -> None:
    """``substeps`` must be an integer (its range is checked with the other inputs)."""
    if isinstance(substeps, bool) or not isinstance(substeps, Integral):
        raise TypeError(f"substeps must be an integer, got {type(substeps).__name__}")


def select_drive(x_ref: Any, v_ref: Any, current: Any) -> tuple[str, Any]:
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


def frequency_count(n: Any) -> int:
    """The ``n`` of ``position_sums``: an integer from 1 to :data:`MAX_FREQUENCIES`,
    else ParameterError."""
    if isinstance(n, bool) or not isinstance(n, Integral):
        raise ParameterError.invalid("n", n, "must be a whole number of frequencies")
    if not 1 <= int(n) <= MAX_FREQUENCIES:
        raise ParameterError.invalid("n", float(n), f"must be between 1 and {MAX_FREQUENCIES} "
                                     "frequencies")
    return int(n)


# --------------------------------------------------------------------------------------
# The robust linear fits (irls_linear, irls_linear_grid)
# --------------------------------------------------------------------------------------


def design_matrix(name: str, x: Any) -> np.ndarray:
    """``x`` as a 2-D float64 array (rows x columns), or InputError naming it."""
    return as_array(name, x, ndim=2)


def candidate_matrices(extras: Any) -> list[np.ndarray]:
    """The candidates' extra columns: a sequence of 2-D arrays (or one 3-D array)."""
    if isinstance(extras, (str, bytes)) or not hasattr(extras, "__iter__"):
        raise InputError.at("extras", "must be a sequence of 2-D arrays, one per candidate")
    return [design_matrix(f"extras[{k}]", e) for k, e in enumerate(extras)]


def round_count(rounds: Any) -> int:
    """``rounds``: a whole number of at least 1."""
    if isinstance(rounds, bool) or not isinstance(rounds, Integral):
        raise TypeError(f"rounds must be an integer, got {type(rounds).__name__}")
    if rounds < 1:
        raise ParameterError.invalid("rounds", float(rounds),
                                     "must be at least 1 (rounds of reweighting)")
    return int(rounds)


def weighting_name(weighting: Any) -> str:
    if not isinstance(weighting, str):
        raise TypeError(f"weighting must be a str, got {type(weighting).__name__}")
    return weighting


def ratio_value(ratio: Any) -> float:
    try:
        return float(ratio)
    except (TypeError, ValueError):
        raise ParameterError.invalid("ratio", ratio, "must be a finite number") from None


def linear_args(x: Any, y: Any, weighting: Any, rounds: Any
                ) -> tuple[np.ndarray, np.ndarray, str, int]:
    """The arguments of ``irls_linear`` converted as both backends take them: ``X`` 2-D
    and ``y`` 1-D float64, the weighting's name, the rounds (at least 1)."""
    name = weighting_name(weighting)
    nr = round_count(rounds)
    return design_matrix("X", x), as_array("y", y), name, nr


def grid_args(x: Any, extras: Any, y: Any, weighting: Any, rounds: Any, ratio: Any
              ) -> tuple[np.ndarray, list[np.ndarray], np.ndarray, str, int, float]:
    """The arguments of ``irls_linear_grid`` converted as both backends take them."""
    name = weighting_name(weighting)
    nr = round_count(rounds)
    rt = ratio_value(ratio)
    xa = design_matrix("X", x)
    cands = candidate_matrices(extras)
    return xa, cands, as_array("y", y), name, nr, rt
