"""A finding taken on the confined route must account for the mismatch where it gains
(``lugre.diagnosis.partial``): the share it removes is measured beyond the noise, and a
term that removes a minor part of a large rest is refused."""

from types import SimpleNamespace

import numpy as np
import pytest
from lugre.diagnosis.candidates import Term
from lugre.diagnosis.partial import PARTIAL_SHARE, explained_share, partial_refusal
from lugre.diagnosis.scoring import Scorer, compare

N, K, NOISE = 20_000, 10, 0.1


def _scorer(rest: np.ndarray, seed: int = 0) -> Scorer:
    r = rest + NOISE * np.random.default_rng(seed).standard_normal(N)
    mask = np.ones(N, bool)
    # one base column (a constant force) held near the model's value by its prior
    return Scorer(r, np.ones((N, 1)), np.array([1e-6]), mask, NOISE ** 2, K)


def _bursts() -> tuple[np.ndarray, np.ndarray]:
    """A mismatch confined to three stretches of the record, and a second shape that
    lives in the same stretches and is unrelated to the first."""
    t = np.arange(N) / N
    where = ((t > 0.12) & (t < 0.18)) | ((t > 0.45) & (t < 0.5)) | ((t > 0.8) & (t < 0.86))
    a = np.where(where, np.sin(2 * np.pi * 40 * t), 0.0)
    b = np.where(where, np.cos(2 * np.pi * 97 * t), 0.0)
    return a, b


def _term(effect: str, x: np.ndarray) -> Term:
    return Term(cand=SimpleNamespace(effect=effect), h=None, X=x[:, None])


@pytest.mark.parametrize("share", [0.2, 0.5, 0.9])
def test_the_share_is_what_the_term_removes_beyond_the_noise(share):
    a, b = _bursts()
    # the rest: a part `share` of its energy along a, the remainder along b
    rest = 0.5 * (np.sqrt(share) * a + np.sqrt(1 - share) * b) * np.sqrt(2)
    sc = _scorer(rest)
    ev = sc.evaluate([_term("x", a)])
    d = compare(sc.evaluate([]), ev, sc.s2)["d"]
    assert explained_share(sc, ev, d, NOISE) == pytest.approx(share, abs=0.05)


def _log(effect: str, d: np.ndarray, why: str) -> list[dict]:
    return [{"effect": effect, "accepted": True, "why": why, "d": d}]


def test_a_term_that_explains_a_minor_part_on_the_confined_route_is_refused():
    a, b = _bursts()
    sc = _scorer(0.4 * a + 0.8 * b)  # a holds a fifth of the rest
    term = _term("stribeck_shape", a)
    ev = sc.evaluate([term])
    d = compare(sc.evaluate([]), ev, sc.s2)["d"]
    out = partial_refusal(sc, [term], ev, _log("stribeck_shape", d,
                                                 "confined but overwhelming"), NOISE, 10.0)
    assert out is not None
    effect, figures, why = out
    assert effect == "stribeck_shape" and figures["share"] < PARTIAL_SHARE
    assert figures["share"] == pytest.approx(0.2, abs=0.05) and "only" in why
    # the same term taken on the consistent route is not this rule's to judge
    assert partial_refusal(sc, [term], ev, _log("stribeck_shape", d,
                                                  "consistent over blocks"), NOISE, 10.0) is None


def test_a_term_that_explains_most_of_its_stretches_stands():
    a, b = _bursts()
    sc = _scorer(0.8 * a + 0.3 * b)
    term = _term("position_friction", a)
    ev = sc.evaluate([term])
    d = compare(sc.evaluate([]), ev, sc.s2)["d"]
    assert partial_refusal(sc, [term], ev, _log("position_friction", d,
                                                  "confined but overwhelming"), NOISE, 10.0) is None


def test_two_findings_that_explain_the_stretches_together_both_stand():
    # the first of a pair removes a minor part alone; with the second in, the two
    # remove the rest, and neither is refused
    a, b = _bursts()
    sc = _scorer(0.4 * a + 0.8 * b)
    ta, tb = _term("offset", a), _term("deadband", b)
    ev = sc.evaluate([ta, tb])
    d = compare(sc.evaluate([]), sc.evaluate([ta]), sc.s2)["d"]
    log = _log("offset", d, "confined but overwhelming")
    assert partial_refusal(sc, [ta, tb], ev, log, NOISE, 10.0) is None
