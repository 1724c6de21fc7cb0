"""Where a residual lives: time, position and velocity ranges above the noise floor, and
its spectrum over position."""

from __future__ import annotations

from typing import Any

import numpy as np

from . import residual as R

__all__ = ["locate", "position_spectrum", "short_ranges"]


def _ranges(centers: np.ndarray, flag: np.ndarray, half: float) -> list[list[float]]:
    out: list[list[float]] = []
    start = None
    for k, f in enumerate(flag):
        if f and start is None:
            start = k
        if (not f or k == flag.size - 1) and start is not None:
            end = k if f else k - 1
            out.append([float(centers[start] - half), float(centers[end] + half)])
            start = None
    return out


def locate(r: np.ndarray, sig: R.Signals, floor: float, *, factor: float = 2.0
           ) -> dict[str, Any]:
    """Where the residual's rms rises above ``factor`` times the noise floor.

    Parameters
    ----------
    r : numpy.ndarray
        Residual [N].
    sig : Signals
        The prepared recording.
    floor : float
        Noise floor [N].
    factor : float, default 2.0
        Threshold over the floor.

    Returns
    -------
    dict
        ``time``, ``position``, ``velocity``: lists of ``[lo, hi]`` ranges;
        ``direction``: rms in motion forward, backward and at rest.
    """
    m = sig.mask
    out: dict[str, Any] = {"threshold": factor * floor}
    for key, val, nb in (("time", sig.t, 40), ("position", sig.x, 30), ("velocity", sig.vf, 20)):
        vv = val[m]
        rr = r[m]
        lo, hi = float(vv.min()), float(vv.max())
        if hi <= lo:
            out[key] = []
            continue
        edges = np.linspace(lo, hi, nb + 1)
        idx = np.clip(np.digitize(vv, edges) - 1, 0, nb - 1)
        cnt = np.bincount(idx, minlength=nb)
        ss = np.bincount(idx, weights=rr * rr, minlength=nb)
        rms = np.sqrt(ss / np.maximum(cnt, 1))
        flag = (rms > factor * floor) & (cnt >= 20)
        centers = 0.5 * (edges[1:] + edges[:-1])
        out[key] = _ranges(centers, flag, 0.5 * (edges[1] - edges[0]))
    vmax = float(np.max(np.abs(sig.vf[m])))
    direction = {}
    for name, sel in (("positive", sig.vf > 0.01 * vmax), ("negative", sig.vf < -0.01 * vmax),
                      ("rest", np.abs(sig.vf) <= 0.01 * vmax)):
        s = sel & m
        direction[name] = float(np.sqrt(np.mean(r[s] ** 2))) if s.sum() > 20 else None
    out["direction"] = direction
    return out


def short_ranges(ranges: list[list[float]]) -> str:
    if len(ranges) > 4:
        return f"{len(ranges)} stretches from {ranges[0][0]:.3g} to {ranges[-1][1]:.3g}"
    return ", ".join(f"[{a:.3g}, {b:.3g}]" for a, b in ranges)


def position_spectrum(r: np.ndarray, sig: R.Signals) -> tuple[np.ndarray, np.ndarray]:
    """Amplitude of the residual's best sinusoid over position, per spatial frequency."""
    m = sig.mask
    step = max(1, int(m.sum() // 4000))
    x = sig.x[m][::step]
    rr = r[m][::step] - np.mean(r[m])
    span = max(float(np.ptp(x)), 1e-9)
    ks = np.arange(1.0 / span, min(200.0 / span, 2000.0), 0.5 / span)
    if ks.size == 0:
        return ks, np.empty(0)
    s, c = R.position_sums(sig, x, rr, float(ks[0]), 0.5 / span, ks.size)
    return ks, 2 * np.hypot(s, c) / x.size
