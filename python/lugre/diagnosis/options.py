"""The options of one diagnosis and the acceptance constants every stage reads."""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

__all__ = ["EXCESS_FLOOR", "IDENTIFY_TOLERANCE", "MIN_SHARE", "PARTIAL_REST", "RIVAL_SHARE",
           "ROWS_KEPT", "Options"]

#: Least rms force of a finding, as a share of the rms motor force: effects below it are
#: statistically visible on clean records (a 0.1 % mass error, the half period of a
#: 10 kHz controller's hold) but change nothing a user would act on.
MIN_SHARE = 0.003

#: A noise floor (after the findings) above this many times what the recorded current's
#: noise and the encoder's resolution explain holds mismatch spread over the band (clean
#: records: 0.9-1.1 times; backlash impacts 4-5 times).
EXCESS_FLOOR = 3.0

#: A rest above this many noise floors, with under 90 % of the mismatch explained,
#: makes the accepted terms look-alikes of something outside the vocabulary.
PARTIAL_REST = 3.0

#: A candidate that passed at the step another was chosen, with at least this share of
#: its held-out gain, is a look-alike: the two are compared in their exact forms.
RIVAL_SHARE = 0.5

#: Scale of the base tolerances for a base identified from a record (lugre fit), not
#: known beforehand: friction levels may move by about a third, not by 3 %.
IDENTIFY_TOLERANCE = 10.0

#: Rows of a column the held-out scores read at most (longer records: every step-th).
ROWS_KEPT = 100_000


@dataclass(frozen=True)
class Options:
    """What the caller of :func:`lugre.diagnose` asked for (its keywords, documented
    there), ``question``: whether the model's own effects are questioned (not in
    the search for one kind that questioning runs), and ``attested``: kinds whose own
    test beside a polished base already passed (the absorbed-effect stage's), which the
    search names on fewer consistent blocks (:data:`lugre.diagnosis.search.ATTESTED`)."""

    holdout: Any = None
    cutoff_hz: float | None = None
    blocks: int = 10
    alpha: float = 1e-3
    min_gain: float = 10.0
    closed_loop: bool = True
    candidates: tuple[str, ...] | None = None
    screw_lead: float | None = None
    free_mass: bool = False
    presliding_fitted: bool = False
    tolerance: float = 1.0
    backend: Any = "core"
    question: bool = True
    attested: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if self.candidates is not None and not isinstance(self.candidates, tuple):
            object.__setattr__(self, "candidates", tuple(self.candidates))

    def but(self, **changes: Any) -> Options:
        """These options with ``changes``."""
        return replace(self, **changes)

    def test(self) -> dict[str, float]:
        """The block test's keywords (:func:`lugre.diagnosis.scoring.accept`)."""
        return {"alpha": self.alpha, "min_gain": self.min_gain}
