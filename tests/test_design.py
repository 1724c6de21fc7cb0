"""Experiment design for the static step, the presliding experiment, and the statement
of what a record cannot determine."""

from __future__ import annotations

import warnings

import lugre
import numpy as np
import pytest
from lugre.paper import static_dataset
from lugre.presliding import fit_presliding, presliding_force

TRUTH = lugre.Model.paper()


def _worst(fit: lugre.StaticFit) -> float:
    return max(abs(getattr(fit, d).params[k] / getattr(TRUTH, d)[k] - 1)
               for d in ("positive", "negative") for k in ("fc", "fs", "sigma2", "vs"))


def _first_fit(seed: int) -> lugre.StaticFit:
    v, F, _ = static_dataset(np.random.default_rng(seed))
    return lugre.fit_static(v, F)


def test_design_respects_budget_and_repeats():
    des = lugre.design_static(_first_fit(1), target=1e-4, budget=60, min_repeats=3)
    for d in ("positive", "negative"):
        assert des.repeats[d].sum() <= 60
        assert des.repeats[d].min() >= 3
        assert not des.reached[d]     # 0.01 % is out of reach with 60 runs
    assert des.notes and "raise the budget" in des.notes[0]
    pts = des.points()
    assert (pts > 0).sum() == des.repeats["positive"].sum()
    loose = lugre.design_static(_first_fit(1), target=0.05, budget=96)
    assert all(loose.reached.values())
    assert loose.repeats["positive"].sum() < des.repeats["positive"].sum()


def test_design_rejects_bad_options():
    fit = _first_fit(2)
    with pytest.raises(lugre.ParameterError, match="target"):
        lugre.design_static(fit, target=0.0)
    with pytest.raises(lugre.ParameterError, match="budget"):
        lugre.design_static(fit, budget=5)
    with pytest.raises(lugre.ParameterError, match="speed_range"):
        lugre.design_static(fit, speed_range=(0.1, 0.01))


def test_following_the_design_beats_the_log_spaced_experiment():
    # 12 data sets: the designed 96 runs per direction against the first 24-speed fit
    rng = np.random.default_rng(5)
    first, designed = [], []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for _ in range(12):
            v, F, _ = static_dataset(rng)
            fit = lugre.fit_static(v, F)
            first.append(_worst(fit))
            vd = lugre.design_static(fit, target=0.002, budget=96).points()
            Fd = lugre.stribeck(vd, TRUTH) + 0.3 * rng.standard_normal(vd.size)
            out = rng.uniform(size=vd.size) < 0.12
            Fd[out] *= 1 + rng.choice([-1.0, 1.0], out.sum()) * rng.uniform(0.1, 0.4, out.sum())
            designed.append(_worst(lugre.fit_static(vd, Fd)))
    assert np.median(designed) < 0.7 * np.median(first)
    assert np.median(designed) < 0.01


def test_presliding_recovers_sigma1_with_exact_static_sets():
    t = np.arange(0.0, 2.0, 1e-4)
    force = presliding_force(t, 28.5)
    plant = lugre.Model.from_dict({k: v for k, v in TRUTH.to_dict().items()
                                   if k != "controller"})
    x = lugre.simulate(plant, t, current=force / plant.force_constant).x
    fit = fit_presliding(t, x, force, plant, start={"sigma0": 3e4, "sigma1": 100.0})
    assert abs(fit.estimate["sigma1"] / 31.62 - 1) < 1e-3
    assert abs(fit.estimate["sigma0"] / 1e5 - 1) < 1e-4
    with pytest.raises(lugre.DataError, match="break-away"):
        fit_presliding(t, x, 2 * force, plant)


def test_stribeck_determinacy_names_what_a_fast_record_cannot_tell():
    t = np.arange(0.0, 4.0, 1e-3)
    fast = lugre.Recording(t=t, x=0.05 * np.sin(2 * np.pi * t), F=np.zeros_like(t))
    flat = TRUTH.with_friction(positive={**TRUTH.positive, "fs": TRUTH.positive["fc"]})
    notes = lugre.stribeck_determinacy(fast, flat)
    assert any(n.startswith("v > 0") and "NOT determined" in n for n in notes)
    # slow plateaus in both directions cover the hump: nothing to say
    v = np.repeat(np.array([1e-3, 3e-3, 1e-2, -1e-3, -3e-3, -1e-2]), 1000)
    slow = lugre.Recording(t=np.arange(v.size) * 1e-3, x=np.cumsum(v) * 1e-3, v=v,
                           F=np.zeros(v.size))
    assert lugre.stribeck_determinacy(slow, TRUTH) == []
