"""Evidence in the words a control engineer acts on, for every page and summary."""

from __future__ import annotations

import re

__all__ = ["plain_text"]

_SCORE = re.compile(
    r"(?:it )?lowers the held-out score by [-+0-9.e]+\s*(?:\([^)]*\))?,?\s*")
_BLOCKS = re.compile(r"gains in (\d+) of (\d+) held-out blocks \(p = ([^)]+)\)")
_JARGON = re.compile(r"\s*\([^)]*(?:chi-square|noise scale|score)[^)]*\)")


def plain_text(text: str) -> str:
    """Evidence in words a control engineer acts on: no statistics' internal scores.

    ``"... it lowers the held-out score by 73442 (chi-square on the coloured noise
    scale), gains in 10 of 10 held-out blocks (p = 1e-12)"`` becomes ``"... it improves
    the fit in 10 of 10 stretches of the record it was not fitted on (chance of that by
    luck: 1e-12)"``.
    """
    out = _SCORE.sub("it improves the fit: it ", text)
    out = _BLOCKS.sub(lambda m: f"gains in {m.group(1)} of {m.group(2)} stretches of the "
                      f"record it was not fitted on (chance of that by luck: {m.group(3)})",
                      out)
    out = _JARGON.sub("", out)
    return out.replace("it improves the fit: it gains", "it improves the fit in").replace(
        "improves the fit in in", "improves the fit in")
