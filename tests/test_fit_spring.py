"""``lugre fit`` on a linear axis with a spring (a cable carrier, a flexure, a
counterweight's spring): the spring's force grows with the position, follows a sine's
acceleration against it, and a fit of the mass alone took it up. Before, a record of a
stiff spring was refused ("the inverse-dynamics fit gives a mass of -18.8 kg") or gave a
mass a quarter off (seed 200 of the independent plant below: 99.5 kg for 139.7, the
residual 24 times the noise floor).

Now the linear start tries the position beside the base when the mass is fitted, keeps
it when it takes a tenth off the robust scale, and the fit places the spring's rest
position by the standstills and polishes its stiffness (``basefit._spring_rest``).
The spring is then set aside for ``lugre diagnose`` to name, as a drag or a joint's
weight is (``lugre fit --effects spring`` keeps it in the model).
The records come from the independent plant of ``benches/calibration_cases.py``.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import pytest
from lugre import diagnose
from lugre.diagnosis import fit_model
from lugre.io import Recording

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benches"))
import calibration_cases as C
from set_aside_check import check_fit_command


def _record(seed: int, spring: bool) -> tuple[dict, dict, dict | None]:
    c = C.draw_case(seed, max_duration=8.0, family="linear")
    fr = c["truth"]["friction"]
    fc = 0.5 * (fr["positive"]["fc"] + fr["negative"]["fc"])
    eff = ({"effect": "spring", "stiffness": 2.0 * fc / c["setup"]["stroke"], "x0": 0.01}
           if spring else None)
    (r, _), = C.records([(c, [eff] if eff else [])])
    return r, c["truth"], eff


def _fit(seed: int, spring: bool) -> tuple[object, object, dict, dict | None]:
    r, truth, eff = _record(seed, spring)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model, fit = fit_model(Recording(**r), force_constant=truth["axis"]["force_constant"])
    return model, fit, truth, eff


@pytest.mark.parametrize("seed", [201, 204])
def test_a_springs_record_is_fitted_beside_the_spring_with_the_right_mass(seed):
    model, fit, truth, eff = _fit(seed, spring=True)
    springs = [e for e in fit.set_aside if e["effect"] == "spring"]
    assert len(springs) == 1 and not model.effects, (fit.set_aside, model.effects)
    s = springs[0]
    assert s["stiffness"] == pytest.approx(eff["stiffness"], rel=0.03)
    assert s["x0"] == pytest.approx(eff["x0"], abs=2e-3)
    assert model.mass == pytest.approx(truth["axis"]["mass"], rel=0.02)
    for d in ("positive", "negative"):
        assert model.friction[d]["fc"] == pytest.approx(truth["friction"][d]["fc"], rel=0.05)
    assert fit.floor_ratio < 1.5


@pytest.mark.parametrize("seed", [301, 305])
def test_a_clean_record_is_fitted_without_a_spring(seed):
    model, fit, truth, _ = _fit(seed, spring=False)
    assert not model.effects and not fit.set_aside
    assert model.mass == pytest.approx(truth["axis"]["mass"], rel=0.02)


def test_the_diagnosis_names_the_spring_the_fit_set_aside():
    r, truth, eff = _record(204, spring=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model, _ = fit_model(Recording(**r), force_constant=truth["axis"]["force_constant"])
        dg = diagnose(Recording(**r), model)
    found = {f.effect: f for f in dg.findings}
    assert set(found) == {"spring"}, dg.verdict
    assert found["spring"].parameters["stiffness"] == pytest.approx(eff["stiffness"], rel=0.05)


def test_the_fit_command_says_the_spring_is_set_aside(tmp_path, capsys):
    c = C.draw_case(204, max_duration=8.0, family="linear")
    fr = c["truth"]["friction"]
    eff = {"effect": "spring", "x0": 0.01,
           "stiffness": (fr["positive"]["fc"] + fr["negative"]["fc"]) / c["setup"]["stroke"]}
    (r, _), = C.records([(c, [eff])])
    check_fit_command(tmp_path, capsys, r, c["truth"]["axis"]["force_constant"], "spring",
                      "growing with the position", "N/m")
