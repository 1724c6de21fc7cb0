"""Rotary axes: a joint's gravity found from a record spanning a fraction of a turn, an
inertia that changed since the model was fitted named as such, and a clean joint
diagnosed against its own fit named nothing (the package's generator; the independent
plant's versions of the drive effects are in test_outside_vocabulary.py)."""

from __future__ import annotations

import math
import warnings

import lugre
import numpy as np
import pytest
from lugre.diagnosis import diagnose, evaluate, fit_model
from lugre.diagnosis.synth import case, rotary_model

pytestmark = pytest.mark.filterwarnings("ignore::lugre.PassivityWarning")


def _joint(effects, seed, kind="sines", axis_seed=None):
    return case(effects, seed=seed, axis_seed=seed if axis_seed is None else axis_seed,
                kind=kind, rotary=True, quantum=1e-5, current_noise=0.005)


@pytest.mark.parametrize("seed, kind", [(11, "sines"), (18, "p2p"), (25, "feeds")])
def test_gravity_is_named_with_its_torque_and_phase(seed, kind):
    ax = rotary_model(seed)
    g = {"effect": "gravity", "torque": 2.0 * ax.positive["fc"], "phase": -0.8}
    rec, hold, believed, _ = _joint([g], seed, kind)
    span = float(rec.x.max() - rec.x.min())
    assert span < 0.5 * 2 * math.pi  # a fraction of a turn
    dg = diagnose(rec, believed, holdout=hold)
    assert [f.effect for f in dg.findings] == ["gravity"], dg.summary()
    p = dg.findings[0].parameters
    assert p["torque"] == pytest.approx(g["torque"], rel=0.15)
    assert abs((p["phase"] - g["phase"] + math.pi) % (2 * math.pi) - math.pi) < 0.15
    before = evaluate(hold, believed)["rms_force"]
    after = evaluate(hold, dg.augmented)["rms_force"]
    assert after < 0.7 * before
    assert "N m" in dg.summary() and " rad" in dg.summary()


def test_a_gravity_on_a_linear_axis_is_refused_with_the_offset_named():
    d = lugre.Model.paper().to_dict()
    d["effects"] = [{"effect": "gravity", "torque": 1.0, "phase": 0.0}]
    with pytest.raises(lugre.ModelError, match=r"effects\[0\].*offset"):
        lugre.Model(d)


def test_an_inertia_changed_since_the_fit_is_named_on_the_next_record():
    """The model fitted on one record of a joint, the next record with 25 % more
    inertia (another configuration of the arm behind it): named as an inertia change
    beyond the fit's interval, with its size, and the held-out error falls."""
    seed = 32
    rec, _, _, truth = _joint([], seed, "p2p")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted, _ = fit_model(rec, force_constant=truth.force_constant)
    more = {"effect": "mass", "delta": 0.25 * truth.mass}
    rec2, hold2, _, _ = _joint([more], seed + 2, "p2p", axis_seed=seed)
    dg = diagnose(rec2, fitted, holdout=hold2)
    mass = [f for f in dg.findings if f.effect == "mass"]
    assert mass, dg.summary()
    assert mass[0].parameters["delta"] == pytest.approx(more["delta"], rel=0.3)
    assert "inertia" in dg.summary() and "kg m^2" in dg.summary()
    assert evaluate(hold2, dg.augmented)["rms_force"] < 0.7 * evaluate(hold2, fitted)["rms_force"]


@pytest.mark.parametrize("seed, kind", [(40, "sines"), (54, "p2p")])
def test_a_clean_joint_against_its_own_fit_names_nothing(seed, kind):
    rec, hold, _, truth = _joint([], seed, kind)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted, _ = fit_model(rec, force_constant=truth.force_constant)
    assert fitted.is_rotary and fitted.mass == pytest.approx(truth.mass, rel=0.05)
    dg = diagnose(rec, fitted, holdout=hold)
    assert dg.findings == [], dg.summary()


def test_the_fit_sets_a_joints_gravity_aside_and_the_diagnosis_names_it():
    """A gravity-loaded joint fitted by the user: the weight's torque is fitted beside
    the base (so friction levels and inertia stay the joint's), left out of the model
    and said; diagnosing against that fit names it with its torque and phase."""
    seed = 11
    ax = rotary_model(seed)
    g = {"effect": "gravity", "torque": 2.0 * ax.positive["fc"], "phase": 0.4}
    rec, hold, _, truth = _joint([g], seed, "sines")
    fitted, fit = fit_model(rec, force_constant=truth.force_constant)
    assert not fitted.effects and [e["effect"] for e in fit.set_aside] == ["gravity"]
    assert fitted.mass == pytest.approx(truth.mass, rel=0.05)
    assert fitted.positive["fc"] == pytest.approx(truth.positive["fc"], rel=0.1)
    dg = diagnose(rec, fitted, holdout=hold)
    assert [f.effect for f in dg.findings] == ["gravity"], dg.summary()
    assert dg.findings[0].parameters["torque"] == pytest.approx(g["torque"], rel=0.15)
    kept, _ = fit_model(rec, force_constant=truth.force_constant, effects=["gravity"])
    assert [e["effect"] for e in kept.effects] == ["gravity"]


def test_a_rotary_axis_writes_its_mass_effect_as_inertia(tmp_path):
    """CONTRACT: the mass effect of a rotary axis is written ``inertia`` (and ``mass``
    is read as the same): in the model file and in the report, with its unit on the
    page."""
    from lugre.html import diagnosis_page

    seed = 32
    payload = {"effect": "mass", "delta": 0.3 * rotary_model(seed).mass}
    rec, hold, believed, _ = _joint([payload], seed, "p2p")
    dg = diagnose(rec, believed, holdout=hold)
    rep = dg.to_dict()
    assert [f["effect"] for f in rep["findings"]] == ["inertia"], dg.summary()
    path = tmp_path / "aug.json"
    lugre.save_model(dg.augmented_model(), path)
    assert '"effect": "inertia"' in path.read_text()
    again = lugre.load_model(path)
    assert again.total_mass == pytest.approx(dg.augmented_model().total_mass)
    assert "kg m^2" in diagnosis_page(rep, dg.data)


def test_an_inertia_varying_with_the_angle_is_unexplained_not_a_weight():
    """Outside the vocabulary: a joint's inertia ``J*(1 + 0.3*cos(x))`` (an arm behind
    it), written into the current as the extra inertia asks for it. Its force is
    periodic in the angle like a weight's and a spring's, but grows with the
    acceleration: read where the joint hardly accelerates and where it does, neither
    is the same, so nothing is named and the rest is said to be unexplained."""
    ax = rotary_model(2900)  # (current noise 1 % of the static friction's current)
    rec, hold, _, truth = case([], seed=2900, axis_seed=2900, kind="sines", rotary=True,
                               quantum=1e-5, duration=20.0,
                               current_noise=0.01 * ax.positive["fs"] / ax.force_constant)

    def varied(r):
        a = np.gradient(np.gradient(r.x, r.t), r.t)
        return lugre.Recording(t=r.t, x=r.x, x_ref=r.x_ref,
                               i=r.i + 0.3 * truth.mass * np.cos(r.x) * a
                               / truth.force_constant, meta={"axis_kind": "rotary"})

    rec, hold = varied(rec), varied(hold)
    fitted, _ = fit_model(rec, force_constant=truth.force_constant)
    dg = diagnose(rec, fitted, holdout=hold)
    assert dg.findings == [], dg.summary()
    assert dg.unexplained, dg.summary()
    said = " ".join(t["why"] for t in dg.to_dict()["trials"])
    assert "the same at any acceleration" in said
