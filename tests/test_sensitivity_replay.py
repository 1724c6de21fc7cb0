"""The sensitivity bench's replay (benches/sensitivity.py) decides a trial as the
diagnosis's block test does at the default constants: over random block statistics,
its decision is ``scoring.accept``'s, so a change of the test shows here."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from lugre.diagnosis.options import MIN_SHARE
from lugre.diagnosis.scoring import accept

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benches"))
from sensitivity import Constants, passes, variants


def test_the_replay_at_the_defaults_is_the_block_test():
    rng = np.random.default_rng(4)
    c = Constants()
    assert c.min_share == MIN_SHARE
    for _ in range(2000):
        ev = {"gain": float(10 ** rng.uniform(-1, 4)) * rng.choice([-1, 1]),
              "p": float(10 ** rng.uniform(-6, 0)), "positive": int(rng.integers(0, 11)),
              "blocks": 10, "ratio": float(10 ** rng.uniform(-1, 3))}
        ok, why = accept(ev, alpha=c.alpha, min_gain=c.min_gain)
        tr = {**ev, "accepted": ok, "why": why, "contrib": 1.0}
        assert passes(tr, 1.0, c) == ok, (ev, why)


def test_a_trial_refused_for_its_physics_stays_refused():
    tr = {"gain": 1e4, "p": 1e-9, "positive": 10, "ratio": None, "contrib": 5.0,
          "accepted": False, "why": "not physical: a negative drag"}
    assert not any(passes(tr, 1.0, c) for _, c in variants())


def test_each_constant_moves_by_half_and_double():
    labels = [label for label, _ in variants()]
    assert labels[0] == "defaults" and len(labels) == 13
