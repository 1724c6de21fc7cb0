"""Evidence in words: held-out gains, the base report and its moves, what stays
unexplained and where, what the record could not have revealed (each candidate says
its own part, :meth:`~lugre.diagnosis.candidates.Candidate.limit`), and the verdict."""

from __future__ import annotations

from dataclasses import replace
from functools import partial
from typing import Any

import numpy as np

from .. import units as U
from ..model import Model
from ..vocabulary import EFFECTS, is_timing
from . import base as B
from . import residual as R
from .candidates import Term
from .candidates.lag import timing_words
from .candidates.linear import ASYMMETRY_EXPERIMENT, Offset
from .candidates.probe import reversals
from .scoring import Scorer

__all__ = ["could_not_reveal", "evidence", "revealed_sizes", "unexplained", "verdict"]


def evidence(t: Term, log: dict[str, Any], K: int, extra: str = "") -> str:
    """The evidence of a finding in two or three sentences a person can check (in the
    words of the axis: torque and inertia on a rotary one)."""
    sig_txt = f"{t.cand.signature[0].upper()}{t.cand.signature[1:]}."
    if log:
        sig_txt += (f" Fitted with the friction levels on nine tenths of the record, it "
                    f"predicts the tenth left out better in {log['positive']} of {K} such "
                    f"stretches (chance of this from noise alone: p = {log['p']:.1g}).")
    return U.words(sig_txt + (" " + extra if extra else ""))


def base_report(model: Model, base: dict[str, float], free: list[str],
                presliding: dict[str, Any]) -> dict[str, dict[str, Any]]:
    """Every base parameter before and after, its change, tolerance and status."""
    out = {}
    for n, rel in B.BASE_PARAMS:
        b0 = B.get_base(model, n)
        b1 = B.get_base(B.apply_base(model, base), n)
        status = "refitted" if n in free else "held"
        if n in B.PRESLIDING and n not in free:
            status = "not determined by this record (held)"
        out[n] = {"before": b0, "after": b1, "change": (b1 - b0) / b0 if b0 else 0.0,
                  "tolerance": rel, "unit": U.si(B.unit(n)), "status": status}
    out["sigma1"]["presliding_test"] = {k: presliding[k] for k in
                                        ("gain", "min_gain", "alpha", "p", "positive",
                                         "blocks", "free", "for_lag", "beside")
                                        if k in presliding}
    return out


def base_moves(base: dict[str, dict[str, Any]], factor: float = 2.0) -> list[dict[str, Any]]:
    """Base parameters that moved by more than ``factor`` tolerances, in words. A damping
    driven to zero (the record does not resolve it) and a value that is numerically zero
    before and after are no moves."""
    out = []
    for n, b in base.items():
        if n in ("sigma1", "positive.sigma2", "negative.sigma2") and b["after"] == 0.0:
            continue
        if max(abs(b["before"]), abs(b["after"])) < 1e-12:
            continue
        if abs(b["change"]) > factor * b["tolerance"]:
            d = b["after"] - b["before"]
            out.append({"parameter": n, "before": b["before"], "after": b["after"],
                        "unit": b["unit"],
                        "text": (f"{U.words(n)} {d:+.3g} {b['unit']} "
                                 f"({100 * b['change']:+.0f} %, from "
                                 f"{b['before']:.4g} to {b['after']:.4g} {b['unit']})")})
    return out


def base_notes(base: dict[str, dict[str, Any]], findings: list[Any]) -> list[str]:
    """Notes on the base: large moves (a finding in words), presliding held, asymmetry."""
    notes = []
    moves = base_moves(base, factor=3.0)
    if moves:
        lv = [m for m in moves if m["parameter"].split(".")[-1] in ("fc", "fs")]
        txt = ("The base moved beyond three tolerances: " + "; ".join(m["text"] for m in moves)
               + ".")
        if lv:
            txt += (" A change of the Coulomb/static level this large means the model's "
                    "friction is off (or something at low speed and at reversals stands in "
                    "for it); the refitted values are in the augmented model.")
        notes.append(txt)
    s1 = base["sigma1"]
    pt = s1.get("presliding_test", {})
    if pt.get("for_lag"):
        notes.append(U.words(
            "sigma0 and sigma1 (presliding stiffness and damping), which lugre fit took "
            "from this record, were refitted beside the lag: at the reversals a lag and a "
            "larger bristle damping read much alike, and the fit had taken the damping."))
    elif pt.get("beside"):
        notes.append(U.words(
            "sigma0 and sigma1 (presliding stiffness and damping), which lugre fit took "
            f"from this record, were refitted beside {' and '.join(pt['beside'])}: held "
            "where the fit put them, they kept that from being named."))
    if "not determined" in s1["status"]:
        pt = s1.get("presliding_test", {})
        blocks = (f"gains in {pt.get('positive', 0)} of {pt.get('blocks', 10)} stretches, "
                  f"p = {pt.get('p', 1):.1g}")
        if (pt.get("p", 1.0) < pt.get("alpha", 0.0)
                and pt.get("gain", 0.0) <= pt.get("min_gain", 0.0)):
            why = (f"freeing them improves the held-out fit by too little to matter (a "
                   f"score gain of {pt.get('gain', 0.0):.3g} against the "
                   f"{pt.get('min_gain', 0.0):.3g} a finding needs; {blocks})")
        else:
            why = f"freeing them does not improve the held-out fit consistently ({blocks})"
        notes.append(U.words(
            "sigma0 and sigma1 (presliding stiffness and damping) are held at the model's "
            f"values: {why}, so this record does not determine them. To determine them: "
            "small back-and-forth moves below the breakaway force (presliding, a few "
            "micrometres) or a small-amplitude current sweep at standstill, logged at "
            "1 kHz or faster."))
    bp, bn = base["positive.fc"]["after"], base["negative.fc"]["after"]
    if not any(f.effect == Offset.effect for f in findings) and abs(bp - bn) > 0.1 * (bp + bn) / 2:
        n = U.si("N")
        notes.append(U.words(
            f"The Coulomb levels differ by direction ({bp:.3g} {n} forward, {bn:.3g} {n} "
            f"backward); a constant force of {(bp - bn) / 2:.3g} {n} with a symmetric level "
            f"would fit the motion equally well. To separate: "
            f"{ASYMMETRY_EXPERIMENT}."))
    return notes


def unexplained(r: np.ndarray, sig: R.Signals, floor: float, where: dict[str, Any],
                after: dict[str, float], lag_rev: dict[str, Any] | None = None,
                mass_ways: dict[str, Any] | None = None,
                excess: dict[str, float] | None = None) -> dict[str, Any] | None:
    """The rest above twice the noise floor: where it lives and what shape it has
    (``lag_rev``: a lag that fitted the reversals only, :func:`lag_at_reversals`;
    ``mass_ways``: a mass term that differs speeding up and braking,
    :func:`mass_both_ways`; ``excess``: a noise floor far above what the measurements
    explain, ``floor`` and ``expected`` [N])."""
    from .locate import short_ranges

    rms1 = after["rms_force"]
    if rms1 <= 2.0 * floor and lag_rev is None and mass_ways is None and excess is None:
        return None
    m = sig.mask
    rr = r[m]
    rev_all, nrev = reversals(sig)
    rev = rev_all[m]
    share_rev = float(np.sum(rr[rev] ** 2) / max(np.sum(rr ** 2), 1e-300))
    shape = []
    if lag_rev is not None:
        shape.append(
            f"at the {nrev} reversals the force acts as if {lag_rev['lag_s'] * 1e3:.2g} ms "
            f"late, between them {lag_rev['lag_away_s'] * 1e3:.2g} ms (+-"
            f"{2 * lag_rev['se_s'] * 1e3:.2g}): not a delay of the drive, which would shift "
            "the force everywhere, but lost motion at each change of direction, e.g. "
            "backlash between motor and load or a presliding stage the model does not "
            "hold")
    if excess is not None:
        shape.append(
            f"the residual's noise floor, {excess['floor']:.2g} {U.si('N')}, is "
            f"{excess['floor'] / excess['expected']:.0f} times what the recorded current's "
            f"noise and the position reading's noise explain ({excess['expected']:.2g} "
            f"{U.si('N')}, both measured above the motion's band): mismatch spread over the whole "
            "band is counted as noise (impacts, e.g. at the reversals; an error of the "
            "position reading periodic in position, crossed at changing speeds; a ripple "
            "of the drive); effects under that floor stay hidden")
    if mass_ways is not None:
        shape.append(
            f"the acceleration force reads as {mass_ways['speeding_up']:+.2g} {U.si('kg')} "
            f"while the drive speeds the axis up and {mass_ways['braking']:+.2g} "
            f"{U.si('kg')} while it brakes "
            "(+- "
            f"{2 * max(mass_ways['speeding_up_se'], mass_ways['braking_se']):.2g}): not a "
            "payload, which is the same mass both ways, but a force that grows with the "
            "force the drive transmits, e.g. friction of a preloaded nut or of a guide "
            "loaded by the drive")
    at_reversals = lag_rev is not None
    if lag_rev is None and rev.any() and share_rev > 2.0 * rev.mean() and share_rev > 0.3:
        at_reversals = True
        shape.append(
            f"{100 * share_rev:.0f} % of the rest lies within 50 ms of the {nrev} "
            f"reversals ({100 * rev.mean():.0f} % of the time): a force step or lost motion "
            "at each change of direction, e.g. backlash between motor and load, or a "
            "presliding stage the model does not hold")
    d = where.get("direction", {})
    # concentrated at low speed (and not already said of the reversals, where the speed
    # is low too): the smallest share of the top speed under which a third of the rest
    # lies, in at most a quarter of the time's share
    if not at_reversals:
        vv = np.abs(sig.vf[m])
        vtop = float(vv.max()) if vv.size else 0.0
        tot = max(float(np.sum(rr ** 2)), 1e-300)
        for frac in (0.01, 0.02, 0.05, 0.1):
            slow = vv <= frac * vtop
            share_slow = float(np.sum(rr[slow] ** 2)) / tot
            if slow.sum() > 20 and share_slow > 0.3 and share_slow > 4.0 * float(slow.mean()):
                fast = float(np.sqrt(np.mean(rr[~slow] ** 2))) if (~slow).any() else 0.0
                shape.append(
                    f"{100 * share_slow:.0f} % of it lies where the axis stands or moves under "
                    f"{_speed(frac * vtop)} ({100 * frac:g} % of the top speed, "
                    f"{100 * slow.mean():.1f} % of the time): "
                    f"{float(np.sqrt(np.mean(rr[slow] ** 2))):.3g} {U.si('N')} rms there "
                    f"against {fast:.3g} {U.si('N')} faster. The friction at standstill and "
                    "low speed (static friction, breakaway, the Stribeck fall, presliding) is "
                    "unlike the model's: a slow current ramp at standstill in both "
                    "directions, and constant-speed passes at "
                    f"{'a few hundredths of a rad/s' if U.is_rotary() else 'a few mm/s'}, "
                    "measure it")
                break
    if d.get("positive") and d.get("negative"):
        ratio = d["positive"] / d["negative"]
        if ratio > 1.5 or ratio < 1 / 1.5:
            shape.append(f"it is {'larger moving forward' if ratio > 1 else 'larger moving backward'}"
                         f" ({d['positive']:.3g} {U.si('N')} against {d['negative']:.3g} "
                         f"{U.si('N')} rms)")
    parts = [f"{k} {short_ranges(where[k])}" for k in ("time", "position", "velocity")
             if where.get(k)]
    shape = [U.words(x) for x in shape]
    msg = (f"after the findings the residual is still {rms1:.3g} {U.si('N')} rms, "
           f"{rms1 / floor:.1f} "
           "times the noise floor, and no effect of the vocabulary explains the rest")
    msg += "; it lives at " + "; ".join(parts) if parts else ""
    msg += ". " + "; ".join(shape) + "." if shape else "."
    return {"rms_force": rms1, "noise_floor": floor, "reversal_share": share_rev,
            "where": {k: where.get(k) for k in ("time", "position", "velocity", "direction")},
            "shape": shape, "message": msg[0].upper() + msg[1:]}


def could_not_reveal(scorer: Scorer, ctx: Any, cands: list[Any], found: list[str],
                     min_gain: float, *, terms: list[Term] | None = None,
                     alpha: float = 1e-3, noise_rms: float = 0.0, min_force: float = 0.0,
                     min_effect: float = 0.2) -> list[dict[str, Any]]:
    """Per effect of the vocabulary not found: the smallest size this record would have
    revealed, by the search's own test.

    An effect of size ``b`` with column ``X`` (per unit size) is added to this record's
    residual, and the held-out blocks judge it as the search would (:func:`revealed_sizes`,
    with ``terms``, the terms found, in both fits): the size given is the smallest from
    which it passes for either sign. The noise, the record's own unevenness (an effect
    that lives in a few blocks passes the consistency test late) and the friction levels'
    share of the effect all count, as they do in the search. So do its other rules: a
    finding's force must reach ``min_effect`` times the noise floor ``noise_rms`` and
    (but for timing) ``min_force``, or it is at most a minor correction; an effect that
    adds most of what the friction levels cannot absorb in one held-out stretch is
    never named; a lag must reach a fifth of the sample interval.
    """
    found_terms = list(terms or [])
    sig = ctx.sig
    # the rows the scorer reads: a limit may keep its fits' columns at those rows only
    ctx = replace(ctx, extra={**ctx.extra, "rows_step": scorer.step})

    def sizes(Xs: list[np.ndarray], effect: str, timing: bool,
              fits: list[Term | None] | None = None) -> np.ndarray:
        # (a minor correction of the same kind, kept in the fit, is part of the effect)
        rest = [t for t in found_terms if t.cand is None or t.effect != effect]
        floor = max(min_effect * noise_rms, 0.0 if timing else min_force)
        out = revealed_sizes(scorer, rest, Xs, alpha=alpha, min_gain=min_gain,
                             min_rms=floor, fits=fits,
                             noise=(noise_rms ** 2, lambda x: R.noise_floor(x, sig)["rms"]))
        # a lag under a fifth of the sample interval is a detail of the sampling
        dt = sig.info.get("dt_logged", sig.dt)  # the record's own sample interval
        return np.maximum(out, 0.2 * dt) if timing else out

    out: list[dict[str, Any]] = []
    for c in cands:
        if c.effect in found:
            continue
        try:
            out.append(c.limit(ctx, partial(sizes, effect=c.effect, timing=c.timing)))
        except (ValueError, ArithmeticError, np.linalg.LinAlgError):  # pragma: no cover
            continue
    return [o for o in out if o is not None]


def revealed_sizes(scorer: Scorer, terms: list[Term], Xs: list[np.ndarray], *,
                   alpha: float, min_gain: float, min_rms: float = 0.0,
                   fits: list[Term | None] | None = None,
                   noise: tuple[float, Any] | None = None) -> np.ndarray:
    """The smallest size ``b`` at which an effect ``b*X`` in this record would pass the
    search's acceptance test (:func:`~lugre.diagnosis.scoring.accept` on the held-out
    blocks, the ``terms`` already found in both fits), for either sign, and whose force
    reaches ``min_rms`` [N] rms, for each column ``X`` of ``Xs`` (their fits stacked);
    ``inf`` when no size up to 64 times the first guess passes.

    The size is the effect's whole size in the record: the residual may already hold
    some of it (an effect under the threshold, or noise along ``X``), which the fit with
    the effect reads as its coefficient; what is added is the size less that. The fits
    are linear in the residual, so the held-out errors of the fit without the effect are
    quadratic in what is added (read from three residuals), and those of the fit with it
    do not change (its free coefficient takes it up): every size is judged exactly, from
    three fits without the column and one with it.

    ``fits`` (per column, or None): the columns the search itself fits for that effect,
    when they are more than the one column (a friction change along the stroke is read
    with a hat function at every knot, each free within its prior): the fit with the
    effect is then that term's, read at the same three residuals, so that the size given
    pays for the freedom the search takes.

    ``noise``: the noise floor's variance [N^2] and the function that reads a floor
    [N] from a residual (:func:`lugre.diagnosis.residual.noise_floor`); with it, the
    variance unit at each size grows by the floor the effect's column alone shows
    there, scaled by the size (a broadband effect raises the floor the search reads; a
    first-order account: the floor is a low quantile, not a sum, so this overstates the
    rise for effects whose band content is uneven, a cogging's).
    """
    from .scoring import _ONE_BLOCK, accept_many

    m = len(Xs)
    out = np.full(m, np.inf)
    if m == 0:
        return out
    xs = [np.asarray(X, float).reshape(-1) for X in Xs]
    parts = [scorer._assemble(terms + [Term(cand=None, h=None, X=x[:, None])]) for x in xs]
    G_b = np.stack([p[0] for p in parts])  # (m, K, d+1, d+1)
    h_b = np.stack([p[1] for p in parts])
    ptol, cen = parts[0][2], parts[0][3]
    d = G_b.shape[-1] - 1
    K = G_b.shape[1]
    new = scorer._fit(G_b, h_b, np.broadcast_to(ptol, (m, d + 1)),
                      np.broadcast_to(cen, (m, d + 1)))
    gx, xx, xr = G_b[:, :, :d, d], G_b[:, :, d, d], h_b[:, :, d]  # (m, K, d), (m, K)
    G0, h0 = G_b[:, :, :d, :d], h_b[:, :, :d]
    # what the design (base and terms) cannot absorb of each column, per unit: the
    # first guess of the size, from the gain alone
    Gt, gt, xxt = G0.sum(1), gx.sum(1), xx.sum(1)
    try:
        perp = xxt - np.einsum("mi,mi->m", gt, np.linalg.solve(
            Gt + 1e-12 * np.trace(Gt, axis1=-2, axis2=-1)[:, None, None] * np.eye(d),
            gt[..., None])[..., 0])
    except np.linalg.LinAlgError:  # pragma: no cover
        perp = xxt
    good = (perp > 1e-12 * np.maximum(xxt, 1e-300)) & np.isfinite(perp)
    b0 = np.where(good, np.sqrt((min_gain + 20.0) * scorer.s2 / np.where(good, perp, 1.0)),
                  1.0)
    # the fits without the column, of the residual plus -b0, 0 and b0 times it
    bs = np.stack([-b0, 0.0 * b0, b0], axis=1)  # (m, 3)
    f = scorer._fit(np.broadcast_to(G0[:, None], (m, 3) + G0.shape[1:]),
                    h0[:, None] + bs[:, :, None, None] * gx[:, None],
                    np.broadcast_to(ptol[:d], (m, 3, d)), np.broadcast_to(cen[:d], (m, 3, d)))
    drr = 2 * bs[:, :, None] * xr[:, None] + bs[:, :, None] ** 2 * xx[:, None]  # (m, 3, K)
    sse3 = f["sse_b"] + drr
    grid = 2.0 ** (np.arange(-24, 49) / 8.0)  # b0/8 to 64*b0, 9 % apart
    G = grid.size
    # all columns and sizes at once: (m, 2G) sizes, either sign, in units of b0
    qs = _quadratic(np.moveaxis(sse3, 1, 0), b0[:, None])  # each (m, K)
    qp = _quadratic(np.moveaxis(f["prior"], 1, 0), b0)  # each (m,)
    held = new["b"][:, -1] / new["sc"][:, -1]  # what the residual holds along each x
    c = b0[:, None] * np.concatenate([grid, -grid])[None, :]
    add = c - held[:, None]  # what is added to the residual for a whole size c
    sse = (qs[0][:, None] + qs[1][:, None] * add[..., None]
           + qs[2][:, None] * add[..., None] ** 2)  # (m, 2G, K)
    prior = qp[0][:, None] + qp[1][:, None] * add + qp[2][:, None] * add ** 2
    n_sse = np.broadcast_to(new["sse_b"][:, None], sse.shape).copy()
    n_prior = np.broadcast_to(new["prior"][:, None], prior.shape).copy()
    for j, ft in enumerate(fits or []):
        if ft is not None and good[j]:
            n_sse[j], n_prior[j] = _fitted_along(scorer, terms, ft, xs[j], float(b0[j]),
                                                 add[j])
    unit = np.full(prior.shape, scorer.s2)
    if noise is not None:
        # an effect that is broadband in the record (a short pitch crossed at speed)
        # raises the noise floor the search reads with it, and so its own unit
        v0, floor_of = noise
        vx = np.array([floor_of(x) ** 2 for x in xs])
        unit = unit * (1.0 + c ** 2 * vx[:, None] / max(v0, 1e-300))
    gains = (sse - n_sse) / unit[..., None] + ((prior - n_prior) / K)[..., None]
    gain = (sse - n_sse).sum(-1) / unit + (prior - n_prior)
    acc = accept_many(gains.reshape(m * 2 * G, K), gain.reshape(-1), alpha=alpha,
                      min_gain=min_gain).reshape(m, 2 * G)
    ok = acc[:, :G] & acc[:, G:]  # for either sign
    # what the base cannot absorb of each column, per held-out block (as the search's
    # one-stretch rule reads it, from the products already at hand)
    q = scorer.J.shape[1]
    if q:
        GJ, gJ = G_b[:, :, :q, :q], gx[:, :, :q]
        beta = np.array([np.linalg.lstsq(GJ[j].sum(0), gJ[j].sum(0), rcond=None)[0]
                         for j in range(m)])
        e_blk = (xx - 2 * np.einsum("mki,mi->mk", gJ, beta)
                 + np.einsum("mi,mkij,mj->mk", beta, GJ, beta))
    else:
        e_blk = xx
    e_tot = e_blk.sum(1)
    one = (e_tot > 0) & (e_blk.max(1) > _ONE_BLOCK * np.where(e_tot > 0, e_tot, 1.0))
    for j in range(m):
        if not good[j] or not ok[j, -1] or one[j]:
            continue  # (one held-out stretch holding most of what it adds: never named)
        fail = np.flatnonzero(~ok[j])
        size = float(b0[j] * (grid[fail[-1] + 1] if fail.size else grid[0]))
        xm = xs[j][scorer.mask]
        rms = float(np.sqrt(np.mean(xm * xm))) if xm.size else 0.0
        out[j] = max(size, min_rms / rms) if rms > 0 else np.inf
    return out


def _fitted_along(scorer: Scorer, terms: list[Term], ft: Term, x: np.ndarray, b0: float,
                  add: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Held-out block errors ``(len(add), K)`` and prior costs of the fit with
    the term ``ft`` when ``add`` times ``x`` is added to the residual: read from the fits
    at ``-b0``, 0 and ``b0`` (a fit is linear in its residual, so these are quadratic)."""
    G, h, ptol, cen = scorer._assemble(terms + [ft, Term(cand=None, h=None, X=x[:, None])])
    d = G.shape[-1] - 1
    gx, xx, xr = G[:, :d, d], G[:, d, d], h[:, d]
    bs = np.array([-b0, 0.0, b0])
    f = scorer._fit(np.broadcast_to(G[:, :d, :d], (3,) + G[:, :d, :d].shape),
                    h[None, :, :d] + bs[:, None, None] * gx[None],
                    np.broadcast_to(ptol[:d], (3, d)), np.broadcast_to(cen[:d], (3, d)))
    drr = 2 * bs[:, None] * xr[None] + bs[:, None] ** 2 * xx[None]  # (3, K)
    qs = _quadratic(f["sse_b"] + drr, b0)
    qp = _quadratic(f["prior"], b0)
    a = np.asarray(add)
    sse = qs[0][None] + qs[1][None] * a[:, None] + qs[2][None] * a[:, None] ** 2
    return sse, qp[0] + qp[1] * a + qp[2] * a ** 2


def _quadratic(v: np.ndarray, h: Any) -> tuple[Any, Any, Any]:
    """Coefficients ``(a, b, c)`` of ``a + b*s + c*s^2`` through the values ``v`` at
    ``s = -h, 0, h`` (along the first axis)."""
    vm, v0, vp = v[0], v[1], v[2]
    return v0, (vp - vm) / (2 * h), (vp + vm - 2 * v0) / (2 * h ** 2)


def verdict(dg: Any) -> str:
    """The verdict in one paragraph: what is wrong, how sure, what to do next."""
    hb, ha = dg.fit.get("holdout_before"), dg.fit.get("holdout_after")
    gain = ""
    carries = True
    if hb and ha and hb.get("rms_force"):
        gain = (f" On the held-out record the {U.force_words()} error goes from "
                f"{hb['rms_force']:.3g} to {ha['rms_force']:.3g} {U.si('N')} rms "
                f"({100 * (ha['rms_force'] / hb['rms_force'] - 1):+.0f} %).")
        carries = not ha["rms_force"] > 1.1 * hb["rms_force"]
        if not carries:
            # the refit describes this record and not the held-out one: a record unlike
            # its hold-out (an unstable stretch, a changed setup) or a refit gone astray
            gain += (" The refit does not carry over to the held-out record: keep the "
                     "model as given, and check this record against the held-out one "
                     "(an unstable or saturated stretch, another setup or temperature) "
                     "before using the augmented model.")
    gone = getattr(dg, "removed", [])
    rebased = getattr(dg, "rebased", None)
    head = (rebased["text"][0].upper() + rebased["text"][1:] + ". ") if rebased else ""
    if rebased and rebased.get("holdout_given") and ha:
        head += (f"On the held-out record the model as given misses by "
                 f"{rebased['holdout_given']['rms_force']:.3g} {U.si('N')} rms, the refitted "
                 f"base with what is found below by {ha['rms_force']:.3g} {U.si('N')}. ")
    if not gone:
        return head + _verdict_findings(dg, gain, carries=carries)
    # the model's own effects that the record contradicts come first: they are what the
    # user wrote, and the augmented model leaves them out
    def listed(rs: list[dict[str, Any]], who: str = "its") -> str:
        return ", ".join(f"{who} {U.words(r['effect'].replace('_', ' '))} "
                         f"({effect_words(r['effect'], r['parameters'])})" for r in rs)

    out = []
    left = [r for r in gone if not r.get("replaced")]
    swapped = [r for r in gone if r.get("replaced")]
    if left:
        out.append(f"The model as given holds what this record contradicts: {listed(left)}; "
                   f"{'it is' if len(left) == 1 else 'they are'} left out of the augmented "
                   "model.")
    if swapped:
        out.append(f"{listed(swapped, 'The model' + chr(39) + 's')} "
                   f"{'does' if len(swapped) == 1 else 'do'} not match this record: searched "
                   "again without it, the record holds another of its kind (below), which "
                   "replaces it.")
    one = len(gone) == 1
    return head + " ".join(out) + " " + _verdict_findings(
        dg, gain, f"without {'it' if one else 'them'}", carries=carries)


def _verdict_findings(dg: Any, gain: str, without: str = "", carries: bool = True) -> str:
    """The findings' part of the verdict; ``carries``: the refit carries over to the
    held-out record (else ``gain`` already says to check first, and no "add them")."""
    if not dg.findings:
        txt = ("Nothing found: the model leaves nothing out that this record can show."
               if not without else
               f"Nothing else found: the model {without} leaves nothing out that this "
               "record can show.")
        if dg.base_moves:
            txt = ("No missing physics found, but the model's base parameters are off: "
                   + "; ".join(m["text"] for m in dg.base_moves) + ".")
        if dg.unexplained:
            txt = ("Unexplained: the model misses this record, but no effect of the "
                   "vocabulary accounts for it. " + dg.unexplained["message"])
        return txt + gain
    names = ", ".join(f"{U.words(f.effect)} ({_params(f)})" for f in dg.findings)
    one = len(dg.findings) == 1
    if not carries:
        txt = f"Found on this record: {names}.{gain}"
    else:
        txt = (f"Found: {names}.{gain} Add {'it' if one else 'them'} to the model (the "
               f"augmented model has {'it' if one else 'them'}).")
    if any(f.alternatives for f in dg.findings):
        txt += " Some have a look-alike this record cannot rule out: see each finding."
    if dg.unexplained:
        txt += " A rest stays unexplained: " + dg.unexplained["message"]
    return txt


def _params(f: Any) -> str:
    return effect_words(f.effect, f.parameters)


def effect_words(effect: str, parameters: dict[str, Any]) -> str:
    """An effect's parameters in a few words with the axis's units ("amplitude 1 N,
    ...")."""
    if is_timing(effect):
        return timing_words(effect, parameters)
    spec = EFFECTS.get(effect)
    units = spec.units if spec is not None else {}
    parts = []
    for k, v in parameters.items():
        if isinstance(v, (int, float)):
            parts.append(f"{k} {v:.3g}{' ' + U.si(units[k]) if units.get(k) else ''}")
    sc, pos = parameters.get("scale"), parameters.get("positions")
    if sc and pos:  # a level along the stroke: its largest change
        sc = np.asarray(sc)
        j = int(np.argmax(np.abs(sc - 1)))
        parts.append(f"level x{sc[j]:.3g} at x = {pos[j]:.3g} {U.si('m')}")
    return ", ".join(parts)


def _speed(v: float) -> str:
    """A low speed [SI] in the display unit (mm/s, or rad/s on a rotary axis)."""
    u, k = U.display("m/s")
    return f"{v * k:.2g} {u}"
