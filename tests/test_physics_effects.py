"""The effects of issue 10 (resonance, deadband, drag, stribeck_shape) against physics
computed another way: the continuous two-mass model under ``solve_ivp``, the
frequency response of the two-mass axis, steady sliding, and records written by an
independent plant (``../shared/datasets/mismatch/``)."""

from __future__ import annotations

import json
from pathlib import Path

import lugre
import numpy as np
import pytest
from scipy import integrate, signal
from shared_data import SHARED

DATASETS = SHARED / "datasets" / "mismatch"  # tests/data (see its README)


def axis(effects, *, friction=None, controller=True):
    d = lugre.Model.paper().to_dict()
    if friction is not None:
        d["friction"] = friction
    d["effects"] = effects
    if not controller:
        del d["controller"]
    return lugre.Model.from_dict(d)


def two_mass_rhs(m: lugre.Model, i_const: float):
    """Right-hand side of the continuous two-mass axis with LuGre friction on the load
    (CONTRACT definitions), written independently of the simulators."""
    res = next(e for e in m.effects if e["effect"] == "resonance")
    drag = sum(e["coefficient"] for e in m.effects if e["effect"] == "drag")
    shape = next((e["exponent"] for e in m.effects if e["effect"] == "stribeck_shape"), 2.0)
    mass, r = m.total_mass, res["load_fraction"]
    k = r * mass * (2 * np.pi * res["frequency"]) ** 2
    c = 2 * res["damping_ratio"] * np.sqrt(k * r * mass)
    f = m.friction

    def rhs(_t, y):
        x, v, xl, vl, z = y
        s = f["positive"] if vl >= 0 else f["negative"]
        g = s["fc"] + (s["fs"] - s["fc"]) * np.exp(-abs(vl / s["vs"]) ** shape)
        zdot = vl - f["sigma0"] * abs(vl) * z / g
        ff = f["sigma0"] * z + f["sigma1"] * zdot + s["sigma2"] * vl
        fk = k * (x - xl) + c * (v - vl)
        fm = m.force_constant * i_const
        return [v, (fm - fk) / ((1 - r) * mass), vl,
                (fk - ff - drag * abs(vl) * vl) / (r * mass), zdot]

    return rhs


def test_resonance_converges_to_continuous_model():
    """Open loop, constant current, both bodies sliding forwards: against solve_ivp
    (DOP853, rtol 1e-12) the exact integrator's error halves with the step (first
    order) and RK4's falls 16-fold (fourth order)."""
    m = axis([{"effect": "resonance", "frequency": 40.0, "damping_ratio": 0.05,
               "load_fraction": 0.6},
              {"effect": "drag", "coefficient": 50.0},
              {"effect": "stribeck_shape", "exponent": 1.3}], controller=False)
    t = np.arange(0, 0.1 + 1e-12, 1e-3)
    i = np.full(t.size, 3.0)
    v0 = 0.2
    sol = integrate.solve_ivp(two_mass_rhs(m, 3.0), (0, t[-1]), [0, v0, 0, v0, 0.0],
                              method="DOP853", t_eval=t, rtol=1e-12, atol=1e-15)
    assert sol.success and np.all(sol.y[3] > 0.05)  # sliding, smooth right-hand side
    errs = {}
    for integ, subs in (("exact", (2, 4, 8, 16, 32)), ("rk4", (1, 2, 4, 8))):
        e = []
        for s in subs:
            r = lugre.simulate(m, t, current=i, integrator=integ, substeps=s, v0=v0)
            e.append(np.max(np.abs(r.x - sol.y[0])))
        errs[integ] = e
    ratios = np.array(errs["exact"][:-1]) / np.array(errs["exact"][1:])
    assert np.all((ratios > 1.8) & (ratios < 2.2)), errs["exact"]
    ratios = np.array(errs["rk4"][:-1]) / np.array(errs["rk4"][1:])
    assert np.all((ratios > 12) & (ratios < 20)), errs["rk4"]
    assert errs["exact"][-1] < 1e-5 and errs["rk4"][-1] < 1e-9


def test_resonance_frequency_response():
    """Current-to-motor-velocity response of the free two-mass axis (almost no
    friction, a soft spring on the load to keep it in place) under a random current:
    its anti-resonance lies at the load's frequency with the motor held, `frequency`,
    its resonance at `frequency/sqrt(1 - r)`."""
    f0, r = 30.0, 0.75
    light = {"model": "lugre", "sigma0": 1e5, "sigma1": 0.0,
             "positive": {"fc": 0.01, "fs": 0.01, "sigma2": 0.0, "vs": 0.01},
             "negative": {"fc": 0.01, "fs": 0.01, "sigma2": 0.0, "vs": 0.01}}
    m = axis([{"effect": "resonance", "frequency": f0, "damping_ratio": 0.03,
               "load_fraction": r},
              {"effect": "spring", "stiffness": 500.0, "x0": 0.0}],
             friction=light, controller=False)
    fs = 2000.0
    t = np.arange(0, 60.0, 1 / fs)
    rng = np.random.default_rng(3)
    i = rng.standard_normal(t.size)
    res = lugre.simulate(m, t, current=i, substeps=5)
    f, pxy = signal.csd(i, res.v, fs=fs, nperseg=8192)
    _, pxx = signal.welch(i, fs=fs, nperseg=8192)
    h = np.abs(pxy / pxx)
    band = (f > 15) & (f < 45)
    fa = f[band][np.argmin(h[band])]
    band = (f > 45) & (f < 100)
    fr = f[band][np.argmax(h[band])]
    assert fa == pytest.approx(f0, rel=0.015)  # bin width 0.24 Hz
    assert fr == pytest.approx(f0 / np.sqrt(1 - r), rel=0.015)


def test_drag_and_shape_steady_sliding():
    """Constant-speed tracking: the motor force settles at the shaped Stribeck force
    plus c*v*|v|, in both directions."""
    c, p = 120.0, 0.8
    m = axis([{"effect": "drag", "coefficient": c},
              {"effect": "stribeck_shape", "exponent": p}])
    t = np.arange(0, 2.0, 1e-4)
    for vr in (0.015, -0.05):
        r = lugre.simulate(m, t, vr * t)
        s = m.positive if vr > 0 else m.negative
        g = s["fc"] + (s["fs"] - s["fc"]) * np.exp(-abs(vr / s["vs"]) ** p)
        want = np.sign(vr) * g + s["sigma2"] * vr + c * vr * abs(vr)
        assert np.mean(r.force[-2000:]) == pytest.approx(want, rel=1e-3)
        assert np.mean(r.friction[-2000:]) == pytest.approx(want - c * vr * abs(vr),
                                                            rel=1e-3)


def test_deadband_small_command_no_motion():
    m = axis([{"effect": "deadband", "current": 0.5}], controller=False)
    t = np.arange(0, 0.5, 1e-3)
    i = 0.49 * np.sin(2 * np.pi * 3 * t)
    r = lugre.simulate(m, t, current=i)
    assert np.all(r.x == 0) and np.all(r.force == 0)
    np.testing.assert_array_equal(r.i, i)


def read_csv(p: Path):
    a = np.genfromtxt(p, delimiter=",", names=True, comments="#")
    return {k: np.asarray(a[k], dtype=float) for k in a.dtype.names}


def dataset_residuals(name: str, which: str):
    """The dataset's model plus its true effects (and, second, without them) under the
    recorded ``x_ref``: rms of the current and position differences to the record,
    and an upper bound on the current's white measurement noise,
    ``std(diff(i))/sqrt(2)``."""
    d = DATASETS / name
    model = json.loads((d / "model.json").read_text())
    truth = json.loads((d / "truth.json").read_text())
    rec = read_csv(d / which)
    out = []
    for effects in (truth["effects"], []):
        model["effects"] = effects
        r = lugre.simulate(lugre.Model.from_dict(model), rec["t"], rec["x_ref"])
        out.append((np.sqrt(np.mean((r.i - rec["i"]) ** 2)),
                    np.sqrt(np.mean((r.x - rec["x"]) ** 2))))
    noise = np.std(np.diff(rec["i"])) / np.sqrt(2)
    return out[0], out[1], noise


#: Per dataset, which residual tells the effect apart ("i" current, "x" position) and
#: the least ratio of that residual without the effect to the one with it. Measured
#: (recording / holdout): resonance x 3.1 / 2.9 (its current differs by only 6 %, the
#: PID hides a 22 Hz load mode from the current), deadband i 2.08 / 1.98, drag i 4.7 /
#: 4.8, stribeck_shape i 1.40 / 1.84.
DATASET_GAIN = {
    "resonance": ("x", 2.5),
    "deadband": ("i", 1.8),
    "drag": ("i", 3.0),
    "stribeck_shape": ("i", 1.3),
}


@pytest.mark.parametrize("name", sorted(DATASET_GAIN))
@pytest.mark.parametrize("which", ["recording.csv", "holdout.csv"])
def test_datasets_current_agrees(name, which):
    """Records of an independent plant (1 kHz samples of a 10 kHz loop, noisy current):
    with the true effect the simulated current matches the recorded one up to the
    noise (rms difference at most 1.3 times the noise bound; measured 1.03-1.19, i.e.
    1.9-4.1 % of the rms current), and clearly better than without it."""
    (di, dx), (di0, dx0), noise = dataset_residuals(name, which)
    assert di < 1.3 * noise, (di, noise)
    kind, gain = DATASET_GAIN[name]
    ratio = di0 / di if kind == "i" else dx0 / dx
    assert ratio > gain, (kind, ratio)
