"""A term that the last joint refit takes to nothing is not a finding.

The clean record below is case 002 of stress seed 15 (``benches/stress_cases.py --seed
15``, unseen when first run, a regression case now): a dead-band passed the block test
beside a resonance; the resonance was then dropped as what the readings' noise makes,
and the refit without it took the dead-band's coefficient below zero, which maps to no
band at all. The report named "a dead-band of 0 mA" explaining 0 % of the residual.
"""

from __future__ import annotations

from lugre.diagnosis import diagnose
from lugre.diagnosis.synth import case


def test_a_dead_band_refitted_to_nothing_is_not_named():
    rec, hold, believed, _ = case(
        [], seed=35004, axis_seed=4474, kind="sines", duration=10.0, rate_hz=5000.0,
        current_noise=0.035161590814103715, quantum=1e-06, base_error=0.01709081339746521)
    dg = diagnose(rec, believed, holdout=hold)
    assert [f.effect for f in dg.findings] == [], dg.summary()
    dropped = [t for t in dg.trials if t["effect"] == "deadband" and "dropped" in t["why"]]
    assert dropped and "no longer changes the force" in dropped[-1]["why"]
