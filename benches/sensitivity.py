"""How the acceptance constants of the block test move false findings and detection:
the first step's trials of a calibration run (``benches/calibration.py``, each
candidate against the base, its held-out block statistics) decided again with each
constant at half and at twice its value:

    python benches/sensitivity.py OUT_DIR/calibration.json [--md OUT.md]

A replay, not a rerun: it decides the first step only (later steps, the look-alike,
partial and physics checks are not replayed; a trial those refused stays refused), and
reads the motor force's rms from the recorded current rather than its low-passed
force. Its agreement with what the diagnosis named at the defaults is printed first:
the table means what it says only as far as that agreement goes.
"""

from __future__ import annotations

import argparse
import gzip
import json
import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

#: The reasons of a refusal the block test and the size rule give; any other refusal
#: (not physical, a lag under a fifth of a sample, a contribution spread thin, small
#: against the noise floor) stays a refusal in the replay.
_REPLAYED = ("gain below threshold", "not consistent", "contribution ", "consistent over",
             "confined but overwhelming")


#: A correction of the believed mass (an inertia on a rotary axis) is no false finding:
#: the bench's believed models are off by 1-2 % in it.
_MASS = ("mass", "inertia")


@dataclass(frozen=True)
class Constants:
    """The block test's constants (``lugre.diagnosis.scoring.accept``) and the size rule
    (``options.MIN_SHARE``)."""

    min_gain: float = 10.0
    alpha: float = 1e-3
    overwhelming: float = 20.0
    min_blocks: int = 3
    ratio: float = 10.0
    min_share: float = 0.003


def passes(tr: dict[str, Any], force_rms: float, c: Constants) -> bool:
    """Whether a first-step trial is named under ``c``."""
    why = str(tr.get("why") or "")
    if not tr.get("accepted") and not why.startswith(_REPLAYED):
        return False
    gain, p = float(tr.get("gain") or 0.0), tr.get("p")
    ratio = tr.get("ratio")
    ratio = math.inf if ratio is None else float(ratio)
    block = gain > c.min_gain and (
        (p is not None and float(p) < c.alpha)
        or (gain > c.overwhelming * c.min_gain and int(tr.get("positive") or 0) >= c.min_blocks
            and ratio > c.ratio))
    return block and float(tr.get("contrib") or 0.0) >= c.min_share * force_rms


def _named(row: dict[str, Any], c: Constants, effect: str | None) -> bool:
    trials = row.get("first_step") or []
    kinds = {"delay": ("delay", "current_lag"), "current_lag": ("delay", "current_lag")}
    want = kinds.get(effect or "", (effect,))
    return any(passes(tr, row["force_rms"], c) for tr in trials
               if (effect is None and tr.get("effect") not in _MASS)
               or (effect is not None and tr.get("effect") in want))


def variants() -> list[tuple[str, Constants]]:
    base = Constants()
    out = [("defaults", base)]
    for name in ("min_gain", "alpha", "overwhelming", "min_blocks", "ratio", "min_share"):
        v = getattr(base, name)
        for k, label in ((0.5, "half"), (2.0, "double")):
            nv = max(1, round(v * k)) if isinstance(v, int) else v * k
            out.append((f"{name} {label} ({nv:g})", replace(base, **{name: nv})))
    return out


def table(rows: list[dict[str, Any]]) -> str:
    clean = [r for r in rows if r["phase"] == "clean" and "first_step" in r]
    sweep = [r for r in rows if r["phase"] == "sweep" and "first_step" in r]
    at = {m: [r for r in sweep if r["multiple"] == m] for m in (0.5, 2.0)}
    lines = ["| constants | false findings (clean) | found at 2x | claimed at 0.5x |",
             "|---|---|---|---|"]
    for label, c in variants():
        ff = sum(_named(r, c, None) for r in clean)
        f2 = sum(_named(r, c, r["effect"]) for r in at[2.0])
        f05 = sum(_named(r, c, r["effect"]) for r in at[0.5])
        lines.append(f"| {label} | {ff} / {len(clean)} ({100 * ff / max(len(clean), 1):.1f} %)"
                     f" | {f2} / {len(at[2.0])} ({100 * f2 / max(len(at[2.0]), 1):.0f} %)"
                     f" | {f05} / {len(at[0.5])} ({100 * f05 / max(len(at[0.5]), 1):.0f} %) |")
    return "\n".join(lines)


def agreement(rows: list[dict[str, Any]]) -> str:
    """How often the replay at the defaults says what the diagnosis said."""
    c, same, n = Constants(), 0, 0
    for r in rows:
        if "first_step" not in r:
            continue
        effect = r["effect"] if r["phase"] == "sweep" else None
        actual = (bool(r.get("found")) if effect else
                  any(f["effect"] not in _MASS for f in r.get("findings") or []))
        same += _named(r, c, effect) == actual
        n += 1
    return f"replay at the defaults agrees with the diagnosis on {same} of {n} records"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("calibration")
    ap.add_argument("--md", help="write the table here too")
    a = ap.parse_args()
    path = Path(a.calibration)
    opener = gzip.open if path.suffix == ".gz" else open
    with opener(path, "rt") as fh:
        rows = json.load(fh)["records"]
    text = agreement(rows) + "\n\n" + table(rows) + "\n"
    print(text)
    if a.md:
        Path(a.md).write_text(text)


if __name__ == "__main__":
    main()
