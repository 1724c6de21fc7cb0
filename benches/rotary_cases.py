"""Write rotary-axis diagnosis cases (joints, rotary tables) in the layout of
../shared/datasets/mismatch, for ../shared/tools/score_diagnosis.py:

    python benches/rotary_cases.py OUT_DIR [--set public|concealed] [--seed S] [--clean N]
    python ../shared/tools/score_diagnosis.py OUT_DIR - $(which lugre)

Random rotary axes (:func:`lugre.diagnosis.synth.rotary_model`: inertia 0.005-2 kg m^2,
torque constant 0.2-5 N m/A, PID at 4-8 kHz), sines, point-to-point moves and feeds of
0.3-1.5 rad, 1 kHz, a 1e-5 rad encoder, current noise of 1 % of the static friction's
current. ``public``: the four
drive effects (gravity, load friction, force ripple, current limit) at full size, a
few seeds; ``concealed``: the same at half the size, on fresh axes and seeds drawn from
``--seed``, plus ``--clean`` clean records and a case outside the vocabulary (an
inertia that varies with the angle, as a joint's does with the arm behind it).

Sizes (public; concealed halves them): gravity 2 fc of torque, load friction 0.1,
force ripple 5 % at a pitch of 0.3 rad, a current limit clipping the top 6 % of the
current the axis asks for without it (concealed: the top 3 %; 0.5 % where the PID, which
has no anti-windup, would run away against it).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from lugre import Recording
from lugre.diagnosis.synth import case as synth_case
from lugre.diagnosis.synth import rotary_model

sys.path.insert(0, str(Path(__file__).resolve().parent))
from concealed_cases import save_case

KINDS = ("sines", "p2p", "feeds")
_REC = {"rotary": True, "quantum": 1e-5, "duration": 20.0}


def case(effects: list[dict], *, seed: int, axis_seed: int, kind: str, **kw):
    """:func:`lugre.diagnosis.synth.case` on the rotary axis ``axis_seed`` with current
    noise of 1 % of its static friction's current (a fixed 5 mA was up to twice the
    friction's current on a light joint with a large torque constant)."""
    ax = rotary_model(axis_seed)
    noise = 0.01 * max(ax.positive["fs"], ax.negative["fs"]) / ax.force_constant
    return synth_case(effects, seed=seed, axis_seed=axis_seed, kind=kind,
                      current_noise=noise, **kw)


def effect(name: str, seed: int, kind: str, scale: float) -> dict:
    """The effect ``name`` on the axis of ``seed`` at ``scale`` of the public size."""
    ax = rotary_model(seed)
    fc = ax.positive["fc"]
    if name == "gravity":
        return {"effect": "gravity", "torque": 2.0 * scale * fc, "phase": 0.6 - seed % 5}
    if name == "load_friction":
        return {"effect": "load_friction", "coefficient": 0.1 * scale}
    if name == "force_ripple":
        return {"effect": "force_ripple", "amplitude": 0.05 * scale, "pitch": 0.3,
                "phase": 0.9}
    if name == "current_limit":
        return _limit(seed, kind, scale)
    raise ValueError(name)


def _limit(seed: int, kind: str, scale: float) -> dict:
    """A current limit clipping the top ``6*scale`` % of the current the axis asks for
    without it, raised (to 99.5 %) when the PID, which has no anti-windup, runs away
    against it: a drive would not be run so."""
    rec, _, _, _ = case([], seed=seed, axis_seed=seed, kind=kind, **_REC)
    top = float(np.max(np.abs(rec.i)))
    for share in (6.0 * scale, 0.5):
        lim = {"effect": "current_limit",
               "current": float(np.percentile(np.abs(rec.i), 100.0 - share))}
        clipped, _, _, _ = case([lim], seed=seed, axis_seed=seed, kind=kind, **_REC)
        if float(np.max(np.abs(clipped.i))) < 3.0 * top:
            break
    return lim


def varying_inertia(out: Path, name: str, seed: int, kind: str) -> None:
    """Outside the vocabulary: an inertia ``J*(1 + 0.3*cos(x))``, written into the record
    as the current the extra inertia asks for (the motion as simulated)."""
    rec, hold, believed, truth = case([], seed=seed, axis_seed=seed, kind=kind, **_REC)

    def varied(r: Recording) -> Recording:
        v = np.gradient(r.x, r.t)
        a = np.gradient(v, r.t)
        extra = 0.3 * truth.mass * np.cos(r.x) * a / truth.force_constant
        return Recording(t=r.t, x=r.x, i=r.i + extra, x_ref=r.x_ref,
                         meta={"axis_kind": "rotary"})

    save_case(out / name, varied(rec), varied(hold), believed,
              [{"effect": "unmodelled", "kind": "varying_inertia", "size": 0.3}],
              {"seed": seed, "kind": kind})


def write(out: Path, name: str, effects: list[dict], seed: int, kind: str) -> None:
    rec, hold, believed, _ = case(effects, seed=seed, axis_seed=seed, kind=kind, **_REC)
    save_case(out / name, rec, hold, believed, effects, {"seed": seed, "kind": kind})


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--set", choices=("public", "concealed"), default="concealed")
    ap.add_argument("--seed", type=int, default=500, help="first seed (concealed)")
    ap.add_argument("--clean", type=int, default=50, help="clean records (concealed)")
    a = ap.parse_args()
    out = Path(a.out)
    names = ("gravity", "load_friction", "force_ripple", "current_limit")
    if a.set == "public":
        for j, name in enumerate(names):
            for k in range(2):
                s, kind = 10 + 7 * j + k, KINDS[(j + k) % 3]
                write(out, f"{name}_{k}", [effect(name, s, kind, 1.0)], s, kind)
        return
    for k in range(a.clean):
        s = a.seed + 3 * k
        write(out, f"clean_{k:02d}", [], s, KINDS[k % 3])
    for j, name in enumerate(names):
        for k in range(5):
            s, kind = a.seed + 1000 + 11 * j + k, KINDS[(j + k) % 3]
            write(out, f"half_{name}_{k}", [effect(name, s, kind, 0.5)], s, kind)
    for k in range(2):
        varying_inertia(out, f"outside_varying_inertia_{k}", a.seed + 2000 + k, KINDS[k])


if __name__ == "__main__":
    main()
