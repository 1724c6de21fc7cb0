"""A current limit's coefficient on its secant, mapped to the limit it stands for: the
clip whose excess has that share of the grid point's (a clip at a low grid point taken
at a small coefficient is a limit near the peaks, not a drive clipped low)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from lugre.diagnosis.candidates import drive as D


def _ctx(i: np.ndarray, kf: float = 25.0) -> SimpleNamespace:
    sig = SimpleNamespace(fm=kf * i, mask=np.ones(i.size, bool))
    return SimpleNamespace(sig=sig, model=SimpleNamespace(force_constant=kf))


def _excess(i: np.ndarray, c: float) -> float:
    return float(np.sqrt(np.mean(np.maximum(np.abs(i) - c, 0.0) ** 2)))


I = 5.4 * np.sin(np.linspace(0.0, 20.0 * np.pi, 20001))


@pytest.mark.parametrize(("h", "b"), [(1.42, 0.06), (1.42, 0.5), (3.0, 1.6), (4.0, 3.0)])
def test_the_limit_has_the_share_of_the_excess_the_coefficient_gives(h: float,
                                                                      b: float) -> None:
    c = D.CurrentLimit().parameter(h, np.array([b]), _ctx(I))
    assert _excess(I, c) == pytest.approx(b * _excess(I, h), rel=1e-6)
    assert (c > h) == (b < 1.0)
    assert 0.0 < c < 5.4


def test_more_than_the_whole_current_clipped_maps_to_a_limit_of_zero() -> None:
    assert 1.6 * _excess(I, 1.42) > _excess(I, 0.0)
    assert D.CurrentLimit().parameter(1.42, np.array([1.6]), _ctx(I)) == pytest.approx(
        0.0, abs=1e-9)


def test_a_coefficient_near_one_keeps_the_grid_point() -> None:
    assert D.CurrentLimit().parameter(1.42, np.array([0.9]), _ctx(I)) == 1.42


@pytest.mark.parametrize("b", [0.0, -0.3])
def test_no_coefficient_or_a_negative_one_clips_nothing(b: float) -> None:
    c = D.CurrentLimit().parameter(1.42, np.array([b]), _ctx(I))
    assert c == pytest.approx(np.max(np.abs(I)), rel=1e-9)
    eff = D.CurrentLimit().to_effects(1.42, np.array([b]), _ctx(I))[0]
    assert eff == {"effect": "current_limit", "current": pytest.approx(c)}


def test_a_limit_that_clips_only_the_very_peaks_is_refused_in_its_exact_form() -> None:
    # a 3 A sine with ten short peaks at 5.4 A: a small coefficient on the clip at
    # 1.42 A maps to a limit that clips those peaks alone (10 of 20 001 samples)
    i = 3.0 * np.sin(np.linspace(0.0, 20.0 * np.pi, 20001))
    i[1000::2000] = 5.4
    b = np.array([0.02])
    c = D.CurrentLimit().parameter(1.42, b, _ctx(i))
    assert 3.0 < c < 5.4 and np.sum(np.abs(i) > c) == 10
    why = D.CurrentLimit().exact_refusal(1.42, b, _ctx(i))
    assert why is not None and "clips 10 of the record's 20001 samples" in why


@pytest.mark.parametrize("b", [0.06, 0.9])
def test_a_limit_that_clips_a_fair_share_stands(b: float) -> None:
    c = D.CurrentLimit().parameter(1.42, np.array([b]), _ctx(I))
    assert np.mean(np.abs(I) > c) > D.LEAST_CLIPPED
    assert D.CurrentLimit().exact_refusal(1.42, np.array([b]), _ctx(I)) is None


def test_the_interval_is_of_the_limits_the_profile_points_stand_for() -> None:
    # every profile point's coefficient maps its grid point as the finding's limit is
    # mapped: the interval holds the limit the finding reports
    ctx = _ctx(I)
    prof = {"h_obj": [1.2, 1.42, 1.7], "beta": [np.array([0.05]), np.array([0.06]),
                                                np.array([0.08])],
            "score": np.array([5.0, 0.0, 3.0])}
    term = SimpleNamespace(profile=prof)
    cl = D.CurrentLimit()
    out = cl.uncertainty(term, np.array([0.06]), ctx, ctx.sig, 1.0)
    c = cl.parameter(1.42, np.array([0.06]), ctx)
    lo, hi = out["current"]
    assert lo <= c <= hi and lo > 1.7
