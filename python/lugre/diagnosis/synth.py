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

__all__ = ["EFFECTS", "concealed", "reference_trajectory"]

#: A default concealed instance of every effect of the vocabulary.
EFFECTS: dict[str, dict[str, Any] | None] = {
    "none": None,
    "cogging": {"effect": "cogging", "amplitude": 2.5, "pitch": 0.03, "phase": 0.7},
    "spring": {"effect": "spring", "stiffness": 40.0, "x0": -0.05},
    "offset": {"effect": "offset", "force": 3.0},
    "position_friction": {"effect": "position_friction",
                          "positions": [-0.1, -0.06, -0.03, 0.0, 0.1],
                          "scale": [1.0, 1.0, 1.3, 1.0, 1.0]},
    "drift": {"effect": "drift", "gain": 0.15, "time_constant": 3.0},  # well inside a 10 s record
    "mass": {"effect": "mass", "delta": 5.0},
    "delay": {"effect": "delay", "seconds": 0.002},
    "current_lag": {"effect": "current_lag", "bandwidth": 60.0},
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
    sf = simulate(truth, tf, reference_trajectory(tf, seed))
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
