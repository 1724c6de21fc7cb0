"""Diagnosis on concealed-effect recordings (lugre.diagnose.synth) and on bad input."""

from __future__ import annotations

import json
import warnings

import lugre
import numpy as np
import pytest
from lugre.diagnose import diagnose, evaluate, fit_inverse_dynamics, write_plots
from lugre.diagnose.synth import concealed
from lugre.exceptions import DataError, UnitsWarning


@pytest.fixture(scope="module")
def cogging_case():
    rec, believed, _truth = concealed("cogging", duration=10.0)
    hold, _, _ = concealed("cogging", duration=10.0, seed=5)
    return rec, believed, diagnose(rec, believed, holdout=hold, closed_loop=False)


def test_cogging_named_with_parameters(cogging_case):
    _, _, dg = cogging_case
    assert [f.effect for f in dg.findings] == ["cogging"]
    p = dg.findings[0].parameters
    assert p["pitch"] == pytest.approx(0.03, rel=0.01)
    assert p["amplitude"] == pytest.approx(2.5, rel=0.1)
    assert dg.fit["holdout_after"]["rms_force"] < 0.7 * dg.fit["holdout_before"]["rms_force"]


def test_report_shape_and_plots(cogging_case, tmp_path):
    rec, believed, dg = cogging_case
    d = json.loads(dg.to_json())
    f = d["findings"][0]
    assert set(f) >= {"effect", "parameters", "where", "explained", "evidence"}
    assert set(f["where"]) == {"position", "time", "velocity"}
    assert 0.3 < f["explained"] <= 1.0
    assert set(d["fit"]) >= {"before", "after", "holdout_before", "holdout_after"}
    aug = dg.augmented_model()
    assert any(e["effect"] == "cogging" for e in aug.effects)
    assert evaluate(rec, aug)["rms_force"] < evaluate(rec, believed)["rms_force"]
    assert "cogging" in dg.summary()
    files = write_plots(dg, tmp_path)
    assert {p.name for p in files} >= {"residual_time.png", "residual_position.png",
                                       "residual_velocity.png", "residual_spectrum.png",
                                       "overlay.png"}
    assert all(p.stat().st_size > 1000 for p in files)


@pytest.mark.parametrize("effect,key,truth,rel", [
    ("spring", "stiffness", 40.0, 0.15),
    ("mass", "delta", 5.0, 0.25),
])
def test_other_effects(effect, key, truth, rel):
    rec, believed, _ = concealed(effect, duration=10.0)
    dg = diagnose(rec, believed, closed_loop=False)
    names = [f.effect for f in dg.findings]
    assert names and names[0] == effect
    assert dg.findings[0].parameters[key] == pytest.approx(truth, rel=rel)


def test_lag_names_delay_or_current_lag():
    rec, believed, _ = concealed("current_lag", duration=10.0)
    dg = diagnose(rec, believed, closed_loop=False)
    f = dg.findings[0]
    named = {f.effect} | {a["effect"] for a in f.alternatives}
    assert "current_lag" in named


def test_noise_gives_no_finding():
    rec, believed, _ = concealed("none", duration=10.0, seed=3)
    dg = diagnose(rec, believed, closed_loop=False)
    assert dg.findings == []
    assert dg.fit["after"]["rms_force"] <= dg.fit["before"]["rms_force"]


def test_evaluate_keys():
    rec, believed, truth = concealed("none", duration=4.0)
    e = evaluate(rec, truth)
    assert e["rms_force"] > 0 and 0 < e["nrmse_force"] < 0.05
    assert e["rms_force"] < evaluate(rec, believed)["rms_force"] * 1.01


def test_fit_inverse_dynamics_recovers_mass_and_viscous():
    rec, _, _truth = concealed("none", duration=10.0)
    m = fit_inverse_dynamics(rec, force_constant=25.0)
    assert m.mass == pytest.approx(25.0, rel=0.05)
    assert m.positive["sigma2"] == pytest.approx(332.5, rel=0.1)


def _rec(**kw):
    t = np.arange(2000) * 1e-3
    base = {"t": t, "x": 0.05 * np.sin(2 * np.pi * t), "i": np.ones_like(t)}
    base.update(kw)
    return lugre.Recording(**base)


def test_bad_input():
    m = lugre.Model.paper()
    with pytest.raises(DataError, match="no motion"):
        diagnose(_rec(x=np.zeros(2000)), m)
    with pytest.raises(DataError, match="samples"):
        diagnose(lugre.Recording(t=np.arange(100) * 1e-3, x=np.zeros(100), i=np.ones(100)), m)
    with pytest.raises(DataError, match="one direction"):
        diagnose(_rec(x=np.linspace(0, 0.1, 2000)), m)
    t = np.arange(2000) * 1e-3
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        try:
            evaluate(_rec(x=50.0 * np.sin(2 * np.pi * t)), m)
        except DataError:
            pass
    assert any(issubclass(x.category, UnitsWarning) and "millimetres" in str(x.message)
               for x in w)
    with pytest.raises(FileNotFoundError):
        diagnose("/nonexistent/recording.csv", m)
