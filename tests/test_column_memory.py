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


def test_a_trial_kept_at_the_rows_read_gives_its_rms_and_columns():
    """A term kept at every third row with its Gram matrix: the rms of its contribution
    over every sample used as from all its columns (to rounding), and its columns whole
    again as built, bit for bit."""
    from lugre.diagnosis import colcache
    from lugre.diagnosis.scoring import Evaluation

    rec, believed, _ = concealed("position_friction", duration=6.0)
    sig = R.prepare(rec, believed)
    ctx = E.Context.build(sig, believed)
    ctx.extra["rows_step"] = 3
    c = E.PositionFriction()
    full = c.columns(None, ctx)
    t = colcache.make_term(c, None, ctx, summed=True)
    assert t.gram is not None and np.array_equal(t.X, full[::3])
    beta = np.random.default_rng(1).normal(size=full.shape[1])
    want = float(np.sqrt(np.mean((full @ beta)[sig.mask] ** 2)))
    got = colcache.contribution_rms(t, beta, sig.mask, ctx)
    assert abs(got - want) <= 1e-12 * want
    rows = colcache.contribution_rows(t, beta, ctx)
    assert rows.shape == (full.shape[0],) and np.allclose(rows[::3], full[::3] @ beta,
                                                          rtol=1e-14, atol=0)
    ev = Evaluation(score=0.0, sse_b=np.zeros(1), prior=0.0, beta=beta, sse=0.0, X=[t.X])
    (w,), ev2 = colcache.whole([t], ev, ctx)
    assert w.gram is None and np.array_equal(w.X, full) and ev2.X[0] is w.X
