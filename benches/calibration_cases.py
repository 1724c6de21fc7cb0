"""Closed-loop records for the calibration bench (issue 27), from a plant written here,
independently of the diagnosis code (nothing of ``lugre.diagnosis`` is imported): its
own LuGre step, PID position or PI speed loop, current path and integrator, many cases
side by side in NumPy lanes (the approach of ``fit_cases.py``'s ``simulate``):

    python benches/calibration_cases.py OUT_DIR [--cases 10] [--seed 2700]
        [--effect NAME --size X]

A case is drawn from its seed alone (:func:`draw_case`):

- the axis: linear (5-200 kg, force constant 5-60 N/A, positions in m) or rotary
  (inertia 0.005-2 kg m^2, torque constant 0.2-5 N m/A, positions in rad); Coulomb,
  static, viscous and Stribeck levels per direction, presliding stiffness and damping;
- the loop: a PID position loop or a PI speed loop at 2, 5 or 10 kHz, tuned to the mass;
- the record: 250 Hz-10 kHz, 3-60 s (mostly 3-20 s), a trajectory of sines,
  point-to-point moves with dwells, or constant-speed passes at several speeds; white or
  coloured (first-order low-passed) current noise of 0.2-2 % of the static level; an
  encoder quantisation (0.1-5 um, or 2^14-2^22 counts a turn);
- the hold-out: another stretch of the same axis under another trajectory of the same
  kind (its own seed), and the same effects;
- the believed model (``model.json``): the truth's base with a drawn error of 0.5-2 %
  (one relative standard deviation drawn per case) on the Coulomb, static and viscous
  levels of both directions and on the mass; no effects. The diagnosis refits the base,
  so this error is what a user's model brings, not a mismatch to find.

The plant (:func:`simulate`) holds every effect of the CONTRACT's vocabulary with the
CONTRACT's definitions, applied where the CONTRACT says: offset, spring, mass, cogging,
position_friction, drift, delay, current_lag, drag, deadband, stribeck_shape, resonance
(two masses: the motor, measured, and the load, carrying friction and the other
forces), gravity (rotary), load_friction, force_ripple and current_limit. A
``position_friction`` is drawn as one trapezoidal bump (four knots). A case with no
effect is a "clean" record; :func:`records` regenerates the same case (same seed,
trajectory, noise) with any effects added.

The plant runs at 10 kHz (the controller at 2, 5 or 10 kHz updates every 5, 2 or 1
steps and holds its command between); the friction's internal state follows the exact
solution of its ODE over a step at the step's speed, the rest is semi-implicit Euler.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

PLANT_HZ = 10_000.0
RECORD_RATES = (250.0, 500.0, 1000.0, 2000.0, 5000.0, 10000.0)
CONTROL_RATES = (2000.0, 5000.0, 10000.0)
TRAJECTORIES = ("sines", "p2p", "feeds")
#: Effects the plant holds (the CONTRACT's vocabulary; gravity on rotary axes only).
EFFECTS = ("offset", "spring", "mass", "cogging", "position_friction", "drift", "delay",
           "current_lag", "drag", "deadband", "stribeck_shape", "resonance", "gravity",
           "load_friction", "force_ripple", "current_limit")


# ---------------------------------------------------------------------------- drawing

def _logu(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(np.exp(rng.uniform(math.log(lo), math.log(hi))))


def draw_case(seed: int, *, max_duration: float = 60.0, family: str | None = None,
              min_duration: float = 3.0) -> dict[str, Any]:
    """A case from its seed: ``{"seed", "family", "truth" (model, no effects),
    "believed", "setup"}``. ``family`` ``"linear"``/``"rotary"`` forces the axis kind;
    the drawn duration is clipped to ``[min_duration, max_duration]`` (nothing else of
    the draw changes)."""
    rng = np.random.default_rng([27, seed])
    rotary = (rng.uniform() < 0.4) if family is None else family == "rotary"
    if rotary:
        m = _logu(rng, 0.005, 2.0)
        kf = _logu(rng, 0.2, 5.0)
        fc = m * _logu(rng, 0.5, 4.0)
        vs_rng = (0.01, 0.1)
        axis = {"kind": "rotary", "inertia": m, "torque_constant": kf}
        stroke = rng.uniform(0.3, 3.0)
        vmax = rng.uniform(0.3, 3.0)
        quantum = 2 * math.pi / 2 ** int(rng.integers(14, 23))
    else:
        m = _logu(rng, 5.0, 200.0)
        kf = rng.uniform(5.0, 60.0)
        fc = m * _logu(rng, 0.3, 2.0)
        vs_rng = (0.003, 0.03)
        axis = {"mass": m, "force_constant": kf}
        stroke = rng.uniform(0.05, 0.3)
        vmax = rng.uniform(0.03, 0.3)
        quantum = _logu(rng, 1e-7, 5e-6)
    sets = {}
    for side in ("positive", "negative"):
        c = fc * float(rng.uniform(0.9, 1.1))
        sets[side] = {"fc": c, "fs": c * float(rng.uniform(1.2, 2.4)),
                      "sigma2": c / (vmax * float(rng.uniform(1.0, 10.0))),
                      "vs": _logu(rng, *vs_rng)}
    fs = max(s["fs"] for s in sets.values())
    # presliding: the static level reached over 20-300 um (linear) or 0.2-3 mrad (rotary)
    x_pre = _logu(rng, 2e-4, 3e-3) if rotary else _logu(rng, 2e-5, 3e-4)
    sigma0 = fs / x_pre
    # damped presliding, but within the passivity bound 4*sigma2*fc/(fs - fc) of both sets
    bound = min(4 * s["sigma2"] * s["fc"] / (s["fs"] - s["fc"]) for s in sets.values())
    sigma1 = min(float(rng.uniform(0.05, 0.5)) * math.sqrt(sigma0 * m), 0.8 * bound)
    loop = "pid" if rng.uniform() < 0.6 else "pi_speed"
    wn = 2 * math.pi * float(rng.uniform(8, 30))
    rate = float(rng.choice(CONTROL_RATES))
    if loop == "pid":
        ctrl = {"type": "pid", "kp": m * wn * wn, "ki": m * wn ** 3 / 5,
                "kd": 1.4 * m * wn, "rate_hz": rate}
    else:
        ctrl = {"type": "pi_speed", "kp": 2 * m * wn, "ki": 2 * m * wn * wn / 5,
                "rate_hz": rate}
    truth = {"axis": axis, "friction": {"model": "lugre", "sigma0": sigma0,
                                        "sigma1": sigma1, **sets},
             "effects": [], "controller": ctrl}
    duration = (_logu(rng, 3.0, 20.0) if rng.uniform() < 0.8 else _logu(rng, 20.0, 60.0))
    duration = float(min(max(duration, min_duration), max_duration))
    rec_rate = float(rng.choice(RECORD_RATES, p=[0.12, 0.14, 0.3, 0.2, 0.14, 0.1]))
    kind = str(rng.choice(TRAJECTORIES))
    noise_kind = "white" if rng.uniform() < 0.5 else "coloured"
    setup = {
        "trajectory": kind, "stroke": float(stroke), "vmax": float(vmax),
        "duration": duration, "rate_hz": rec_rate, "quantum": float(quantum),
        "noise": noise_kind,
        "current_noise": float(rng.uniform(0.002, 0.02)) * fs / kf,  # rms [A]
        "noise_cutoff_hz": float(rng.uniform(0.02, 0.2)) * rec_rate,
        "base_error": float(rng.uniform(0.005, 0.02)),
        "trajectory_seeds": [int(rng.integers(2**31)), int(rng.integers(2**31))],
        "noise_seeds": [int(rng.integers(2**31)), int(rng.integers(2**31))],
    }
    believed = json.loads(json.dumps(truth))
    e = setup["base_error"]
    for side in ("positive", "negative"):
        s = believed["friction"][side]
        for k in ("fc", "fs", "sigma2"):
            s[k] *= 1 + e * rng.standard_normal()
        s["fs"] = max(s["fs"], s["fc"])
    key = "inertia" if rotary else "mass"
    believed["axis"][key] *= 1 + e * rng.standard_normal()
    family_name = (f"{'rotary' if rotary else 'linear'}/{loop}/{kind}/{noise_kind}/"
                   f"{rec_rate:g}Hz/{duration:.0f}s")
    return {"seed": int(seed), "family": family_name, "truth": truth, "believed": believed,
            "setup": setup}


# ----------------------------------------------------------------------- trajectories

def _quintic(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    u = np.clip(u, 0.0, 1.0)
    return u ** 3 * (10 - 15 * u + 6 * u * u), 30 * u * u * (1 - u) ** 2


_U = np.linspace(0.0, 1.0, 4001)


def _feed_shape(ramp: float) -> tuple[np.ndarray, np.ndarray]:
    """A normalised constant-speed pass (position 0 to 1 over u in 0..1) whose speed
    rises and falls smoothly over a fraction ``ramp`` of it at each end."""
    w = np.minimum(_quintic(_U / ramp)[0], _quintic((1 - _U) / ramp)[0])
    p = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(_U))])
    return p / p[-1], w / p[-1]


class Reference:
    """A position reference and its derivative, evaluated at any times."""

    def __init__(self, kind: str, seed: int, stroke: float, vmax: float, duration: float):
        rng = np.random.default_rng(seed)
        self.kind = kind
        if kind == "sines":
            f1 = _logu(rng, max(2.0 / duration, 0.1), 1.0)
            self.f = f1 * np.array([1.0, 1.7, 2.9]) * rng.uniform(0.9, 1.1, 3)
            w = np.array([0.6, 0.25, 0.15])
            self.a = w * min(stroke, vmax / (2 * np.pi * float(np.sum(w * self.f))))
            self.ph = rng.uniform(0, 2 * np.pi, 3)
            return
        segs = []  # (start, duration, from, to, shape)
        tk, pos = 0.3, 0.0
        speeds = np.array([0.05, 0.15, 0.4, 1.0]) * vmax
        j = 0
        while tk < duration:
            if kind == "p2p":
                # every move crosses to the other side: reversals in short records too
                side = -math.copysign(1.0, pos) if pos else float(rng.choice([-1.0, 1.0]))
                tgt = side * float(rng.uniform(0.2, 1.0)) * stroke
                dur = max(float(rng.uniform(0.3, 1.5)), 1.875 * abs(tgt - pos) / vmax)
                segs.append((tk, dur, pos, tgt, "p2p"))
                tk += dur + float(rng.uniform(0.1, 0.8))
            else:
                sp = float(speeds[rng.integers(speeds.size)])
                length = min(2 * stroke, sp * float(rng.uniform(0.5, 1.0))
                             * min(4.0, duration / 4))
                sgn = 1.0 if j % 2 == 0 else -1.0
                if abs(pos + sgn * length) > stroke:
                    sgn = -sgn
                tgt = pos + sgn * length
                ramp = min(0.25, 0.15 * sp / max(length, 1e-12) + 0.02)
                dur = length / sp / (1 - ramp)
                segs.append((tk, dur, pos, tgt, ramp))
                tk += dur + float(rng.uniform(0.1, 0.3))
                j += 1
            pos = tgt
        self.segs = segs
        self.t0 = np.array([s[0] for s in segs] + [np.inf])
        self.shapes = {s[4]: _feed_shape(s[4]) for s in segs if s[4] != "p2p"}

    def __call__(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        t = np.asarray(t, float)
        if self.kind == "sines":
            r, dr = _quintic(t / 1.0)
            s = sum(a * np.sin(2 * np.pi * f * t + p) for a, f, p in zip(self.a, self.f, self.ph))
            ds = sum(a * 2 * np.pi * f * np.cos(2 * np.pi * f * t + p)
                     for a, f, p in zip(self.a, self.f, self.ph))
            return r * s, dr * s + r * ds
        x = np.zeros_like(t)
        v = np.zeros_like(t)
        idx = np.searchsorted(self.t0, t, side="right") - 1
        for j in np.unique(idx):
            if j < 0:
                continue
            t0, dur, p0, p1, shape = self.segs[j]
            sel = idx == j
            u = np.clip((t[sel] - t0) / dur, 0.0, 1.0)
            if shape == "p2p":
                p, dp = _quintic(u)
            else:
                P, W = self.shapes[shape]
                p, dp = np.interp(u, _U, P), np.interp(u, _U, W)
            x[sel] = p0 + (p1 - p0) * p
            v[sel] = (p1 - p0) / dur * dp * ((u > 0) & (u < 1))
        return x, v


# ----------------------------------------------------------------------------- plant

_OFF: dict[str, float] = {
    "offset": 0.0, "spring_k": 0.0, "spring_x0": 0.0, "delta": 0.0,
    "cog_a": 0.0, "cog_p": 1.0, "cog_ph": 0.0,
    "pf_c": 0.0, "pf_in": 0.0, "pf_out": 1.0, "pf_s": 0.0,
    "drift_g": 0.0, "drift_tau": 1.0, "delay": 0.0, "lag_bw": math.inf,
    "drag": 0.0, "deadband": 0.0, "exponent": 2.0,
    "res_f": 10.0, "res_z": 0.05, "res_r": 0.0, "grav_t": 0.0, "grav_ph": 0.0,
    "load_c": 0.0, "rip_a": 0.0, "rip_p": 1.0, "rip_ph": 0.0, "imax": math.inf,
}


def effect_params(effects: list[dict[str, Any]]) -> dict[str, float]:
    """The plant's parameters of a list of CONTRACT effect objects (one of each kind;
    ``position_friction`` as a trapezoid: four knots, scale ``[1, s, s, 1]``)."""
    p = dict(_OFF)
    for e in effects:
        n = e["effect"]
        if n == "offset":
            p["offset"] = e["force"]
        elif n == "spring":
            p["spring_k"], p["spring_x0"] = e["stiffness"], e["x0"]
        elif n in ("mass", "inertia"):
            p["delta"] = e["delta"]
        elif n == "cogging":
            p["cog_a"], p["cog_p"], p["cog_ph"] = e["amplitude"], e["pitch"], e["phase"]
        elif n == "position_friction":
            x, s = e["positions"], e["scale"]
            if len(x) != 4 or s[0] != 1.0 or s[3] != 1.0 or s[1] != s[2]:
                raise ValueError("the plant holds a trapezoidal position_friction only")
            p["pf_c"] = 0.5 * (x[1] + x[2])
            p["pf_in"], p["pf_out"] = 0.5 * (x[2] - x[1]), 0.5 * (x[3] - x[0])
            p["pf_s"] = s[1] - 1.0
        elif n == "drift":
            p["drift_g"], p["drift_tau"] = e["gain"], e["time_constant"]
        elif n == "delay":
            p["delay"] = e["seconds"]
        elif n == "current_lag":
            p["lag_bw"] = e["bandwidth"]
        elif n == "drag":
            p["drag"] = e["coefficient"]
        elif n == "deadband":
            p["deadband"] = e["current"]
        elif n == "stribeck_shape":
            p["exponent"] = e["exponent"]
        elif n == "resonance":
            p["res_f"], p["res_z"], p["res_r"] = (e["frequency"], e["damping_ratio"],
                                                  e["load_fraction"])
        elif n == "gravity":
            p["grav_t"], p["grav_ph"] = e["torque"], e["phase"]
        elif n == "load_friction":
            p["load_c"] = e["coefficient"]
        elif n == "force_ripple":
            p["rip_a"], p["rip_p"], p["rip_ph"] = e["amplitude"], e["pitch"], e["phase"]
        elif n == "current_limit":
            p["imax"] = e["current"]
        else:
            raise ValueError(f"the plant does not hold {n!r}")
    return p


def simulate(models: list[dict[str, Any]], refs: list[Reference], durations: list[float],
             steps: list[int], chunk: int = 20_000) -> list[tuple[np.ndarray, np.ndarray]]:
    """All lanes side by side at PLANT_HZ: for each lane, its (x, commanded current)
    sampled every ``steps[j]`` plant steps over ``durations[j]`` seconds."""
    L = len(models)
    h = 1.0 / PLANT_HZ
    col = lambda f: np.array([f(a) for a in models], float)
    fr = lambda k, side: col(lambda a: a["friction"][side][k])
    FC = (fr("fc", "positive"), fr("fc", "negative"))
    FS = (fr("fs", "positive"), fr("fs", "negative"))
    S2 = (fr("sigma2", "positive"), fr("sigma2", "negative"))
    VS = (fr("vs", "positive"), fr("vs", "negative"))
    m0 = col(lambda a: a["axis"].get("mass", a["axis"].get("inertia")))
    kf = col(lambda a: a["axis"].get("force_constant", a["axis"].get("torque_constant")))
    s0 = col(lambda a: a["friction"]["sigma0"])
    s1 = col(lambda a: a["friction"]["sigma1"])
    pid = np.array([a["controller"]["type"] == "pid" for a in models])
    kp = col(lambda a: a["controller"]["kp"])
    ki = col(lambda a: a["controller"].get("ki", 0.0))
    kd = col(lambda a: a["controller"].get("kd", 0.0))
    div = np.array([round(PLANT_HZ / a["controller"]["rate_hz"]) for a in models])
    E = [effect_params(a["effects"]) for a in models]
    P = {k: np.array([e[k] for e in E], float) for k in _OFF}
    M = m0 + P["delta"]
    r = P["res_r"]
    two = r > 0
    rr = np.where(two, r, 0.5)
    mm, ml = (1 - rr) * M, rr * M
    kc = ml * (2 * np.pi * P["res_f"]) ** 2
    cc = 2 * P["res_z"] * np.sqrt(kc * ml)
    alpha = np.where(np.isfinite(P["lag_bw"]), 1 - np.exp(-2 * np.pi * np.where(
        np.isfinite(P["lag_bw"]), P["lag_bw"], 1.0) * h), 1.0)
    dsteps = P["delay"] * PLANT_HZ
    d0 = np.floor(dsteps).astype(int)
    dfr = dsteps - d0
    H = int(max(d0.max() + 2, 2))
    hist = np.zeros((H, L))
    lanes = np.arange(L)
    pf_w = np.maximum(P["pf_out"] - P["pf_in"], 1e-12)
    x = np.zeros(L); v = np.zeros(L); xl = np.zeros(L); vl = np.zeros(L)
    z = np.zeros(L); integ = np.zeros(L); cur = np.zeros(L); il = np.zeros(L)
    n_all = math.ceil(max(durations) * PLANT_HZ)
    outs: list[list[tuple[np.ndarray, np.ndarray]]] = [[] for _ in range(L)]
    for c0 in range(0, n_all, chunk):
        c1 = min(c0 + chunk, n_all)
        tc = np.arange(c0, c1) / PLANT_HZ
        rx = np.empty((c1 - c0, L)); rv = np.empty((c1 - c0, L))
        for j, ref in enumerate(refs):
            rx[:, j], rv[:, j] = ref(tc)
        xs = np.empty((c1 - c0, L)); cs = np.empty((c1 - c0, L))
        for q in range(c1 - c0):
            k = c0 + q
            upd = (k % div) == 0
            e = np.where(pid, rx[q] - x, rv[q] - v)
            integ = np.where(upd, integ + e * (div * h), integ)
            u = kp * e + ki * integ + np.where(pid, kd * (rv[q] - v), 0.0)
            cur = np.where(upd, u / kf, cur)
            xs[q], cs[q] = x, cur
            hist[k % H] = cur
            # the current that acts: delayed, lagged, dead-banded, clipped
            i_d = ((1 - dfr) * hist[(k - d0) % H, lanes]
                   + dfr * hist[(k - d0 - 1) % H, lanes])
            il = il + alpha * (i_d - il)
            ia = np.sign(il) * np.maximum(np.abs(il) - P["deadband"], 0.0)
            ia = np.clip(ia, -P["imax"], P["imax"])
            fm = kf * ia * (1 + P["rip_a"] * np.sin(2 * np.pi * x / P["rip_p"] + P["rip_ph"]))
            # friction on the load
            pos = vl >= 0
            lvl = (1 + P["pf_s"] * np.clip((P["pf_out"] - np.abs(xl - P["pf_c"])) / pf_w,
                                           0.0, 1.0))
            lvl = lvl * (1 - P["drift_g"] * (1 - np.exp(-(k * h) / P["drift_tau"])))
            extra = P["load_c"] * np.abs(kf * cur)
            fc = np.where(pos, FC[0], FC[1]) * lvl + extra
            fs = np.where(pos, FS[0], FS[1]) * lvl + extra
            s2 = np.where(pos, S2[0], S2[1])
            vs = np.where(pos, VS[0], VS[1])
            gv = fc + (fs - fc) * np.exp(-np.abs(vl / vs) ** P["exponent"])
            zdot = vl - s0 * np.abs(vl) * z / gv
            ff = s0 * z + s1 * zdot + s2 * vl
            lam = s0 * np.abs(vl) / gv
            zss = np.sign(vl) * gv / s0
            z = np.where(lam > 0, zss + (z - zss) * np.exp(-lam * h), z)
            fe = (P["offset"] + P["spring_k"] * (xl - P["spring_x0"])
                  + P["cog_a"] * np.sin(2 * np.pi * xl / P["cog_p"] + P["cog_ph"])
                  + P["grav_t"] * np.sin(xl + P["grav_ph"]) + P["drag"] * np.abs(vl) * vl)
            fcpl = kc * (x - xl) + cc * (v - vl)
            a1 = (fm - ff - fe) / M
            am = np.where(two, (fm - fcpl) / mm, a1)
            al = np.where(two, (fcpl - ff - fe) / ml, a1)
            v = v + h * am
            vl = vl + h * al
            x = x + h * v
            xl = xl + h * vl
        for j in range(L):
            st = steps[j]
            first = (-c0) % st
            outs[j].append((xs[first::st, j].copy(), cs[first::st, j].copy()))
    res = []
    for j in range(L):
        n = round(durations[j] * PLANT_HZ / steps[j])
        res.append((np.concatenate([o[0] for o in outs[j]])[:n],
                    np.concatenate([o[1] for o in outs[j]])[:n]))
    return res


# ---------------------------------------------------------------------------- records

def _lanes(case: dict[str, Any], effects: list[dict[str, Any]]):
    st = case["setup"]
    model = {**case["truth"], "effects": [dict(e) for e in effects]}
    out = []
    for s in st["trajectory_seeds"]:
        ref = Reference(st["trajectory"], s, st["stroke"], st["vmax"], st["duration"])
        out.append((model, ref, st["duration"], round(PLANT_HZ / st["rate_hz"])))
    return out


def _finish(case: dict[str, Any], k: int, ref: Reference, x: np.ndarray, i: np.ndarray
            ) -> dict[str, np.ndarray]:
    """Recorded columns of lane ``k`` (0 recording, 1 hold-out): noise and encoder."""
    st = case["setup"]
    t = np.arange(x.size) / st["rate_hz"]
    rng = np.random.default_rng(st["noise_seeds"][k])
    w = rng.standard_normal(t.size)
    if st["noise"] == "coloured":
        a = 1 - math.exp(-2 * math.pi * st["noise_cutoff_hz"] / st["rate_hz"])
        from scipy.signal import lfilter

        y = lfilter([a], [1.0, a - 1.0], w)  # first-order low pass
        w = y / max(float(np.std(y)), 1e-300)
    xr, vr = ref(t)
    cols = {"t": t, "x": np.round(x / st["quantum"]) * st["quantum"],
            "i": i + st["current_noise"] * w}
    if case["truth"]["controller"]["type"] == "pid":
        cols["x_ref"] = xr
    else:
        cols["v_ref"] = vr
    return cols


def records(jobs: list[tuple[dict[str, Any], list[dict[str, Any]]]]
            ) -> list[tuple[dict[str, np.ndarray], dict[str, np.ndarray]]]:
    """(recording, hold-out) columns for each (case, effects), all simulated as lanes of
    one run (cases of similar durations run best together)."""
    lanes = [ln for case, eff in jobs for ln in _lanes(case, eff)]
    sims = simulate([ln[0] for ln in lanes], [ln[1] for ln in lanes],
                    [ln[2] for ln in lanes], [ln[3] for ln in lanes])
    out = []
    for j, (case, _eff) in enumerate(jobs):
        pair = [_finish(case, k, lanes[2 * j + k][1], *sims[2 * j + k]) for k in (0, 1)]
        out.append((pair[0], pair[1]))
    return out


def write_case(d: Path, case: dict[str, Any], effects: list[dict[str, Any]],
               rec: dict[str, np.ndarray], hold: dict[str, np.ndarray]) -> None:
    """A case folder: recording.csv, holdout.csv (CONTRACT), truth.json, model.json."""
    d.mkdir(parents=True, exist_ok=True)
    rot = case["truth"]["axis"].get("kind") == "rotary"
    for fn, cols in (("recording.csv", rec), ("holdout.csv", hold)):
        head = "# axis_kind: rotary\n" if rot else ""
        np.savetxt(d / fn, np.column_stack(list(cols.values())), delimiter=",",
                   header=head + ",".join(cols), comments="", fmt="%.10g")
    truth = {**case["truth"], "effects": effects}
    (d / "truth.json").write_text(json.dumps({**truth, "setup": {
        **case["setup"], "seed": case["seed"], "family": case["family"]}}, indent=1))
    (d / "model.json").write_text(json.dumps(case["believed"], indent=1))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--cases", type=int, default=10)
    ap.add_argument("--seed", type=int, default=2700)
    ap.add_argument("--max-duration", type=float, default=60.0)
    ap.add_argument("--effect", default=None, help="a JSON effect object to add")
    a = ap.parse_args()
    eff = [json.loads(a.effect)] if a.effect else []
    cases = [draw_case(a.seed + j, max_duration=a.max_duration) for j in range(a.cases)]
    for case, (rec, hold) in zip(cases, records([(c, eff) for c in cases])):
        d = Path(a.out) / f"seed{case['seed']}"
        write_case(d, case, eff, rec, hold)
        print(f"wrote {d}: {case['family']}", flush=True)


if __name__ == "__main__":
    main()
