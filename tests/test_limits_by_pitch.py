"""A periodic force's limit is given per pitch: the largest over the range searched
overstates it at most pitches (the shortest pitch, crossed fastest, hides the most), so
the calibration bench claimed a cogging at half the single figure in 10 of 12 records.
The report keeps that largest figure as ``smallest`` and gives each pitch's beside it."""

from __future__ import annotations

import re
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from lugre.diagnosis import diagnose
from lugre.diagnosis.synth import case

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benches"))
from calibration import _at_pitch


@pytest.fixture(scope="module")
def limits():
    rec, hold, believed, _ = case([], seed=35001, kind="sines", duration=8.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        dg = diagnose(rec, believed, holdout=hold)
    return {c["effect"]: c for c in dg.to_dict()["could_not_reveal"]}


@pytest.mark.parametrize("effect", ["cogging", "force_ripple"])
def test_each_pitch_has_its_limit_and_the_largest_is_the_entrys(limits, effect):
    c = limits[effect]
    p, b = np.array(c["by_pitch"]["pitch"]), np.array(c["by_pitch"]["smallest"], float)
    assert p.size >= 6 and np.all(np.diff(p) < 0)  # longest pitch first
    assert np.all(np.isfinite(b)) and np.all(b > 0)
    assert c["smallest"] == pytest.approx(b.max())
    assert b.min() < 0.9 * b.max()  # the pitches differ: one figure would overstate
    assert len(re.findall(r"under [0-9.]+ (?:N|%)", c["text"])) == 2, c["text"]  # two halves


def test_the_bench_reads_the_limit_at_its_pitch(limits):
    bp = limits["cogging"]["by_pitch"]
    p, b = bp["pitch"], bp["smallest"]
    assert _at_pitch(bp, p[2]) == pytest.approx(b[2])
    mid = float(np.sqrt(p[2] * p[3]))
    assert min(b[2], b[3]) <= _at_pitch(bp, mid) <= max(b[2], b[3])
    assert _at_pitch({"pitch": p, "smallest": [None] + b[1:]}, mid) is None
