"""Results shared by :mod:`lugre` (Rust core) and :mod:`lugre.reference`: a simulation's
:class:`SimResult`, :func:`~lugre.load_coupling`'s :class:`CouplingResult` and the
robust linear fits' :class:`LinearFit` and :class:`GridFit`."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, NamedTuple

import numpy as np

__all__ = ["CouplingResult", "GridFit", "LinearFit", "SimResult"]


class SimResult:
    """Sampled trajectories of a simulated axis, one value per sample time.

    Parameters
    ----------
    t : array_like
        Sample times [s].
    x : array_like
        Position [m].
    v : array_like
        Velocity [m/s].
    z : array_like
        Bristle deflection [m].
    i : array_like
        Current [A]: the actual current with a current loop, else the command.
    friction : array_like
        LuGre friction force [N].
    force : array_like
        Motor force acting on the mass [N].

    Attributes
    ----------
    t, x, v, z, i, friction, force : numpy.ndarray
        1-D float64 arrays of equal length.
    """

    __slots__ = ("force", "friction", "i", "t", "v", "x", "z")

    #: Names of the arrays, in order.
    fields: tuple[str, ...] = ("t", "x", "v", "z", "i", "friction", "force")

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    z: np.ndarray
    i: np.ndarray
    friction: np.ndarray
    force: np.ndarray

    def __init__(
        self,
        t: Any,
        x: Any,
        v: Any,
        z: Any,
        i: Any,
        friction: Any,
        force: Any,
    ) -> None:
        arrays = {"t": t, "x": x, "v": v, "z": z, "i": i, "friction": friction,
                  "force": force}
        n = None
        for name, a in arrays.items():
            arr = np.ascontiguousarray(a, dtype=np.float64)
            if arr.ndim != 1:
                raise ValueError(f"SimResult.{name} must be 1-D, got shape {arr.shape}")
            if n is None:
                n = arr.size
            elif arr.size != n:
                raise ValueError(
                    f"SimResult.{name} has {arr.size} samples but t has {n}"
                )
            object.__setattr__(self, name, arr)

    @classmethod
    def from_dict(cls, t: Any, arrays: Mapping[str, Any]) -> SimResult:
        """Build from the sample times and a mapping with the other six arrays.

        Parameters
        ----------
        t : array_like
            Sample times [s].
        arrays : Mapping
            ``x``, ``v``, ``z``, ``i``, ``friction`` and ``force``.

        Returns
        -------
        SimResult
        """
        return cls(t, *(arrays[k] for k in cls.fields[1:]))

    def to_dict(self) -> dict[str, np.ndarray]:
        """The arrays by name (not copies).

        Returns
        -------
        dict
        """
        return {k: getattr(self, k) for k in self.fields}

    def __len__(self) -> int:
        return int(self.t.size)

    def __repr__(self) -> str:
        n = self.t.size
        span = f", t=[{self.t[0]:g}, {self.t[-1]:g}] s" if n else ""
        return f"SimResult({n} samples{span}; fields {', '.join(self.fields)})"

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, SimResult):
            return NotImplemented
        return all(np.array_equal(getattr(self, k), getattr(other, k)) for k in self.fields)

    __hash__ = None  # type: ignore[assignment]

    def __reduce__(self) -> tuple[Any, ...]:
        return (SimResult, tuple(getattr(self, k) for k in self.fields))


class CouplingResult(NamedTuple):
    """The load behind a ``resonance`` coupling at the sample instants
    (:func:`lugre.load_coupling`); a tuple ``(force, x_load, v_load, z)``.

    Attributes
    ----------
    force : numpy.ndarray
        Force the coupling passes to the load, ``k*(x - x_load) + c*(v - v_load)`` [N];
        the motor needs ``(1 - r)*M*a_m + force``.
    x_load : numpy.ndarray
        Load position [m].
    v_load : numpy.ndarray
        Load velocity [m/s].
    z : numpy.ndarray
        Bristle deflection of the load's friction [m].
    """

    force: np.ndarray
    x_load: np.ndarray
    v_load: np.ndarray
    z: np.ndarray


class LinearFit(NamedTuple):
    """A robust linear fit ``y ~ X b`` by IRLS (``irls_linear`` of ``lugre._native`` and
    :mod:`lugre.reference`).

    Attributes
    ----------
    coef : numpy.ndarray
        Coefficients ``b``, one per column, from the last round's weighted solve.
    weights : numpy.ndarray
        Weight of each row from the residuals of ``coef`` (0: rejected).
    residuals : numpy.ndarray
        ``y - X b``.
    sse : float
        Weighted sum of squares ``sum w*e^2``.
    scale : float
        Scale the weights were computed at (``1.4826*MAD + 1e-12``).
    """

    coef: np.ndarray
    weights: np.ndarray
    residuals: np.ndarray
    sse: float
    scale: float


class GridFit(NamedTuple):
    """The best of a base design and its candidates (``irls_linear_grid``).

    Attributes
    ----------
    chosen : int or None
        Index of the chosen candidate, None for the base design alone.
    fit : LinearFit
        The chosen fit: coefficients of the base columns, then of the candidate's.
    base_sse : float
        Weighted sum of squares of the base design alone.
    sse : numpy.ndarray
        Weighted sum of squares of each candidate.
    """

    chosen: int | None
    fit: LinearFit
    base_sse: float
    sse: np.ndarray
