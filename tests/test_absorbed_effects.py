"""An effect that ``lugre fit`` took into the base it fitted on the record is named when
that record is diagnosed against the fit: the base fitted again beside the effect, and
the search run again from there (``lugre.diagnosis.absorbed``).

Before, the stress seed 15 cases 027 (a dead-band of 62 mA: the fit raised fc and fs
and tripled sigma1) and 028 (a quadratic drag: the fit gave a backward Coulomb level of
0 and a Stribeck speed eight times the axis's) ended "unexplained"; against the near-true
model both were named. The record of the independent plant (benches/calibration_cases.py)
was drawn for this test: its dead-band went unnamed the same way. Since session 18
``lugre fit`` fits a drag beside the base (``tests/test_fit_drag.py``), and the drag of
028 is named without the stage.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from lugre.diagnosis import diagnose, fit_model
from lugre.diagnosis.absorbed import ABSORBING, absorbed_effect
from lugre.diagnosis.synth import case
from lugre.io import Recording
from lugre.vocabulary import kind

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benches"))
import calibration_cases as C

#: (setup of the stress case, the effect in the record)
STRESS = {
    "deadband": ({"seed": 35054, "axis_seed": 6189, "kind": "p2p", "duration": 10.0,
                  "rate_hz": 5000.0, "current_noise": 0.0036122724146760363,
                  "quantum": 1e-07, "base_error": 0.018413692322127875},
                 {"effect": "deadband", "current": 0.06198418425698665}),
    "drag": ({"seed": 35056, "axis_seed": None, "kind": "p2p", "duration": 6.0,
              "rate_hz": 2000.0, "current_noise": 0.029151730040939464, "quantum": 5e-06,
              "base_error": 0.01076369655601923},
             {"effect": "drag", "coefficient": 176.40902511981074}),
}


def _chain(rec: Recording, force_constant: float, controller: dict | None,
           hold: Recording) -> object:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted, _ = fit_model(rec, force_constant=force_constant)
        if controller:
            fitted = fitted.replace(controller=controller)
        return diagnose(rec, fitted, holdout=hold)


def _stress_chain(effects: list[dict], **setup: object) -> object:
    """A stress case (:func:`lugre.diagnosis.synth.case`) through the chain."""
    rec, hold, believed, _ = case(effects, **setup)
    return _chain(rec, believed.force_constant, believed.controller, hold)


def _chain_mass_given(effects: list[dict], **setup: object) -> object:
    """A stress case through the chain with the mass given (issue 24's protocol)."""
    rec, hold, believed, _ = case(effects, **setup)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted, _ = fit_model(rec, force_constant=believed.force_constant,
                              mass=believed.mass)
        return diagnose(rec, fitted.replace(controller=believed.controller), holdout=hold)


def _held_out(dg: object) -> tuple[float, float]:
    return dg.fit["holdout_before"]["rms_force"], dg.fit["holdout_after"]["rms_force"]


def _named(dg: object, effect: dict, tol: float, rebased: bool = True) -> None:
    name, key = effect["effect"], ABSORBING[effect["effect"]]
    got = {f.effect: f.parameters for f in dg.findings}
    assert list(got) == [name], dg.summary()
    assert got[name][key] == pytest.approx(effect[key], rel=tol), got
    if rebased:
        assert dg.rebased and name in dg.rebased["text"], dg.rebased


@pytest.mark.parametrize("name", sorted(STRESS))
def test_an_effect_the_fit_took_in_is_named_against_that_fit(name):
    setup, effect = STRESS[name]
    dg = _stress_chain([effect], **setup)
    # (since session 18 the fit sets a drag aside itself: the diagnosis names it from
    # a sound base, without the stage)
    _named(dg, effect, 0.05, rebased=name != "drag")
    before, after = _held_out(dg)
    assert after < 0.5 * before, dg.fit


#: (setup of the stress case, the effect, the relative tolerance of its parameter):
#: stress seed 16, cases 038 (a current lag, 30 s) and 030 (a coupling, cut to 10 s),
#: both unnamed against their fits before, and a coupling whose first trial lay far off
SIZED = {
    "current_lag": ({"seed": 36076, "axis_seed": None, "kind": "p2p", "duration": 30.0,
                     "rate_hz": 2000.0, "current_noise": 0.012823425748502051,
                     "quantum": 1e-07, "base_error": 0.013917539087418784},
                    {"effect": "current_lag", "bandwidth": 118.76543260017726}, 0.1),
    "resonance": ({"seed": 36060, "axis_seed": None, "kind": "p2p", "duration": 10.0,
                   "rate_hz": 5000.0, "current_noise": 0.013142035907952262,
                   "quantum": 1e-06, "base_error": 0.017267598909539893},
                  {"effect": "resonance", "frequency": 19.125373748485444,
                   "damping_ratio": 0.03765913612181255,
                   "load_fraction": 0.7749611735599393}, 0.25),
    # stress seed 19, case 030: the first trial against the fit's bent base sat at 64 Hz
    # with the wrong damping and load share; the stage's neighbourhood of it never
    # reached the coupling, which went unnamed ("unexplained", 0.80 N held out)
    "resonance_far_from_its_trial": (
        {"seed": 39060, "axis_seed": None, "kind": "p2p", "duration": 30.0,
         "rate_hz": 2000.0, "current_noise": 0.011820679861515524, "quantum": 1e-07,
         "base_error": 0.019049314729677667},
        {"effect": "resonance", "frequency": 29.318664249709293,
         "damping_ratio": 0.06522827794883668, "load_fraction": 0.5462972451479696}, 0.05),
}


@pytest.mark.parametrize("name", sorted(SIZED))
def test_a_timing_or_coupling_the_fit_took_in_is_named_against_that_fit(name):
    setup, effect, tol = SIZED[name]
    dg = _stress_chain([effect], **setup)
    key = ABSORBING[effect["effect"]]
    got = {kind(f.effect): f.parameters for f in dg.findings}
    assert list(got) == [kind(effect["effect"])], dg.summary()
    assert got[kind(effect["effect"])][key] == pytest.approx(effect[key], rel=tol), got
    assert dg.rebased and effect["effect"] in dg.rebased["text"], dg.rebased
    before, after = _held_out(dg)
    assert after < 0.5 * before, dg.fit


def test_a_coupling_beside_a_spring_is_sized_with_the_spring_held():
    """Stress seed 21, case 045: a fitted base that took in a coupling and a spring. The
    first search's spring left most of the rest unexplained (not named), and the
    coupling sized alone left 1.42 N: nothing was named (held out 2.24 -> 1.84 N). Held
    beside the spring the rest resembled, the coupling is sized at its frequency and
    the second search names both. A small load friction beside them (1.6 % on the
    confined route, named until session 24) stood in for the base: refitted without
    it, the base fits the record as well, and the search from there names the two."""
    truth = [{"effect": "resonance", "frequency": 18.032018277729065,
              "damping_ratio": 0.03815249875876202, "load_fraction": 0.6922564295725715},
             {"effect": "spring", "stiffness": 22.801514036427417,
              "x0": -0.0035238481903315353}]
    dg = _stress_chain(truth, seed=41090, axis_seed=None, kind="p2p",
                       duration=20.0, rate_hz=2000.0,
                       current_noise=0.038699352962639454, quantum=1e-07,
                       base_error=0.015758705404010483)
    got = {f.effect: f.parameters for f in dg.findings}
    assert set(got) == {"resonance", "spring"}, dg.summary()
    assert got["resonance"]["frequency"] == pytest.approx(18.03, rel=0.05)
    assert got["spring"]["stiffness"] == pytest.approx(22.80, rel=0.05)
    assert dg.rebased and "other than load_friction" in dg.rebased["text"], dg.rebased
    before, after = _held_out(dg)
    assert after < 0.2 * before, dg.fit


def test_a_coupling_whose_trial_lost_against_the_bent_base_is_sized():
    """Stress seed 23, case 042: a 29.3 Hz coupling on a 6 s point-to-point record. The
    fit gave sigma1 = 0 and a softer sigma0, and against that base the resonance trial
    lost at every frequency: no start for the absorbed stage, "unexplained" (0.38 N
    held out). Where the search leaves the record unexplained, the resonance is sized
    from its trial's frequency all the same."""
    truth = {"effect": "resonance", "frequency": 29.280573104767917,
             "damping_ratio": 0.06716422355279661, "load_fraction": 0.6048048514981181}
    dg = _stress_chain([truth], seed=43084, axis_seed=8756, kind="p2p",
                       duration=6.0, rate_hz=1000.0,
                       current_noise=0.0040866957595806575, quantum=1e-07,
                       base_error=0.006073485933775821)
    got = {f.effect: f.parameters for f in dg.findings}
    assert list(got) == ["resonance"], dg.summary()
    assert got["resonance"]["frequency"] == pytest.approx(29.28, rel=0.1)
    assert dg.rebased and "resonance" in dg.rebased["text"], dg.rebased
    before, after = _held_out(dg)
    assert after < 0.3 * before, dg.fit


def test_a_delay_in_a_base_fitted_near_its_floor_is_named():
    """Stress seed 23, case 025: a 1.31 ms delay in a record the fit took to 1.3 times
    its noise floor. Beside a lag the base's residual fell from 0.131 to 0.107 N: 86 %
    of its excess over the floor, but not the fifth of its rms the stage asked, and
    nothing was named (0.16 N held out where the true model with the delay reaches
    0.11 N). The stage also takes half the excess over the floor."""
    truth = {"effect": "delay", "seconds": 0.0013134481143544422}
    dg = _stress_chain([truth], seed=43050, axis_seed=4545, kind="p2p",
                       duration=10.0, rate_hz=2000.0,
                       current_noise=0.005275814150924591, quantum=1e-06,
                       base_error=0.007570479097147127)
    got = {kind(f.effect): f.parameters for f in dg.findings}
    assert list(got) == [kind("delay")], dg.summary()
    assert got[kind("delay")]["seconds"] == pytest.approx(truth["seconds"], rel=0.15)
    assert dg.rebased, dg.summary()
    before, after = _held_out(dg)
    assert after < 0.7 * before, dg.fit


def test_an_absorbed_delay_is_named_on_its_own_test_beside_a_bump():
    """Stress seed 22, case 045: a 1.12 ms delay beside a 16 % friction bump, 20 s of
    sines at 5 kHz. The lag sized beside the refitted base passed its own test (10 of
    10 stretches, p = 0.0006), but the second search's quicker refit lost one block
    (9 of 10, p = 0.13): only the bump was named (0.12 N held out, 0.033 N with the
    true model). An attested kind is named on most blocks, and its finding says so."""
    bump = [1.0017729729053477, 1.0036379041947774, 1.0070122438683096,
            1.0126975332861623, 1.0215992317118894, 1.0345154739980287,
            1.0518138633223222, 1.0730692590272213, 1.0968010406908741,
            1.120470841592477, 1.140844683131329, 1.154687622574503,
            1.1595979348129528]
    truth = [{"effect": "delay", "seconds": 0.0011241871500546764},
             {"effect": "position_friction",
              "positions": list(-0.10433235354639793 + 0.005625 * np.arange(25)),
              "scale": bump + bump[-2::-1]}]
    dg = _stress_chain(truth, seed=42090, axis_seed=None, kind="sines",
                       duration=20.0, rate_hz=5000.0,
                       current_noise=0.004586628031802712, quantum=1e-07,
                       base_error=0.018972492282081626)
    got = {kind(f.effect): f for f in dg.findings}
    assert set(got) == {kind("delay"), "position_friction"}, dg.summary()
    assert got[kind("delay")].parameters["seconds"] == pytest.approx(1.124e-3, rel=0.15)
    assert "named on its own test" in got[kind("delay")].evidence
    before, after = _held_out(dg)
    assert after < 0.05 * before, dg.fit


def test_a_deadband_sized_beside_a_stribeck_shape_starts_a_sound_search():
    """Stress seed 22, case 047: a 76 mA dead-band beside a Stribeck exponent of 0.9.
    The dead-band was sized beside the exponent the rest resembled (0.25 -> 0.096 N),
    but the second search started from that base without the exponent, 2.7 N off, and
    named nothing. It now starts from the base polished beside the dead-band alone."""
    truth = [{"effect": "deadband", "current": 0.07616372799468052},
             {"effect": "stribeck_shape", "exponent": 0.9}]
    dg = _stress_chain(truth, seed=42094, axis_seed=None, kind="sines",
                       duration=30.0, rate_hz=2000.0,
                       current_noise=0.016411177146353526, quantum=5e-06,
                       base_error=0.005241671559467986)
    got = {f.effect: f.parameters for f in dg.findings}
    assert set(got) == {"deadband", "stribeck_shape"}, dg.summary()
    assert got["deadband"]["current"] == pytest.approx(0.0762, rel=0.3)
    assert dg.rebased and "beside it and stribeck_shape" in dg.rebased["text"]
    before, after = _held_out(dg)
    assert after < 0.7 * before, dg.fit


def test_a_coupling_is_sized_beside_what_the_rest_resembled_when_alone_fails():
    """Stress seed 24, case 054: a Stribeck exponent of 3.2, a warm-up drift and a
    29.9 Hz coupling on 20 s of sines. The rest resembled a drift and the exponent; the
    drift sized alone passed its test but the search from its base named nothing, and
    the case ended "unexplained" (held out 0.49 N). Beside the two, the coupling is
    sized (0.26 -> 0.08 N) and the second search names all three."""
    truth = [{"effect": "stribeck_shape", "exponent": 3.2},
             {"effect": "drift", "gain": 0.0611695020327063,
              "time_constant": 5.321246447606497},
             {"effect": "resonance", "frequency": 29.88797572186502,
              "damping_ratio": 0.07964110527421099, "load_fraction": 0.7263904713806387}]
    dg = _stress_chain(truth, seed=44108, axis_seed=None, kind="sines",
                       duration=20.0, rate_hz=5000.0,
                       current_noise=0.0045235767750005556, quantum=1e-07,
                       base_error=0.018576034052507632)
    got = {f.effect: f.parameters for f in dg.findings}
    assert set(got) == {"stribeck_shape", "drift", "resonance"}, dg.summary()
    assert got["resonance"]["frequency"] == pytest.approx(29.89, rel=0.15)
    assert got["drift"]["gain"] == pytest.approx(0.0612, rel=0.3)
    assert dg.rebased and "resonance" in dg.rebased["text"], dg.rebased
    before, after = _held_out(dg)
    assert after < 0.6 * before, dg.fit


def test_a_drift_sized_beside_a_spring_is_searched_from_the_base_beside_both():
    """Stress seed 25, case 046: a warm-up drift beside an 18.6 N/m spring, 30 s of
    sines. The drift is sized beside the spring the rest resembled (0.66 -> 0.08 N).
    From the base polished again beside the drift alone, the base bent to the spring
    once more, and the search named a lag and a load friction beside the two (0.17 N
    held out); from the base fitted beside both it names the two alone. Both are
    searched; the one that leaves less is kept."""
    truth = [{"effect": "drift", "gain": 0.10952103684861492,
              "time_constant": 3.9545214138592537},
             {"effect": "spring", "stiffness": 18.61475389102747,
              "x0": 0.018607364231180062}]
    dg = _stress_chain(truth, seed=45092, axis_seed=None, kind="sines",
                       duration=30.0, rate_hz=2000.0,
                       current_noise=0.011268035451713612, quantum=5e-06,
                       base_error=0.011389292740645074)
    got = {f.effect: f.parameters for f in dg.findings}
    assert set(got) == {"drift", "spring"}, dg.summary()
    assert got["drift"]["gain"] == pytest.approx(0.1095, rel=0.3)
    assert got["spring"]["stiffness"] == pytest.approx(18.61, rel=0.1)
    before, after = _held_out(dg)
    assert after < 0.15 * before, dg.fit


def test_a_delay_beside_a_coupling_that_took_its_phase_is_named():
    """Stress seed 26, case 049: a 1.18 ms delay beside a 19.2 Hz coupling (damping
    0.067), 20 s of sines at 5 kHz, fitted with the mass given. Against the fit the
    coupling was found first and profiled alone: it read the delay's phase as damping
    (0.18), and the delay then added too little beside it to be named (a gain of 13
    that passed the block test, held back by the noise floor). Only the coupling was
    named (0.35 N held out; the near-true model with both 0.17 N). A term held back by
    the noise floor alone is tried again beside the coupling profiled anew with it."""
    truth = [{"effect": "delay", "seconds": 0.0011821118081391507},
             {"effect": "resonance", "frequency": 19.19632728860017,
              "damping_ratio": 0.06702574028857947, "load_fraction": 0.7047011340470077}]
    dg = _chain_mass_given(truth, seed=46098, axis_seed=1484, kind="sines",
                           duration=20.0, rate_hz=5000.0,
                           current_noise=0.012903275137765922, quantum=5e-06,
                           base_error=0.007447486581329662)
    got = {kind(f.effect): f.parameters for f in dg.findings}
    assert set(got) == {kind("delay"), "resonance"}, dg.summary()
    assert got["resonance"]["frequency"] == pytest.approx(19.2, rel=0.05)
    assert any("profiled again with it" in t["why"] for t in dg.trials), dg.summary()
    before, after = _held_out(dg)
    assert after < 0.35 * before, dg.fit


def test_a_coupling_the_fit_took_into_a_floor_of_mismatch_is_named():
    """Stress seed 29, case 042: a lightly damped 20.7 Hz coupling, 30 s of sines at
    1 kHz, fitted with the mass given. The fitted base took it in up to its noise floor
    (0.40 N, 5.6 times what the readings' noise explains): beside the coupling the rms
    falls from 0.40 to 0.17 N and the floor to 0.14 N, but the rest above each floor
    rose, and the coupling was refused as one that merely filters the readings' noise.
    Nothing was named (0.60 N held out; the near-true model names the coupling). A
    floor is read at most three times the readings' noise in that check."""
    truth = [{"effect": "resonance", "frequency": 20.70609579300278,
              "damping_ratio": 0.030970680466576687, "load_fraction": 0.5165236452420976}]
    dg = _chain_mass_given(truth, seed=49084, axis_seed=4614, kind="sines", duration=30.0,
                           rate_hz=1000.0, current_noise=0.005615403990188426,
                           quantum=1e-07, base_error=0.00823077235240473)
    got = {f.effect: f.parameters for f in dg.findings}
    assert list(got) == ["resonance"], dg.summary()
    assert got["resonance"]["frequency"] == pytest.approx(20.7, rel=0.1)
    before, after = _held_out(dg)
    assert after < 0.3 * before, dg.fit


def test_a_deadband_that_stands_in_for_the_fitted_base_is_not_named():
    """Stress seed 27, case 035: a warm-up drift on a 10 s feed record, fitted with the
    mass given. The fit bent its humps to the drift; the search named the drift and,
    from the bent base, a 7 mA dead-band beside it (the near-true model names the
    drift alone). Refitted with the drift in and the dead-band left out, the base fits
    the record about as well; the search from there names the drift alone and leaves no
    more on the held-out record."""
    truth = [{"effect": "drift", "gain": 0.11431690023846773,
              "time_constant": 3.207970161373143}]
    dg = _chain_mass_given(truth, seed=47070, axis_seed=8175, kind="feeds",
                           duration=10.0, rate_hz=2000.0,
                           current_noise=0.01779884188565775, quantum=5e-06,
                           base_error=0.006363450768474049)
    assert [f.effect for f in dg.findings] == ["drift"], dg.summary()
    assert any("stood in for the base" in n for n in dg.notes), dg.notes
    before, after = _held_out(dg)
    assert after < 0.5 * before, dg.fit


def test_a_coupling_the_first_pass_dropped_as_noise_is_not_taken_for_absorbed():
    """Stress seed 28, case 003: a clean 30 s record of sines at 5 kHz, fitted with the
    mass given. The first pass found a damped 76 Hz coupling and dropped it: noise like
    the record's added raised its gain by more than half (SIMEX). The stage for effects
    a fitted base absorbed then sized the coupling beside a refitted base and named it
    (64 Hz). An effect the first pass dropped as the readings' noise was not absorbed."""
    dg = _chain_mass_given([], seed=48006, axis_seed=7867, kind="sines",
                           duration=30.0, rate_hz=5000.0,
                           current_noise=0.004132995666346363, quantum=1e-07,
                           base_error=0.014202946071288285)
    assert dg.findings == [], dg.summary()
    assert any("SIMEX" in t["why"] and t["effect"] == "resonance" for t in dg.trials)


def test_a_coupling_that_only_filters_the_current_noise_is_not_absorbed():
    """Stress seed 24, case 040: a drag, and a fit at 1.1 times its noise floor. Sized
    beside the fitted base, a 29.6 Hz coupling took the residual from 0.289 to 0.193 N
    (p = 0.005 over the blocks): the coupling low-passes the recorded current's noise
    on its way to the load. The rest over each residual's own floor barely moved (0.105
    -> 0.097 N), and the stage no longer takes it."""
    rec, _, believed, _ = case([{"effect": "drag", "coefficient": 282.8839057247163}],
                               seed=44080, axis_seed=6846, kind="p2p", duration=6.0,
                               rate_hz=5000.0, current_noise=0.021571025533386756,
                               quantum=1e-06, base_error=0.008375846299466234)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted, _ = fit_model(rec, force_constant=believed.force_constant)
    coupling = {"effect": "resonance", "frequency": 29.7, "damping_ratio": 0.1,
                "load_fraction": 0.85}
    far = absorbed_effect(rec, fitted, fitted, [coupling], cutoff_hz=None, backend="core",
                          free_mass=True, blocks=10, alpha=1e-3, min_gain=10.0)
    assert far is None, {k: far[k] for k in ("effect", "size", "rms_given", "rms_refit")}


def _plant(seed: int, share: float | None) -> tuple[Recording, Recording, dict, dict | None]:
    c = C.draw_case(seed, max_duration=8.0, family="linear")
    axis, fr = c["truth"]["axis"], c["truth"]["friction"]
    fc = 0.5 * (fr["positive"]["fc"] + fr["negative"]["fc"])
    eff = None if share is None else {"effect": "deadband",
                                      "current": share * fc / axis["force_constant"]}
    (r, h), = C.records([(c, [eff] if eff else [])])
    return Recording(**r), Recording(**h), c, eff


def test_a_deadband_in_an_independent_plants_record_is_named_against_its_fit():
    rec, hold, c, eff = _plant(101, 0.1)
    dg = _chain(rec, c["truth"]["axis"]["force_constant"], c["believed"].get("controller"),
                hold)
    _named(dg, eff, 0.05)


def test_a_clean_independent_record_against_its_fit_names_nothing():
    rec, hold, c, _ = _plant(104, None)
    dg = _chain(rec, c["truth"]["axis"]["force_constant"], c["believed"].get("controller"),
                hold)
    assert not dg.findings and not dg.rebased, dg.summary()


def test_a_clean_rotary_record_against_its_fit_gets_no_lag_from_the_grids_edge():
    """A clean 500 Hz record of a rotary axis of the independent plant (seed 37003,
    coloured noise): the stage sized a "current lag" at its grid's lowest bandwidth,
    10 Hz, and the second search named a 14 ms delay that did worse on the held-out
    record (4.35 against 3.68 mN m). A size the grid does not bracket is refused, and
    with a held-out record a second pass is kept only when it does as well there."""
    c = C.draw_case(37003, max_duration=15.0)
    assert c["truth"]["axis"].get("kind") == "rotary"
    (r, h), = C.records([(c, [])])
    rec, hold = Recording(**r), Recording(**h)
    rec.meta["axis_kind"] = hold.meta["axis_kind"] = "rotary"
    dg = _chain(rec, c["truth"]["axis"]["torque_constant"], c["believed"].get("controller"),
                hold)
    assert not dg.findings and not dg.rebased, dg.summary()


def test_a_drag_beside_a_deadband_survives_the_joint_refit():
    """Stress seed 18, case 047 (unseen when drawn): the fit set the drag aside, the
    search took it and a current limit, and the current limit's exact form left the
    joint refit 1.4e8 noise units worse than without it; the backward check then
    dropped both, and the dead-band was never reached (``joint._without_weak`` now
    drops one term at a time)."""
    setup = {"seed": 38094, "axis_seed": 8038, "kind": "p2p", "duration": 10.0,
             "rate_hz": 5000.0, "current_noise": 0.01889120651249719, "quantum": 1e-07,
             "base_error": 0.019896702923822288}
    effects = [{"effect": "drag", "coefficient": 54.00109976350709},
               {"effect": "deadband", "current": 0.02833876845406429}]
    dg = _stress_chain(effects, **setup)
    got = {f.effect: f.parameters for f in dg.findings}
    assert sorted(got) == ["deadband", "drag"], dg.summary()
    assert got["drag"]["coefficient"] == pytest.approx(54.0, rel=0.05)
    assert got["deadband"]["current"] == pytest.approx(0.0283, rel=0.05)
    assert dg.fit["holdout_after"]["rms_force"] < 0.2 * dg.fit["holdout_before"]["rms_force"]


def test_a_drift_gain_is_read_with_the_levels_rescaled_beside_it():
    """A drift's gain at its time constant, read off the base polished without it: with
    the levels' scale beside it the warm-up's gain comes out; against the polished base
    alone the trend reads a fraction of itself (the levels took its mean)."""
    from lugre.diagnosis import residual as R
    from lugre.diagnosis.absorbed import _polisher, drift_gain

    eff = {"effect": "drift", "gain": 0.1, "time_constant": 3.0}
    rec, _hold, believed, _ = case([eff], seed=41106, axis_seed=None, kind="sines",
                                   duration=12.0, rate_hz=1000.0, current_noise=0.01)
    sig = R.prepare(rec, believed, cutoff_hz=None, backend=None)
    rms0, base, r0 = _polisher(sig, True)(believed, 30)
    g = drift_gain(sig, base, r0, eff["time_constant"])
    assert g == pytest.approx(eff["gain"], rel=0.25), g  # (a secant: the polish goes on)
    rms1 = _polisher(sig, True)(believed.replace(effects=[{**eff, "gain": g}]), 30)[0]
    assert rms1 < 0.5 * rms0, (rms0, rms1)
