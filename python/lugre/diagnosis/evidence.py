"""Evidence in words: held-out gains, the offset against asymmetric levels, what a record
determines of a drift, the motor force at rest, and the experiments that separate
look-alikes."""

from __future__ import annotations

from functools import partial
from typing import Any

import numpy as np

from ..model import Model
from . import base as B
from . import residual as R
from .search import Scorer, Term

__all__ = ["EXPERIMENT", "drift_identifiability", "evidence", "offset_alternative",
           "rest_evidence"]


EXPERIMENT = {
    ("delay", "current_lag"): (
        "drive the axis at rest with a current step or a chirp up to a few hundred Hz and "
        "compare force (or acceleration) and current: a pure delay shifts the phase "
        "linearly with frequency at constant gain, a first-order lag attenuates the gain "
        "by 3 dB at its bandwidth"
    ),
    ("offset", "asymmetry"): (
        "hold the axis at rest under position control at several positions, approaching "
        "each from both sides: a constant force shows as a steady holding current whose "
        "mean over the two approaches is the offset, an asymmetric Coulomb level gives "
        "holding currents that average to zero"
    ),
    ("mass", "force_friction"): (
        "record moves whose decelerations the drive must brake (short strokes at high "
        "acceleration, or a vertical axis moving down): a payload is the same mass "
        "speeding up and braking, a friction that grows with the drive force reads as a "
        "heavier axis speeding up and a lighter one braking"
    ),
}

#: Coulomb/static levels an offset shifts: +F forward, -F backward (the friction of the
#: CONTRACT opposes the motion, the offset adds to the force the motor must give).
_OFFSET_LEVELS = {"positive.fc": 1.0, "positive.fs": 1.0, "negative.fc": -1.0,
                  "negative.fs": -1.0}


def _moves(beta: np.ndarray, names: list[str], tol: np.ndarray) -> dict[str, float]:
    """Base changes in units of their tolerance (prior standard deviation)."""
    return {n: float(b / t) for n, b, t in zip(names, beta, tol)}


def offset_alternative(scorer: Scorer, terms: list[Term], ev: Any, names: list[str],
                        tol: np.ndarray, model: Model, sig: R.Signals, min_gain: float
                        ) -> tuple[dict[str, Any] | None, str]:
    """Weigh the offset against per-direction Coulomb/static levels (parsimony).

    The same data are fitted once with the offset and once without it (the base
    levels free); the held-out errors are compared, and the base moves of each story
    are counted in units of their tolerance. Returns the alternative (when the two fit
    about equally well on held-out data) and a sentence for the evidence.
    """
    k = next(j for j, t in enumerate(terms) if t.effect == "offset")
    rest = [t for t in terms if t.effect != "offset"]
    # the alternative at its best: Coulomb/static levels free (flat prior)
    free_tol = np.array([t * (1e3 if n in _OFFSET_LEVELS else 1.0) for n, t in zip(names, tol)])
    alt = scorer.like(tol=free_tol).evaluate(rest)
    q = len(names)
    m_off = _moves(ev.beta[:q], names, tol)
    m_alt = _moves(alt.beta[:q], names, tol)
    cost_off = float(sum(v * v for v in m_off.values()))
    cost_alt = float(sum(v * v for v in m_alt.values()))
    big_alt = {n: v for n, v in m_alt.items() if abs(v) >= 1.0}
    big_off = {n: v for n, v in m_off.items() if abs(v) >= 1.0}
    d_fit = float((alt.sse_b.sum() - ev.sse_b.sum()) / scorer.s2)
    start = q + sum(t.X.shape[1] for t in terms[:k])
    force = float(ev.beta[start])
    levels = {n: B.get_base(model, n) + ev.beta[names.index(n)]
              for n in _OFFSET_LEVELS if n in names}
    alt_levels = {n: B.get_base(model, n) + alt.beta[names.index(n)]
                  for n in _OFFSET_LEVELS if n in names}
    alt_txt = ", ".join(f"{n} {v:.3g} N" for n, v in alt_levels.items())
    verdict = ("fit the held-out blocks about as well" if d_fit <= 3.0 * min_gain else
               f"fit the held-out blocks worse by {d_fit:.0f} (chi-square)")
    txt = (f"Parsimony: one parameter (offset {force:.3g} N, {len(big_off)} base parameters "
           f"moved by over one tolerance, sum of squared moves {cost_off:.0f}) against "
           f"asymmetric Coulomb/static levels ({alt_txt}), which move {len(big_alt)} base "
           f"parameters by over one tolerance (sum of squared moves {cost_alt:.0f}) and "
           f"{verdict}.")
    rest_txt = rest_evidence(sig)
    if rest_txt:
        txt += " " + rest_txt
    if d_fit > 3.0 * min_gain:
        return None, txt
    return {
        "effect": "asymmetric_friction",
        "parameters": {**{n: float(v) for n, v in alt_levels.items()},
                       "moves_in_tolerances": {n: round(v, 2) for n, v in big_alt.items()}},
        "note": (f"Coulomb/static levels shifted by direction ({alt_txt}, against "
                 f"{', '.join(f'{n} {v:.3g} N' for n, v in levels.items())} with the "
                 "offset) fit the motion about as well but move more parameters"),
        "experiment": EXPERIMENT[("offset", "asymmetry")],
    }, txt


def drift_identifiability(term: Term, T: float, thr: float = 10.0
                           ) -> tuple[dict[str, Any], str]:
    """What a record determines of a drift: intervals from the held-out profile over tau.

    Over a record short against the time constant, gain and time constant trade off and
    only the change over the record (a trend) is determined. The interval is the set of
    time constants whose held-out score lies within ``thr`` of the best (the selection
    threshold on the coloured chi-square scale, at the resolution of the grid); the time
    constant counts as determined when that interval closes inside the record.
    """
    pr = term.profile
    if pr is None:
        return {}, ""
    h, sc, beta = pr["h"], pr["score"], pr["beta"]
    ok = sc <= sc.min() + thr
    g = -beta[ok, 0]
    taus = h[ok]
    lo, hi = float(taus.min()), float(taus.max())
    open_hi = hi >= 0.999 * pr["grid_max"]
    open_lo = lo <= 1.001 * pr["grid_min"]
    determined = not open_hi and not open_lo and hi <= T
    rate = g / taus
    total = g * (1.0 - np.exp(-T / taus))
    unc = {"time_constant": [lo, None if open_hi else hi],
           "gain": [float(g.min()), float(g.max())],
           "initial_rate_per_s": [float(rate.min()), float(rate.max())],
           "change_over_record": [float(total.min()), float(total.max())],
           "mean_rate_per_s": [float(total.min() / T), float(total.max() / T)],
           "time_constant_determined": bool(determined),
           "criterion": f"held-out score within {thr:g} of the best"}
    if not determined:
        txt = (f"Over the {T:.3g} s record the Coulomb/static level falls by "
               f"{100 * total.min():.2g} to {100 * total.max():.2g} % "
               f"({100 * total.min() / T:.2g} to {100 * total.max() / T:.2g} %/s on average); "
               f"the time constant is not determined (from {lo:.3g} s to "
               f"{'beyond the grid' if open_hi else f'{hi:.3g} s'}: gain and time constant "
               "trade off), the pair reported is the best on the grid.")
    else:
        txt = (f"Time constant {lo:.3g} to {hi:.3g} s and gain {g.min():.3g} to "
               f"{g.max():.3g} fit within {thr:g} of the best held-out score; the level "
               f"falls by {100 * total.min():.2g} to {100 * total.max():.2g} % over the "
               "record.")
    return unc, txt


def rest_evidence(sig: R.Signals, min_s: float = 0.2) -> str:
    """Mean motor force in stretches at rest (entered from either side), if any."""
    still = (sig.v == 0.0) & sig.mask
    n_min = int(min_s * sig.fs)
    runs = []
    k = 0
    n = still.size
    while k < n:
        if still[k]:
            j = k
            while j < n and still[j]:
                j += 1
            if j - k >= n_min:
                runs.append((k, j))
            k = j
        else:
            k += 1
    if not runs:
        return ""
    means = [float(np.mean(sig.fm_f[a:b])) for a, b in runs]
    tot = sum(b - a for a, b in runs) / sig.fs
    return (f"At rest ({len(runs)} stretches, {tot:.2g} s) the motor force averages "
            f"{np.mean(means):.3g} N (friction can hold any force up to the static level "
            "there, so this bounds rather than measures the offset).")


def evidence(t: Term, log: dict[str, Any], K: int, extra: str = "") -> str:
    """The evidence of a finding in two or three sentences a person can check."""
    sig_txt = f"{t.cand.signature[0].upper()}{t.cand.signature[1:]}."
    if log:
        sig_txt += (f" Fitted with the friction levels on nine tenths of the record, it "
                    f"predicts the tenth left out better in {log['positive']} of {K} such "
                    f"stretches (chance of this from noise alone: p = {log['p']:.1g}).")
    return sig_txt + (" " + extra if extra else "")


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
                  "tolerance": rel, "unit": B.unit(n), "status": status}
    out["sigma1"]["presliding_test"] = {k: presliding[k] for k in
                                        ("gain", "min_gain", "alpha", "p", "positive",
                                         "blocks", "free")
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
                        "text": (f"{n} {d:+.3g} {b['unit']} ({100 * b['change']:+.0f} %, from "
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
        notes.append(
            "sigma0 and sigma1 (presliding stiffness and damping) are held at the model's "
            f"values: {why}, so this record does not determine them. To determine them: "
            "small back-and-forth moves below the breakaway force (presliding, a few "
            "micrometres) or a small-amplitude current sweep at standstill, logged at "
            "1 kHz or faster.")
    bp, bn = base["positive.fc"]["after"], base["negative.fc"]["after"]
    if not any(f.effect == "offset" for f in findings) and abs(bp - bn) > 0.1 * (bp + bn) / 2:
        notes.append(
            f"The Coulomb levels differ by direction ({bp:.3g} N forward, {bn:.3g} N "
            f"backward); a constant force of {(bp - bn) / 2:.3g} N with a symmetric level "
            f"would fit the motion equally well. To separate: "
            f"{EXPERIMENT[('offset', 'asymmetry')]}.")
    return notes


def reversals(sig: R.Signals, window: float = 0.05) -> tuple[np.ndarray, int]:
    """Samples within ``window`` seconds of a reversal of the motion (a change of sign
    of the filtered velocity beyond 2 % of its peak), and the number of reversals."""
    vf = np.where(sig.mask, sig.vf, 0.0)
    vmax = float(np.max(np.abs(vf)))
    rev = np.zeros(vf.size, dtype=bool)
    s = np.sign(np.where(np.abs(vf) > 0.02 * vmax, vf, 0.0))
    nz = np.flatnonzero(s)
    flips = nz[1:][s[nz[1:]] != s[nz[:-1]]]
    w = max(int(window * sig.fs), 3)
    for j in flips:
        rev[max(j - w, 0):j + w] = True
    return rev & sig.mask, int(flips.size)


def _start(scorer: Scorer, terms: list[Term], k: int) -> int:
    """Index of the first coefficient of ``terms[k]`` in a fit's ``beta``."""
    return scorer.J.shape[1] + sum(t.X.shape[1] for t in terms[:k])


def _refit_on(scorer: Scorer, terms: list[Term], k: int, sel: np.ndarray,
              nuisance: list[Term] | None = None) -> tuple[float, float] | None:
    """The first coefficient of ``terms[k]`` refitted, jointly with the base and the
    other terms (and the ``nuisance`` terms, whose share of its column it does not
    claim), on the samples ``sel`` alone, and its standard error; None when those
    samples hold nothing of its column."""
    x = terms[k].X[sel, 0]
    if nuisance:  # (their share of the column is not the term's)
        N = np.column_stack([t.X[sel, 0] for t in nuisance])
        x = x - N @ np.linalg.lstsq(N, x, rcond=None)[0]
        terms = list(terms) + list(nuisance)
    sxx = float(np.sum(x ** 2))
    if not sxx > 0:
        return None
    ev = scorer.like(mask=sel, center=None).evaluate(terms)
    return float(ev.beta[_start(scorer, terms, k)]), float(np.sqrt(scorer.s2 / sxx))


def _rate_noise_power(sig: Any) -> float:
    """Mean square per sample of the recorded force's noise in its filtered rate of
    change (``sig.dfm``): the white level above the motion's band through the
    residual's low-pass and the central difference; 0 when it cannot be read."""
    # (the force is low-passed as the residual is; np.gradient's power response)
    return R.force_noise_power(sig, lambda ff: (np.sin(2 * np.pi * ff * sig.dt) / sig.dt) ** 2)


def lag_at_reversals(scorer: Scorer, terms: list[Term], k: int, ev: Any,
                     ctx: Any) -> dict[str, Any] | None:
    """Is the lag term ``terms[k]`` a time shift of the whole force, or a mismatch at
    the reversals only?

    A delay or a current lag shifts the motor force everywhere: between reversals too,
    wherever the force changes (accelerations). Lost motion (backlash between motor
    and load, a presliding stage the model does not hold) fits a lag at the reversals
    alone. The lag is refitted, jointly with the base and the other terms, on the
    samples more than 50 ms from any reversal; when that record determines it (its
    standard error a quarter of the full fit's lag or less) and it is under half the
    full fit's, more than four standard errors below, the lag is a reversal mismatch.
    A mass error is fitted beside it there when no mass term is in (the believed mass
    is never exact, and between reversals the force changes with the acceleration).
    Returns the figures, or None when the record cannot tell.
    """
    sig = ctx.sig
    rev, nrev = reversals(sig)
    away = scorer.mask & ~rev
    if nrev == 0 or away.sum() < 0.2 * scorer.mask.sum():
        return None
    tau = float(ev.beta[_start(scorer, terms, k)])
    nuisance = None
    if not any(t.effect == "mass" for t in terms if t.cand is not None):
        from .effects import Mass

        nuisance = [Term(cand=Mass(), h=None, X=Mass().columns(None, ctx))]
    fit = _refit_on(scorer, terms, k, away, nuisance) if tau > 0 else None
    if fit is None:
        return None
    tau_away, se = fit
    # the lag's column is the recorded force's rate of change, and the current's own
    # noise in it pulls the fitted lag toward zero by the noise's share of the column
    # (errors in variables): little at the reversals, where the force changes fast,
    # much between them. Both fits are corrected; where the noise is most of the
    # column there, those samples cannot tell
    nn = _rate_noise_power(sig)

    def share(sel: np.ndarray) -> float:  # the noise's share of the column there
        sxx = float(np.sum(sig.dfm[sel] ** 2))
        return sel.sum() * nn / sxx if sxx > 0 else 1.0

    if nn > 0.0:
        s_away = share(away)
        if s_away > 0.75:
            return None
        tau = float(tau / (1.0 - min(share(scorer.mask), 0.75)))
        tau_away, se = float(tau_away / (1.0 - s_away)), float(se / (1.0 - s_away))
    return {"lag_s": tau, "lag_away_s": tau_away, "se_s": se, "reversals": nrev,
            "reversals_only": bool(se < 0.25 * tau and tau_away < 0.5 * tau
                                   and tau - tau_away > 4.0 * se)}


def mass_both_ways(scorer: Scorer, terms: list[Term], k: int, ev: Any,
                   ctx: Any) -> dict[str, Any] | None:
    """Is the mass term ``terms[k]`` a payload, the same mass speeding up and braking?

    A payload adds ``delta*a`` whichever way the force points. A friction that grows
    with the force the drive transmits (a preloaded nut, a guide loaded by the drive)
    adds ``mu*|F|`` against the motion: like a heavier axis while the axis speeds up,
    like a lighter one while the drive brakes it. The term is refitted, jointly with the
    base and the other terms, on the samples where the drive speeds the axis up
    (``F*v > 0`` and ``a*v > 0``) and on those where it brakes (``F*v < 0``); when both
    determine it (standard errors under a quarter of the full fit's) and they differ by
    more than four combined standard errors and by more than half the full fit, the
    term is no payload. Returns the figures, or None when the record cannot tell.
    """
    sig = ctx.sig
    m = scorer.mask
    fv = sig.fm_f * sig.vf
    up = m & (fv > 0) & (sig.a * sig.vf > 0)
    brake = m & (fv < 0)
    if up.sum() < 0.05 * m.sum() or brake.sum() < 0.05 * m.sum():
        return None
    full = float(ev.beta[_start(scorer, terms, k)])
    out: dict[str, Any] = {"delta_kg": full}
    for name, sel in (("speeding_up", up), ("braking", brake)):
        fit = _refit_on(scorer, terms, k, sel)
        if fit is None:
            return None
        out[name], out[name + "_se"] = fit
    a, b = out["speeding_up"], out["braking"]
    se = float(np.hypot(out["speeding_up_se"], out["braking_se"]))
    out["not_payload"] = bool(max(out["speeding_up_se"], out["braking_se"]) < 0.25 * abs(full)
                              and abs(a - b) > 4.0 * se and abs(a - b) > 0.5 * abs(full))
    return out


def deadband_braking(scorer: Scorer, terms: list[Term], k: int, ev: Any,
                     ctx: Any) -> dict[str, Any] | None:
    """Is the dead-band term ``terms[k]`` a dead-band, the same where the drive brakes?

    A dead-band takes force away along the current: wherever the current is over the
    band, the logged force is ``b`` more than what acts, in the current's direction.
    More friction than the model holds also needs more force, but along the motion.
    The two agree while the drive pushes the axis along (force and velocity of one
    sign, most of a record) and part while it brakes: there a dead-band still takes
    force along the current, against the motion. The term is refitted, jointly with
    the base and the other terms, on the samples where the drive brakes the moving axis
    (``F*v < 0``); when they determine it (standard error under a quarter of the full
    fit's) and it differs from the full fit by more than four standard errors and by
    more than half, no one dead-band explains both: the term stands for something else
    (a friction bump on part of the stroke read 0.56 of its band overall and 2.0 +- 0.13
    braking; dead-bands of 2-150 mA on the generator read within 0.35 and 5 standard
    errors). Returns the figures, or None when the record cannot tell.
    """
    sig = ctx.sig
    m = scorer.mask
    vmax = float(np.max(np.abs(sig.vf[m])))
    brake = m & (sig.fm_f * sig.vf < 0) & (np.abs(sig.vf) > 0.02 * vmax)
    full = float(ev.beta[_start(scorer, terms, k)])
    # (braking is rare where friction stops the axis: the standard error decides)
    fit = _refit_on(scorer, terms, k, brake) if full > 0 and brake.sum() >= 20 else None
    if fit is None:
        return None
    b, se = fit
    return {"coefficient": full, "braking": b, "braking_se": se,
            "not_deadband": bool(se < 0.25 * full and abs(b - full) > 4.0 * se
                                 and abs(b - full) > 0.5 * full)}


def mass_alternative(delta: float, mass: float, ctx: Any,
                     mask: np.ndarray) -> dict[str, Any] | None:
    """A named mass the record cannot tell from a friction growing with the drive force.

    Where the drive almost never brakes the axis (``F*v < 0`` on under 5 % of the
    samples), ``mu*|F|`` against the motion equals ``mu*F = mu*m*a + mu*friction``: a
    payload ``mu*m`` beside friction levels ``mu`` higher, which the base refit takes.
    :func:`mass_both_ways` cannot test it then; the finding says so. None when the
    record holds enough braking, or the term is a lighter axis (``mu`` would be < 0).
    """
    sig = ctx.sig
    m = mask & np.isfinite(sig.fm_f)
    brake = float(np.mean((sig.fm_f * sig.vf)[m] < 0)) if m.any() else 0.0
    if brake >= 0.05 or delta <= 0:
        return None
    return {"effect": "friction growing with the drive force (outside the vocabulary)",
            "parameters": {"mu": float(delta / mass), "braking_share": brake},
            "experiment": EXPERIMENT[("mass", "force_friction")]}


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
            f"the residual's noise floor, {excess['floor']:.2g} N, is "
            f"{excess['floor'] / excess['expected']:.0f} times what the recorded current's "
            f"noise and the position reading's noise explain ({excess['expected']:.2g} "
            "N, both measured above the motion's band): mismatch spread over the whole "
            "band is counted as noise (impacts, e.g. at the reversals; an error of the "
            "position reading periodic in position, crossed at changing speeds; a ripple "
            "of the drive); effects under that floor stay hidden")
    if mass_ways is not None:
        shape.append(
            f"the acceleration force reads as {mass_ways['speeding_up']:+.2g} kg while the "
            f"drive speeds the axis up and {mass_ways['braking']:+.2g} kg while it brakes "
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
                    f"{frac * vtop * 1e3:.2g} mm/s ({100 * frac:g} % of the top speed, "
                    f"{100 * slow.mean():.1f} % of the time): "
                    f"{float(np.sqrt(np.mean(rr[slow] ** 2))):.3g} N rms there against "
                    f"{fast:.3g} N faster. The friction at standstill and low speed (static "
                    "friction, breakaway, the Stribeck fall, presliding) is unlike the model's: "
                    "a slow current ramp at standstill in both directions, and constant-speed "
                    "passes at a few mm/s, measure it")
                break
    if d.get("positive") and d.get("negative"):
        ratio = d["positive"] / d["negative"]
        if ratio > 1.5 or ratio < 1 / 1.5:
            shape.append(f"it is {'larger moving forward' if ratio > 1 else 'larger moving backward'}"
                         f" ({d['positive']:.3g} N against {d['negative']:.3g} N rms)")
    parts = [f"{k} {short_ranges(where[k])}" for k in ("time", "position", "velocity")
             if where.get(k)]
    msg = (f"after the findings the residual is still {rms1:.3g} N rms, {rms1 / floor:.1f} "
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

    def sizes(Xs: list[np.ndarray], effect: str) -> np.ndarray:
        # (a minor correction of the same kind, kept in the fit, is part of the effect)
        rest = [t for t in found_terms if t.cand is None or t.effect != effect]
        floor = max(min_effect * noise_rms, 0.0 if effect == "delay" else min_force)
        out = revealed_sizes(scorer, rest, Xs, alpha=alpha, min_gain=min_gain,
                             min_rms=floor)
        # a lag under a fifth of the sample interval is a detail of the sampling
        dt = sig.info.get("dt_logged", sig.dt)  # the record's own sample interval
        return np.maximum(out, 0.2 * dt) if effect == "delay" else out

    def size(X: np.ndarray, effect: str) -> float:
        return float(sizes([X], effect)[0])

    out: list[dict[str, Any]] = []
    span = ctx.xrange[1] - ctx.xrange[0]
    for c in cands:
        if c.effect in found:
            continue
        e = c.effect
        try:
            if e == "offset":
                b = size(np.ones(len(sig)), e)
                out.append(_hide(e, b, "N", f"a constant force {_under(b, '{:.2g} N')}", experiment=(
                    "per-direction friction levels absorb a constant force while the axis "
                    "moves; " + EXPERIMENT[("offset", "asymmetry")].split(":")[0]
                    + " separates them")))
            elif e == "spring":
                b = size(sig.x - np.mean(sig.x[sig.mask]), e)
                out.append(_hide(e, b, "N/m", f"a spring {_under(b, '{:.3g} N/m')}"
                                 + (f" ({b * span:.2g} N over the stroke)" if np.isfinite(b) else "")))
            elif e == "mass":
                b = size(sig.a, e)
                out.append(_hide(e, b, "kg", f"a payload {_under(b, '{:.2g} kg')}"))
            elif e == "drag":
                b = size(sig.filt(np.abs(sig.v) * sig.v), e)
                out.append(_hide(e, b, "N s^2/m^2", f"a drag {_under(b, '{:.3g} N s^2/m^2')}"))
            elif e == "cogging":
                kmax = c.kmax(ctx)
                ks = np.geomspace(1.5 / max(span, 1e-9), max(kmax, 2.0 / max(span, 1e-9)), 8)
                amps = sizes([sig.filt(np.sin(2 * np.pi * k * sig.x)) for k in ks], e)
                seen = np.isfinite(amps)
                b = float(np.max(amps[seen])) if seen.any() else float("inf")
                blind = ""
                if seen.any() and not seen.all():
                    pb = 1e3 / ks[~seen]
                    blind = (f" (of any size at pitches near {pb.min():.3g} to {pb.max():.3g} "
                             "mm: what the friction levels cannot absorb lies in one "
                             "held-out stretch)")
                txt = (f"a cogging {_under(b, '{:.2g} N')} at pitches {1e3 / ks[-1]:.3g} to "
                       f"{1e3 / ks[0]:.3g} mm{blind}, or any at pitches under "
                       f"{1e3 / kmax:.3g} mm (faster than the filter band at this record's "
                       "slowest motion),")
                out.append(_hide(e, b, "N", txt, experiment=(
                    "slow constant-speed passes (a few mm/s) show short pitches")))
            elif e == "delay":
                b = size(sig.dfm, e)
                out.append(_hide("delay/current_lag", b, "s",
                                 f"a delay or current lag {_under(b * 1e3, '{:.2g} ms')}"))
            elif e == "drift":
                b = _share(size((sig.t / max(sig.t[-1], 1e-9)) * ctx.fcs, e))
                out.append(_hide(e, b, "-", f"a friction drift {_under(100 * b, '{:.2g} %')} over the "
                                 "record"))
            elif e == "position_friction":
                b = _share(size(sig.filt(ctx.fcs * (np.abs(sig.x - np.mean(sig.x))
                                                    < 0.1 * span)), e))
                out.append(_hide(e, b, "-", f"a friction change {_under(100 * b, '{:.2g} %')} over a "
                                 "tenth of the stroke"))
            elif e in ("stribeck_shape", "deadband", "resonance"):
                out.append(_nonlinear_hidden(c, ctx, partial(sizes, effect=e)))
        except (ValueError, ArithmeticError, np.linalg.LinAlgError):  # pragma: no cover
            continue
    return [o for o in out if o is not None]


def revealed_sizes(scorer: Scorer, terms: list[Term], Xs: list[np.ndarray], *,
                   alpha: float, min_gain: float, min_rms: float = 0.0) -> np.ndarray:
    """The smallest size ``b`` at which an effect ``b*X`` in this record would pass the
    search's acceptance test (:func:`~lugre.diagnosis.search.accept` on the held-out
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
    """
    from .search import _ONE_BLOCK, accept_many

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
    score3 = f["score"] + drr.sum(-1) / scorer.s2
    grid = 2.0 ** (np.arange(-24, 49) / 8.0)  # b0/8 to 64*b0, 9 % apart
    G = grid.size
    # all columns and sizes at once: (m, 2G) sizes, either sign, in units of b0
    qs = _quadratic(np.moveaxis(sse3, 1, 0), b0[:, None])  # each (m, K)
    qp = _quadratic(np.moveaxis(f["prior"], 1, 0), b0)  # each (m,)
    qc = _quadratic(np.moveaxis(score3, 1, 0), b0)
    held = new["b"][:, -1] / new["sc"][:, -1]  # what the residual holds along each x
    c = b0[:, None] * np.concatenate([grid, -grid])[None, :]
    add = c - held[:, None]  # what is added to the residual for a whole size c
    sse = (qs[0][:, None] + qs[1][:, None] * add[..., None]
           + qs[2][:, None] * add[..., None] ** 2)  # (m, 2G, K)
    prior = qp[0][:, None] + qp[1][:, None] * add + qp[2][:, None] * add ** 2
    gains = ((sse - new["sse_b"][:, None]) / scorer.s2
             + ((prior - new["prior"][:, None]) / K)[..., None])
    gain = qc[0][:, None] + qc[1][:, None] * add + qc[2][:, None] * add ** 2 \
        - new["score"][:, None]
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


def _share(b: float) -> float:
    """A relative size: one the friction itself would have to change sign to reach (100 %
    or more) is no size the record reveals."""
    return b if b < 1.0 else float("inf")


def _under(b: float, fmt: str) -> str:
    """"under 0.3 N" for a finite size, "of any size" for none."""
    return "under " + fmt.format(b) if np.isfinite(b) else "of any size"


def _quadratic(v: np.ndarray, h: Any) -> tuple[Any, Any, Any]:
    """Coefficients ``(a, b, c)`` of ``a + b*s + c*s^2`` through the values ``v`` at
    ``s = -h, 0, h`` (along the first axis)."""
    vm, v0, vp = v[0], v[1], v[2]
    return v0, (vp - vm) / (2 * h), (vp + vm - 2 * v0) / (2 * h ** 2)


def _hide(effect: str, b: float, unit: str, what: str, rng: Any = None,
          experiment: str = "") -> dict[str, Any]:
    verb = "would not be seen in" if np.isfinite(b) else "cannot be seen in"
    return {"effect": effect, "smallest": b if np.isfinite(b) else None, "unit": unit,
            "range": rng, "experiment": experiment, "text": f"{what} {verb} this record"}


def _amps(a: float) -> str:
    return f"{a * 1e3:.3g} mA" if abs(a) < 1 else f"{a:.3g} A"


def _nonlinear_hidden(c: Any, ctx: Any, many: Any) -> dict[str, Any] | None:
    """What the record could hide of a nonlinear effect; ``many(Xs)`` the sizes of
    columns of it (:func:`revealed_sizes`)."""
    sig = ctx.sig
    if c.effect == "stribeck_shape":
        m = ctx.model
        hump = min(m.positive["fs"] / m.positive["fc"], m.negative["fs"] / m.negative["fc"])
        slow = float(np.mean(np.abs(sig.vf[sig.mask]) < 3 * min(m.positive["vs"],
                                                                  m.negative["vs"])))
        exp = ("steady slow feeds at 0.3 to 3 times the Stribeck velocity in both directions "
               "would show it")
        if hump < 1.02:
            return _hide(c.effect, float("inf"), "-", "the shape of the Stribeck curve (the "
                         "model has no static level above the Coulomb level, fs = fc)",
                         experiment=exp)
        b = float(many([c.columns(1.0, ctx)[:, 0]])[0])  # exponent 2 -> 1
        if not np.isfinite(b) or b > 5:
            return _hide(c.effect, float("inf"), "-", "the shape of the Stribeck curve",
                         experiment=exp)
        return _hide(c.effect, b, "-", f"a Stribeck exponent within {b:.2g} of 2",
                     experiment=exp if slow < 0.05 else "")
    if c.effect == "deadband":
        d0 = 0.02
        b = d0 * float(many([c.columns(d0, ctx)[:, 0]])[0])
        kf = ctx.model.force_constant
        return _hide(c.effect, b, "A", (f"a dead-band under {_amps(b)} ({b * kf:.2g} N of motor force)"
                     if np.isfinite(b) else "a dead-band of any size"))
    if c.effect == "resonance":
        g = c.grid(ctx)
        if g is None:
            return _hide(c.effect, float("inf"), "Hz", "a resonance",
                         experiment="the filter band is too narrow; record faster")
        fs = sorted({h[0] for h in g})
        pts = [(f, 0.05, 0.5) for f in fs]
        cols = c.columns_many(pts, ctx) or [c.columns(h, ctx) for h in pts]  # (in parallel)
        sizes = list(many([X[:, 0] for X in cols]))  # in units of the half-mass load's force
        hidden = [f for f, sz in zip(fs, sizes) if sz > 1.0]
        if not hidden:
            # the load's force grows about in proportion to its share of the mass
            b = 0.5 * float(max(sizes))
            return _hide(c.effect, b, "load fraction",
                         f"a resonance with under {100 * b:.2g} % of the mass behind its "
                         f"coupling (lightly damped, at {fs[0]:.3g} to {fs[-1]:.3g} Hz)")
        return _hide(c.effect, 0.5, "load fraction",
                     f"a resonance with half the mass on the coupling at {hidden[0]:.3g} to "
                     f"{hidden[-1]:.3g} Hz",
                     experiment=("the record's motion does not excite those frequencies; a "
                                 "current chirp from 5 Hz to the drive's bandwidth at rest, or "
                                 "fast reversals, would"))
    return None


def verdict(dg: Any) -> str:
    """The verdict in one paragraph: what is wrong, how sure, what to do next."""
    hb, ha = dg.fit.get("holdout_before"), dg.fit.get("holdout_after")
    gain = ""
    carries = True
    if hb and ha and hb.get("rms_force"):
        gain = (f" On the held-out record the force error goes from {hb['rms_force']:.3g} to "
                f"{ha['rms_force']:.3g} N rms ({100 * (ha['rms_force'] / hb['rms_force'] - 1):+.0f} %).")
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
                 f"{rebased['holdout_given']['rms_force']:.3g} N rms, the refitted base with "
                 f"what is found below by {ha['rms_force']:.3g} N. ")
    if not gone:
        return head + _verdict_findings(dg, gain, carries=carries)
    # the model's own effects that the record contradicts come first: they are what the
    # user wrote, and the augmented model leaves them out
    def listed(rs: list[dict[str, Any]], who: str = "its") -> str:
        return ", ".join(f"{who} {r['effect'].replace('_', ' ')} "
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
    names = ", ".join(f"{f.effect} ({_params(f)})" for f in dg.findings)
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
    """An effect's parameters in a few words with their units ("amplitude 1 N, ...")."""
    units = {"amplitude": "N", "pitch": "m", "phase": "rad", "stiffness": "N/m", "x0": "m",
             "force": "N", "delta": "kg", "seconds": "s", "bandwidth": "Hz",
             "gain": "", "time_constant": "s", "frequency": "Hz", "damping_ratio": "",
             "load_fraction": "", "current": "A", "coefficient": "N s^2/m^2",
             "exponent": ""}
    if effect in ("delay", "current_lag"):
        from .timing import timing_words

        return timing_words(effect, parameters)
    parts = []
    for k, v in parameters.items():
        if isinstance(v, (int, float)):
            parts.append(f"{k} {v:.3g}{' ' + units.get(k, '') if units.get(k) else ''}")
    if effect == "position_friction" and parameters.get("scale"):
        sc = np.asarray(parameters["scale"])
        j = int(np.argmax(np.abs(sc - 1)))
        parts.append(f"level x{sc[j]:.3g} at x = {parameters['positions'][j]:.3g} m")
    return ", ".join(parts)
