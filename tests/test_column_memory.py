"""The search's columns built with less memory give the same numbers, bit for bit."""

from __future__ import annotations

import numpy as np
from lugre.diagnosis import candidates as E
from lugre.diagnosis import residual as R
from lugre.diagnosis.candidates import position
from lugre.diagnosis.synth import concealed


def test_position_friction_columns_built_in_parts_as_whole():
    rec, believed, _ = concealed("position_friction", duration=6.0)
    sig = R.prepare(rec, believed)
    ctx = E.Context.build(sig, believed)
    c = E.PositionFriction()
    kn = c.knots(ctx)
    assert kn.size > position._AT_ONCE  # (built in more than one part)
    x = np.clip(sig.x, kn[0], kn[-1])
    hats = np.column_stack([np.interp(x, kn, np.eye(kn.size)[j]) for j in range(kn.size)])
    whole = sig.filt(hats * ctx.fcs[:, None])
    assert np.array_equal(c.columns(None, ctx), whole)

