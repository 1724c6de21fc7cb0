"""Diagnosis driver: residual, base re-estimation, effect search, joint refit, report."""

from __future__ import annotations

import math
import time
import warnings
from typing import Any

import numpy as np

from .._native import simulate
from ..exceptions import DataError, InputError
from ..io import Recording
from ..model import Model, _as_model
from . import effects as E
from . import residual as R
from .report import Diagnosis, Finding
from .search import Scorer, Term, forward_select

__all__ = ["diagnose", "evaluate", "fit_inverse_dynamics", "locate"]

_EXPERIMENT = {
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
}

#: Coulomb/static levels an offset shifts: +F forward, -F backward (the friction of the
#: CONTRACT opposes the motion, the offset adds to the force the motor must give).
_OFFSET_LEVELS = {"positive.fc": 1.0, "positive.fs": 1.0, "negative.fc": -1.0,
                  "negative.fs": -1.0}


def _moves(beta: np.ndarray, names: list[str], tol: np.ndarray) -> dict[str, float]:
    """Base changes in units of their tolerance (prior standard deviation)."""
    return {n: float(b / t) for n, b, t in zip(names, beta, tol)}


def _offset_alternative(scorer: Scorer, terms: list[Term], ev: Any, names: list[str],
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
    alt = Scorer(scorer.r, scorer.J, free_tol, scorer.mask, scorer.s2, scorer.K,
                 center=scorer.center).evaluate(rest)
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
    levels = {n: E.get_base(model, n) + ev.beta[names.index(n)]
              for n in _OFFSET_LEVELS if n in names}
    alt_levels = {n: E.get_base(model, n) + alt.beta[names.index(n)]
                  for n in _OFFSET_LEVELS if n in names}
    alt_txt = ", ".join(f"{n} {v:.3g} N" for n, v in alt_levels.items())
    verdict = ("fit the held-out blocks about as well" if d_fit <= 3.0 * min_gain else
               f"fit the held-out blocks worse by {d_fit:.0f} (chi-square)")
    txt = (f"Parsimony: one parameter (offset {force:.3g} N, {len(big_off)} base parameters "
           f"moved by over one tolerance, sum of squared moves {cost_off:.0f}) against "
           f"asymmetric Coulomb/static levels ({alt_txt}), which move {len(big_alt)} base "
           f"parameters by over one tolerance (sum of squared moves {cost_alt:.0f}) and "
           f"{verdict}.")
    rest_txt = _rest_evidence(sig)
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
        "experiment": _EXPERIMENT[("offset", "asymmetry")],
    }, txt


def _drift_identifiability(term: Term, T: float, thr: float = 10.0
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


def _rest_evidence(sig: R.Signals, min_s: float = 0.2) -> str:
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


def _rec(recording: Any) -> Recording:
    if isinstance(recording, Recording):
        return recording
    from ..io import read_recording

    if isinstance(recording, (str, bytes)) or hasattr(recording, "__fspath__"):
        return read_recording(recording)
    raise InputError.at("recording", "give a lugre.Recording or the path of a recording")


def _metrics(r: np.ndarray, f: np.ndarray, mask: np.ndarray) -> dict[str, float]:
    rr = r[mask]
    ff = f[mask]
    rms = float(np.sqrt(np.mean(rr * rr)))
    rf = float(np.sqrt(np.mean(ff * ff)))
    return {"rms_force": rms, "nrmse_force": rms / rf if rf > 0 else math.nan}


def evaluate(recording: Any, model: Any, *, cutoff_hz: float | None = None) -> dict[str, float]:
    """Inverse-dynamics force residual of a recording against a model.

    ``r = K_F*i - m*a - F_friction - sum(F_effect)`` with every term low-passed by the
    same zero-phase filter, ``a`` from the filtered position and the bristle state
    driven by the measured velocity.

    Parameters
    ----------
    recording : Recording or path
        The recording.
    model : Model, dict or path
        The model (its effects included).
    cutoff_hz : float, optional
        Low-pass cut-off (default ``fs/25``).

    Returns
    -------
    dict
        ``rms_force`` [N], ``nrmse_force`` (rms residual over rms motor force),
        ``noise_floor`` [N], ``samples``, ``cutoff_hz``.
    """
    rec = _rec(recording)
    m = _as_model(model)
    R.check_recording(rec, m)
    sig = R.prepare(rec, m, cutoff_hz=cutoff_hz)
    R.check_units(sig, m)
    r = R.residual(m, sig)
    out = _metrics(r, sig.fm_f, sig.mask)
    out["noise_floor"] = R.noise_floor(r, sig)["rms"]
    out["samples"] = len(sig)
    out["cutoff_hz"] = sig.cutoff_hz
    return out


# --------------------------------------------------------------------------------------
# Locating the residual
# --------------------------------------------------------------------------------------


def _ranges(centers: np.ndarray, flag: np.ndarray, half: float) -> list[list[float]]:
    out: list[list[float]] = []
    start = None
    for k, f in enumerate(flag):
        if f and start is None:
            start = k
        if (not f or k == flag.size - 1) and start is not None:
            end = k if f else k - 1
            out.append([float(centers[start] - half), float(centers[end] + half)])
            start = None
    return out


def locate(r: np.ndarray, sig: R.Signals, floor: float, *, factor: float = 2.0
           ) -> dict[str, Any]:
    """Where the residual's rms rises above ``factor`` times the noise floor.

    Parameters
    ----------
    r : numpy.ndarray
        Residual [N].
    sig : Signals
        The prepared recording.
    floor : float
        Noise floor [N].
    factor : float, default 2.0
        Threshold over the floor.

    Returns
    -------
    dict
        ``time``, ``position``, ``velocity``: lists of ``[lo, hi]`` ranges;
        ``direction``: rms in motion forward, backward and at rest.
    """
    m = sig.mask
    out: dict[str, Any] = {"threshold": factor * floor}
    for key, val, nb in (("time", sig.t, 40), ("position", sig.x, 30), ("velocity", sig.vf, 20)):
        vv = val[m]
        rr = r[m]
        lo, hi = float(vv.min()), float(vv.max())
        if hi <= lo:
            out[key] = []
            continue
        edges = np.linspace(lo, hi, nb + 1)
        idx = np.clip(np.digitize(vv, edges) - 1, 0, nb - 1)
        cnt = np.bincount(idx, minlength=nb)
        ss = np.bincount(idx, weights=rr * rr, minlength=nb)
        rms = np.sqrt(ss / np.maximum(cnt, 1))
        flag = (rms > factor * floor) & (cnt >= 20)
        centers = 0.5 * (edges[1:] + edges[:-1])
        out[key] = _ranges(centers, flag, 0.5 * (edges[1] - edges[0]))
    vmax = float(np.max(np.abs(sig.vf[m])))
    direction = {}
    for name, sel in (("positive", sig.vf > 0.01 * vmax), ("negative", sig.vf < -0.01 * vmax),
                      ("rest", np.abs(sig.vf) <= 0.01 * vmax)):
        s = sel & m
        direction[name] = float(np.sqrt(np.mean(r[s] ** 2))) if s.sum() > 20 else None
    out["direction"] = direction
    return out


# --------------------------------------------------------------------------------------
# Diagnosis
# --------------------------------------------------------------------------------------


def _effects_of(terms: list[Term], betas: list[np.ndarray], ctx: E.Context
                ) -> list[dict[str, Any]]:
    out: list[dict[str, Any]] = []
    for t, b in zip(terms, betas):
        out.extend(t.cand.to_effects(t.h, b, ctx))
    return out


def _split(beta: np.ndarray, q: int, terms: list[Term]) -> tuple[np.ndarray, list[np.ndarray]]:
    k = q
    out = []
    for t in terms:
        p = t.X.shape[1]
        out.append(np.array(beta[k:k + p], dtype=float))
        k += p
    return np.array(beta[:q], dtype=float), out


def _refine(model: Model, sig: R.Signals, terms: list[Term], base: dict[str, float],
            betas: list[np.ndarray], s2: float, iters: int = 3
            ) -> tuple[Model, dict[str, float], list[np.ndarray], E.Context]:
    """Damped Gauss-Newton on base parameters and effect coefficients (exact residual).

    Each step solves the linearised joint problem (base prior centred on the model as
    given) and is halved until the exact residual decreases.
    """
    given = list(model.effects)
    theta0 = {n: E.get_base(model, n) for n, _ in E.BASE_PARAMS}
    tolrel = dict(E.BASE_PARAMS)

    def build(base: dict[str, float], betas: list[np.ndarray]) -> tuple[Any, ...]:
        base = dict(base)
        betas = [b.copy() for b in betas]
        bm = E.apply_base(model, base)
        for k, t in enumerate(terms):  # keep the overall friction level in the base
            if t.effect == "position_friction":
                sc = 1.0 + betas[k]
                c = float(np.median(sc))
                betas[k] = sc / c - 1.0
                for side in ("positive", "negative"):
                    for key in ("fc", "fs"):
                        base[f"{side}.{key}"] = E.get_base(bm, f"{side}.{key}") * c
                bm = E.apply_base(model, base)
        ctx = E.Context.build(sig, bm)
        aug = bm.replace(effects=given + _effects_of(terms, betas, ctx))
        base = {n: E.get_base(aug, n) for n, _ in E.BASE_PARAMS}
        r = R.residual(aug, sig)
        return float(np.sum(r[sig.mask] ** 2)), aug, base, betas, ctx, r

    sse, aug, base, betas, ctx, r = build(base, betas)
    for _ in range(iters):
        J, names, _, _ = E.base_jacobian(aug, sig)
        tol = np.array([tolrel[n] * max(abs(theta0[n]), 1e-12) for n in names])
        center = np.array([theta0[n] - base[n] for n in names])
        cur_terms = [Term(cand=t.cand, h=t.h, X=t.cand.columns(t.h, ctx), prior=t.prior)
                     for t in terms]
        ev = Scorer(r, J, tol, sig.mask, s2, blocks=2, center=center).evaluate(cur_terms)
        d, dbs = _split(ev.beta, len(names), cur_terms)
        lam = 1.0
        improved = False
        for _h in range(4):
            nb = dict(base)
            for n, dv in zip(names, d):
                nb[n] = base[n] + lam * dv
            nbetas = [b + lam * db for b, db in zip(betas, dbs)]
            out = build(nb, nbetas)
            if out[0] < sse:
                sse, aug, base, betas, ctx, r = out
                improved = True
                break
            lam *= 0.5
        if not improved or lam < 1.0:
            break
    return aug, base, betas, ctx


def _closed_loop(rec: Recording, before: Model, after: Model) -> dict[str, Any] | None:
    c = before.controller
    if c is None or rec.x_ref is None or c.get("type", "pid") != "pid":
        return None
    out = {}
    for key, m in (("before", before), ("after", after)):
        try:
            s = simulate(m, rec.t, rec.x_ref, x0=float(rec.x[0]))
        except (ValueError, ArithmeticError) as e:  # pragma: no cover - diverging
            return {"error": str(e)}
        meas_i = rec.i if rec.i is not None else rec.F / m.force_constant
        out[key] = {"rms_position": float(np.sqrt(np.mean((s.x - rec.x) ** 2))),
                    "rms_current": float(np.sqrt(np.mean((s.i - meas_i) ** 2)))}
    return out


def _evidence(t: Term, log: dict[str, Any], K: int, extra: str = "") -> str:
    txt = (f"{t.cand.signature[0].upper()}{t.cand.signature[1:]}: fitted jointly with the base "
           f"parameters it lowers the held-out score by {log['gain']:.0f} (chi-square on the "
           f"coloured noise scale), gains in {log['positive']} of {K} held-out blocks "
           f"(p = {log['p']:.2g}).")
    return txt + (" " + extra if extra else "")


def diagnose(
    recording: Any,
    model: Any,
    *,
    holdout: Any = None,
    cutoff_hz: float | None = None,
    blocks: int = 10,
    alpha: float = 1e-3,
    min_gain: float = 10.0,
    closed_loop: bool = True,
    candidates: list[str] | None = None,
) -> Diagnosis:
    """Find the physics a model leaves out of a recording.

    Parameters
    ----------
    recording : Recording or path
        The recording to diagnose (``t``, ``x``, ``i`` or ``F``; ``x_ref`` for the
        closed-loop comparison).
    model : Model, dict or path
        The model believed to describe the axis.
    holdout : Recording or path, optional
        A second recording on which the gain is checked.
    cutoff_hz : float, optional
        Parallel low-pass cut-off (default ``fs/25``).
    blocks : int, default 10
        Contiguous held-out blocks of the selection.
    alpha : float, default 1e-3
        Significance level of the block test.
    min_gain : float, default 10.0
        Least held-out score gain of an accepted effect.
    closed_loop : bool, default True
        Also compare closed-loop simulations when the controller and ``x_ref`` are known.
    candidates : list of str, optional
        Restrict the search to these effects (default: the whole vocabulary).

    Returns
    -------
    Diagnosis

    Raises
    ------
    DataError
        Too short, no motion, motion in one direction only.
    """
    t_start = time.perf_counter()
    rec = _rec(recording)
    model = _as_model(model)
    R.check_recording(rec, model)
    sig = R.prepare(rec, model, cutoff_hz=cutoff_hz)
    R.check_units(sig, model)
    r0 = R.residual(model, sig)
    fr0 = R.base_friction(model, sig)
    ctx = E.Context.build(sig, model, fr0)
    J, names, _, tol = E.base_jacobian(model, sig, fr0)
    n_used = int(sig.mask.sum())
    noise = R.noise_floor(r0, sig)
    s2 = noise["rms"] ** 2 * n_used / noise["n_eff"]
    ev0 = Scorer(r0, J, tol, sig.mask, s2, blocks).evaluate([])
    noise = R.noise_floor(ev0.resid, sig)  # floor of the base-refit residual
    s2 = noise["rms"] ** 2 * n_used / noise["n_eff"]
    scorer = Scorer(r0, J, tol, sig.mask, s2, blocks)
    cands = E.candidates()
    if candidates is not None:
        cands = [c for c in cands if c.effect in set(candidates)]
    terms, ev, log = forward_select(scorer, ctx, cands, alpha=alpha, min_gain=min_gain,
                                    noise_rms=noise["rms"])
    q = J.shape[1]
    ev_sel = ev
    d, betas = _split(ev.beta, q, terms)
    betas_sel = [b.copy() for b in betas]
    base = {n: E.get_base(model, n) for n, _ in E.BASE_PARAMS}
    for n, dv in zip(names, d):
        base[n] += dv
    notes: list[str] = []
    alternatives: dict[int, list[dict[str, Any]]] = {}

    # delay or current lag: same first-order signature, tell apart by the exact forms
    lag_k = next((k for k, t in enumerate(terms) if t.effect == "delay"), None)
    if lag_k is not None:
        fits = {}
        for form in ("delay", "current_lag"):
            tt = list(terms)
            tt[lag_k] = Term(cand=terms[lag_k].cand, h=form, X=terms[lag_k].X)
            aug_f, base_f, betas_f, ctx_f = _refine(model, sig, tt, dict(base),
                                                    [b.copy() for b in betas], s2)
            rf = R.residual(aug_f, sig)
            fits[form] = (aug_f, base_f, betas_f, ctx_f, tt, rf)
        sse = {f: np.array([np.sum(v[5][sig.mask][b] ** 2) for b in scorer.blocks])
               for f, v in fits.items()}
        dd = (sse["delay"] - sse["current_lag"]) / s2
        better = "current_lag" if dd.sum() > 0 else "delay"
        other = "delay" if better == "current_lag" else "current_lag"
        tstat = abs(dd.mean()) / (dd.std(ddof=1) / math.sqrt(dd.size) + 1e-300)
        aug, base, betas, ctx, terms, _ = fits[better]
        if tstat < 3.0 or abs(dd.sum()) < min_gain:
            ao = fits[other]
            eff = ao[4][lag_k].cand.to_effects(other, ao[2][lag_k], ao[3])[0]
            alternatives[lag_k] = [{
                "effect": other,
                "parameters": {k: v for k, v in eff.items() if k != "effect"},
                "experiment": _EXPERIMENT[("delay", "current_lag")],
            }]
    elif terms:
        aug, base, betas, ctx = _refine(model, sig, terms, base, betas, s2)
        # a term accepted in the linearised selection whose share collapses in the joint
        # refit (rms contribution under min_effect of the noise floor) is not a finding
        small = []
        for k, t in enumerate(terms):
            c = np.einsum("ij,j->i", t.cand.columns(t.h, ctx), betas[k])[sig.mask]
            if float(np.sqrt(np.mean(c * c))) < 0.2 * noise["rms"]:
                small.append(k)
        if small:
            for k in small:
                lg = next((g for g in log if g["accepted"] and g["effect"] == terms[k].effect),
                          None)
                if lg is not None:
                    lg["accepted"] = False
                    lg["why"] += ("; dropped: its contribution after the joint refit is "
                                  "small against the noise floor")
            keep = [k for k in range(len(terms)) if k not in small]
            terms = [terms[k] for k in keep]
            base = {n: E.get_base(model, n) for n, _ in E.BASE_PARAMS}
            for n, dv in zip(names, d):
                base[n] += dv
            betas0 = [betas_sel[k] for k in keep]
            aug, base, betas, ctx = _refine(model, sig, terms, base, betas0, s2,
                                            iters=3 if terms else 2)
    else:
        aug, base, betas, ctx = _refine(model, sig, [], base, [], s2, iters=2)

    r1 = R.residual(aug, sig)
    noise_after = R.noise_floor(r1, sig)
    tot0 = float(np.sum(r0[sig.mask] ** 2))
    findings: list[Finding] = []
    accepted = [lg for lg in log if lg["accepted"]]
    for k, t in enumerate(terms):
        X = t.cand.columns(t.h, ctx)
        contrib = np.einsum("ij,j->i", X, betas[k])
        rem = r1 + contrib  # the final model without this term
        gain_e = np.sum(rem[sig.mask] ** 2) - np.sum(r1[sig.mask] ** 2)
        expl = float(np.clip(gain_e / tot0, 0.0, 1.0))
        effs = t.cand.to_effects(t.h, betas[k], ctx)
        e0 = effs[0]
        lg = next((g for g in accepted if g["effect"] == t.effect), accepted[min(k, len(accepted) - 1)])
        extra = ""
        if t.effect == "cogging":
            extra = (f"The residual's spectrum over position peaks at a pitch of "
                     f"{e0['pitch'] * 1e3:.4g} mm.")
        if t.effect == "position_friction":
            sc = np.array(e0["scale"])
            j = int(np.argmax(np.abs(sc - 1)))
            extra = (f"Largest change x{sc[j]:.3g} of the Coulomb/static level at "
                     f"x = {e0['positions'][j]:.4g} m.")
        unc: dict[str, Any] = {}
        if t.effect == "drift":
            unc, extra = _drift_identifiability(t, float(sig.t[sig.mask][-1]),
                                                thr=min_gain)
        if t.effect == "offset":
            alt_off, extra = _offset_alternative(scorer, terms, ev_sel, names, tol, model,
                                                 sig, min_gain)
            if alt_off is not None:
                alternatives.setdefault(k, []).append(alt_off)
        f = Finding(effect=e0["effect"],
                    parameters={a: v for a, v in e0.items() if a != "effect"},
                    where=t.cand.where(t.h, betas[k], ctx), explained=expl,
                    evidence=_evidence(t, lg, blocks, extra),
                    alternatives=alternatives.get(k, []), uncertainty=unc)
        findings.append(f)
        for e in effs[1:]:  # e.g. a spring whose x0 cannot be placed: offset beside it
            findings.append(Finding(effect=e["effect"],
                                    parameters={a: v for a, v in e.items() if a != "effect"},
                                    where={"position": None, "time": None, "velocity": None},
                                    explained=0.0, evidence="Part of the spring term above."))
    findings.sort(key=lambda f: -f.explained)

    # base moves
    base_rep = {}
    for n, rel in E.BASE_PARAMS:
        b0 = E.get_base(model, n)
        b1 = E.get_base(E.apply_base(model, base), n)
        base_rep[n] = {"before": b0, "after": b1, "change": (b1 - b0) / b0 if b0 else 0.0,
                       "tolerance": rel}
    far = [n for n, b in base_rep.items() if abs(b["change"]) > 3 * b["tolerance"]]
    if far:
        notes.append("Moved more than three tolerances (poorly determined or standing in "
                     "for something else): " + ", ".join(
                         f"{n} {100 * base_rep[n]['change']:+.0f} %" for n in far) + ".")
    bp, bn = base_rep["positive.fc"]["after"], base_rep["negative.fc"]["after"]
    if not any(f.effect == "offset" for f in findings) and abs(bp - bn) > 0.1 * (bp + bn) / 2:
        notes.append(
            f"The Coulomb levels differ by direction ({bp:.3g} N forward, {bn:.3g} N "
            f"backward); a constant force of {(bp - bn) / 2:.3g} N with a symmetric level "
            f"would fit the motion equally well. To separate: "
            f"{_EXPERIMENT[('offset', 'asymmetry')]}.")

    fit: dict[str, Any] = {"before": _metrics(r0, sig.fm_f, sig.mask),
                           "after": _metrics(r1, sig.fm_f, sig.mask),
                           "holdout_before": {}, "holdout_after": {}}
    if holdout is not None:
        hb = evaluate(holdout, model, cutoff_hz=cutoff_hz)
        ha = evaluate(holdout, aug, cutoff_hz=cutoff_hz)
        fit["holdout_before"] = {k: hb[k] for k in ("rms_force", "nrmse_force")}
        fit["holdout_after"] = {k: ha[k] for k in ("rms_force", "nrmse_force")}
    fit["held_out_blocks"] = {
        "base_refit": float(np.sqrt(ev0.sse_b.sum() / n_used)),
        "with_findings": float(np.sqrt(ev.sse_b.sum() / n_used)),
    }
    if closed_loop:
        cl = _closed_loop(rec, model, aug)
        if cl is not None and "error" not in cl:
            fit["closed_loop"] = cl

    located = {"before": locate(r0, sig, noise["rms"]), "after": locate(r1, sig, noise["rms"])}
    unexplained = None
    rms1 = fit["after"]["rms_force"]
    if rms1 > 2.0 * noise["rms"]:
        la = located["after"]
        unexplained = {
            "rms_force": rms1, "noise_floor": noise["rms"],
            "where": {k: la[k] for k in ("time", "position", "velocity", "direction")},
            "message": (
                f"after the findings the residual is still {rms1:.3g} N rms, "
                f"{rms1 / noise['rms']:.1f} times the noise floor, and no effect of the "
                "vocabulary explains the rest; it lives at "
                + "; ".join(f"{k} {_short(la[k])}" for k in ("time", "position", "velocity")
                            if la[k]) + "."),
        }
    _, pk = _position_spectrum(r1, sig)
    ks0, pk0 = _position_spectrum(r0, sig)
    data = {"t": sig.t, "x": sig.x, "v": sig.vf, "force": sig.fm_f, "before": r0, "after": r1,
            "mask": sig.mask, "spectrum_k": ks0, "spectrum_before": pk0, "spectrum_after": pk,
            "model_before": sig.fm_f - r0, "model_after": sig.fm_f - r1}
    dg = Diagnosis(findings=findings, fit=fit, model=model, augmented=aug, base=base_rep,
                   noise={**noise, "rms_before_refit": R.noise_floor(r0, sig)["rms"],
                          "rms_after": noise_after["rms"]},
                   located=located, unexplained=unexplained, notes=notes, trials=log,
                   data=data)
    dg.timing = time.perf_counter() - t_start
    return dg


def _short(ranges: list[list[float]]) -> str:
    if len(ranges) > 4:
        return f"{len(ranges)} stretches from {ranges[0][0]:.3g} to {ranges[-1][1]:.3g}"
    return ", ".join(f"[{a:.3g}, {b:.3g}]" for a, b in ranges)


def _position_spectrum(r: np.ndarray, sig: R.Signals) -> tuple[np.ndarray, np.ndarray]:
    """Amplitude of the residual's best sinusoid over position, per spatial frequency."""
    m = sig.mask
    step = max(1, int(m.sum() // 4000))
    x = sig.x[m][::step]
    rr = r[m][::step] - np.mean(r[m])
    span = max(float(np.ptp(x)), 1e-9)
    ks = np.arange(1.0 / span, min(200.0 / span, 2000.0), 0.5 / span)
    out = np.empty(ks.size)
    for j0 in range(0, ks.size, 100):
        kk = ks[j0:j0 + 100]
        ph = 2 * np.pi * np.outer(kk, x)
        s, c = np.sin(ph), np.cos(ph)
        out[j0:j0 + 100] = 2 * np.hypot(np.einsum("ij,j->i", s, rr),
                                         np.einsum("ij,j->i", c, rr)) / x.size
    return ks, out


# --------------------------------------------------------------------------------------
# Base fit by inverse dynamics
# --------------------------------------------------------------------------------------


def fit_inverse_dynamics(
    recording: Any,
    *,
    mass: float | None = None,
    force_constant: float = 1.0,
    sigma0: float | None = None,
    cutoff_hz: float | None = None,
    controller: dict[str, Any] | None = None,
) -> Model:
    """Fit a LuGre axis model by robust least squares on the inverse dynamics.

    ``F = m*a + sign(v)*g(v) + sigma2*v`` with per-direction ``fc``, ``fs``, ``vs``,
    ``sigma2``: linear in ``m``, ``fc`` and ``sigma2`` (and ``fs - fc`` for a given
    ``vs``, found on a grid), on low-passed data, with IGG weights (robust to spikes).
    ``sigma0`` is a guess (the maximum friction over ten encoder counts, at least over
    10 um) and ``sigma1`` a damping guess; no offset is fitted (the diagnosis tests it
    as a candidate effect).

    Parameters
    ----------
    recording : Recording or path
        With motion in both directions.
    mass : float, optional
        Known mass [kg]; estimated otherwise.
    force_constant : float, default 1.0
        K_F [N/A] (needed when the recording holds the current).
    sigma0 : float, optional
        Bristle stiffness [N/m]; guessed otherwise.
    cutoff_hz : float, optional
        Low-pass cut-off (default ``fs/25``).
    controller : dict, optional
        Controller section to put in the model.

    Returns
    -------
    Model
    """
    rec = _rec(recording)
    R.check_recording(rec)
    proto = Model.paper().replace(
        axis={"mass": 1.0, "force_constant": float(force_constant)}, effects=[],
        controller=None)
    sig = R.prepare(rec, proto, cutoff_hz=cutoff_hz)
    v = sig.v
    m = sig.mask
    vmax = float(np.max(np.abs(sig.vf[m])))
    pos, neg = (v > 0).astype(float), (v < 0).astype(float)
    y = sig.fm_f.copy()
    if mass is not None:
        y = y - float(mass) * sig.a

    def design(vs: float | None) -> np.ndarray:
        cols = [] if mass is not None else [sig.a]
        cols += [sig.filt(pos), sig.filt(pos * v), sig.filt(-neg), sig.filt(neg * v)]
        if vs is not None:
            e = np.exp(-(v / vs) ** 2)
            cols += [sig.filt(pos * e), sig.filt(-neg * e)]
        return np.column_stack(cols)

    def irls(X: np.ndarray) -> tuple[np.ndarray, float]:
        w = np.ones(int(m.sum()))
        Xm, ym = X[m], y[m]
        b = np.zeros(X.shape[1])
        for _ in range(8):
            G = np.einsum("ij,ik,i->jk", Xm, Xm, w)
            b = np.linalg.solve(G + 1e-12 * np.trace(G) * np.eye(G.shape[0]),
                                np.einsum("ij,i->j", Xm, w * ym))
            e = ym - np.einsum("ij,j->i", Xm, b)
            s = 1.4826 * np.median(np.abs(e - np.median(e))) + 1e-12
            u = np.abs(e) / s
            w = np.where(u <= 1.5, 1.0, np.where(u <= 2.5, 1.5 / u, 0.0))
        e = ym - np.einsum("ij,j->i", Xm, b)
        return b, float(np.sum(w * e * e))

    b0, sse0 = irls(design(None))
    best = (sse0, None, b0)
    if vmax > 0:
        for vs in vmax * np.logspace(-2.5, -0.5, 15):
            b, sse = irls(design(vs))
            if b[-1] > 0 and b[-2] > 0 and sse < 0.98 * best[0]:
                best = (sse, vs, b)
    _, vs, b = best
    off = 0 if mass is not None else 1
    mm = float(mass) if mass is not None else float(b[0])
    if not mm > 0:
        raise DataError(f"the inverse-dynamics fit gives a mass of {mm:.3g} kg: the record "
                        "does not excite the inertia; give the mass")
    fcp, s2p, fcn, s2n = (float(b[off + k]) for k in range(4))
    dp = float(b[off + 4]) if vs is not None else 0.0
    dn = float(b[off + 5]) if vs is not None else 0.0
    vs_val = float(vs) if vs is not None else 0.05 * max(vmax, 1e-6)
    fcp, fcn = max(fcp, 1e-3), max(fcn, 1e-3)
    fsmax = max(fcp + dp, fcn + dn)
    if sigma0 is None:
        q = max(sig.info.get("quantum", 0.0), 1e-6)
        sigma0 = fsmax / max(10 * q, 1e-5)
    sigma1 = 0.05 * math.sqrt(sigma0 * mm)
    doc = {
        "axis": {"mass": mm, "force_constant": float(force_constant)},
        "friction": {
            "model": "lugre", "sigma0": float(sigma0), "sigma1": float(sigma1),
            "positive": {"fc": fcp, "fs": fcp + max(dp, 0.0), "sigma2": max(s2p, 0.0),
                         "vs": vs_val},
            "negative": {"fc": fcn, "fs": fcn + max(dn, 0.0), "sigma2": max(s2n, 0.0),
                         "vs": vs_val},
        },
        "effects": [],
    }
    if controller is not None:
        doc["controller"] = controller
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return Model(doc)
