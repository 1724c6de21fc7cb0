"""Steady-state points from a raw constant-velocity record in NumPy
(``src/estimate/plateaus.rs``), twin of :func:`lugre.steady_state_points`.

:func:`plateaus` is the twin of the core's binding ``_core.plateaus``: the same checks in
the same order, the same segmentation (runs of constant ``v_ref``, or runs of the
velocity differentiated from ``x`` that stay near their running mean), the same
settling rule and the same averages, with the same results (a :class:`PlateauResult`
with the attributes of ``_core.PlateauResult``) and the same notes.
The running means and sums are taken in the core's order (a loop over Python floats,
``np.add.accumulate``), the windowed velocities elementwise, so the two agree bit for
bit. :func:`steady_state_points` runs the facade's own orchestration
(:func:`lugre.identify._steady_state_points`: the recording, its force, the result
and its notes) around this kernel.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._entry import table_or_same
from .._fits import SteadyStatePoints
from ..exceptions import DataError, InputError, ParameterError
from ..identify import _steady_state_points
from ..io import Recording
from .checks import _check_finite, _check_len, _check_time
from .static import _usize
from .static_vp import _div

__all__ = ["PlateauResult", "SteadyStatePoints", "plateaus", "steady_state_points"]

Segment = tuple[int, int, float]


@dataclass(frozen=True)
class PlateauResult:
    """What :func:`plateaus` finds, with the attributes of the core's
    ``_core.PlateauResult``, which :func:`lugre.identify._steady_state_points` reads from
    either."""

    v: np.ndarray
    """Mean measured velocity of each point [m/s]."""
    F: np.ndarray
    """Mean force of each point [N]."""
    F_std: np.ndarray
    """Standard deviation of the force samples behind each point [N]."""
    n_samples: list[int]
    plateau: list[int]
    segment_start: list[int]
    segment_end: list[int]
    segment_velocity: list[float]
    segment_first_used: list[int]
    segment_settled: list[bool]
    used: list[bool]
    notes: list[str]


def _e4(x: float) -> str:
    """Rust's ``{:.4e}`` of a finite ``f64`` (``-1.2346e-2``: no ``+``, no padding)."""
    mant, ex = format(x, ".4e").split("e")
    return f"{mant}e{int(ex)}"


def _as_f64(name: str, a: Any) -> np.ndarray:
    """A 1-D float64 array, as the binding takes it."""
    try:
        arr = np.ascontiguousarray(a, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise InputError.at(name, f"must be an array of numbers ({e})") from None
    if arr.ndim != 1:
        raise InputError.at(name, "must be a contiguous 1-D float64 array")
    return arr


def _segments_from_ref(vr: list[float]) -> list[Segment]:
    """Runs of constant ``v_ref`` (within 1e-9 of its largest magnitude), zero excluded."""
    vmax = 0.0
    for v in vr:
        vmax = max(vmax, abs(v))
    tol = 1e-9 * vmax
    out: list[Segment] = []
    s = 0
    n = len(vr)
    for k in range(1, n + 1):
        if k == n or abs(vr[k] - vr[s]) > tol:
            if abs(vr[s]) > tol:
                out.append((s, k, vr[s]))
            s = k
    return out


def _segments_from_x(t: np.ndarray, x: np.ndarray, half: int, tol: float) -> list[Segment]:
    """Runs of the velocity differentiated from ``x`` over ``2*half`` samples that stay
    within ``tol`` (relative) of their running mean."""
    n = t.size
    if n < 2 * half + 2:
        return []
    vf = ((x[2 * half:] - x[: n - 2 * half]) / (t[2 * half:] - t[: n - 2 * half])).tolist()
    vmax = 0.0
    for v in vf:
        vmax = max(vmax, abs(v))
    abs_tol = 1e-3 * vmax
    out: list[Segment] = []
    m = len(vf)
    s = 0
    total = vf[0]
    for k in range(1, m + 1):
        mean = total / float(k - s)
        if k == m or abs(vf[k] - mean) > tol * abs(mean) + abs_tol:
            if abs(mean) > abs_tol:
                out.append((s + half, k + half, mean))
            if k < m:
                s = k
                total = vf[k]
        else:
            total += vf[k]
    return out


def _sum(a: np.ndarray) -> float:
    """The sum in index order (``Iterator::sum``), not NumPy's pairwise one."""
    return float(np.add.accumulate(a)[-1])


def plateaus(t: Any, x: Any, force: Any, v_ref: Any = None, settle_fraction: float = 0.3,
             velocity_tolerance: float = 0.02, window: int = 0, min_samples: int = 20,
             chunks: int = 1) -> PlateauResult:
    """Find the constant-velocity plateaus of a record and average each settled one
    (twin of ``_core.plateaus``; same arguments, results and errors).

    Parameters
    ----------
    t, x, force : array_like
        Time [s], position [m] and motor force [N], 1-D, same length.
    v_ref : array_like, optional
        The velocity reference [m/s]: plateaus are its runs of constant value.
    settle_fraction : float
        Leading fraction of each plateau always dropped, in ``[0, 1)``.
    velocity_tolerance : float
        Relative tolerance on the windowed velocity, > 0.
    window : int
        Velocity window in samples (0: a tenth of the plateau, at least 5).
    min_samples : int
        Fewest settled samples that make a plateau usable.
    chunks : int
        Points per plateau (replicates from equal chunks of its settled part).

    Returns
    -------
    PlateauResult
        ``v``, ``F``, ``F_std`` (arrays, one per point), ``n_samples``, ``plateau``
        (lists, one per point), ``segment_start``, ``segment_end``,
        ``segment_velocity``, ``segment_first_used``, ``segment_settled`` (lists, one per
        detected plateau), ``used`` (one per sample) and ``notes``.

    Raises
    ------
    InputError
        ``t`` empty, not finite or not increasing; ``x``, ``force`` or ``v_ref`` of
        another length or not finite.
    ParameterError
        ``settle_fraction`` outside ``[0, 1)``; ``velocity_tolerance`` not > 0.
    DataError
        No plateau settled.
    OverflowError
        ``window``, ``min_samples`` or ``chunks`` negative (the binding's ``usize``).
    """
    # the binding converts its arguments first, in order, then the core checks
    ta, xa, fa = _as_f64("t", t), _as_f64("x", x), _as_f64("F", force)
    vra = None if v_ref is None else _as_f64("v_ref", v_ref)
    settle = float(settle_fraction)
    vtol = float(velocity_tolerance)
    window, min_samples, chunks = _usize(window), _usize(min_samples), _usize(chunks)
    tl, xl, fl = ta.tolist(), xa.tolist(), fa.tolist()
    _check_time("t", tl)
    n = len(tl)
    _check_len("x", xl, n, "t")
    _check_len("force", fl, n, "t")
    _check_finite("x", xl)
    _check_finite("force", fl)
    vrl = None
    if vra is not None:
        vrl = vra.tolist()
        _check_len("v_ref", vrl, n, "t")
        _check_finite("v_ref", vrl)
    if not 0.0 <= settle < 1.0:
        raise ParameterError.invalid("settle_fraction", settle, "must be in [0, 1)")
    if not (vtol > 0.0 and math.isfinite(vtol)):
        raise ParameterError.invalid("velocity_tolerance", vtol,
                                     "must be a finite number greater than zero")
    chunks = max(chunks, 1)
    if vrl is not None:
        segs = _segments_from_ref(vrl)
    else:
        half = (window + 1) // 2 if window > 0 else max(n // 200, 3)
        segs = _segments_from_x(ta, xa, half, vtol)

    v: list[float] = []
    f: list[float] = []
    f_std: list[float] = []
    n_samples: list[int] = []
    plateau: list[int] = []
    seg_first: list[int] = []
    seg_settled: list[bool] = []
    used = [False] * n
    notes: list[str] = []
    need = max(min_samples, 2 * chunks)
    for si, (s, e, vnom) in enumerate(segs):
        length = e - s
        w = window if window > 0 else max(length // 10, 5)
        start0 = s + math.ceil(settle * float(length))
        first = e
        if w < length and start0 < e:
            # the last window (start index) whose velocity is off the plateau value
            tol = vtol * abs(vnom)
            vw = (xa[s + w:e] - xa[s:e - w]) / (ta[s + w:e] - ta[s:e - w])
            bad = np.flatnonzero(np.abs(vw - vnom) > tol)
            first = start0 if bad.size == 0 else max(start0, s + int(bad[-1]) + w)
        long_enough = e > first and e - first >= need
        drifting = False
        if long_enough:
            # a steady plateau has no trend: the two halves' mean speeds agree
            mid = first + (e - first) // 2
            v1 = _div(xl[mid] - xl[first], tl[mid] - tl[first])
            v2 = _div(xl[e - 1] - xl[mid], tl[e - 1] - tl[mid])
            drifting = abs(v2 - v1) > 0.5 * vtol * abs(vnom)
        settled = long_enough and not drifting
        seg_settled.append(settled)
        seg_first.append(first if settled else e)
        if not settled:
            head = f"plateau {si} (v = {_e4(vnom)} m/s, samples {s}..{e}) skipped: "
            notes.append(
                head + "the speed drifts through it (the axis is still accelerating)"
                if drifting else
                head + f"the velocity did not settle within {vtol * 100.0:.0f} % of its "
                "nominal value"
            )
            continue
        m = e - first
        for c in range(chunks):
            a = first + c * m // chunks
            b = first + (c + 1) * m // chunks
            k = b - a
            mean = _sum(fa[a:b]) / float(k)
            d = fa[a:b] - mean
            var = _sum(d * d) / float(max(k, 2) - 1)
            v.append(_div(xl[b - 1] - xl[a], tl[b - 1] - tl[a]))
            f.append(mean)
            f_std.append(math.sqrt(var))
            n_samples.append(k)
            plateau.append(si)
        used[first:e] = [True] * m
    if not v:
        raise DataError(
            f"data: no settled constant-velocity plateau found ({len(segs)} candidate "
            "segments): record longer plateaus, or give v_ref, or raise velocity_tolerance"
        )
    return PlateauResult(
        v=np.array(v, dtype=np.float64),
        F=np.array(f, dtype=np.float64),
        F_std=np.array(f_std, dtype=np.float64),
        n_samples=n_samples,
        plateau=plateau,
        segment_start=[s for s, _, _ in segs],
        segment_end=[e for _, e, _ in segs],
        segment_velocity=[vn for _, _, vn in segs],
        segment_first_used=seg_first,
        segment_settled=seg_settled,
        used=used,
        notes=notes,
    )


def steady_state_points(recording: Recording | str, force_constant: float | None = None, *,
                        columns: dict[str, str] | None = None, settle_fraction: float = 0.3,
                        velocity_tolerance: float = 0.02, chunks: int = 1,
                        min_samples: int = 20) -> SteadyStatePoints:
    """Find constant-velocity plateaus in a raw record, drop transients, average (NumPy
    twin of :func:`lugre.steady_state_points`; same parameters, result and errors).

    Parameters
    ----------
    recording : Recording, path or table
        With ``t``, ``x`` and ``F`` or ``i`` (then ``force_constant`` is needed).
    force_constant : float, optional
        K_F [N/A] for a record of currents.
    columns : dict, optional
        Column mapping when ``recording`` is a path.
    settle_fraction, velocity_tolerance, chunks, min_samples
        As in :func:`lugre.identify.steady_state_points`.

    Returns
    -------
    SteadyStatePoints
    """
    return _steady_state_points(plateaus, table_or_same(recording), force_constant,
                                columns=columns, settle_fraction=settle_fraction,
                                velocity_tolerance=velocity_tolerance, chunks=chunks,
                                min_samples=min_samples)
