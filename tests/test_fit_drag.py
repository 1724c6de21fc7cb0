"""``lugre fit`` on a record with a quadratic drag (a seal, a wiper, air or oil shear at
speed): the force grows faster than the speed, and the base's straight line through it
meets zero below the Coulomb level. Before, the fit bent its levels to follow it (on
records of the independent plant below, levels 20-75 % low or negative, the fit 3-10
times the noise floor; on a stress record a positive level of 4.5e-8 N beside a
"Stribeck hump" of 470 N), and the diagnosis, starting from that base, named nothing.

Now the linear start tries the drag's column beside the base and keeps it when it
brings a level back from below zero; a fit left far from the floor is tried again with
it (``basefit.DRAG_FAR``). The drag is set aside for ``lugre diagnose`` to name, as a
joint's weight is. The records come from the independent plant of
``benches/calibration_cases.py``.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from lugre import diagnose
from lugre.diagnosis import fit_model
from lugre.io import Recording

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benches"))
import calibration_cases as C
from set_aside_check import check_fit_command


def _record(seed: int, drag: bool) -> tuple[dict, dict, float]:
    """A linear plant record, with a drag of 1.5 times the mean Coulomb level at the
    record's top speed."""
    c = C.draw_case(seed, max_duration=8.0, family="linear")
    fr = c["truth"]["friction"]
    (plain, _), = C.records([(c, [])])
    vmax = float(np.max(np.abs(np.diff(plain["x"]) / np.diff(plain["t"]))))
    coef = 0.75 * (fr["positive"]["fc"] + fr["negative"]["fc"]) / vmax ** 2
    if not drag:
        return plain, c["truth"], coef
    (r, _), = C.records([(c, [{"effect": "drag", "coefficient": coef}])])
    return r, c["truth"], coef


def _fit(r: dict, truth: dict) -> tuple[object, object]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit_model(Recording(**r), force_constant=truth["axis"]["force_constant"])


@pytest.mark.parametrize("seed", [202, 201])  # (a level below zero; far from the floor)
def test_a_drags_record_is_fitted_beside_the_drag(seed):
    r, truth, coef = _record(seed, drag=True)
    model, fit = _fit(r, truth)
    drags = [e for e in fit.set_aside if e["effect"] == "drag"]
    assert len(drags) == 1 and not model.effects, (fit.set_aside, model.effects)
    assert drags[0]["coefficient"] == pytest.approx(coef, rel=0.02)
    assert model.mass == pytest.approx(truth["axis"]["mass"], rel=0.03)
    for d in ("positive", "negative"):
        assert model.friction[d]["fc"] == pytest.approx(truth["friction"][d]["fc"], rel=0.02)
    assert fit.floor_ratio < 1.5


@pytest.mark.parametrize("seed", [202, 301])
def test_a_clean_record_is_fitted_without_a_drag(seed):
    r, truth, _ = _record(seed, drag=False)
    model, fit = _fit(r, truth)
    assert not fit.set_aside and not model.effects


def test_the_diagnosis_names_the_drag_the_fit_set_aside():
    r, truth, coef = _record(201, drag=True)
    model, _ = _fit(r, truth)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        dg = diagnose(Recording(**r), model)
    found = {f.effect: f for f in dg.findings}
    assert "drag" in found, dg.verdict
    assert found["drag"].parameters["coefficient"] == pytest.approx(coef, rel=0.05)


def test_the_fit_command_says_the_drag_is_set_aside(tmp_path, capsys):
    r, truth, _ = _record(202, drag=True)
    check_fit_command(tmp_path, capsys, r, truth["axis"]["force_constant"], "drag",
                      "square of the speed", "N s²/m²")
