"""A search run again from a refitted base does not lose a finding of the first pass
and then do worse without it (``lugre.diagnosis.core._kept``).

Stress seed 20, case 035: a warm-up drift (friction 9.7 % higher at the start, time
constant 4.3 s) on a 22 kg axis, 30 s of constant-speed feeds at 5 kHz. Diagnosed
against what ``lugre fit`` makes of the record, the first pass names the drift; the
base, refitted with it in, moves its humps, and the search from there tested the drift
just short of naming it and left 0.105 N where the first pass had left 0.099 N (held
out: 0.448 N against 0.231 N). The diagnosis ended "unexplained".
"""

from __future__ import annotations

import warnings

import pytest
from lugre.diagnosis import diagnose, evaluate, fit_model
from lugre.diagnosis.core import _kept
from lugre.diagnosis.synth import case

SETUP = {"seed": 40070, "axis_seed": 5569, "kind": "feeds", "duration": 30.0,
         "rate_hz": 5000.0, "current_noise": 0.009373192784997016, "quantum": 5e-06,
         "base_error": 0.0198853711956876}
DRIFT = {"effect": "drift", "gain": 0.09692911163176213, "time_constant": 4.266804230949121}


def test_a_drift_named_from_a_fitted_base_is_not_lost_to_its_refit():
    rec, hold, believed, _ = case([DRIFT], **SETUP)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fitted, _ = fit_model(rec, force_constant=believed.force_constant)
        dg = diagnose(rec, fitted.replace(controller=believed.controller))
    got = {f.effect: f.parameters for f in dg.findings}
    assert list(got) == ["drift"], dg.summary()
    assert got["drift"]["gain"] == pytest.approx(DRIFT["gain"], rel=0.5), got
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
    assert _kept(_Pass(["drift", "cogging"], 0.2, 0.5), first).findings[0].effect == "drift"
    lost_worse = _Pass([], 0.105, 0.45)
    assert _kept(lost_worse, first) is first
    lost_better = _Pass([], 0.08, 0.2)
    assert _kept(lost_better, first) is lost_better
    # without a held-out record, the record's own rest decides
    assert _kept(_Pass([], 0.105), _Pass(["drift"], 0.099)).findings[0].effect == "drift"
    assert _kept(_Pass([], 0.09), _Pass(["drift"], 0.099)).findings == []
