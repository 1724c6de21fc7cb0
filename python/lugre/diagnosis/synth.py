"""Concealed-effect recordings: a known effect hidden in a closed-loop record.

The plant is the paper axis (m = 25 kg, K_F = 25 N/A) under its PID at 10 kHz, driven
through a smooth back-and-forth reference, with one effect of the vocabulary added,
small against friction. The recorded current gets white noise and sparse spikes, the
position a 1 um quantisation; the model handed to the diagnosis has its base
parameters off by about 1 %.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .._native import simulate
from ..io import Recording
from ..model import Model
from ..vocabulary import (
    COGGING,
    CURRENT_LAG,
    DELAY,
    DRIFT,
    MASS,
    OFFSET,
    POSITION_FRICTION,
    SPRING,
)

__all__ = ["EFFECTS", "axis_model", "case", "concealed", "reference_trajectory", "rotary_model",
           "trajectory"]

#: A default concealed instance of every effect of the vocabulary.
EFFECTS: dict[str, dict[str, Any] | None] = {
    "none": None,
    COGGING: {"effect": COGGING, "amplitude": 2.5, "pitch": 0.03, "phase": 0.7},
    SPRING: {"effect": SPRING, "stiffness": 40.0, "x0": -0.05},
    OFFSET: {"effect": OFFSET, "force": 3.0},
    POSITION_FRICTION: {"effect": POSITION_FRICTION,
                          "positions": [-0.1, -0.06, -0.03, 0.0, 0.1],
                          "scale": [1.0, 1.0, 1.3, 1.0, 1.0]},
    DRIFT: {"effect": DRIFT, "gain": 0.15, "time_constant": 3.0},  # well inside a 10 s record
    MASS: {"effect": MASS, "delta": 5.0},
    DELAY: {"effect": DELAY, "seconds": 0.002},
    CURRENT_LAG: {"effect": CURRENT_LAG, "bandwidth": 60.0},
}


def reference_trajectory(t: np.ndarray, seed: int = 0) -> np.ndarray:
    """A smooth back-and-forth position reference over about +-0.15 m [m]."""
    rng = np.random.default_rng(seed)
    f = np.array([0.23, 0.41, 0.67]) * (1 + 0.05 * rng.standard_normal(3))
    a = np.array([0.09, 0.04, 0.02])
    ph = rng.uniform(0, 2 * np.pi, 3)
    x = sum(ai * np.sin(2 * np.pi * fi * t + p) for ai, fi, p in zip(a, f, ph))
    # a smooth start (continuous acceleration): a kink would step the PID's derivative
    # term, a current step of several amperes that no drive reference has
    u = np.clip(t / 1.0, 0.0, 1.0)
    ramp = u * u * u * (10.0 - 15.0 * u + 6.0 * u * u)
    return ramp * x


def concealed(
    effect: str | dict[str, Any] | None,
    *,
    duration: float = 12.0,
    rate_hz: float = 1000.0,
    seed: int = 0,
    current_noise: float = 0.01,
    spike_rate: float = 0.003,
    quantum: float = 1e-6,
    base_error: float = 0.01,
) -> tuple[Recording, Model, Model]:
    """Simulate a recording with a concealed effect.

    Parameters
    ----------
    effect : str, dict or None
        A name of :data:`EFFECTS` or an effect object (``None``/``"none"``: nothing).
    duration, rate_hz : float
        Length [s] and sample rate [Hz].
    seed : int
        Random seed (trajectory, noise, base errors).
    current_noise : float
        Standard deviation of the current noise [A].
    spike_rate : float
        Fraction of samples carrying a spike (+-1 A).
    quantum : float
        Encoder resolution [m].
    base_error : float
        Relative standard deviation of the errors of the believed base parameters.

    Returns
    -------
    recording : Recording
    believed : Model
        The model handed to the diagnosis (no effect, base off by ~``base_error``).
    truth : Model
        The model that generated the data.
    """
    eff = EFFECTS[effect] if isinstance(effect, str) else effect
    rng = np.random.default_rng(seed + 1000)
    paper = Model.paper()
    d = paper.to_dict()
    d["controller"] = {"type": "pid", "kp": 5e4, "ki": 5e5, "kd": 1500.0, "rate_hz": 10000.0}
    d["effects"] = [] if eff is None else [dict(eff)]
    truth = Model(d)
    n = int(duration * rate_hz)
    t = np.arange(n) / rate_hz
    # the reference is generated at the controller's rate (as a drive does); a reference
    # interpolated from the record's rate would put a 1-sample staircase into the
    # derivative term, a kick the sampled current does not show. Outputs are instantaneous
    # samples at the record's rate.
    over = max(1, round(d["controller"]["rate_hz"] / rate_hz))
    tf = np.arange(n * over) / (rate_hz * over)
    sf = simulate(truth, tf, reference_trajectory(tf, seed), integrator="rk4")
    xr = reference_trajectory(t, seed)

    class _S:
        x = sf.x[::over]
        i = sf.i[::over]

    s = _S
    i = s.i + current_noise * rng.standard_normal(t.size)
    spikes = rng.random(t.size) < spike_rate
    i[spikes] += rng.choice([-1.0, 1.0], spikes.sum())
    x = np.round(s.x / quantum) * quantum
    rec = Recording(t=t, x=x, i=i, x_ref=xr)
    b = paper.to_dict()
    b["controller"] = d["controller"]
    f = b["friction"]
    for side in ("positive", "negative"):
        for k in ("fc", "fs", "sigma2", "vs"):
            f[side][k] *= 1 + base_error * rng.standard_normal()
        f[side]["fs"] = max(f[side]["fs"], f[side]["fc"])
    b["axis"]["mass"] *= 1 + base_error * rng.standard_normal()
    return rec, Model(b), truth


def axis_model(seed: int) -> Model:
    """A random axis: mass 6-90 kg, force constant 10-60 N/A, Coulomb friction 2-8 % of
    the weight-like scale ``10*mass``, static 1.3-2.2x Coulomb, a PID at 5-10 kHz tuned
    to the mass (same bandwidth as the paper axis)."""
    rng = np.random.default_rng(seed + 7000)
    m = float(np.exp(rng.uniform(np.log(6.0), np.log(90.0))))
    kf = float(rng.uniform(10.0, 60.0))
    sets, s0 = _friction(rng, m, 10.0 * m * rng.uniform(0.02, 0.08), (0.003, 0.02))
    return _pid_axis({"mass": m, "force_constant": kf}, m, sets, s0,
                     float(rng.choice([5000.0, 10000.0])))


def rotary_model(seed: int) -> Model:
    """A random rotary axis (a joint or a rotary table, joint side): inertia 0.005-2
    kg m^2, torque constant 0.2-5 N m/A, Coulomb friction 2-8 % of the scale
    ``20*inertia`` N m, static 1.3-2.2x Coulomb, Stribeck speeds 0.01-0.1 rad/s, a PID at
    4-8 kHz with the bandwidth of the paper axis."""
    rng = np.random.default_rng(seed + 9000)
    j = float(np.exp(rng.uniform(np.log(0.005), np.log(2.0))))
    kt = float(np.exp(rng.uniform(np.log(0.2), np.log(5.0))))
    sets, s0 = _friction(rng, j, 20.0 * j * rng.uniform(0.02, 0.08), (0.01, 0.1))
    return _pid_axis({"kind": "rotary", "inertia": j, "torque_constant": kt}, j, sets, s0,
                     float(rng.choice([4000.0, 8000.0])))


def _friction(rng: np.random.Generator, m: float, fc: float, vs: tuple[float, float]
              ) -> tuple[dict[str, dict[str, float]], float]:
    """Random static sets about ``fc`` (static 1.3-2.2x, viscous 4-16 times the mass,
    Stribeck speeds log-uniform over ``vs``) and a bristle stiffness for them."""
    sets = {}
    for side in ("positive", "negative"):
        f = fc * (1 + 0.05 * rng.standard_normal())
        sets[side] = {"fc": f, "fs": f * rng.uniform(1.3, 2.2),
                      "sigma2": m * rng.uniform(4.0, 16.0),
                      "vs": float(np.exp(rng.uniform(np.log(vs[0]), np.log(vs[1]))))}
    s0 = 3.0 * max(sets["positive"]["fs"], sets["negative"]["fs"]) / 1e-3 * rng.uniform(0.5, 2)
    return sets, s0


def _pid_axis(axis: dict[str, Any], m: float, sets: dict[str, Any], s0: float,
              rate: float) -> Model:
    """The model of a random axis under a PID with the paper axis's bandwidth."""
    g = m / 25.0
    return Model({
        "axis": axis,
        "friction": {"model": "lugre", "sigma0": s0, "sigma1": 0.3 * np.sqrt(s0 * m) * 0.05,
                     **sets},
        "effects": [],
        "controller": {"type": "pid", "kp": 5e4 * g, "ki": 5e5 * g, "kd": 1500.0 * g,
                       "rate_hz": rate},
    })


def trajectory(kind: str, t: np.ndarray, seed: int = 0, stroke: float = 0.15) -> np.ndarray:
    """A position reference [m]: ``"sines"`` (smooth back and forth), ``"p2p"``
    (point-to-point moves with dwells, S-curve profiles) or ``"feeds"`` (constant-speed
    passes at several speeds, slow ones included, both ways)."""
    if kind == "sines":
        return reference_trajectory(t, seed) * (stroke / 0.15)
    rng = np.random.default_rng(seed + 3000)
    x = np.zeros_like(t)
    if kind == "p2p":
        tk, pos = 1.0, 0.0
        while tk < t[-1]:
            target = float(rng.uniform(-stroke, stroke))
            dur = float(rng.uniform(0.4, 1.5))
            u = np.clip((t - tk) / dur, 0, 1)
            sm = u * u * u * (10 - 15 * u + 6 * u * u)
            x = np.where(t >= tk, pos + (target - pos) * sm, x)
            pos = target
            tk += dur + float(rng.uniform(0.1, 0.6))
        return x
    if kind == "feeds":
        speeds = np.array([0.003, 0.01, 0.03, 0.1, 0.2]) * (stroke / 0.15)
        rng.shuffle(speeds)
        v = np.zeros_like(t)
        seg = (t[-1] - 1.0) / (2 * speeds.size)
        for j, sp in enumerate(np.repeat(speeds, 2)):
            a, b = 1.0 + j * seg, 1.0 + (j + 1) * seg
            sgn = 1.0 if j % 2 == 0 else -1.0
            u = np.clip((t - a) / (b - a), 0, 1)
            v += sgn * sp * np.sin(np.pi * u) ** 0.2 * ((t >= a) & (t < b))
        x = np.cumsum(v) * (t[1] - t[0])
        u = np.clip(t / 1.0, 0.0, 1.0)
        return x * u * u * u * (10.0 - 15.0 * u + 6.0 * u * u)
    raise ValueError(f"unknown trajectory {kind!r}")


def case(truth_effects: list[dict[str, Any]], *, seed: int, axis_seed: int | None = None,
         kind: str = "sines", duration: float = 20.0, rate_hz: float = 1000.0,
         current_noise: float = 0.01, quantum: float = 1e-6, base_error: float = 0.01,
         rotary: bool = False) -> tuple[Recording, Recording, Model, Model]:
    """A concealed case: recording and hold-out (another seed of the same trajectory
    kind), the believed model (base off by ``base_error``) and the truth.

    ``axis_seed`` None: the paper axis; else :func:`axis_model`, or with ``rotary``
    :func:`rotary_model` (strokes of 0.3-1.5 rad, quantum and noise as given, in rad
    and A).
    """
    truth = (Model.paper().replace(controller={"type": "pid", "kp": 5e4, "ki": 5e5,
                                               "kd": 1500.0, "rate_hz": 10000.0})
             if axis_seed is None else
             rotary_model(axis_seed) if rotary else axis_model(axis_seed))
    truth = truth.replace(effects=[dict(e) for e in truth_effects])
    recs = []
    for s in (seed, seed + 1):
        rng = np.random.default_rng(s + 1000)
        rate = float(truth.controller["rate_hz"])
        over = max(1, round(rate / rate_hz))
        n = int(duration * rate_hz)
        tf = np.arange(n * over) / (rate_hz * over)
        stroke = (0.15 if axis_seed is None else float(rng.uniform(0.3, 1.5)) if rotary
                  else float(rng.uniform(0.05, 0.3)))
        sf = simulate(truth, tf, trajectory(kind, tf, s, stroke), integrator="rk4")
        t = tf[::over]
        i = sf.i[::over] + current_noise * rng.standard_normal(t.size)
        x = np.round(sf.x[::over] / quantum) * quantum
        recs.append(Recording(t=t, x=x, i=i, x_ref=trajectory(kind, t, s, stroke),
                              meta={"axis_kind": truth.kind}))
    rng = np.random.default_rng(seed + 2000)
    b = truth.to_dict()
    b["effects"] = []
    f = b["friction"]
    for side in ("positive", "negative"):
        for k in ("fc", "fs", "sigma2", "vs"):
            f[side][k] *= 1 + base_error * rng.standard_normal()
        f[side]["fs"] = max(f[side]["fs"], f[side]["fc"])
    return recs[0], recs[1], Model(b), truth
