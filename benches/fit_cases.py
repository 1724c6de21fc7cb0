"""Closed-loop records of random axes from a plant written here, independently of the
package (its own LuGre step, controllers and integrator, all cases side by side in
NumPy lanes), to check `lugre fit` against the truth:

    python benches/fit_cases.py OUT_DIR [--cases 30] [--seed 1] [--duration 20]
    python benches/fit_score.py OUT_DIR

Each case folder holds ``recording.csv`` (fitted), ``holdout.csv`` (another stretch of
the same axis under another trajectory of the same kind) and ``truth.json`` (the
model, CONTRACT form, with the recording's setup). Axes: 5-200 kg, friction levels,
Stribeck humps and presliding drawn per axis; PID position loops or PI speed loops at
2-10 kHz; sines, slow reversal-heavy sweeps or point-to-point moves; records at
250 Hz-10 kHz with current noise and encoder quantisation.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np

PLANT_HZ = 20_000.0


def draw_axis(rng: np.random.Generator) -> dict:
    mass = float(np.exp(rng.uniform(math.log(5), math.log(200))))
    kf = float(rng.uniform(5, 60))
    fc = mass * float(rng.uniform(0.3, 2.0))
    sets = {}
    for side in ("positive", "negative"):
        c = fc * float(rng.uniform(0.9, 1.1))
        sets[side] = {"fc": c, "fs": c * float(rng.uniform(1.2, 2.4)),
                      "sigma2": c / float(rng.uniform(0.03, 0.3)),
                      "vs": float(rng.uniform(0.003, 0.03))}
    fs = max(s["fs"] for s in sets.values())
    sigma0 = fs / float(np.exp(rng.uniform(math.log(2e-5), math.log(3e-4))))
    sigma1 = float(rng.uniform(0.05, 0.5)) * math.sqrt(sigma0 * mass)
    loop = "pid" if rng.uniform() < 0.6 else "pi_speed"
    wn = 2 * math.pi * float(rng.uniform(8, 30))
    rate = float(rng.choice([2000.0, 5000.0, 10000.0]))
    if loop == "pid":
        ctrl = {"type": "pid", "kp": mass * wn * wn, "ki": mass * wn ** 3 / 5,
                "kd": 1.4 * mass * wn, "rate_hz": rate}
    else:
        ctrl = {"type": "pi_speed", "kp": 2 * mass * wn, "ki": 2 * mass * wn * wn / 5,
                "rate_hz": rate}
    return {"axis": {"mass": mass, "force_constant": kf},
            "friction": {"model": "lugre", "sigma0": sigma0, "sigma1": sigma1, **sets},
            "effects": [], "controller": ctrl}


def trajectory(kind: str, t: np.ndarray, rng: np.random.Generator, vmax: float
               ) -> tuple[np.ndarray, np.ndarray]:
    """(x_ref, v_ref) of a kind, peak speed about ``vmax``."""
    ramp = np.clip(t / 0.5, 0, 1) ** 2 * (3 - 2 * np.clip(t / 0.5, 0, 1))
    if kind == "sine":
        f = rng.uniform(0.15, 0.8, 3)
        a = vmax / (2 * np.pi * f) * np.array([0.6, 0.3, 0.15])
        ph = rng.uniform(0, 2 * np.pi, 3)
        x = ramp * sum(ai * np.sin(2 * np.pi * fi * t + p) for ai, fi, p in zip(a, f, ph))
    elif kind == "sweep":  # slow, reversal-heavy: crosses the Stribeck range often
        f0 = rng.uniform(0.3, 1.0)
        vs = vmax * 0.25
        x = ramp * (vs / (2 * np.pi * f0) * np.sin(2 * np.pi * f0 * t)
                    + 4 * vs / (2 * np.pi * 0.07) * np.sin(2 * np.pi * 0.07 * t))
    else:  # point-to-point moves with dwells
        x = np.zeros_like(t)
        tk, pos = 0.3, 0.0
        while tk < t[-1]:
            dur = float(rng.uniform(0.4, 1.5))
            tgt = float(np.clip(pos + rng.uniform(-1, 1) * vmax * dur * 0.6, -0.3, 0.3))
            s = np.clip((t - tk) / dur, 0, 1)
            x = np.where(t >= tk, pos + (tgt - pos) * (s - np.sin(2 * np.pi * s) / (2 * np.pi)), x)
            pos, tk = tgt, tk + dur + float(rng.uniform(0.1, 0.6))
    v = np.gradient(x, t)
    return x, v


def simulate(axes: list[dict], refs: list[tuple[np.ndarray, np.ndarray]], n: int
             ) -> tuple[np.ndarray, np.ndarray]:
    """All axes side by side at PLANT_HZ: (x, commanded current), shape (n, lanes)."""
    L = len(axes)
    h = 1.0 / PLANT_HZ
    g = lambda key, side: np.array([a["friction"][side][key] for a in axes])
    P = {k: (g(k, "positive"), g(k, "negative")) for k in ("fc", "fs", "sigma2", "vs")}
    m = np.array([a["axis"]["mass"] for a in axes])
    kf = np.array([a["axis"]["force_constant"] for a in axes])
    s0 = np.array([a["friction"]["sigma0"] for a in axes])
    s1 = np.array([a["friction"]["sigma1"] for a in axes])
    c = [a["controller"] for a in axes]
    pid = np.array([ci["type"] == "pid" for ci in c])
    kp = np.array([ci["kp"] for ci in c])
    ki = np.array([ci["ki"] for ci in c])
    kd = np.array([ci.get("kd", 0.0) for ci in c])
    div = np.array([round(PLANT_HZ / ci["rate_hz"]) for ci in c])
    xr = np.stack([r[0] for r in refs], 1)
    vr = np.stack([r[1] for r in refs], 1)
    x = np.zeros(L); v = np.zeros(L); z = np.zeros(L); integ = np.zeros(L); cur = np.zeros(L)
    xs = np.empty((n, L)); cs = np.empty((n, L))
    for k in range(n):
        upd = (k % div) == 0
        e = np.where(pid, xr[k] - x, vr[k] - v)
        integ = np.where(upd, integ + e / (PLANT_HZ / div), integ)
        u = kp * e + ki * integ + np.where(pid, kd * (vr[k] - v), 0.0)
        cur = np.where(upd, u / kf, cur)
        xs[k], cs[k] = x, cur
        pos = v >= 0
        fc = np.where(pos, P["fc"][0], P["fc"][1]); fs = np.where(pos, P["fs"][0], P["fs"][1])
        s2 = np.where(pos, P["sigma2"][0], P["sigma2"][1]); vs = np.where(pos, P["vs"][0], P["vs"][1])
        gv = fc + (fs - fc) * np.exp(-(v / vs) ** 2)
        zdot = v - s0 * np.abs(v) * z / gv
        ff = s0 * z + s1 * zdot + s2 * v
        lam = s0 * np.abs(v) / gv
        zss = np.sign(v) * gv / s0
        z = np.where(lam > 0, zss + (z - zss) * np.exp(-lam * h), z)
        v = v + h * (kf * cur - ff) / m
        x = x + h * v
    return xs, cs


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--cases", type=int, default=30)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--duration", type=float, default=20.0)
    a = ap.parse_args()
    rng = np.random.default_rng(a.seed)
    n = int(a.duration * PLANT_HZ)
    tp = np.arange(n) / PLANT_HZ
    axes, setups, refs = [], [], []
    for j in range(a.cases):
        ax = draw_axis(rng)
        kind = ["sine", "sweep", "p2p"][j % 3]
        vmax = float(rng.uniform(0.03, 0.3))
        rate = float(rng.choice([250.0, 1000.0, 2000.0, 5000.0, 10000.0]))
        quantum = float(np.exp(rng.uniform(math.log(1e-7), math.log(5e-6))))
        noise = float(rng.uniform(0.002, 0.01)) * ax["friction"]["positive"]["fs"] / \
            ax["axis"]["force_constant"]
        for _ in range(2):
            refs.append(trajectory(kind, tp, rng, vmax))
            axes.append(ax)
        setups.append({"trajectory": kind, "vmax": vmax, "rate_hz": rate, "quantum": quantum,
                       "current_noise": noise, "seed": a.seed, "duration": a.duration})
    xs, cs = simulate(axes, refs, n)
    out = Path(a.out)
    for j, st in enumerate(setups):
        d = out / f"case{j:02d}"
        d.mkdir(parents=True, exist_ok=True)
        ax = axes[2 * j]
        step = round(PLANT_HZ / st["rate_hz"])
        nrng = np.random.default_rng([a.seed, j])
        for lane, fn in ((2 * j, "recording.csv"), (2 * j + 1, "holdout.csv")):
            t = tp[::step]
            x = np.round(xs[::step, lane] / st["quantum"]) * st["quantum"]
            i = cs[::step, lane] + st["current_noise"] * nrng.standard_normal(t.size)
            ref = refs[lane][0 if ax["controller"]["type"] == "pid" else 1][::step]
            name = "x_ref" if ax["controller"]["type"] == "pid" else "v_ref"
            np.savetxt(d / fn, np.column_stack([t, x, i, ref]), delimiter=",",
                       header=f"t,x,i,{name}", comments="", fmt="%.10g")
        (d / "truth.json").write_text(json.dumps({**ax, "setup": st}, indent=1))
        print(f"wrote {d.name}: {st['trajectory']}, {ax['axis']['mass']:.3g} kg, "
              f"{st['rate_hz']:.0f} Hz, {ax['controller']['type']}", flush=True)


if __name__ == "__main__":
    main()
