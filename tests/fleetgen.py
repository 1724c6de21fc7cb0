"""A generated fleet of axes recorded every night, for the fleet tests and bench.

``write_fleet(DIR)`` writes ``DIR/AXIS/model.json`` and one recording a night per axis:
20 axes (17 linear from :func:`lugre.diagnosis.synth.axis_model`, 3 rotary from
``rotary_model``) over 10 nights, each night's friction levels scattered by a few per
cent (temperature), and

- three axes wearing: their Coulomb and static levels rise 6 % a night from night 5;
- one axis gaining a cogging force from night 6 (a magnet, a screw nut going);
- one axis whose cogging, present from the start and not in its model, grows from
  night 5 (wear of a cogging source);
- one axis with a steady cogging its model does not hold (found every night, no change);
- a few corrupt files (a truncated CSV, garbage bytes in a ``.npz`` and a ``.parquet``,
  a column missing, a file without a time).

Recordings are short (3 s at 1 kHz) and in every format the fleet reads (CSV, MAT, NPZ,
Parquet, HDF5); their time is in the file name or, for some CSV axes, in a
``# time:`` line. ``python tests/fleetgen.py DIR`` writes one.
"""

from __future__ import annotations

import datetime as dt
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from lugre import Model, Recording, save_model, simulate, write_recording
from lugre.diagnosis.synth import axis_model, rotary_model, trajectory

AXES = 20
NIGHTS = 10
START = dt.datetime(2024, 3, 1, 2, 0, 0)
DURATION = 3.0
RATE_HZ = 1000.0
#: Night-to-night scatter of the friction levels (relative standard deviation).
SCATTER = 0.02

WEARING = ("axis-02", "axis-07", "axis-19")
GAINS_EFFECT = "axis-11"
GROWS = "axis-14"
STEADY_COGGING = "axis-05"
CHANGED = (*WEARING, GAINS_EFFECT, GROWS)
FORMATS = (".csv", ".npz", ".mat", ".parquet", ".h5")


@dataclass
class Fleet:
    """What was written: the folder, the axes, the recordings and the corrupt files."""

    root: Path
    axes: list[str] = field(default_factory=list)
    recordings: list[tuple[str, str]] = field(default_factory=list)
    corrupt: dict[tuple[str, str], str] = field(default_factory=dict)

    @property
    def unchanged(self) -> list[str]:
        return [a for a in self.axes if a not in CHANGED]


def _axis(j: int) -> Model:
    return rotary_model(400 + j) if j >= 17 else axis_model(300 + j)


def _believed(truth: Model, seed: int) -> Model:
    """The axis's model file: the truth without effects, base off by about 1 %."""
    rng = np.random.default_rng(seed)
    b = truth.to_dict()
    b["effects"] = []
    for side in ("positive", "negative"):
        f = b["friction"][side]
        for k in ("fc", "fs", "sigma2", "vs"):
            f[k] *= 1 + 0.01 * rng.standard_normal()
        f["fs"] = max(f["fs"], f["fc"])
    return Model(b)


def _cogging(truth: Model, stroke: float, share: float) -> dict[str, Any]:
    fc = 0.5 * (truth.positive["fc"] + truth.negative["fc"])
    return {"effect": "cogging", "amplitude": share * fc, "pitch": 0.15 * stroke,
            "phase": 0.7}


def _night(name: str, truth: Model, stroke: float, k: int, rng: np.random.Generator
           ) -> Model:
    """The axis on night ``k``: scattered levels, wear, effects."""
    d = truth.to_dict()
    wear = 0.06 * (k - 4) if name in WEARING and k >= 5 else 0.0
    s_level = 1 + SCATTER * float(np.clip(rng.standard_normal(), -2.5, 2.5)) + wear
    s_visc = 1 + SCATTER * float(np.clip(rng.standard_normal(), -2.5, 2.5))
    for side in ("positive", "negative"):
        f = d["friction"][side]
        f["fc"] *= s_level
        f["fs"] *= s_level
        f["sigma2"] *= s_visc
    effects = []
    if name == GAINS_EFFECT and k >= 6:
        effects.append(_cogging(truth, stroke, 0.12))
    if name == GROWS:
        effects.append(_cogging(truth, stroke, 0.08 * (1 + 0.35 * max(0, k - 4))))
    if name == STEADY_COGGING:
        effects.append(_cogging(truth, stroke, 0.08))
    d["effects"] = effects
    return Model(d)


def _record(model: Model, stroke: float, seed: int, rng: np.random.Generator) -> Recording:
    """The nightly test move (the same reference every night), logged at 1 kHz."""
    rate = float(model.controller["rate_hz"])
    over = max(1, round(rate / RATE_HZ))
    n = int(DURATION * RATE_HZ)
    tf = np.arange(n * over) / (RATE_HZ * over)
    sim = simulate(model, tf, x_ref=trajectory("sines", tf, seed, stroke), integrator="rk4")
    t = tf[::over]
    quantum = 1e-5 if model.kind == "rotary" else 1e-6
    x = np.round(sim.x[::over] / quantum) * quantum
    i = sim.i[::over] + 0.01 * rng.standard_normal(t.size)
    return Recording(t=t, x=x, i=i, x_ref=trajectory("sines", t, seed, stroke))


def _write(path: Path, rec: Recording, when: dt.datetime, in_name: bool) -> Path:
    if in_name:
        path = path.with_name(f"{when:%Y-%m-%dT%H%M}{path.suffix}")
    else:
        rec.meta["time"] = when.isoformat() + "Z"
    write_recording(rec, path)
    return path


def write_fleet(root: str | Path, nights: int = NIGHTS, axes: int = AXES,
                corrupt: bool = True) -> Fleet:
    """Write the fleet under ``root`` (created); returns what was written."""
    fleet = Fleet(Path(root))
    fleet.root.mkdir(parents=True, exist_ok=True)
    for j in range(axes):
        name = f"axis-{j:02d}"
        rng = np.random.default_rng(5000 + j)
        truth = _axis(j)
        stroke = float(rng.uniform(0.6, 1.2)) if truth.kind == "rotary" else float(
            rng.uniform(0.08, 0.2))
        folder = fleet.root / name
        folder.mkdir(exist_ok=True)
        save_model(_believed(truth, 6000 + j), folder / "model.json")
        suffix = FORMATS[j % len(FORMATS)]
        in_name = not (suffix == ".csv" and j % 2 == 1)
        for k in range(nights):
            when = START + dt.timedelta(days=k, minutes=7 * j)
            rec = _record(_night(name, truth, stroke, k, rng), stroke, 700 + j, rng)
            path = _write(folder / f"night-{k:02d}{suffix}", rec, when, in_name)
            fleet.recordings.append((name, path.name))
        fleet.axes.append(name)
    if corrupt:
        _corrupt(fleet)
    return fleet


def _corrupt(fleet: Fleet) -> None:
    """Unreadable recordings beside the good ones (times in their names)."""
    day = START + dt.timedelta(days=NIGHTS)
    stamp = f"{day:%Y-%m-%d}"
    bad = {
        ("axis-01", f"{stamp}T0300.csv"): b"# truncated in the copy\nt,x,i\n0.0,0.0,0.1\n0.001,",
        ("axis-03", f"{stamp}T0300.npz"): b"PK\x03\x04 this is not a zip archive",
        ("axis-08", f"{stamp}T0300.parquet"): b"PAR1 garbage bytes, not a parquet file",
        ("axis-12", f"{stamp}T0300.csv"): b"t,i\n0.0,0.1\n0.001,0.2\n0.002,0.1\n",
        ("axis-16", "spare-move.csv"): b"t,x,i\n0.0,0.0,0.1\n0.001,0.0,0.2\n",
    }
    for (axis, name), data in bad.items():
        (fleet.root / axis / name).write_bytes(data)
        fleet.corrupt[(axis, name)] = ""


if __name__ == "__main__":
    f = write_fleet(sys.argv[1])
    print(f"{len(f.recordings)} recordings of {len(f.axes)} axes, {len(f.corrupt)} corrupt, "
          f"in {f.root}")
