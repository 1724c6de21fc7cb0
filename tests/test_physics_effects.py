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

DATASETS = Path(__file__).resolve().parents[2] / "shared" / "datasets" / "mismatch"


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
    assert fa == pytest.approx(f0, rel=0.03)
    assert fr == pytest.approx(f0 / np.sqrt(1 - r), rel=0.03)


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


def dataset_agreement(name: str, which: str = "recording.csv"):
    """(rms(i_sim - i_rec)/rms(i_rec), the same without the effect) on a dataset:
    the model of the dataset plus its true effects, under the recorded x_ref."""
    d = DATASETS / name
    model = json.loads((d / "model.json").read_text())
    truth = json.loads((d / "truth.json").read_text())
    rec = read_csv(d / which)
    out = []
    for effects in (truth["effects"], []):
        model["effects"] = effects
        r = lugre.simulate(lugre.Model.from_dict(model), rec["t"], rec["x_ref"])
        out.append(np.sqrt(np.mean((r.i - rec["i"]) ** 2)) / np.sqrt(np.mean(rec["i"] ** 2)))
    return out


#: Largest normalised rms current difference accepted per dataset, and the smallest
#: gain over the same model without the effect (measured values in the docstring).
DATASET_LIMITS = {
    "resonance": (0.10, 2.0),
    "deadband": (0.10, 1.2),
    "drag": (0.10, 2.0),
    "stribeck_shape": (0.10, 1.2),
}


@pytest.mark.skipif(not DATASETS.is_dir(), reason="shared datasets not available")
@pytest.mark.parametrize("name", sorted(DATASET_LIMITS))
@pytest.mark.parametrize("which", ["recording.csv", "holdout.csv"])
def test_datasets_current_agrees(name, which):
    with_effect, without = dataset_agreement(name, which)
    limit, gain = DATASET_LIMITS[name]
    assert with_effect < limit, (with_effect, without)
    assert without > gain * with_effect, (with_effect, without)
