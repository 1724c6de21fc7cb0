"""Refuse recordings a fit or a diagnosis cannot use: gaps in the sampling and positions
in the wrong unit. Each refusal names the fix (``--resample``, ``--x-unit mm``, a column
expression such as ``x=pos/1000``); :func:`resample_uniform` is the first of them.
"""

from __future__ import annotations

import numpy as np

from .exceptions import DataError
from .recording import Recording

__all__ = ["MAX_SPAN", "MAX_SPEED", "require_plausible", "resample_uniform"]

#: Largest position span [m] of a plausible servo-axis recording.
MAX_SPAN = 5.0
#: Largest speed [m/s] of a plausible servo-axis recording.
MAX_SPEED = 20.0
#: Largest speed [rad/s] of a plausible rotary-axis recording (a motor shaft at
#: 10 000 rpm); faster, the positions are likely degrees.
MAX_ROTARY_SPEED = 1100.0
#: A sample interval longer than this many median intervals is a gap.
GAP_FACTOR = 1.5


def _name(rec: Recording) -> str:
    return rec.source or "the recording"


def require_plausible(rec: Recording, axis_kind: str | None = None) -> Recording:
    """Return ``rec`` when its sampling is uniform and its units look like metres (on a
    rotary axis, ``axis_kind="rotary"`` or the recording's ``meta["axis_kind"]``:
    radians).

    Raises
    ------
    DataError
        The sampling has gaps (an interval longer than 1.5 median intervals): the fix is
        ``--resample`` / :func:`resample_uniform` or cutting the record; or the positions
        span more than 5 m or the speed exceeds 20 m/s: the fix is ``--x-unit mm`` /
        ``read_recording(..., x_unit="mm")`` or a mapping such as ``x=pos/1000``.
    """
    from .readers import MAX_MAGNITUDE

    for c in rec.columns:
        a = getattr(rec, c)
        big = np.flatnonzero(np.abs(a) > MAX_MAGNITUDE)
        if big.size:
            k = int(big[0])
            raise DataError(
                f"{_name(rec)}: sample {k} of column {c!r} is {a[k]:.6g}, beyond any "
                f"measurement (|value| > {MAX_MAGNITUDE:g}): fix or remove the sample"
            )
    t = rec.t
    if t.size < 3:
        return rec
    dt = np.diff(t)
    med = float(np.median(dt))
    gaps = np.flatnonzero(dt > GAP_FACTOR * med * 1.0001 + 1e-12)
    if gaps.size:
        k = int(gaps[np.argmax(dt[gaps])])
        raise DataError(
            f"{_name(rec)}: the sampling has gaps: {gaps.size} of {dt.size} intervals are "
            f"longer than {GAP_FACTOR:g} times the usual {med:.4g} s (the longest, "
            f"{dt[k]:.4g} s, after t = {t[k]:.6g} s); fits and diagnoses need uniform "
            "sampling: add --resample (Python: lugre.io.resample_uniform(rec)) to "
            "interpolate onto a uniform grid, or cut the record at the gaps"
        )
    speed = np.abs(np.diff(rec.x)) / med
    vmax = float(np.percentile(speed, 99)) if speed.size else 0.0
    if (axis_kind or rec.meta.get("axis_kind")) == "rotary":
        return _plausible_rotary(rec, vmax)
    span = float(np.ptp(rec.x))
    if span > MAX_SPAN or vmax > MAX_SPEED:
        what = (f"the positions span {span:.4g} m" if span > MAX_SPAN
                else f"the speed reaches {vmax:.4g} m/s")
        raise DataError(
            f"{_name(rec)}: {what}, beyond a servo axis: the positions look like "
            "millimetres, but recordings are in metres: add --x-unit mm (Python: "
            "read_recording(..., x_unit='mm')) or map the column as x=pos/1000"
        )
    return rec


def _plausible_rotary(rec: Recording, vmax: float) -> Recording:
    """A rotary axis's record: any number of turns, at most :data:`MAX_ROTARY_SPEED`."""
    if vmax > MAX_ROTARY_SPEED:
        raise DataError(
            f"{_name(rec)}: the speed reaches {vmax:.4g} rad/s ({vmax * 30 / np.pi:.4g} "
            "rpm), beyond a servo axis: the positions look like degrees, but a rotary "
            "axis's recordings are in radians: add --x-unit deg (Python: "
            "read_recording(..., x_unit='deg'))")
    return rec


def resample_uniform(rec: Recording, dt: float | None = None) -> Recording:
    """Linear interpolation of every column onto a uniform time grid.

    Parameters
    ----------
    rec : Recording
        The recording.
    dt : float, optional
        The grid step [s]; the median sample interval by default.

    Returns
    -------
    Recording
        A new recording from ``t[0]`` to ``t[-1]``, with ``meta["resampled"]`` saying
        what was done.
    """
    t = rec.t
    if t.size < 2:
        return rec
    step = float(np.median(np.diff(t))) if dt is None else float(dt)
    if not (np.isfinite(step) and step > 0.0):
        from .exceptions import InputError

        raise InputError.at("dt", f"is {step}: give a positive sample interval [s]")
    n = int(np.floor((t[-1] - t[0]) / step * (1 + 1e-12))) + 1
    grid = t[0] + step * np.arange(n)
    cols = {c: np.interp(grid, t, getattr(rec, c)) for c in rec.columns if c != "t"}
    meta = {**rec.meta, "resampled": (f"linearly interpolated from {t.size} samples onto "
                                      f"a uniform grid of {n} samples, dt = {step:.6g} s")}
    return Recording(t=grid, **cols, meta=meta, source=rec.source)
