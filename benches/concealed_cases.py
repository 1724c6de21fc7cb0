"""Write concealed diagnosis cases in the layout of ../shared/datasets/mismatch (each a
folder with recording.csv, holdout.csv, model.json, truth.json), for
../shared/tools/score_diagnosis.py:

    python benches/concealed_cases.py OUT_DIR [--clean 50] [--quick]
    python ../shared/tools/score_diagnosis.py OUT_DIR - $(which lugre)

Clean records on random axes and trajectories (the false-finding rate), every effect of
the vocabulary at about half the sizes of the public cases on the paper axis and on
random axes, payloads, dead times and lags, and combinations.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np
from lugre import save_model
from lugre.diagnosis.synth import axis_model, case


def save_case(d: Path, rec, hold, believed, effects: list[dict], setup: dict,
              fmt: str = "%.9g") -> None:
    """One case folder in the layout of ../shared/datasets/mismatch."""
    d.mkdir(parents=True, exist_ok=True)
    for fn, r in (("recording.csv", rec), ("holdout.csv", hold)):
        cols = {"t": r.t, "x": r.x, "i": r.i, "x_ref": r.x_ref}
        np.savetxt(d / fn, np.column_stack(list(cols.values())), delimiter=",",
                   header=",".join(cols), comments="", fmt=fmt)
    save_model(believed, d / "model.json")
    (d / "truth.json").write_text(json.dumps({"effects": effects, "setup": {
        k: (v if not isinstance(v, float) or math.isfinite(v) else None)
        for k, v in setup.items()}}, indent=1))


def write(out: Path, name: str, effects: list[dict], **kw) -> None:
    rec, hold, believed, _truth = case(effects, **kw)
    save_case(out / name, rec, hold, believed, effects, kw)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--clean", type=int, default=50, help="clean records")
    ap.add_argument("--quick", action="store_true", help="10 s records")
    a = ap.parse_args()
    out = Path(a.out)
    dur = 10.0 if a.quick else 20.0
    kinds = ("sines", "p2p", "feeds")
    for k in range(a.clean):
        write(out, f"clean_{k:02d}", [], seed=100 + 7 * k, axis_seed=None if k % 5 == 0 else k,
              kind=kinds[k % 3], duration=dur)
    half = {
        "cogging": {"effect": "cogging", "amplitude": 1.5, "pitch": 0.02, "phase": 1.1},
        "offset": {"effect": "offset", "force": 1.5},
        "spring": {"effect": "spring", "stiffness": 20.0, "x0": 0.03},
        "drift": {"effect": "drift", "gain": 0.08, "time_constant": 6.0},
        "payload": {"effect": "mass", "delta": 1.5},
        "delay": {"effect": "delay", "seconds": 0.0006},
        "current_lag": {"effect": "current_lag", "bandwidth": 120.0},
        "deadband": {"effect": "deadband", "current": 0.075},
        "drag": {"effect": "drag", "coefficient": 60.0},
        "stribeck_shape": {"effect": "stribeck_shape", "exponent": 1.2},
        "resonance": {"effect": "resonance", "frequency": 30.0, "damping_ratio": 0.06,
                      "load_fraction": 0.6},
    }
    for j, (name, e) in enumerate(half.items()):
        write(out, f"half_{name}", [e], seed=500 + j, kind=kinds[j % 3], duration=dur)
    write(out, "combo_cogging_offset", [half["cogging"], half["offset"]], seed=600,
          kind="sines", duration=dur)
    # the same effects on random axes, sized against each axis' friction and mass
    for j, name in enumerate(half):
        ax = axis_model(40 + j)
        fc = ax.positive["fc"]
        e = {
            "cogging": {"effect": "cogging", "amplitude": 0.06 * fc, "pitch": 0.016,
                        "phase": 0.3},
            "offset": {"effect": "offset", "force": 0.06 * fc},
            "spring": {"effect": "spring", "stiffness": 0.4 * fc, "x0": 0.0},
            "drift": {"effect": "drift", "gain": 0.1, "time_constant": 5.0},
            "payload": {"effect": "mass", "delta": 0.06 * ax.mass},
            "delay": {"effect": "delay", "seconds": 0.0008},
            "current_lag": {"effect": "current_lag", "bandwidth": 90.0},
            "deadband": {"effect": "deadband", "current": 0.06 * fc / ax.force_constant},
            "drag": {"effect": "drag", "coefficient": 0.1 * fc / 0.1**2},  # 10 % fc at 0.1 m/s
            "stribeck_shape": {"effect": "stribeck_shape", "exponent": 1.1},
            "resonance": {"effect": "resonance", "frequency": 26.0, "damping_ratio": 0.05,
                          "load_fraction": 0.7},
        }[name]
        write(out, f"axis_{name}", [e], seed=700 + j, axis_seed=40 + j, kind=kinds[j % 3],
              duration=dur)
    write(out, "combo_deadband_drag", [half["deadband"], half["drag"]], seed=601,
          kind="p2p", duration=dur)


if __name__ == "__main__":
    main()
