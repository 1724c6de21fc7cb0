"""The look-alike stage after a swap: a rival pair found before the swap whose chosen
term the swap dropped is not compared any more (it ended the diagnosis in a
``StopIteration`` once: a fitted base refitted beside a coupling, whose story of a
resonance and a current limit gave way to a dead-band's, then met the current limit's
pair with a mass)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from lugre.diagnosis import select as S
from lugre.diagnosis.candidates import Term


def _term(effect: str) -> Term:
    return Term(cand=SimpleNamespace(effect=effect, supersedes=()), h=None,
                X=np.zeros((1, 1)))


def _log(effects: list[str]) -> list[dict]:
    return [{"step": 1, "effect": e, "accepted": True, "why": "consistent"} for e in effects]


@pytest.fixture
def staged(monkeypatch: pytest.MonkeyPatch) -> dict:
    """A search whose first story (resonance, current limit) loses to a dead-band's by a
    wide margin in every block, and whose second pair (current limit against a mass) was
    found before the swap."""
    calls: list[list[str]] = []
    rivals = iter([[("resonance", "deadband"), ("current_limit", "mass")]])

    def searcher(w, scorer, opts):
        def run(cands):
            names = [c.effect for c in cands]
            calls.append(names)
            story = (["mass"] if "resonance" in names else ["deadband"]
                     if "current_limit" in names else ["deadband", "mass"])
            return [_term(e) for e in story], None, _log(story)
        return run

    def exact(prep, w, bs, opts, tt, ee):
        effects = {t.effect for t in tt}
        if "resonance" in effects:
            return np.full(10, 1e6)
        return np.full(10, 1.0) + 1e-3 * np.arange(10)

    monkeypatch.setattr(S, "_searcher", searcher)
    monkeypatch.setattr(S, "_exact_sse", exact)
    monkeypatch.setattr(S, "_close_rivals", lambda log, terms, nested: next(rivals, []))
    return {"calls": calls}


def test_a_pair_whose_term_a_swap_dropped_is_not_compared(staged: dict) -> None:
    cands = [SimpleNamespace(effect=e, supersedes=()) for e in
             ("resonance", "current_limit", "deadband", "mass")]
    terms = [_term("resonance"), _term("current_limit")]
    opts = SimpleNamespace(min_gain=10.0)
    w = SimpleNamespace(s2=1.0, ctx=None)
    bs = SimpleNamespace(scorer=None)
    out_terms, _, log, lookalike = S._lookalikes(
        None, w, bs, cands, {}, opts, (terms, None, _log(["resonance", "current_limit"])))
    assert [t.effect for t in out_terms] == ["deadband"]
    assert lookalike == {}
    # one run for the first pair only: the current limit's pair was dropped with it
    assert len(staged["calls"]) == 1
    assert "deadband fits better" in next(g["why"] for g in log if g["effect"] == "resonance")
