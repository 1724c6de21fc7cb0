"""The recording: a sampled record of an axis (``t``, ``x``, ``i`` or ``F``, ...).

A recording holds ``t`` [s] (strictly increasing), ``x`` [m], and the motor current ``i``
[A] or the motor force ``F`` [N]; optionally ``v`` [m/s], ``x_ref`` [m] and ``v_ref``
[m/s]. Reading and writing files is :mod:`lugre.readers`; tables with named columns
(pandas, dicts, structured arrays) become recordings through :mod:`lugre.tabular`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .exceptions import InputError, _fmt_f64

__all__ = ["COLUMNS", "Recording"]

#: Column names of a recording, in the order they are written.
COLUMNS: tuple[str, ...] = ("t", "x", "i", "F", "v", "x_ref", "v_ref")

_DESCRIPTION = {
    "t": "time [s]",
    "x": "measured position [m]",
    "i": "motor current [A]",
    "F": "motor force [N]",
    "v": "measured velocity [m/s]",
    "x_ref": "position reference [m]",
    "v_ref": "velocity reference [m/s]",
}



def _column_array(name: str, a: Any) -> np.ndarray:
    arr = np.asarray(a, dtype=float)
    if arr.ndim != 1:
        arr = np.squeeze(arr)
        if arr.ndim != 1:
            raise InputError.at(
                name, f"must be one-dimensional, got shape {np.shape(a)}: give a vector"
            )
    return np.ascontiguousarray(arr)


@dataclass
class Recording:
    """A sampled record of an axis.

    Parameters
    ----------
    t : array_like
        Time [s], strictly increasing.
    x : array_like
        Measured position [m].
    i : array_like, optional
        Motor current [A] (command or measurement). ``i`` or ``F`` must be given.
    F : array_like, optional
        Motor force [N].
    v : array_like, optional
        Measured velocity [m/s].
    x_ref, v_ref : array_like, optional
        Position [m] or velocity [m/s] reference.
    meta : dict, optional
        Metadata, from the ``# key: value`` lines of a CSV file.
    source : str, optional
        The file it was read from.

    Raises
    ------
    InputError
        Arrays of different lengths, empty, not finite, or ``t`` not strictly
        increasing; neither ``i`` nor ``F`` given.

    Examples
    --------
    >>> r = Recording(t=[0.0, 0.001, 0.002], x=[0.0, 1e-5, 2e-5], i=[1.0, 1.0, 1.1])
    >>> r.force(25.0)
    array([25. , 25. , 27.5])
    """

    t: np.ndarray
    x: np.ndarray
    i: np.ndarray | None = None
    F: np.ndarray | None = None
    v: np.ndarray | None = None
    x_ref: np.ndarray | None = None
    v_ref: np.ndarray | None = None
    meta: dict[str, str] = field(default_factory=dict)
    source: str | None = None

    def __post_init__(self) -> None:
        for name in COLUMNS:
            a = getattr(self, name)
            if a is not None:
                setattr(self, name, _column_array(name, a))
        if self.i is None and self.F is None:
            raise InputError.at(
                "i", "a recording needs the motor current i or the motor force F: give one"
            )
        n = self.t.size
        if n == 0:
            raise InputError.at("t", "is empty: give at least one sample")
        for name in self.columns:
            a = getattr(self, name)
            if a.size != n:
                raise InputError.at(
                    name,
                    f"has {a.size} samples but t has {n}: give arrays of the same length",
                )
            bad = np.flatnonzero(~np.isfinite(a))
            if bad.size:
                k = int(bad[0])
                raise InputError.at(
                    name,
                    f"element {k} is {_fmt_f64(a[k])} : remove or interpolate non-finite "
                    "samples",
                )
        bad = np.flatnonzero(np.diff(self.t) <= 0.0)
        if bad.size:
            k = int(bad[0]) + 1
            raise InputError.at(
                "t",
                f"time is not strictly increasing at element {k} ({_fmt_f64(self.t[k])} "
                f"after {_fmt_f64(self.t[k - 1])}): sort the record and drop repeated "
                "samples",
            )
        self.meta = dict(self.meta)

    @classmethod
    def from_simulation(cls, result: Any, *, x_ref: Any = None, v_ref: Any = None,
                        current_noise: float = 0.0, quantum: float = 0.0,
                        seed: int | None = None) -> Recording:
        """A recording of a simulated axis, as a drive would log it.

        Parameters
        ----------
        result : SimulationResult
            What :func:`lugre.simulate` returned (its ``t``, ``x`` and current ``i``).
        x_ref, v_ref : array_like, optional
            The reference the loop followed, kept as a column.
        current_noise : float, default 0
            Standard deviation of white noise added to the current [A].
        quantum : float, default 0
            Encoder resolution [m]: positions rounded to it (0: exact).
        seed : int, optional
            Seed of the noise.

        Examples
        --------
        >>> import numpy as np, lugre
        >>> t = np.arange(0, 0.01, 1e-4)
        >>> r = lugre.simulate(lugre.Model.paper(), t, x_ref=0.01 * t)
        >>> len(lugre.Recording.from_simulation(r, x_ref=0.01 * t, quantum=1e-6))
        100
        """
        x = np.asarray(result.x, dtype=float)
        if quantum < 0 or current_noise < 0:
            raise InputError.at("quantum" if quantum < 0 else "current_noise",
                                "must be zero or positive")
        if quantum > 0:
            x = np.round(x / quantum) * quantum
        i = np.asarray(result.i, dtype=float)
        if current_noise > 0:
            i = i + current_noise * np.random.default_rng(seed).standard_normal(i.size)
        return cls(t=np.asarray(result.t, dtype=float), x=x, i=i, x_ref=x_ref, v_ref=v_ref)

    @property
    def columns(self) -> tuple[str, ...]:
        """Names of the columns present, in :data:`COLUMNS` order."""
        return tuple(c for c in COLUMNS if getattr(self, c) is not None)

    def __len__(self) -> int:
        return int(self.t.size)

    def fingerprint(self) -> dict[str, Any]:
        """What identifies this record's samples: their count, first time and duration
        [s], and a digest of the time, position and current (or force) values, so that
        a model fitted on it can tell the record again (read from the same file, the
        values are the same to the bit)."""
        import hashlib

        h = hashlib.sha256()
        for name in ("t", "x", "i", "F"):
            a = getattr(self, name)
            if a is not None:
                h.update(name.encode())
                h.update(np.ascontiguousarray(a, dtype="<f8").tobytes())
        return {"samples": len(self), "start_s": float(self.t[0]),
                "duration_s": float(self.t[-1] - self.t[0]), "digest": h.hexdigest()[:20]}

    @property
    def dt(self) -> float:
        """Median sample interval [s] (``nan`` for a single sample)."""
        return float(np.median(np.diff(self.t))) if self.t.size > 1 else math.nan

    def force(self, force_constant: float | Any | None = None) -> np.ndarray:
        """The motor force [N]: ``F`` when recorded, else ``force_constant * i``.

        Parameters
        ----------
        force_constant : float or Model, optional
            K_F [N/A] (or a model, whose ``force_constant`` is used). Needed only when
            the recording holds the current ``i`` and not ``F``.

        Returns
        -------
        numpy.ndarray
            A new array.
        """
        if self.F is not None:
            return self.F.copy()
        if force_constant is None:
            raise InputError.at(
                "force_constant",
                "the recording holds the current i, not the force F: give the force "
                "constant K_F [N/A] (or the model)",
            )
        kf = getattr(force_constant, "force_constant", force_constant)
        kf = float(kf)
        if not (math.isfinite(kf) and kf > 0.0):
            raise InputError.at("force_constant", f"is {kf}: give a positive K_F [N/A]")
        assert self.i is not None
        return kf * self.i

    def slice(self, which: Any) -> Recording:
        """The samples selected by a boolean mask or a time range.

        Parameters
        ----------
        which : array_like of bool, or (t_start, t_end)
            A mask of the recording's length, or a time range; ``t_start <= t <= t_end``
            is kept and either end may be ``None``.

        Returns
        -------
        Recording
            A new recording with copies of the selected samples (same ``meta`` and
            ``source``).
        """
        if isinstance(which, tuple) and len(which) == 2:
            lo, hi = which
            mask = np.ones(self.t.size, dtype=bool)
            if lo is not None:
                mask &= self.t >= float(lo)
            if hi is not None:
                mask &= self.t <= float(hi)
        else:
            mask = np.asarray(which)
            if mask.dtype != bool or mask.shape != self.t.shape:
                raise InputError.at(
                    "which",
                    f"must be a boolean mask of {self.t.size} samples or a "
                    "(t_start, t_end) pair",
                )
        kw: dict[str, Any] = {
            c: getattr(self, c)[mask].copy() for c in self.columns
        }
        return Recording(**kw, meta=dict(self.meta), source=self.source)

    def to_dict(self) -> dict[str, np.ndarray]:
        """The columns present, as a dict of arrays (not copies)."""
        return {c: getattr(self, c) for c in self.columns}

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Recording):
            return NotImplemented
        if self.columns != other.columns or self.meta != other.meta:
            return False
        return all(np.array_equal(getattr(self, c), getattr(other, c)) for c in self.columns)

    __hash__ = None  # type: ignore[assignment]

