"""Write diagnosis cases from a plant written here independently of the crate (its own
LuGre step, PID and integrator), in the layout of ../shared/datasets/mismatch: physics
OUTSIDE the vocabulary, with truth ``{"effect": "unmodelled"}``, and this plant's own
versions of three effects the vocabulary has since taken in (``force_ripple``,
``load_friction``, ``saturation`` as ``current_limit``), with their truth:

    python benches/outside_cases.py OUT_DIR [--quick]
    python ../shared/tools/score_diagnosis.py OUT_DIR - $(which lugre)

The right answer on an unmodelled case is no vocabulary finding and the
"unexplained" flag, with where the rest lives; on the others, the effect named. A clean record from the same plant checks that the plant itself
does not read as a mismatch. Kinds:

- ``backlash``: a gap between motor and load (friction on the load, encoder on the
  motor); the motor crosses the gap at each reversal.
- ``force_ripple``: the force constant ripples with the magnet pitch, so a force
  periodic in position proportional to the current (not a cogging: it scales with the
  load).
- ``load_friction``: Coulomb friction growing with the transmitted force (a preloaded
  nut or a guide loaded by the drive force).
- ``viscous_warmup``: the viscous coefficient falls as the lubricant warms (the
  Coulomb level stays).
- ``saturation``: the drive limits its force; the logged current is the command.
- ``encoder``: a periodic error of the position reading (4 mm period), the motion itself
  unaffected: an apparent force growing with the square of the speed.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np

M, KF = 25.0, 25.0
#: The magnet pitch of the force ripple [m].
RIPPLE_PITCH = 0.032
SETS = {1: (28.7, 60.2, 332.5, 0.01), -1: (28.5, 60.1, 333.0, 0.01)}
S0, S1 = 1e5, 31.62
KP, KI, KD, RATE = 5e4, 5e5, 1500.0, 10000.0


def reference(kind: str, t: np.ndarray, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    u = np.clip(t / 1.0, 0.0, 1.0)
    ramp = u * u * u * (10.0 - 15.0 * u + 6.0 * u * u)
    if kind == "sines":
        f = np.array([0.21, 0.43, 0.71]) * (1 + 0.05 * rng.standard_normal(3))
        a = np.array([0.08, 0.04, 0.015])
        ph = rng.uniform(0, 2 * np.pi, 3)
        return ramp * sum(ai * np.sin(2 * np.pi * fi * t + p) for ai, fi, p in zip(a, f, ph))
    # trapezoidal point-to-point moves with dwells
    x = np.zeros_like(t)
    tk, pos = 0.5, 0.0
    while tk < t[-1]:
        tgt = float(rng.uniform(-0.12, 0.12))
        dur = float(rng.uniform(0.5, 1.6))
        s = np.clip((t - tk) / dur, 0, 1)
        x = np.where(t >= tk, pos + (tgt - pos) * (s - np.sin(2 * np.pi * s) / (2 * np.pi)), x)
        pos, tk = tgt, tk + dur + float(rng.uniform(0.2, 0.8))
    return x


def plant(kind: str, xr: np.ndarray, size: float) -> tuple[np.ndarray, np.ndarray]:
    """Closed loop at 10 kHz: returns motor position and logged current per step."""
    dt = 1.0 / RATE
    n = xr.size
    xs, cur = np.empty(n), np.empty(n)
    two = kind == "backlash"
    mm = 0.3 * M if two else M  # motor side
    ml = M - mm
    gap = size  # half gap [m]
    kc = ml * (2 * math.pi * 120.0) ** 2 if two else 0.0
    cc = 2 * 0.2 * math.sqrt(kc * ml) if two else 0.0
    x = v = xl = vl = z = integ = 0.0
    e_prev = 0.0
    for k in range(n):
        e = xr[k] - x
        integ += e * dt
        u = KP * e + KI * integ + KD * (e - e_prev) / dt if k else KP * e
        e_prev = e
        i_cmd = u / KF
        force = KF * i_cmd
        if kind == "force_ripple":
            force *= 1.0 + size * math.sin(2 * math.pi * x / RIPPLE_PITCH + 0.4)
        elif kind == "saturation":
            if abs(force) > size:
                integ -= e * dt  # anti-windup: the integrator holds while saturated
            force = max(-size, min(size, force))
        xs[k], cur[k] = x, i_cmd
        # friction on the body that carries it
        vf = vl if two else v
        fc, fs, s2, vs = SETS[1 if vf >= 0 else -1]
        if kind == "load_friction":
            fc, fs = fc + size * abs(force), fs + size * abs(force)
        if kind == "viscous_warmup":
            s2 *= 1.0 - size * (1.0 - math.exp(-k * dt / 6.0))
        g = fc + (fs - fc) * math.exp(-(vf / vs) ** 2)
        zss = g / S0 * (1.0 if vf > 0 else -1.0 if vf < 0 else 0.0)
        lam = S0 * abs(vf) / g
        z_new = zss + (z - zss) * math.exp(-lam * dt) if lam > 0 else z
        dz = (z_new - z) / dt
        ff = S0 * z_new + S1 * dz + s2 * vf
        z = z_new
        if two:
            d = x - xl
            dv = v - vl
            fcpl = 0.0
            if d > gap:
                fcpl = kc * (d - gap) + cc * dv
            elif d < -gap:
                fcpl = kc * (d + gap) + cc * dv
            v += dt * (force - fcpl - 0.02 * s2 * v) / mm
            vl += dt * (fcpl - ff) / ml
            x += dt * v
            xl += dt * vl
        else:
            v += dt * (force - ff) / M
            x += dt * v
    return xs, cur


def record(kind: str, size: float, seed: int, duration: float, traj: str):
    rng = np.random.default_rng(seed + 1000)
    tf = np.arange(int(duration * RATE)) / RATE
    xr = reference(traj, tf, seed)
    x, i = plant(kind, xr, size)
    if kind == "encoder":  # a periodic error of the scale: the motion is right, its reading not
        x = x + size * np.sin(2 * np.pi * x / 0.004 + 0.3)
    over = 10
    t = tf[::over]
    i = i[::over] + 0.01 * rng.standard_normal(t.size)
    x = np.round(x[::over] / 1e-6) * 1e-6
    return {"t": t, "x": x, "i": i, "x_ref": xr[::over]}


def believed(seed: int) -> dict:
    """The model handed to the diagnosis: the plant's base, each parameter off by ~1 %."""
    rng = np.random.default_rng(seed + 2000)
    sets = {}
    for sgn, side in ((1, "positive"), (-1, "negative")):
        fc, fs, s2, vs = (p * (1 + 0.01 * rng.standard_normal()) for p in SETS[sgn])
        sets[side] = {"fc": fc, "fs": max(fs, fc), "sigma2": s2, "vs": vs}
    return {"axis": {"mass": M * (1 + 0.01 * rng.standard_normal()), "force_constant": KF},
            "friction": {"model": "lugre", "sigma0": S0, "sigma1": S1, **sets},
            "effects": [],
            "controller": {"type": "pid", "kp": KP, "ki": KI, "kd": KD, "rate_hz": RATE}}


def write(out: Path, name: str, kind: str, size: float, seed: int, duration: float,
          traj: str) -> None:
    d = out / name
    d.mkdir(parents=True, exist_ok=True)
    for fn, s in (("recording.csv", seed), ("holdout.csv", seed + 1)):
        r = record(kind, size, s, duration, traj)
        np.savetxt(d / fn, np.column_stack(list(r.values())), delimiter=",",
                   header=",".join(r), comments="", fmt="%.9g")
    (d / "model.json").write_text(json.dumps(believed(seed), indent=1))
    effects = [] if kind == "clean" else [truth_of(kind, size)]
    (d / "truth.json").write_text(json.dumps({"effects": effects, "setup": {
        "trajectory": traj, "duration": duration, "seed": seed}}, indent=1))


def truth_of(kind: str, size: float) -> dict:
    """The truth of a case: the vocabulary's effect for the kinds it now holds (this
    plant's own versions of them, an independent check), else ``unmodelled``."""
    if kind == "force_ripple":
        return {"effect": "force_ripple", "amplitude": size, "pitch": RIPPLE_PITCH,
                "phase": 0.4}
    if kind == "load_friction":
        return {"effect": "load_friction", "coefficient": size}
    if kind == "saturation":
        return {"effect": "current_limit", "current": size / KF}
    return {"effect": "unmodelled", "kind": kind, "size": size}


#: name, kind, size, trajectory of each case written by :func:`main`
CASES = [("clean_sines", "clean", 0.0, "sines"), ("clean_p2p", "clean", 0.0, "p2p"),
         ("backlash", "backlash", 20e-6, "sines"),
         ("backlash_p2p", "backlash", 20e-6, "p2p"),
         ("force_ripple", "force_ripple", 0.04, "sines"),
         ("load_friction", "load_friction", 0.05, "sines"),
         ("load_friction_p2p", "load_friction", 0.05, "p2p"),
         ("viscous_warmup", "viscous_warmup", 0.3, "sines"),
         ("saturation_p2p", "saturation", 90.0, "p2p"),
         ("encoder", "encoder", 2e-6, "sines")]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--quick", action="store_true", help="10 s records")
    a = ap.parse_args()
    out = Path(a.out)
    dur = 10.0 if a.quick else 20.0
    for j, (name, kind, size, traj) in enumerate(CASES):
        write(out, name, kind, size, 900 + 10 * j, dur, traj)
        print(f"wrote {name}", flush=True)


if __name__ == "__main__":
    main()
