"""Alarms from an axis's history, and how much the axis changed (the fleet page's order).

Every rule compares the latest recordings with a baseline, the axis's first
:data:`BASELINE` diagnosed recordings, and asks the change to persist over the last
:data:`RECENT` recordings, so that one odd night (a cold start, a noisy record) raises
nothing:

- ``level``: a direction's refitted Coulomb level departs from the baseline's median by
  more than :data:`LEVEL_SHARE` of it AND by more than :data:`LEVEL_SIGMAS` times the
  baseline's night-to-night scatter (a robust standard deviation, 1.4826 MAD, at least
  :data:`SCATTER_FLOOR` of the level), the same way in each of the last recordings;
- ``new_effect``: an effect found in at least :data:`NEW_MIN` of the last
  :data:`NEW_WINDOW` recordings and in at most :data:`NEW_BASELINE_MAX` of the baseline;
- ``growth``: an effect found in most of the baseline whose size exceeds the baseline's
  median by more than :data:`GROWTH_SHARE` of it, by more than three times its scatter,
  and with its interval's low end above the baseline's interval (when the diagnosis
  gives one), in each of the last recordings.

``since`` is the first recording of the persistent change: the earliest recording after
the baseline reached from the latest one through changed recordings only (for a new
effect, without two missing in a row).
"""

from __future__ import annotations

import datetime as _dt
import statistics
from dataclasses import dataclass
from typing import Any

from .. import units as U
from .trends import SIZE, AxisHistory, size_of

__all__ = ["BASELINE", "GROWTH_SHARE", "LEVEL_SHARE", "LEVEL_SIGMAS", "NEW_BASELINE_MAX",
           "NEW_MIN", "NEW_WINDOW", "RECENT", "SCATTER_FLOOR", "Alarm", "assess"]

BASELINE = 5
RECENT = 3
LEVEL_SHARE = 0.10
LEVEL_SIGMAS = 3.0
SCATTER_FLOOR = 0.01
NEW_WINDOW = 4
NEW_MIN = 3
NEW_BASELINE_MAX = 1
GROWTH_SHARE = 0.25

_WAY = {"positive": "moving forward", "negative": "moving back"}


@dataclass
class Alarm:
    """One alarm of ALARMS.json."""

    axis: str
    kind: str
    effect: str | None
    since: _dt.datetime
    evidence: str
    score: float

    def to_dict(self) -> dict[str, Any]:
        return {"axis": self.axis, "kind": self.kind, "effect": self.effect,
                "since": self.since.isoformat(), "evidence": self.evidence}


def _robust(vals: list[float], floor: float) -> tuple[float, float]:
    """Median and robust standard deviation (1.4826 MAD, at least ``floor`` of the
    median's magnitude)."""
    med = statistics.median(vals)
    mad = statistics.median(abs(v - med) for v in vals)
    return med, max(1.4826 * mad, floor * abs(med))


def _since(flags: list[bool], gap: int = 0) -> int | None:
    """Index of the first flagged recording of the trailing run (after the baseline),
    allowing ``gap`` unflagged recordings in a row inside the run."""
    first, misses = None, 0
    for k in range(len(flags) - 1, BASELINE - 1, -1):
        if flags[k]:
            first, misses = k, 0
        else:
            misses += 1
            if misses > gap:
                break
    return first


def _when(h: AxisHistory, k: int) -> str:
    return f"{h.times[k]:%Y-%m-%d %H:%M} ({h.recordings[k]})"


def level_alarm(h: AxisHistory) -> tuple[Alarm | None, float]:
    """The ``level`` alarm of an axis (or None) and its level change in bands."""
    parts, since, score = [], None, 0.0
    unit = U.base_unit("fc")
    for d in ("positive", "negative"):
        vals = h.levels.get(d, [])
        base = [v for v in vals[:BASELINE] if v is not None]
        if len(base) < 3 or len(vals) < BASELINE + RECENT:
            continue
        med, sd = _robust(base, SCATTER_FLOOR)
        band = max(LEVEL_SHARE * abs(med), LEVEL_SIGMAS * sd)
        delta = [None if v is None else v - med for v in vals]
        recent = [x for x in delta[-RECENT:] if x is not None]
        if recent:
            score = max(score, abs(statistics.median(recent)) / band)
        up = [x is not None and x > band for x in delta]
        down = [x is not None and x < -band for x in delta]
        flags = up if all(up[-RECENT:]) else down if all(down[-RECENT:]) else None
        if flags is None:
            continue
        k0 = _since(flags)
        assert k0 is not None
        since = k0 if since is None else min(since, k0)
        now = statistics.median(vals[-RECENT:])  # type: ignore[type-var]
        parts.append(
            f"{_WAY[d]} {'rose' if flags is up else 'fell'} from {U.fmt(med, unit)} (median of "
            f"the first {len(base)} recordings, night-to-night scatter {U.fmt(sd, unit, 2)}) "
            f"to {U.fmt(now, unit)} ({100 * (now - med) / med:+.0f} %) over the last {RECENT} "
            f"recordings, beyond the alarm band of {U.fmt(band, unit, 2)} (the larger of "
            f"{100 * LEVEL_SHARE:.0f} % and {LEVEL_SIGMAS:g} times the scatter) since "
            f"{_when(h, k0)}")
    if since is None:
        return None, score
    text = (f"The Coulomb {U.force_words()} level {'; '.join(parts)}. Look for lost or "
            "changed lubrication, wear or dirt on the guideway or screw, or a seal or "
            "bearing going; refit the model (lugre fit) once the cause is found.")
    return Alarm(h.axis, "level", None, h.times[since], text, score), score


def _describe(effect: str, seen: Any) -> str:
    out = []
    for name, v in seen.parameters.items():
        if not isinstance(v, (int, float)):
            continue
        unit = U.unit_of(effect, name)
        iv = seen.intervals.get(name)
        ci = (f" (95 % {U.fmt_range(iv[0], iv[1], unit, 3)})"
              if isinstance(iv, (list, tuple)) and len(iv) == 2 else "")
        out.append(f"{name} {U.fmt(v, unit, 3)}{ci}")
    return ", ".join(out)


def effect_alarms(h: AxisHistory) -> tuple[list[Alarm], float]:
    """The ``new_effect`` and ``growth`` alarms of an axis and its effects' change."""
    alarms, score = [], 0.0
    if len(h) < BASELINE + RECENT:
        return alarms, score
    for effect, series in sorted(h.effects.items()):
        found = [s is not None for s in series]
        in_base = sum(found[:BASELINE])
        if in_base <= NEW_BASELINE_MAX:
            a, s = _new_effect(h, effect, series, found, in_base)
        elif in_base >= (BASELINE + 1) // 2 + 1:
            a, s = _growth(h, effect, series)
        else:
            continue
        score = max(score, s)
        if a is not None:
            alarms.append(a)
    return alarms, score


def _new_effect(h: AxisHistory, effect: str, series: list[Any], found: list[bool],
                in_base: int) -> tuple[Alarm | None, float]:
    recent = sum(found[-NEW_WINDOW:])
    score = recent / NEW_MIN
    if recent < NEW_MIN:
        return None, score
    k0 = _since(found, gap=1)
    if k0 is None:
        return None, score
    last = next(s for s in reversed(series) if s is not None)
    n_since = sum(found[k0:])
    text = (f"{effect} found in {n_since} of the {len(found) - k0} recordings since "
            f"{_when(h, k0)} and in {in_base} of the first {BASELINE}; in the latest: "
            f"{_describe(effect, last)}. The model does not hold it: find its cause "
            "(a magnet, a screw nut, a coupling), or add it to the model (lugre diagnose "
            "--out-model) if it is to stay.")
    return Alarm(h.axis, "new_effect", effect, h.times[k0], text, score), score


def _growth(h: AxisHistory, effect: str, series: list[Any]) -> tuple[Alarm | None, float]:
    sizes = [size_of(effect, s.parameters, s.intervals) if s else (None, None, None)
             for s in series]
    base = [z for z, _, _ in sizes[:BASELINE] if z is not None]
    his = [hi for _, _, hi in sizes[:BASELINE] if hi is not None]
    s0, sd = _robust(base, 0.02)
    top = statistics.median(his) if his else s0 + 2 * sd
    grown = [z is not None and z > s0 * (1 + GROWTH_SHARE) and z > s0 + 3 * sd
             and (lo is None or lo > top) for z, lo, _ in sizes]
    recent = [z for z, _, _ in sizes[-RECENT:] if z is not None]
    score = (statistics.median(recent) / (s0 * (1 + GROWTH_SHARE))) if recent and s0 else 0.0
    if not all(grown[-RECENT:]):
        return None, score
    k0 = _since(grown)
    assert k0 is not None
    name = SIZE[effect]
    unit = U.unit_of(effect, name)
    now = sizes[-1][0]
    assert now is not None
    text = (f"{effect} {name} grew from {U.fmt(s0, unit, 3)} (median of the first "
            f"{len(base)} recordings, 95 % interval up to {U.fmt(top, unit, 3)}) to "
            f"{U.fmt(now, unit, 3)} in the latest ({100 * (now - s0) / s0:+.0f} %), above "
            f"{100 * GROWTH_SHARE:.0f} % and beyond its intervals in each recording since "
            f"{_when(h, k0)}. A growing {effect} is wear: inspect the part that makes it "
            "before it fails.")
    return Alarm(h.axis, "growth", effect, h.times[k0], text, score), score


def assess(h: AxisHistory) -> tuple[list[Alarm], float]:
    """An axis's alarms and its change score (1 is a rule's threshold)."""
    with U.axis(h.kind):
        level, s1 = level_alarm(h)
        effects, s2 = effect_alarms(h)
    alarms = ([level] if level else []) + effects
    return alarms, max(s1, s2)
