"""The base fit (``lugre fit``): the record's own optimum from the tool's starts, on
records written by a plant independent of the package, with honest intervals; the core
and its NumPy twin on the same inputs."""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import lugre
import numpy as np
import pytest
from lugre.diagnosis import evaluate
from lugre.diagnosis import residual as R
from lugre.diagnosis.base import apply_base
from lugre.diagnosis.basefit import base_names, identify, starts
from lugre.diagnosis.inverse import fit_inverse_dynamics

TRUTH = {
    "axis": {"mass": 12.0, "force_constant": 20.0},
    "friction": {"model": "lugre", "sigma0": 2.0e5, "sigma1": 150.0,
                 "positive": {"fc": 9.0, "fs": 16.0, "sigma2": 80.0, "vs": 0.012},
                 "negative": {"fc": 8.5, "fs": 15.0, "sigma2": 90.0, "vs": 0.010}},
    "effects": [],
}


def plant(seed: int, seconds: float = 8.0, cogging: float = 0.0,
          sigma1: float | None = None) -> lugre.Recording:
    """A PID-controlled LuGre axis written here (semi-implicit Euler at 5 kHz, its own
    bristle step), logged at 1 kHz with a 1 um encoder and current noise (``sigma1``
    in place of the truth's when given)."""
    rng = np.random.default_rng(seed)
    h, n = 2e-4, int(seconds / 2e-4)
    t = np.arange(n) * h
    f = rng.uniform(0.2, 0.6, 2)
    ph = rng.uniform(0, 2 * np.pi, 2)
    xr = 0.03 * np.sin(2 * np.pi * f[0] * t + ph[0]) + 0.01 * np.sin(2 * np.pi * f[1] * t + ph[1])
    m, kf = TRUTH["axis"]["mass"], TRUTH["axis"]["force_constant"]
    fr = TRUTH["friction"]
    s0, s1 = fr["sigma0"], fr["sigma1"] if sigma1 is None else sigma1
    wn = 2 * np.pi * 15
    kp, ki, kd = m * wn * wn, m * wn ** 3 / 5, 1.4 * m * wn
    x = v = z = integ = 0.0
    x = xr[0]
    xs, cs = np.empty(n), np.empty(n)
    for k in range(n):
        e = xr[k] - x
        integ += e * h
        vr = (xr[k] - xr[k - 1]) / h if k else 0.0
        cur = (kp * e + ki * integ + kd * (vr - v)) / kf
        xs[k], cs[k] = x, cur
        st = fr["positive"] if v >= 0 else fr["negative"]
        g = st["fc"] + (st["fs"] - st["fc"]) * math.exp(-(v / st["vs"]) ** 2)
        zdot = v - s0 * abs(v) * z / g
        force = s0 * z + s1 * zdot + st["sigma2"] * v + cogging * math.sin(2 * np.pi * x / 0.01)
        if v != 0.0:
            zss = math.copysign(g / s0, v)
            z = zss + (z - zss) * math.exp(-s0 * abs(v) * h / g)
        v += h * (kf * cur - force) / m
        x += h * v
    sl = slice(0, n, 5)
    return lugre.Recording(t=t[sl], x=np.round(xs[sl] / 1e-6) * 1e-6,
                           i=cs[sl] + 0.005 * rng.standard_normal(cs[sl].size))


@pytest.fixture(scope="module")
def records():
    return plant(1), plant(2)


@pytest.fixture(scope="module")
def fitted(records):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return identify(records[0], force_constant=20.0)


def test_fit_reaches_the_truth_on_an_independent_plant(records, fitted):
    """Mass and friction within 5 % of the plant's, and the held-out force error of the
    fitted model within 1.3 times the true model's (the linear inverse-dynamics start
    alone is several times worse)."""
    rec, hold = records
    m = fitted.model
    assert abs(m.mass / 12.0 - 1) < 0.05
    for d in ("positive", "negative"):
        for k in ("fc", "fs", "sigma2", "vs"):
            assert abs(m.friction[d][k] / TRUTH["friction"][d][k] - 1) < 0.05, (d, k)
            key = f"{d}.hump" if k == "fs" else f"{d}.{k}"
            assert fitted.profiles[key]["determined"], key
    true = evaluate(hold, lugre.Model(TRUTH))["nrmse_force"]
    got = evaluate(hold, m)["nrmse_force"]
    start = evaluate(hold, fit_inverse_dynamics(rec, force_constant=20.0))["nrmse_force"]
    assert got <= 1.3 * true
    assert start > 2 * got


def test_intervals_hold_the_truth_where_determined(fitted):
    truth = lugre.Model(TRUTH)
    for name, p in fitted.profiles.items():
        if not p["determined"] or name.startswith("sigma"):
            continue
        lo, hi = p["ci95"]
        side, _, key = name.rpartition(".")
        want = (truth.mass if name == "mass" else
                truth.friction[side]["fs"] - truth.friction[side]["fc"] if key == "hump"
                else truth.friction[side][key])
        # the intervals carry the noise; a 4 % margin covers the filter's small bias
        assert lo * 0.96 <= want <= hi * 1.04, (name, lo, want, hi)


def test_the_fit_stays_at_the_noise_floor_and_says_so(fitted):
    words, far = fitted.floor_words()
    assert not far and fitted.floor_ratio < 1.5
    assert "noise floor" in words


def test_a_left_out_cogging_is_far_from_the_noise_floor():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = identify(plant(3, cogging=1.5), force_constant=20.0, profiles=False)
    words, far = res.floor_words()
    assert far and "lugre diagnose" in words


def test_no_hump_is_reported_as_such():
    """A record of an axis without a Stribeck hump: fs = fc within the noise, vs not
    determined (it does nothing), never a hump invented from a start value."""
    saved = {d: dict(TRUTH["friction"][d]) for d in ("positive", "negative")}
    try:
        for d in ("positive", "negative"):
            TRUTH["friction"][d]["fs"] = TRUTH["friction"][d]["fc"]
        rec = plant(4)
    finally:
        for d, st in saved.items():
            TRUTH["friction"][d].update(st)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = identify(rec, force_constant=20.0)
    for d in ("positive", "negative"):
        hump = res.model.friction[d]["fs"] - res.model.friction[d]["fc"]
        assert hump < 0.05 * res.model.friction[d]["fc"]
        assert not res.profiles[f"{d}.vs"]["determined"]


def _on_core_and_twin(records, fit):
    """``fit(sig, mask, start, names)`` on the first record's first 1.5 s, on the
    core's kernels and on the NumPy twin's: both results and both kernels."""
    from lugre import reference

    rec = records[0].slice((0.0, 1.5))
    start = fit_inverse_dynamics(rec, force_constant=20.0, sliding=0.05)
    names = base_names(True)
    out, kernels_used = [], []
    for kernels in ("core", reference.kernels):
        sig = R.prepare(rec, start, backend=kernels)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            out.append(fit(sig, [bool(b) for b in sig.mask], start, names))
        kernels_used.append(sig.kernel)
    return out, kernels_used


def _same_values(a, b):
    for k, v in a["values"].items():
        assert v == pytest.approx(b["values"][k], rel=1e-7, abs=1e-9), k


def test_core_and_twin_agree(records):
    """The same fit from the same starts on the core's kernels and on the NumPy twin's."""
    from lugre import reference

    def fit(sig, mask, start, names):
        return sig.kernel.fit_base(starts(start, sig)[:4], mask, names, max_iter=15,
                                   keep=2, scouts=3)

    (a, b), (_, twin) = _on_core_and_twin(records, fit)
    assert isinstance(twin, reference.InverseRecord)
    assert a["start"] == b["start"]
    _same_values(a, b)
    assert a["cost"] == pytest.approx(b["cost"], rel=1e-7)


def test_a_start_at_its_optimum_is_not_followed_again_and_the_twin_agrees(records):
    """A scout that converged is kept as it is (two iterations from the optimum, not
    two more from where it stopped); a looser ``tol`` and no information give the same
    on the core and on the twin, the information None."""

    def fit(sig, mask, start, names):
        best = start
        for _ in range(2):  # (this record's optimum is reached slowly)
            first = sig.kernel.fit_base([best], mask, names, max_iter=300, keep=1)
            best = apply_base(start, first["values"])
        assert first["information"].shape == (len(names), len(names))
        return sig.kernel.fit_base([best], mask, names, keep=1, tol=1e-4,
                                   information=False)

    (a, b), _ = _on_core_and_twin(records, fit)
    for again in (a, b):
        assert again["information"] is None
        # (two iterations each under tol; followed again, two more)
        assert again["iterations"] == 2
    _same_values(a, b)


def test_fit_base_refuses_bad_arguments(records):
    rec = records[0].slice((0.0, 1.0))
    start = fit_inverse_dynamics(rec, force_constant=20.0)
    sig = R.prepare(rec, start)
    mask = [bool(b) for b in sig.mask]
    with pytest.raises(ValueError, match="names"):
        sig.kernel.fit_base([start], mask, ["positive.nope"])
    with pytest.raises(ValueError, match="mask"):
        sig.kernel.fit_base([start], mask[:-1], ["mass"])
    with pytest.raises(ValueError, match="start"):
        sig.kernel.fit_base([], mask, ["mass"])
    with pytest.raises(ValueError, match="weighting"):
        sig.kernel.fit_base([start], mask, ["mass"], weighting="bogus")
    for tol in (-1.0, float("nan")):
        with pytest.raises(ValueError, match="tol"):
            sig.kernel.fit_base([start], mask, ["mass"], tol=tol)


def test_fit_with_effects_refits_the_base_with_them():
    """The public cogging case (an independent plant): without the cogging in the model
    the hump is pulled astray by it; `fit --effects cogging` finds the cogging and fits
    the base again with it held, to the plant's levels."""
    from lugre import fit_model
    from shared_data import shared_file

    rec = lugre.read_recording(shared_file("mismatch", "cogging", "recording.csv"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model, fit = fit_model(rec, force_constant=25.0, effects=["cogging"])
    cog = next(e for e in model.effects if e["effect"] == "cogging")
    assert cog["amplitude"] == pytest.approx(3.0, rel=0.05)
    assert cog["pitch"] == pytest.approx(0.025, rel=0.01)
    for d, fs in (("positive", 60.2), ("negative", 60.1)):
        assert model.friction[d]["fs"] == pytest.approx(fs, rel=0.05)
        assert model.friction[d]["vs"] == pytest.approx(0.01, rel=0.1)
    assert not fit.floor_words()[1]  # at the noise floor once the cogging is in


def test_a_non_passive_fit_holds_sigma1_at_the_bound_and_says_so(fitted):
    """sigma1 beyond 4*sigma2*fc/(fs - fc) makes the friction map non-passive: the fit
    holds it at the bound, keeps what it had found, and its note says so."""
    from dataclasses import replace

    from lugre.diagnosis.basefit import _passive
    from lugre.diagnosis.fitreport import undetermined_notes

    res = fitted
    bound = min(res.model.passivity_bound())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        loose = replace(res, model=res.model.with_friction(sigma1=3.0 * bound))
    held = _passive(loose)
    assert held.model.is_passive and held.model.sigma1 == pytest.approx(bound)
    assert held.profiles["sigma1"]["fitted"] == pytest.approx(3.0 * bound)
    note = [n for n in undetermined_notes(held) if n.startswith("sigma1")]
    assert note and "passivity bound" in note[0] and "not passive" in note[0]
    assert _passive(res) is res  # a passive fit is returned as it is


def test_a_sigma1_the_record_puts_beyond_the_bound_is_kept_and_said():
    """The bound is sufficient for passivity, not necessary. Held at it, a sigma1 the
    record determines beyond it cost fresh fit cases (benches/fit_cases.py seed 5) 7 to
    20 times the true model's held-out error; it is kept, with a note."""
    from lugre.diagnosis.fitreport import undetermined_notes

    s1 = 2.5 * min(lugre.Model(TRUTH).passivity_bound())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = identify(plant(1, sigma1=s1), force_constant=20.0)
        truth = lugre.Model({**TRUTH, "friction": {**TRUTH["friction"], "sigma1": s1}})
    assert res.model.sigma1 == pytest.approx(s1, rel=0.1)
    assert res.profiles["sigma1"]["passivity_bound"] < res.profiles["sigma1"]["ci95"][0]
    note = [n for n in undetermined_notes(res) if n.startswith("sigma1")]
    assert note and "beyond the passivity bound" in note[0] and "kept" in note[0]
    hold = plant(2, sigma1=s1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ratio = evaluate(hold, res.model)["nrmse_force"] / evaluate(hold, truth)["nrmse_force"]
    assert ratio < 1.3


def test_a_sigma1_held_for_passivity_stays_within_the_records_interval(tmp_path):
    """A sigma1 the record bounds on both sides, but too loosely to call determined,
    was held at half its passivity bound, outside its interval: the fresh fit cases of
    benches/fit_cases.py seed 7 (an independent plant) scored 2.4 and 3.1 times the
    true model's held-out error (case 01, 250 Hz: 0.95 with sigma1 held at the bound,
    within the interval)."""
    import subprocess
    import sys

    bench = Path(__file__).resolve().parents[1] / "benches" / "fit_cases.py"
    subprocess.run([sys.executable, str(bench), str(tmp_path), "--cases", "2", "--seed", "7"],
                   check=True, capture_output=True)
    d = tmp_path / "case01"
    truth = json.loads((d / "truth.json").read_text())
    truth.pop("setup")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = identify(lugre.read_recording(d / "recording.csv"),
                       force_constant=truth["axis"]["force_constant"])
        hold = lugre.read_recording(d / "holdout.csv")
        ratio = (evaluate(hold, res.model)["nrmse_force"]
                 / evaluate(hold, lugre.Model(truth))["nrmse_force"])
    p = res.profiles["sigma1"]
    lo, hi = p["ci95"]
    assert lo <= res.model.sigma1 <= hi and res.model.is_passive, p
    assert ratio < 1.3


def test_the_band_is_read_again_until_it_settles():
    """A clean record of constant-speed feeds (stress seed 20's axis of case 035: 22.8
    kg, 30 s at 5 kHz, 5 um encoder): the linear start's mass of 0.07 kg read it in a
    band of 200 Hz, the fit there came to 1.09 kg, and the one reading again, at
    104 Hz, stopped with 21.9 kg at 0.95 N rms, "1.1 times the noise floor" of that band.
    Read again until the band settles (26 Hz) the fit is at the floor of its own."""
    from lugre.diagnosis import fit_model
    from lugre.diagnosis.synth import case

    setup = {"seed": 40070, "axis_seed": 5569, "kind": "feeds", "duration": 30.0,
             "rate_hz": 5000.0, "current_noise": 0.009373192784997016, "quantum": 5e-06,
             "base_error": 0.0198853711956876}
    rec, _, believed, truth = case([], **setup)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model, res = fit_model(rec, force_constant=believed.force_constant)
        rms = evaluate(rec, model)["rms_force"]
    assert model.mass == pytest.approx(truth.mass, rel=0.02)
    assert rms < 1.5 * res.noise < 0.15, (rms, res.noise)



@pytest.mark.parametrize("seed", [1, 3])
def test_a_damping_at_zero_gets_an_interval_from_its_profile(seed):
    """Multiplicative profile steps never leave zero: a fitted sigma1 of 0 read
    "determined, 0 to 0" (stress seeds 19 and 20, fits bent by a coupling or a Stribeck
    shape they did not hold). From zero the profile steps by the damping's natural size
    (``0.05*sqrt(sigma0*m)``, 77 N s/m here); on records of the plant with no bristle
    damping the fit puts sigma1 at zero, and the interval reaches above it, called
    determined only when it ends within a twentieth of that size."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = identify(plant(seed, sigma1=0.0), force_constant=20.0)
    p = res.profiles["sigma1"]
    assert p["value"] == 0.0, p
    lo, hi = p["ci95"]
    assert lo == 0.0 and hi is not None and hi > 0.0, p
    scale = 0.05 * math.sqrt(res.model.sigma0 * res.model.mass)
    assert p["determined"] == (hi <= 0.05 * scale), p
