"""Diagnosis on the independent mismatch datasets and on the real EMPS record."""

from __future__ import annotations

import json

import lugre
import pytest
from lugre.diagnosis import diagnose, fit_inverse_dynamics
from shared_data import SHARED

MISMATCH = SHARED / "datasets" / "mismatch"
EMPS = SHARED / "datasets" / "emps" / "emps_estimation.csv"



@pytest.mark.parametrize("case", ["none", "cogging", "position_friction", "deadband", "drag",
                                  "stribeck_shape", "resonance"])
def test_mismatch_case(case):
    d = MISMATCH / case
    truth = json.loads((d / "truth.json").read_text())["effects"]
    dg = diagnose(lugre.read_recording(d / "recording.csv"), lugre.load_model(d / "model.json"),
                  holdout=lugre.read_recording(d / "holdout.csv"), closed_loop=False)
    named = [f.effect for f in dg.findings]
    assert named == [e["effect"] for e in truth]
    from lugre.html import diagnosis_page

    assert "Verdict" in diagnosis_page(dg.to_dict(), dg.data)  # the page of every report
    before = dg.fit["holdout_before"]["rms_force"]
    after = dg.fit["holdout_after"]["rms_force"]
    if truth:
        # measured 2026-11-26: after/before 0.016 (drag) to 0.091 (position friction);
        # held to the worst measured + 6 points
        assert after <= 0.15 * before
    else:
        assert after <= before * 1.001
    # Tolerances: what the tool reaches on these records (measured 2026-11-26, the same
    # on main and with the speed work), plus a stated margin: relative errors measured
    # + 2 points (pitch and phase: + 0.2 % and + 0.02 rad; they are exact to 1e-4)
    for f, e in zip(dg.findings, truth):
        if e["effect"] == "cogging":  # measured: pitch 0.007 %, amplitude 0.2 %, 0.001 rad
            assert f.parameters["pitch"] == pytest.approx(e["pitch"], rel=0.002)
            assert f.parameters["amplitude"] == pytest.approx(e["amplitude"], rel=0.025)
            assert f.parameters["phase"] == pytest.approx(e["phase"], abs=0.02)
        p = f.parameters
        if e["effect"] == "deadband":  # measured 0.5 %
            assert p["current"] == pytest.approx(e["current"], rel=0.025)
        if e["effect"] == "drag":  # measured 0.06 %
            assert p["coefficient"] == pytest.approx(e["coefficient"], rel=0.02)
        if e["effect"] == "stribeck_shape":  # measured 7.3 %
            assert p["exponent"] == pytest.approx(e["exponent"], rel=0.095)
        if e["effect"] == "resonance":  # measured 2.8 %
            assert p["frequency"] == pytest.approx(e["frequency"], rel=0.05)
            for k in ("frequency", "damping_ratio", "load_fraction"):
                lo, hi = f.uncertainty[k]  # the held-out profile's interval holds the truth
                assert lo <= e[k] <= hi, (k, lo, hi)
        if e["effect"] == "position_friction":
            aug = dg.augmented_model()
            pf = next(x for x in aug.effects if x["effect"] == "position_friction")
            import numpy as np

            xs = np.array(e["positions"])
            s_true = np.array(e["scale"])
            s_est = np.interp(xs, pf["positions"], pf["scale"])
            assert np.max(np.abs(s_est - s_true)) < 0.05  # measured 0.032, + 0.018
            lo, hi = f.where["position"]
            assert lo < e["generated_as"]["center"] < hi


@pytest.fixture(scope="module")
def emps_laps():
    rec = lugre.read_recording(EMPS)
    fit_part, check = rec.slice((None, 12.42)), rec.slice((12.42, None))
    base = fit_inverse_dynamics(fit_part)
    return fit_part, check, base, diagnose(fit_part, base, holdout=check)


def test_emps_laps(emps_laps):
    _, _, base, dg = emps_laps
    assert base.mass == pytest.approx(95.1, rel=0.02)  # measured 0.45 %, + 1.5 points
    before = dg.fit["holdout_before"]["nrmse_force"]
    after = dg.fit["holdout_after"]["nrmse_force"]
    assert before < 0.0408  # per-direction LuGre base beats the symmetric benchmark model
    assert after <= before
    # what stays is at standstill and creeping speeds (a few % of the time holds over a
    # third of it): said where it lives, with the test that measures it
    shape = " ".join(dg.unexplained["shape"])
    assert "stands or moves under" in shape and "slow current ramp at standstill" in shape


PULSES = SHARED / "datasets" / "emps" / "emps_validation_pulses.csv"


def test_emps_model_questioned_on_another_session(emps_laps):
    # the augmented model of laps 1-2 keeps every effect on laps 3-4 (recorded right
    # after); on the pulses record, another session, its 2.5 mm cogging sits 0.7 mm
    # (1.76 rad) away: it is removed and found again at its pitch, with the reason
    # said; its delay (0.57 ms) is searched again and replaced (0.74-0.76 ms there)
    _, check, _, dg = emps_laps
    aug = dg.augmented_model()
    assert {"cogging", "delay"} <= {e["effect"] for e in aug.effects}
    laps = diagnose(check, aug, closed_loop=False)
    assert laps.removed == []
    pulses = diagnose(lugre.read_recording(PULSES), aug, closed_loop=False)
    gone = {r["effect"]: r for r in pulses.removed}
    assert set(gone) == {"cogging", "delay"}
    assert gone["delay"].get("replaced") and not gone["cogging"].get("replaced")
    timing = next(f for f in pulses.findings if f.effect in ("delay", "current_lag"))
    assert 0.00065 < timing.parameters["seconds"] < 0.00085
    cog = next(f for f in pulses.findings if f.effect == "cogging")
    assert cog.parameters["pitch"] == pytest.approx(0.0025, rel=0.01)
    assert 0.6 < cog.parameters["amplitude"] < 1.1
    assert any("position origin likely differs" in n for n in pulses.notes)
    assert pulses.fit["after"]["nrmse_force"] < 0.8 * pulses.fit["before"]["nrmse_force"]


def test_clean_record_holds_the_presliding_parameters():
    """On the clean record sigma0 and sigma1 stay where the model has them (the old
    half-sample lag of the bristles moved sigma1 by +150 %), the base moves within its
    tolerance, and the report says what the record could have hidden."""
    d = MISMATCH / "none"
    dg = diagnose(lugre.read_recording(d / "recording.csv"), lugre.load_model(d / "model.json"),
                  closed_loop=False)
    assert dg.findings == []
    assert "not determined" in dg.base["sigma1"]["status"]
    assert abs(dg.base["sigma1"]["change"]) < 0.1
    assert all(abs(b["change"]) < 2 * b["tolerance"] for b in dg.base.values())
    hidden = {h["effect"]: h for h in dg.could_not_reveal}
    assert {"offset", "mass", "drag", "deadband", "cogging", "resonance"} <= set(hidden)
    assert 0 < hidden["mass"]["smallest"] < 1.0  # kg: a 1 kg payload would be seen
    # the public resonance (75 % of the mass at 22 Hz) would be seen on this record
    assert 0 < hidden["resonance"]["smallest"] < 0.75, hidden["resonance"]
    assert dg.verdict.startswith("Nothing found")


@pytest.mark.parametrize("case", ["resonance", "stribeck_shape"])
def test_diagnosing_the_augmented_model_again(case):
    # a model may hold one resonance, one Stribeck shape and one timing term: diagnosed
    # again, the augmented model made the search add a second and stopped with "holds
    # more than one resonance" (a crash of the natural second pass). Those it holds are
    # kept as given, said so, and nothing more is found
    d = MISMATCH / case
    rec = lugre.read_recording(d / "recording.csv")
    first = diagnose(rec, lugre.load_model(d / "model.json"), closed_loop=False)
    assert [f.effect for f in first.findings] == [case]
    again = diagnose(rec, first.augmented_model(), closed_loop=False)
    assert again.findings == [], again.summary()
    assert any("already holds its" in n for n in again.notes)
    assert case not in {h["effect"] for h in again.could_not_reveal}


@pytest.mark.parametrize("case", ["none", "cogging", "position_friction", "deadband", "drag",
                                  "stribeck_shape", "resonance"])
def test_a_wrong_effect_in_the_model_is_removed(case):
    # the independent plant's records, the model given an effect the axis lacks (8 % of
    # the Coulomb level: a cogging at a seventh of the stroke, or a spring where the
    # record's cogging is): it is removed and what the record holds is named as before
    import numpy as np

    d = MISMATCH / case
    truth = [e["effect"] for e in json.loads((d / "truth.json").read_text())["effects"]]
    rec = lugre.read_recording(d / "recording.csv")
    md = lugre.load_model(d / "model.json").to_dict()
    fc = 0.5 * (md["friction"]["positive"]["fc"] + md["friction"]["negative"]["fc"])
    x = np.asarray(rec.x)
    stroke, mid = float(np.ptp(x)), float(0.5 * (x.max() + x.min()))
    wrong = ({"effect": "spring", "stiffness": 0.08 * fc / (0.5 * stroke), "x0": mid}
             if "cogging" in truth else
             {"effect": "cogging", "amplitude": 0.08 * fc, "pitch": stroke / 7.3, "phase": 1.0})
    md["effects"] = [wrong]
    dg = diagnose(rec, lugre.Model.from_dict(md), closed_loop=False)
    assert [r["effect"] for r in dg.removed] == [wrong["effect"]]
    assert [f.effect for f in dg.findings] == truth
    assert wrong not in dg.augmented.effects


@pytest.mark.parametrize("frequency,load,replaced", [(30.0, 0.75, True), (22.0, 0.5, True),
                                                     (22.0, 0.75, False)])
def test_a_resonance_in_the_model_is_searched_again(frequency, load, replaced):
    # the independent plant's 22 Hz coupling on 75 % of the mass: a model holding one at
    # 30 Hz, or on half the mass, has it replaced by the one the record holds; the
    # right one given is kept
    d = MISMATCH / "resonance"
    md = lugre.load_model(d / "model.json").to_dict()
    md["effects"] = [{"effect": "resonance", "frequency": frequency, "damping_ratio": 0.04,
                      "load_fraction": load}]
    dg = diagnose(lugre.read_recording(d / "recording.csv"), lugre.Model.from_dict(md),
                  closed_loop=False)
    if not replaced:
        assert dg.removed == [] and dg.findings == []
        return
    assert [(r["effect"], r.get("replaced")) for r in dg.removed] == [("resonance", True)]
    (f,) = dg.findings
    assert f.parameters["frequency"] == pytest.approx(22.0, rel=0.1)
    assert f.parameters["load_fraction"] == pytest.approx(0.75, abs=0.1)


def test_a_far_base_is_refitted_before_anything_is_named():
    """The clean public record against its model with the Stribeck hump removed, vs six
    times too large and sigma0 twenty times too small: the base is refitted first (to
    the record's hump, vs and sigma0), nothing is named in its place, and the report
    gives the model as given's held-out error beside the refitted one's."""
    d = MISMATCH / "none"
    m = lugre.load_model(d / "model.json").to_dict()
    for s in ("positive", "negative"):
        m["friction"][s]["fs"] = m["friction"][s]["fc"]
        m["friction"][s]["vs"] *= 6
    m["friction"]["sigma0"] *= 0.05
    dg = diagnose(lugre.read_recording(d / "recording.csv"), m,
                  holdout=lugre.read_recording(d / "holdout.csv"), closed_loop=False)
    assert dg.findings == []
    assert dg.rebased is not None
    moved = {mv["name"] for mv in dg.rebased["moves"]}
    assert {"positive.hump", "negative.hump", "sigma0"} <= moved
    aug = dg.augmented_model()
    for s in ("positive", "negative"):
        assert aug.friction[s]["fs"] - aug.friction[s]["fc"] == pytest.approx(31.5, rel=0.1)
        assert aug.friction[s]["vs"] == pytest.approx(0.01, rel=0.1)
    assert dg.rebased["holdout_given"]["rms_force"] > 20 * dg.fit["holdout_after"]["rms_force"]
    assert dg.verdict.startswith("The base as given is far")
    from lugre.html import diagnosis_page

    assert "Base refitted first" in diagnosis_page(dg.to_dict(), dg.data)
