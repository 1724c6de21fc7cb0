"""Write diagnosis cases under conditions the other sets do not vary, in the layout of
../shared/datasets/mismatch, for ../shared/tools/score_diagnosis.py:

    python benches/stress_cases.py OUT_DIR [--seed 0] [--clean 20] [--single 22]
        [--pairs 8] [--triples 4]
    python ../shared/tools/score_diagnosis.py OUT_DIR - $(which lugre)

Every case draws its own conditions: the axis (the paper axis or a random 6-90 kg one),
the trajectory (sines, point-to-point, constant-speed feeds), the record's length
(6-30 s), its sample rate (1, 2 or 5 kHz), the current noise (3-40 mA), the encoder
(0.1-5 um) and how far the believed base is off (0.5-2 %). Effects are sized against
each axis (its friction, mass and force constant) at 0.6-1.2 times the half sizes of
`concealed_cases.py`, alone, in pairs and in threes. Seeds start where the other sets'
end, so nothing here was seen while the method was written.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import numpy as np
from concealed_cases import save_case  # benches/ is the script's folder
from lugre import Model
from lugre.diagnosis.synth import axis_model, case, trajectory

EFFECTS = ("cogging", "offset", "spring", "drift", "mass", "delay", "current_lag",
           "deadband", "drag", "stribeck_shape", "resonance", "position_friction")
#: Effects that cannot be told apart from each other by name in one record (the scorer
#: counts delay and current_lag as one family); one of a kind per combination.
EXCLUSIVE = ({"delay", "current_lag"}, {"offset", "spring"})


def sized(name: str, ax: Model, rng: np.random.Generator, stroke: float,
          xrange: tuple[float, float] | None = None) -> dict[str, Any]:
    """One effect, sized against the axis at 0.6-1.2 times the half sizes; ``xrange``
    the positions the case's trajectory covers (a friction bump is placed inside)."""
    k = float(rng.uniform(0.6, 1.2))
    fc = 0.5 * (ax.positive["fc"] + ax.negative["fc"])
    kf = float(ax.force_constant)
    if name == "cogging":
        return {"effect": "cogging", "amplitude": 0.06 * fc * k,
                "pitch": float(rng.choice([0.005, 0.01, 0.016, 0.025, 0.04])) * stroke / 0.15,
                "phase": float(rng.uniform(-np.pi, np.pi))}
    if name == "offset":
        return {"effect": "offset", "force": float(rng.choice([-1, 1])) * 0.06 * fc * k}
    if name == "spring":
        return {"effect": "spring", "stiffness": 0.06 * fc * k / (0.4 * stroke),
                "x0": float(rng.uniform(-0.3, 0.3)) * stroke}
    if name == "drift":
        return {"effect": "drift", "gain": 0.1 * k, "time_constant": float(rng.uniform(3, 6))}
    if name == "mass":
        return {"effect": "mass", "delta": 0.06 * ax.mass * k}
    if name == "delay":
        return {"effect": "delay", "seconds": float(rng.uniform(0.4e-3, 1.5e-3))}
    if name == "current_lag":
        return {"effect": "current_lag", "bandwidth": float(rng.uniform(50.0, 120.0))}
    if name == "deadband":
        return {"effect": "deadband", "current": 0.06 * fc / kf * k}
    if name == "drag":
        vmax = 0.1 * stroke / 0.15
        return {"effect": "drag", "coefficient": 0.1 * fc * k / vmax**2}
    if name == "stribeck_shape":
        return {"effect": "stribeck_shape", "exponent": float(rng.choice([0.9, 1.2, 3.2]))}
    if name == "resonance":
        return {"effect": "resonance", "frequency": float(rng.uniform(18.0, 32.0)),
                "damping_ratio": float(rng.uniform(0.03, 0.08)),
                "load_fraction": float(rng.uniform(0.5, 0.8))}
    if name == "position_friction":
        u = float(rng.uniform(-0.5, 0.5))
        c = u * stroke
        w = 0.15 * stroke
        if xrange is not None:
            # inside the inner 80 % of what the trajectory covers (constant-speed feeds
            # run from 0 forward only: a bump drawn about 0 could lie off the record)
            lo, hi = xrange
            span = hi - lo
            if not lo + 0.1 * span <= c <= hi - 0.1 * span:
                c = 0.5 * (lo + hi) + 0.8 * u * span
                w = 0.15 * min(stroke, span)
        gain = 0.25 * k
        xs = np.linspace(c - 3 * w, c + 3 * w, 25)
        sc = 1.0 + gain * np.exp(-0.5 * ((xs - c) / w) ** 2)
        return {"effect": "position_friction", "positions": [float(v) for v in xs],
                "scale": [float(v) for v in sc],
                "generated_as": {"gain": gain, "center": c, "width": w}}
    raise ValueError(name)


def conditions(rng: np.random.Generator) -> dict[str, Any]:
    return {
        "axis_seed": None if rng.random() < 0.3 else int(rng.integers(200, 10_000)),
        "kind": str(rng.choice(["sines", "p2p", "feeds"])),
        "duration": float(rng.choice([6.0, 10.0, 20.0, 30.0])),
        "rate_hz": float(rng.choice([1000.0, 2000.0, 5000.0])),
        "current_noise": float(np.exp(rng.uniform(np.log(0.003), np.log(0.04)))),
        "quantum": float(rng.choice([1e-7, 1e-6, 5e-6])),
        "base_error": float(rng.uniform(0.005, 0.02)),
    }


def write(out: Path, name: str, effects: list[str], seed: int,
          rng: np.random.Generator) -> None:
    cond = conditions(rng)
    ax = (Model.paper() if cond["axis_seed"] is None else axis_model(cond["axis_seed"]))
    # the stroke synth.case draws for the recording on a random axis (the paper axis: 0.15 m)
    stroke = (0.15 if cond["axis_seed"] is None
              else float(np.random.default_rng(seed + 1000).uniform(0.05, 0.3)))
    n = int(cond["duration"] * cond["rate_hz"])
    xr = trajectory(cond["kind"], np.arange(n) / cond["rate_hz"], seed, stroke)
    truth = [sized(e, ax, rng, stroke, (float(xr.min()), float(xr.max()))) for e in effects]
    sim = [{k: v for k, v in e.items() if k != "generated_as"} for e in truth]
    rec, hold, believed, _ = case(sim, seed=seed, **cond)
    save_case(out / name, rec, hold, believed, truth, {**cond, "seed": seed}, fmt="%.10g")


def combination(rng: np.random.Generator, size: int) -> list[str]:
    while True:
        pick = [str(e) for e in rng.choice(EFFECTS, size, replace=False)]
        if all(len(ex & set(pick)) <= 1 for ex in EXCLUSIVE):
            return pick


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--clean", type=int, default=20)
    ap.add_argument("--single", type=int, default=24)
    ap.add_argument("--pairs", type=int, default=8)
    ap.add_argument("--triples", type=int, default=4)
    a = ap.parse_args()
    out = Path(a.out)
    rng = np.random.default_rng(90_000 + a.seed)
    seed = 20_000 + 1000 * a.seed
    plan = [[] for _ in range(a.clean)]
    plan += [[EFFECTS[j % len(EFFECTS)]] for j in range(a.single)]
    plan += [combination(rng, 2) for _ in range(a.pairs)]
    plan += [combination(rng, 3) for _ in range(a.triples)]
    for j, effects in enumerate(plan):
        name = f"{j:03d}_" + ("clean" if not effects else "+".join(effects))
        write(out, name, effects, seed + 2 * j, rng)
        print("wrote", name, flush=True)


if __name__ == "__main__":
    main()
