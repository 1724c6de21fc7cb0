"""Stage 1: the record checked and filtered, the residual of the model as given."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..io import Recording
from ..model import Model
from . import residual as R
from .options import ROWS_KEPT, Options

__all__ = ["Prepared", "prepare"]


@dataclass(frozen=True)
class Prepared:
    """A record ready for the diagnosis of one model.

    ``model``: the model diagnosed (the given one less the effects a previous pass
    removed, ``removed``) and its residual ``r0``; ``model_given`` and ``r0_given``: the
    model as the user gave it, which the report compares against; ``step``: every
    step-th row is read by the held-out scores of a long record.
    """

    rec: Recording
    sig: R.Signals
    model: Model
    r0: np.ndarray
    model_given: Model
    r0_given: np.ndarray
    removed: tuple[dict[str, Any], ...]
    n_used: int
    step: int


def prepare(rec: Recording, model: Model, opts: Options, *, given: Model | None = None,
            removed: tuple[dict[str, Any], ...] = ()) -> Prepared:
    """Checks, filtered signals and residuals; ``given``: the model as the user gave it
    when ``model`` is that model without the effects ``removed``."""
    R.check_recording(rec, model)
    sig = R.prepare(rec, model, cutoff_hz=opts.cutoff_hz, backend=opts.backend)
    R.check_units(sig, model)
    r0 = R.residual(model, sig)
    n_used = int(sig.mask.sum())
    # a long record's held-out scores read every step-th sample (all they score is
    # band-limited), so that the grid columns kept stay under about 100 000 rows each;
    # the sums agree to a part in a thousand, but a marginal decision (a gain at its
    # threshold) can move, so records up to that size are read whole
    step = max(1, min(sig.rows_step, n_used // ROWS_KEPT))
    r0_given = r0 if given is None else R.residual(given, sig)
    return Prepared(rec=rec, sig=sig, model=model, r0=r0,
                    model_given=model if given is None else given, r0_given=r0_given,
                    removed=tuple(removed), n_used=n_used, step=step)
