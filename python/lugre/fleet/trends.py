"""Each axis's history from the store: its friction levels per direction and each effect's
parameters over time, recording by recording (the recordings that were diagnosed)."""

from __future__ import annotations

import datetime as _dt
import json
from dataclasses import dataclass, field
from typing import Any

from ..vocabulary import (
    COGGING,
    CURRENT_LAG,
    CURRENT_LIMIT,
    DEADBAND,
    DELAY,
    DRAG,
    DRIFT,
    FORCE_RIPPLE,
    GRAVITY,
    LOAD_FRICTION,
    MASS,
    OFFSET,
    POSITION_FRICTION,
    RESONANCE,
    SPRING,
    STRIBECK_SHAPE,
)

__all__ = ["SIZE", "AxisHistory", "Seen", "histories", "size_of"]

#: The parameter that says how large each effect is (its magnitude is compared).
SIZE = {COGGING: "amplitude", FORCE_RIPPLE: "amplitude", OFFSET: "force", SPRING: "stiffness",
        DRAG: "coefficient", DEADBAND: "current", MASS: "delta", DELAY: "seconds",
        CURRENT_LAG: "bandwidth", DRIFT: "gain", GRAVITY: "torque",
        LOAD_FRICTION: "coefficient", CURRENT_LIMIT: "current", STRIBECK_SHAPE: "exponent",
        RESONANCE: "frequency", POSITION_FRICTION: "scale"}


@dataclass
class Seen:
    """An effect as one recording's diagnosis found it."""

    parameters: dict[str, Any]
    intervals: dict[str, Any]
    explained: float | None


def size_of(effect: str, parameters: dict[str, Any], intervals: dict[str, Any]
            ) -> tuple[float | None, float | None, float | None]:
    """The effect's size (the magnitude of its :data:`SIZE` parameter; for a
    ``position_friction`` the largest departure of its scale from 1) and that
    parameter's interval, ``(size, low, high)``."""
    name = SIZE.get(effect)
    v = parameters.get(name) if name else None
    if effect == POSITION_FRICTION and isinstance(v, list) and v:
        return max(abs(float(s) - 1.0) for s in v), None, None
    if not isinstance(v, (int, float)):
        return None, None, None
    iv = intervals.get(name) if name else None
    if isinstance(iv, (list, tuple)) and len(iv) == 2 and all(
            isinstance(b, (int, float)) for b in iv):
        lo, hi = sorted(abs(float(b)) for b in iv)
        if float(iv[0]) * float(iv[1]) < 0:
            lo = 0.0
        return abs(float(v)), lo, hi
    return abs(float(v)), None, None


@dataclass
class AxisHistory:
    """One axis's diagnosed recordings, in time order."""

    axis: str
    kind: str
    recordings: list[str] = field(default_factory=list)
    times: list[_dt.datetime] = field(default_factory=list)
    nrmse: list[float | None] = field(default_factory=list)
    levels: dict[str, list[float | None]] = field(default_factory=dict)
    effects: dict[str, list[Seen | None]] = field(default_factory=dict)
    errors: int = 0

    def __len__(self) -> int:
        return len(self.recordings)


def histories(store: Any) -> list[AxisHistory]:
    """Every axis's history (the recordings with status ok and a time)."""
    kinds = {r["axis"]: r["kind"] for r in store.rows("SELECT axis, kind FROM axes")}
    out: dict[str, AxisHistory] = {a: AxisHistory(a, k or "linear") for a, k in kinds.items()}
    recs = store.rows("SELECT axis, recording, time, status, nrmse_force FROM recordings "
                      "ORDER BY axis, time, recording")
    index: dict[tuple[str, str], int] = {}
    for r in recs:
        h = out.setdefault(r["axis"], AxisHistory(r["axis"], "linear"))
        if r["status"] != "ok" or r["time"] is None:
            h.errors += 1
            continue
        index[(r["axis"], r["recording"])] = len(h)
        h.recordings.append(r["recording"])
        h.times.append(r["time"])
        h.nrmse.append(r["nrmse_force"])
    for h in out.values():
        h.levels = {"positive": [None] * len(h), "negative": [None] * len(h)}
    for r in store.rows("SELECT axis, recording, direction, level FROM levels"):
        k = index.get((r["axis"], r["recording"]))
        if k is not None and r["direction"] in ("positive", "negative"):
            out[r["axis"]].levels[r["direction"]][k] = r["level"]
    for r in store.rows("SELECT axis, recording, effect, parameters, intervals, explained "
                        "FROM findings ORDER BY rank"):
        k = index.get((r["axis"], r["recording"]))
        if k is None:
            continue
        h = out[r["axis"]]
        series = h.effects.setdefault(r["effect"], [None] * len(h))
        if series[k] is None:  # the first (most important) of an effect found twice
            series[k] = Seen(json.loads(r["parameters"]), json.loads(r["intervals"] or "{}"),
                             r["explained"])
    return [out[a] for a in sorted(out)]
