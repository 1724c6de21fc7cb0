"""The calibration bench's generator (benches/calibration_cases.py, a plant independent of
the diagnosis) is sane: clean records diagnosed against their true model name nothing
(on most of a handful), and an effect added at 3x the limit the report gives for that
same record is named. Short records (4 s at 1 kHz) keep it under a minute."""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from lugre.diagnosis import diagnose
from lugre.io import Recording
from lugre.model import Model

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benches"))
import calibration_cases as C

SEEDS = (5, 6, 8, 9)


def _case(seed: int) -> dict:
    c = C.draw_case(seed, max_duration=4.0)
    c["setup"]["rate_hz"] = 1000.0
    return c


def _diagnose(case: dict, rec: dict, hold: dict, model: dict) -> dict:
    kind = case["truth"]["axis"].get("kind", "linear")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return diagnose(Recording(**rec, meta={"axis_kind": kind}), Model(model),
                        holdout=Recording(**hold, meta={"axis_kind": kind})).to_dict()


@pytest.fixture(scope="module")
def clean():
    cases = [_case(s) for s in SEEDS]
    recs = C.records([(c, []) for c in cases])
    return [(c, r, h, _diagnose(c, r, h, c["truth"])) for c, (r, h) in zip(cases, recs)]


def test_clean_records_against_their_truth_name_nothing(clean):
    named = [(c["seed"], c["family"], [f["effect"] for f in d["findings"]])
             for c, _, _, d in clean]
    assert sum(not n for _, _, n in named) >= len(clean) - 1, named


def test_the_plant_holds_what_the_model_says(clean):
    # against the true model the force residual is the current noise, no more: under
    # twice its rms (in force; the diagnosis's filter takes some of it away)
    for c, _, _, d in clean:
        kf = c["truth"]["axis"].get("force_constant", c["truth"]["axis"].get("torque_constant"))
        noise = c["setup"]["current_noise"] * kf
        assert d["fit"]["after"]["rms_force"] < 2.0 * noise, (c["seed"], noise, d["fit"])


@pytest.mark.parametrize("name", ["delay", "drag"])
def test_an_effect_at_three_times_its_limit_is_named(clean, name):
    case, rec, _, d = next((c, r, h, d) for c, r, h, d in clean if not d["findings"])
    lim = {e["effect"]: e for e in d["could_not_reveal"]}
    b = lim["delay/current_lag" if name == "delay" else name]["smallest"]
    assert np.isfinite(b) and b > 0
    eff = ({"effect": "delay", "seconds": 3 * b} if name == "delay"
           else {"effect": "drag", "coefficient": 3 * b})
    (r, h), = C.records([(case, [eff])])
    np.testing.assert_array_equal(r["t"], rec["t"])  # the same record, the effect added
    got = _diagnose(case, r, h, case["truth"])
    assert name in [f["effect"] for f in got["findings"]], (case["seed"], eff, got["findings"])


def test_a_light_inertia_is_named_not_the_load_friction_it_looks_like():
    """Seed 33028 of the calibration bench: a clean joint (p2p, PID, 1 kHz, 15 s) whose
    believed inertia is 1.2 % light. The first search chose a current limit; a load
    friction fitted far better in its exact form and took its place, and stood: the
    inertia, which fits it as well (its block gains not told apart, t = 0.9), was never
    compared. Now a kept story is compared in turn with a close rival that is the
    axis's mass, and where the two are not told apart the mass is named, the load
    friction beside it as its look-alike."""
    case = C.draw_case(33028, max_duration=15.0, min_duration=3.0)
    (rec, hold), = C.records([(case, [])])
    d = _diagnose(case, rec, hold, case["believed"])
    assert [f["effect"] for f in d["findings"]] == ["inertia"], d["findings"]
    err = case["truth"]["axis"]["inertia"] - case["believed"]["axis"]["inertia"]
    assert d["findings"][0]["parameters"]["delta"] == pytest.approx(err, rel=0.2)
    assert [a["effect"] for a in d["findings"][0]["alternatives"]] == ["load_friction"]


@pytest.mark.parametrize("seed", [39181, 39149, 38996, 39226])
def test_a_term_that_stood_in_for_a_believed_base_is_dropped(seed):
    """Clean records of the calibration bench whose believed base is off by 1-2 %:
    39181 (a linear axis, constant-speed feeds, 5 s at 2 kHz) and 39149 (a joint,
    point-to-point, 7 s at 1 kHz, coloured noise), where the search's linearised base
    moves left a rest that a drag and a Stribeck shape took up on the confined route
    (gains in 9 of 10 held-out blocks, p = 0.08 and 0.03); 38996 (PID, point-to-point,
    3 s at 1 kHz) and 39226 (PI speed loop, feeds, 4 s at 500 Hz), where a spring and a
    dead-band took up what a believed mass 1.7-2 % off left along the acceleration
    (block t under 5). The base refitted without the term (and, for the weak ones, the
    mass freed within 3 %) fits the record as well, and the search from there names
    nothing, or the term is refused before (:data:`~lugre.diagnosis.partial.IN_RECORD`)."""
    case = C.draw_case(seed, max_duration=15.0, min_duration=3.0)
    (rec, hold), = C.records([(case, [])])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        kind = case["truth"]["axis"].get("kind", "linear")
        dg = diagnose(Recording(**rec, meta={"axis_kind": kind}), Model(case["believed"]),
                      holdout=Recording(**hold, meta={"axis_kind": kind}))
    named = [f.effect for f in dg.findings if f.effect not in ("mass", "inertia")]
    assert named == [], dg.findings
    # (on 39149 no term is taken any more: the Stribeck shape's confined gain is refused
    # as one the record fitted whole does not show)
    taken = [t for t in dg.trials if t.get("accepted")]
    assert not taken or any("stood in for the base" in n for n in dg.notes), dg.notes
