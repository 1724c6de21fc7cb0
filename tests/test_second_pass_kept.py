"""A search run again from a refitted base does not lose a finding of the first pass
and then do worse without it (``lugre.diagnosis.core._kept``).

Stress seed 20, case 035: a warm-up drift (friction 9.7 % higher at the start, time
constant 4.3 s) on a 22.8 kg axis, 30 s of constant-speed feeds at 5 kHz, diagnosed
against the model ``lugre fit`` made of the record before its band was read until it
settled (b201979): 22.1 kg, levels bent by the drift. The first pass names the drift;
the base, refitted with it in, moves its humps, and the search from there tested the
drift just short of naming it and left 0.105 N where the first pass had left 0.099 N
(held out: 0.448 N against 0.231 N). The diagnosis ended "unexplained". (The fit of
today puts this record's base where the record does, and the first pass stands alone.)
"""

from __future__ import annotations

import warnings

import pytest
from lugre import Model
from lugre.diagnosis import diagnose, evaluate
from lugre.diagnosis.core import _kept
from lugre.diagnosis.synth import case

SETUP = {"seed": 40070, "axis_seed": 5569, "kind": "feeds", "duration": 30.0,
         "rate_hz": 5000.0, "current_noise": 0.009373192784997016, "quantum": 5e-06,
         "base_error": 0.0198853711956876}
DRIFT = {"effect": "drift", "gain": 0.09692911163176213, "time_constant": 4.266804230949121}


#: The model the fit made of the record before b201979 (its base and mass as fitted; the
#: file's identification reduced to the names it fitted).
OLD_FIT = {
    "axis": {"mass": 22.092918587433886, "force_constant": 27.137711383325264},
    "friction": {"model": "lugre", "sigma0": 58315.20367506519, "sigma1": 99.38833530385436,
                 "positive": {"fc": 12.14057665298252, "fs": 24.0715853920287,
                              "sigma2": 231.2855264058356, "vs": 0.008541653317855629},
                 "negative": {"fc": 13.298582695073529, "fs": 23.185412074915845,
                              "sigma2": 210.6742349775354, "vs": 0.01152209178611245}},
    "identification": {"parameters": {n: {} for n in (
        "mass", "positive.fc", "positive.hump", "positive.sigma2", "positive.vs",
        "negative.fc", "negative.hump", "negative.sigma2", "negative.vs", "sigma0",
        "sigma1")}},
}


def test_a_drift_named_from_a_fitted_base_is_not_lost_to_its_refit():
    rec, hold, believed, _ = case([DRIFT], **SETUP)
    fitted = Model(OLD_FIT).replace(controller=believed.controller)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        dg = diagnose(rec, fitted)
    got = {f.effect: f.parameters for f in dg.findings}
    assert list(got) == ["drift"], dg.summary()
    assert got["drift"]["gain"] == pytest.approx(DRIFT["gain"], rel=0.5), got
    assert any("did not name drift" in n and "the first search is reported" in n
               for n in dg.notes), dg.notes
    # on the held-out record (the drift again from the start), against the fitted model
    before, after = (evaluate(hold, m)["rms_force"] for m in (fitted, dg.augmented))
    assert after < 0.3 * before, (before, after)


class _Pass:
    def __init__(self, effects: list[str], rest: float, held_out: float = 0.0) -> None:
        self.findings = [type("F", (), {"effect": e})() for e in effects]
        self.fit = {"after": {"rms_force": rest},
                    "holdout_after": {"rms_force": held_out} if held_out else None}


def test_the_second_pass_is_kept_unless_it_loses_a_finding_and_does_worse():
    first = _Pass(["drift"], 0.099, 0.23)
    keeps_all = _Pass(["drift", "cogging"], 0.2, 0.5)
    assert _kept(keeps_all, first) is keeps_all
    lost_worse = _Pass([], 0.105, 0.45)
    first.notes = []
    assert _kept(lost_worse, first) is first
    assert "0.45 N rms against 0.23 N" in first.notes[0], first.notes
    lost_better = _Pass([], 0.08, 0.2)
    assert _kept(lost_better, first) is lost_better
    # without a held-out record, the record's own rest decides
    alone = _Pass(["drift"], 0.099)
    alone.notes = []
    assert _kept(_Pass([], 0.105), alone).findings[0].effect == "drift"
    assert "on this record" in alone.notes[0], alone.notes
    assert _kept(_Pass([], 0.09), _Pass(["drift"], 0.099)).findings == []
