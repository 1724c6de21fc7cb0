"""The diagnosis as a straight line: prepare the record, weigh the base, search the
effects, refit, gather the evidence, report; and :func:`evaluate`."""

from __future__ import annotations

import math
import time
import warnings
from typing import Any

import numpy as np

from ..exceptions import InputError, PassivityWarning
from ..io import Recording
from ..model import Model, _as_model
from . import base as B
from . import effects as E
from . import evidence as V
from . import residual as R
from .locate import locate, position_spectrum
from .rebase import far_base
from .refit import refine, split
from .report import Diagnosis, Finding
from .search import (
    Scorer,
    Term,
    accept,
    compare,
    forward_select,
    make_term,
    told_apart,
)
from .simex import noise_made, surrogates

__all__ = ["EXCESS_FLOOR", "MIN_SHARE", "ONE_OF_A_KIND", "PARTIAL_REST", "as_recording",
           "diagnose", "evaluate"]

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


def as_recording(recording: Any) -> Recording:
    """A :class:`~lugre.Recording` from a recording or a path."""
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


#: A friction level shift on an evaluated record is reported when it exceeds this share
#: of the model's Coulomb level and three standard errors (over ten time blocks).
LEVEL_SHIFT_SHARE = 0.03


def level_shift(r: np.ndarray, sig: R.Signals, model: Model) -> dict[str, Any] | None:
    """How far the friction on this record sits from the model's, per direction.

    The mean residual while the axis moves forward, and minus it while it moves back:
    the friction magnitude the model misses (> 0: the record's friction is higher).
    Standard errors from ten consecutive time blocks of each direction (the residual is
    coloured). Both shifts with one sign are a change of friction since the model's
    record (temperature, lubrication, another session); opposite signs are a constant
    force. None when a direction has under 200 samples.
    """
    out: dict[str, Any] = {}
    for d, sgn in (("positive", 1.0), ("negative", -1.0)):
        sel = np.flatnonzero(sig.mask & (sgn * sig.vf > 0))
        if len(sel) < 200:
            return None
        vals = sgn * r[sel]
        blocks = [b.mean() for b in np.array_split(vals, 10)]
        fc = float(model.friction[d]["fc"])
        out[d] = {"shift": float(vals.mean()), "se": float(np.std(blocks, ddof=1) / np.sqrt(10)),
                  "share_of_fc": float(vals.mean() / fc) if fc > 0 else math.nan}
    sig_d = [abs(out[d]["shift"]) > 3.0 * out[d]["se"]
             and abs(out[d]["share_of_fc"]) > LEVEL_SHIFT_SHARE for d in ("positive", "negative")]
    same = out["positive"]["shift"] * out["negative"]["shift"] > 0
    out["significant"] = bool(any(sig_d))
    out["kind"] = ("friction level" if same else "constant force") if any(sig_d) else None
    return out


def level_shift_text(ls: dict[str, Any] | None) -> str | None:
    """One sentence on a significant :func:`level_shift`, or None."""
    if not ls or not ls["significant"]:
        return None
    p, n = ls["positive"], ls["negative"]
    figs = (f"{p['shift']:+.3g} N ({100 * p['share_of_fc']:+.1f} % of fc) moving forward, "
            f"{n['shift']:+.3g} N ({100 * n['share_of_fc']:+.1f} %) moving back")
    if ls["kind"] == "friction level":
        return (f"the friction on this record differs from the model's by {figs}: friction "
                "has changed since the model's record (temperature, lubrication, wear); "
                "compare records taken warm, at the same temperature, or refit the levels "
                "on this one (lugre diagnose refits them)")
    return (f"the force on this record differs from the model's by {figs}, opposite ways: "
            "a constant force (an offset: gravity, a cable) the model does not hold")


def evaluate(recording: Any, model: Any, *, cutoff_hz: float | None = None,
             backend: str = "core") -> dict[str, Any]:
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
    backend : {"core", "reference"}, default "core"
        The compiled kernel or its NumPy twin.

    Returns
    -------
    dict
        ``rms_force`` [N], ``nrmse_force`` (rms residual over rms motor force),
        ``noise_floor`` [N], ``samples``, ``cutoff_hz``, and ``level_shift``: the
        friction the model misses per direction (see :func:`level_shift`; None when a
        direction has too few samples).
    """
    rec = as_recording(recording)
    m = _as_model(model)
    R.check_recording(rec, m)
    sig = R.prepare(rec, m, cutoff_hz=cutoff_hz, backend=backend)
    R.check_units(sig, m)
    r = R.residual(m, sig)
    out: dict[str, Any] = _metrics(r, sig.fm_f, sig.mask)
    out["noise_floor"] = R.noise_floor(r, sig)["rms"]
    out["samples"] = len(sig)
    out["cutoff_hz"] = sig.cutoff_hz
    out["level_shift"] = level_shift(r, sig, m)
    return out


def _closed_loop(rec: Recording, before: Model, after: Model,
                 simulate: Any) -> dict[str, Any] | None:
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


#: A candidate that passed at the step another was chosen, with at least this share of
#: its held-out gain, is a look-alike: the two are compared in their exact forms.
RIVAL_SHARE = 0.5


def _close_rivals(log: list[dict[str, Any]], terms: list[Any],
                  nested: dict[str, set[str]]) -> list[tuple[str, str]]:
    """(chosen, rival) pairs: an accepted term and the strongest other candidate that
    passed at its step with a gain close to its own. Nested candidates (a spring
    contains an offset, ``nested[effect]``) are left to the parsimony test."""
    named = {t.effect for t in terms if not t.minor}
    run, runs, prev = 0, [], 0
    for g in log:  # the log of a search run again starts at step 1
        run += g["step"] < prev
        prev = g["step"]
        runs.append(run)
    out = []
    for j, g in enumerate(log):
        if not g["accepted"] or g["effect"] not in named:
            continue
        rivals = [h for i, h in enumerate(log)
                  if runs[i] == runs[j] and h["step"] == g["step"] and h.get("ok")
                  and h["effect"] != g["effect"] and h["effect"] not in named
                  and h["effect"] not in nested.get(g["effect"], set())
                  and g["effect"] not in nested.get(h["effect"], set())
                  and h["gain"] >= RIVAL_SHARE * g["gain"]]
        if rivals:
            out.append((g["effect"], max(rivals, key=lambda h: h["gain"])["effect"]))
    return out


#: Scale of the base tolerances for a base identified from a record (lugre fit), not
#: known beforehand: friction levels may move by about a third, not by 3 %.
IDENTIFY_TOLERANCE = 10.0

#: Rows of a column the held-out scores read at most (longer records: every step-th).
ROWS_KEPT = 100_000


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
    screw_lead: float | None = None,
    free_mass: bool = False,
    tolerance: float = 1.0,
    backend: str = "core",
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
    screw_lead : float, optional
        Lead of the ball screw [m] (one revolution); default ``axis.screw_lead`` of the
        model when it has one. Its pitch and harmonics are always tried for cogging.
    free_mass : bool, default False
        Re-estimate the mass as a base parameter (model identification) instead of
        testing a ``mass`` effect (a payload).
    tolerance : float, default 1.0
        Scale of the base parameters' tolerances (the prior on how far they may move
        from the model): 1 diagnoses a model believed about right; identification from
        a rough start uses a wide one.
    backend : {"core", "reference"}, default "core"
        Numerics from the compiled core, or from its NumPy twin ``lugre.reference``
        (the same diagnosis, slower; for checking).

    Returns
    -------
    Diagnosis

    Raises
    ------
    DataError
        Too short, no motion, motion in one direction only, gaps in the sampling.
    """
    t_start = time.perf_counter()
    model = _as_model(model)  # (warns once if the model given is not passive)
    rec = as_recording(recording)
    # a base that lugre fit identified (its model file says so) carries whatever the
    # record's effects put into it: its levels and mass are re-estimated as freely as in
    # identification, so that an effect the fit absorbed (a dead-band in fc, a spring
    # in the mass) can be named instead of being held out by the prior
    fitted = (model.to_dict().get("identification") or {}).get("parameters") or {}
    if fitted:
        tolerance = max(tolerance, IDENTIFY_TOLERANCE)
        free_mass = free_mass or "mass" in fitted
    kw = {"holdout": holdout, "cutoff_hz": cutoff_hz, "blocks": blocks, "alpha": alpha,
          "min_gain": min_gain, "closed_loop": closed_loop, "candidates": candidates,
          "screw_lead": screw_lead, "free_mass": free_mass, "tolerance": tolerance,
          "backend": backend}
    with warnings.catch_warnings():  # the trial models of the search and the refits
        warnings.simplefilter("ignore", PassivityWarning)
        dg = _diagnose(rec, model, **kw)
        # the base is a starting point: when the record puts it far from where it was
        # given, the search runs again from where the record puts it
        far = None if candidates is not None else far_base(
            rec, model, dg.augmented, cutoff_hz=cutoff_hz, backend=backend,
            free_mass=free_mass)
        if far is not None:
            first = dg
            dg = _diagnose(rec, far["model"], **kw)
            dg.model = model
            # the model as given, on this record and the held-out one, from the first
            # pass (the second's "before" is the refitted base's)
            dg.rebased = {**{k: v for k, v in far.items() if k != "model"},
                          "given": first.fit["before"],
                          "holdout_given": first.fit["holdout_before"] or None}
            dg.verdict = V.verdict(dg)
    if fitted:
        dg.notes.append(
            "The model's base was identified by lugre fit (its file says so): its friction "
            "levels" + (" and mass were" if "mass" in fitted else " were") + " re-estimated "
            "as freely as in identification, so that an effect the fit took into them can "
            "be named.")
    if model.is_passive and not dg.augmented.is_passive:
        warnings.warn(
            "the augmented model's sigma1 exceeds the passivity bound 4*sigma2*fc/(fs - fc) "
            "of its friction (Barabanov & Ortega 2000): the refit moved sigma1 or the "
            "levels that far; check the base moves in the report before using it",
            PassivityWarning, stacklevel=2)
    dg.timing = time.perf_counter() - t_start
    return dg


def _diagnose(
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
    screw_lead: float | None = None,
    free_mass: bool = False,
    tolerance: float = 1.0,
    backend: str = "core",
    _given: tuple[Model, list[dict[str, Any]]] | None = None,
    _question: bool = True,
) -> Diagnosis:
    """:func:`diagnose` without its warnings' filter. ``_given``: the model as the user
    gave it and its effects removed so far, when ``model`` is that model without them;
    ``_question``: question the model's own effects (not in a search for one kind)."""
    rec = as_recording(recording)
    model = _as_model(model)
    # 1. prepare: checks, filtered signals, the residual of the model as given
    R.check_recording(rec, model)
    sig = R.prepare(rec, model, cutoff_hz=cutoff_hz, backend=backend)
    R.check_units(sig, model)
    r0 = R.residual(model, sig)
    n_used = int(sig.mask.sum())
    # a long record's held-out scores read every step-th sample (all they score is
    # band-limited), so that the grid columns kept stay under about 100 000 rows each;
    # the sums agree to a part in a thousand, but a marginal decision (a gain at its
    # threshold) can move, so records up to that size are read whole
    step = max(1, min(sig.rows_step, n_used // ROWS_KEPT))
    # the model's own effects, questioned first: one the record contradicts (the held-
    # out stretches are predicted better without it) is removed, and the search then
    # looks for what the record holds instead (a cogging given at a 20 mm pitch where
    # the record has one at 30 mm)
    model_given, r0_given, removed = model, r0, []
    if _given is not None:
        model_given, removed = _given[0], list(_given[1])
        r0_given = R.residual(model_given, sig)
    if _question and model.effects:
        settings: dict[str, Any] = {"blocks": blocks, "alpha": alpha, "min_gain": min_gain,
                                    "step": step, "tolerance": tolerance}
        model, contradicted, r0 = question_effects(model, sig, r0, **settings)
        model, replaced, r0 = replace_one_of_a_kind(
            rec, model, sig, r0, cutoff_hz=cutoff_hz, screw_lead=screw_lead,
            backend=backend, **settings)
        removed += contradicted + replaced
    fr0 = R.base_friction(model, sig)
    ctx = E.Context.build(sig, model, fr0)
    lead = screw_lead if screw_lead is not None else model.axis.get("screw_lead")
    ctx.extra["screw_lead"] = float(lead) if lead else None
    ctx.extra["blocks"] = int(blocks)

    # 2. the base: friction levels always; the presliding pair only when the record
    #    shows it (held-out profile test); the mass as a base parameter only when asked
    wanted = B.LEVELS + B.PRESLIDING + (("mass",) if free_mass else ())
    J, names, _, tol = B.base_jacobian(model, sig, names=wanted)
    tol = tol * float(tolerance)
    held = [k for k, n in enumerate(names) if n not in B.PRESLIDING]
    ctx.extra["rows_step"] = step
    noise, s2 = _variance_unit(r0, J[:, held], tol[held], sig, blocks, step)
    sc_held = Scorer(r0, J[:, held], tol[held], sig.mask, s2, blocks, step=step)
    sc_free = Scorer(r0, J, tol, sig.mask, s2, blocks, step=step)
    ev_held = sc_held.evaluate([])
    J_all, names_all, tol_all = J, names, tol

    def presliding_test(ev_h: Any, ev_f: Any) -> dict[str, Any]:
        # the presliding pair acts at every reversal, in every block: only consistent
        # held-out gains free it (a gain confined to a few blocks is some other
        # mismatch at the reversals there, which sigma1 would absorb: -100 % on clean
        # records)
        pt = compare(ev_h, ev_f, s2)
        pt["min_gain"], pt["alpha"] = min_gain, alpha
        pt["free"] = bool(len(held) < len(names_all)
                          and accept(pt, alpha=alpha, min_gain=min_gain)[0]
                          and pt["p"] < alpha)
        return pt

    def base_set(free: bool) -> tuple[Scorer, np.ndarray, list[str], np.ndarray]:
        if free:
            return sc_free, J_all, names_all, tol_all
        return sc_held, J_all[:, held], [names_all[k] for k in held], tol_all[held]

    presliding = presliding_test(ev_held, sc_free.evaluate([]))
    scorer, J, names, tol = base_set(presliding["free"])

    # 3. search: greedy forward selection over the vocabulary, held-out blocks
    cands = E.candidates()
    # one of a kind in a model: a resonance, a Stribeck shape and a timing term the
    # model already holds are kept as given (diagnosing an augmented model again)
    held_kinds = _held_kinds(model)
    cands = [c for c in cands if c.effect not in held_kinds]
    if free_mass:
        cands = [c for c in cands if c.effect != "mass"]
    if candidates is not None:
        cands = [c for c in cands if c.effect in set(candidates)]
    min_force = MIN_SHARE * _rms(sig.fm_f, sig.mask)
    terms, ev, log = forward_select(scorer, ctx, cands, alpha=alpha, min_gain=min_gain,
                                    noise_rms=noise["rms"], min_force=min_force)
    # a named term whose physics fails its own check is refused, and the search runs
    # again without it: a lag that fits the reversals but not the motion between them
    # is lost motion, not timing; a mass that differs speeding up and braking is no
    # payload. The rest is described instead.
    refused: dict[str, dict[str, Any]] = {}
    for effect, check, key, why in (
            ("delay", V.lag_at_reversals, "reversals_only",
             lambda c: (f"between the reversals the lag is {c['lag_away_s'] * 1e3:.2g} ms, "
                        f"not {c['lag_s'] * 1e3:.2g} ms (lost motion, not timing)")),
            ("mass", V.mass_both_ways, "not_payload",
             lambda c: (f"{c['speeding_up']:+.2g} kg speeding up, {c['braking']:+.2g} kg "
                        "braking (no payload)")),
            ("deadband", V.deadband_braking, "not_deadband",
             lambda c: (f"where the drive brakes the axis it reads {c['braking']:.2g} "
                        f"times the band it reads overall ({c['coefficient']:.2g}): no one "
                        "dead-band explains both"))):
        k = next((k for k, t in enumerate(terms) if t.effect == effect and not t.minor), None)
        chk = None if k is None else check(scorer, terms, k, ev, ctx)
        if chk is None or not chk[key]:
            continue
        refused[effect] = chk
        for g in log:
            if g["accepted"] and g["effect"] == effect:
                g["accepted"] = False
                g["why"] += "; not named: " + why(chk)
        terms, ev, log2 = forward_select(
            scorer, ctx, [c for c in cands if c.effect not in refused], alpha=alpha,
            min_gain=min_gain, noise_rms=noise["rms"], min_force=min_force)
        log += log2
    lag_rev, mass_ways = refused.get("delay"), refused.get("mass")

    # look-alikes: when another candidate passed at the step a term was chosen, with a
    # gain close to its own, the linearised columns only put them in order. Both
    # stories are refitted in their exact forms and the one whose exact residual is
    # smaller on the blocks is kept; when they are not told apart, the other is given
    # beside the finding (a 200 Hz current lag logged at 10 kHz was named a dead-band
    # by its linearised gain; exactly, the dead-band left 0.107 N, the timing 0.059 N)
    def exact_sse(tt: list[Any], ee: Any) -> np.ndarray:
        dd, bb = split(ee.beta, J.shape[1], tt)
        b0 = {n: B.get_base(model, n) for n, _ in B.BASE_PARAMS}
        for n, dv in zip(names, dd):
            b0[n] += dv
        try:
            out = refine(model, sig, tt, b0, bb, s2, names, iters=3, tolerance=tolerance)
        except ValueError:  # no valid model on the way (a coefficient out of range)
            return np.full(len(scorer.used_blocks), np.inf)
        return block_sse(out[0])

    def block_sse(m: Model) -> np.ndarray:
        rr = R.residual(m, sig)[sig.mask]
        return np.array([np.sum(rr[b] ** 2) for b in scorer.used_blocks])

    lookalike: dict[str, dict[str, Any]] = {}
    for eff, other in _close_rivals(log, terms, {c.effect: set(c.supersedes) for c in cands}):
        if eff in lookalike or other in lookalike:
            continue
        terms_b, ev_b, log_b = forward_select(
            scorer, ctx, [c for c in cands if c.effect != eff and c.effect not in refused],
            alpha=alpha, min_gain=min_gain, noise_rms=noise["rms"], min_force=min_force)
        if not any(t.effect == other and not t.minor for t in terms_b):
            continue
        dd = (exact_sse(terms, ev) - exact_sse(terms_b, ev_b)) / s2  # > 0: the other fits
        if not np.all(np.isfinite(dd)):
            continue  # one story has no valid exact form: the selection stands
        # told apart as a term is accepted: consistently over the blocks, or confined
        # (a dead-band acts where the current crosses zero) and overwhelming there
        separated, tstat = told_apart(dd, min_gain)
        if separated and dd.sum() > 0:
            for g in log:
                if g["accepted"] and g["effect"] == eff:
                    g["accepted"] = False
                    g["why"] += (f"; not named: {other} fits better in its exact form "
                                 f"(by {dd.sum():.0f} in squared-error units of the noise)")
            terms, ev, log = terms_b, ev_b, log + log_b
        elif not separated:
            kb = next(j for j, t in enumerate(terms_b) if t.effect == other)
            beta_b = split(ev_b.beta, J.shape[1], terms_b)[1][kb]
            e_b = terms_b[kb].cand.to_effects(terms_b[kb].h, beta_b, ctx)[0]
            from ..html import EXPERIMENTS

            lookalike[eff] = {
                "effect": other, "parameters": {a: v for a, v in e_b.items() if a != "effect"},
                "experiment": "; ".join(
                    f"for {'an' if e[0] in 'aeiou' else 'a'} {e.replace('_', ' ')}, "
                    f"{EXPERIMENTS.get(e, 'a second record')}" for e in (eff, other)),
                "note": (f"fits {'slightly better' if dd.sum() > 0 else 'about as well'} in "
                         f"its exact form (difference {abs(dd.sum()):.0f} in squared-error "
                         f"units of the noise, t = {tstat:.1f} over the blocks): this record "
                         "does not tell them apart")}
    # the presliding test again, with the terms in: a mismatch the vocabulary explains
    # (a Stribeck shape at low speed, a small mass error) no longer passes for presliding,
    # and presliding hidden behind one can show once it is explained
    if terms:
        after = presliding_test(sc_held.evaluate(terms), sc_free.evaluate(terms))
        if after["free"] != presliding["free"]:
            presliding = after
            scorer, J, names, tol = base_set(presliding["free"])
            ev = scorer.evaluate(terms)
    ev_sel = ev
    terms_sel = list(terms)  # as the search's scorer reads them (for what it could miss)
    intervals = _jackknife_intervals(terms, ev_sel, J.shape[1], ctx)

    # 4. refit: the exact forms jointly with the base; timing told apart by its forms
    q = J.shape[1]
    d, betas = split(ev.beta, q, terms)
    base0 = {n: B.get_base(model, n) for n, _ in B.BASE_PARAMS}
    for n, dv in zip(names, d):
        base0[n] += dv
    alternatives: dict[int, list[dict[str, Any]]] = {}
    lag_k = next((k for k, t in enumerate(terms) if t.effect == "delay"), None)
    if lag_k is not None:
        from .timing import choose_timing

        aug, base, betas, ctx, terms, alt = choose_timing(
            model, sig, terms, lag_k, base0, betas, s2, names, scorer.used_blocks, min_gain,
            tolerance)
        if alt is not None:
            alternatives[lag_k] = [alt]
    else:
        aug, base, betas, ctx, terms = refine(model, sig, terms, dict(base0), betas, s2,
                                              names, iters=3 if terms else 2,
                                              tolerance=tolerance)
    # a term whose share collapses in the joint refit (rms contribution under 0.2 of
    # the noise floor) is not a finding: drop it and refit the rest. Beside a timing
    # term (refitted in its two forms above) only what falls under the practical size
    # is dropped: the timing refit moves the other terms little, and a floor raised by
    # broadband mismatch (EMPS) would drop a term the held-out lap confirms
    floor = 0.0 if lag_k is not None else 0.2 * noise["rms"]
    small = [k for k, t in enumerate(terms)
             if not t.minor and t.effect != "delay"
             and _rms(t.cand.columns(t.h, ctx) @ betas[k], sig.mask) < max(floor, min_force)]
    if small:
        for k in small:
            lg = next((g for g in log if g["accepted"] and g["effect"] == terms[k].effect),
                      None)
            if lg is not None:
                lg["accepted"] = False
                lg["why"] += ("; dropped: its contribution after the joint refit is "
                              "small against the noise floor")
        keep = [k for k in range(len(terms)) if k not in small]
        aug, base, betas, ctx, terms = refine(
            model, sig, [terms[k] for k in keep], dict(base0), [betas[k] for k in keep],
            s2, names, iters=3 if keep else 2, tolerance=tolerance)
        alternatives = {keep.index(k): v for k, v in alternatives.items() if k in keep}

    def drop_terms(why: dict[int, str], terms: list[Any], betas: list[np.ndarray],
                   base: dict[str, float], alternatives: dict[int, list[dict[str, Any]]]
                   ) -> tuple[Any, ...]:
        """Drop terms ``why`` names (the log says why) and refit the rest, the timing
        term's form chosen again."""
        for k, reason in why.items():
            lg = next((g for g in log if g["accepted"] and g["effect"] == terms[k].effect),
                      None)
            if lg is not None:
                lg["accepted"] = False
                lg["why"] += "; dropped: " + reason
        keep = [k for k in range(len(terms)) if k not in why]
        terms, betas = [terms[k] for k in keep], [betas[k] for k in keep]
        t_k = next((j for j, t in enumerate(terms) if t.effect == "delay"), None)
        if t_k is not None:  # the timing's form chosen again without them
            from .timing import choose_timing

            aug, base, betas, ctx, terms, alt = choose_timing(
                model, sig, terms, t_k, dict(base), betas, s2, names,
                scorer.used_blocks, min_gain, tolerance)
            return aug, base, betas, ctx, terms, ({t_k: [alt]} if alt is not None else {})
        aug, base, betas, ctx, terms = refine(
            model, sig, terms, dict(base), betas, s2, names, iters=3 if terms else 2,
            tolerance=tolerance)
        return aug, base, betas, ctx, terms, {keep.index(k): v for k, v in
                                              alternatives.items() if k in keep}

    # backward check: with every term in its exact form, each finding must still add to
    # the refit without it, in most blocks (a damped resonance
    # took up a current lag's attenuation while the selection's timing column was a
    # pure delay; with the lag in its exact form it explained nothing more)
    named_k = [k for k, t in enumerate(terms) if not t.minor and t.effect != "delay"]
    if len([t for t in terms if not t.minor]) >= 2 and named_k:
        sse_all = block_sse(aug)
        weak = []
        t_k = next((j for j, t in enumerate(terms) if t.effect == "delay"), None)
        for k in named_k:
            keep = [j for j in range(len(terms)) if j != k]
            # without it, the timing term may take either form (a lag's attenuation
            # is what a damped resonance beside a pure delay stands for)
            forms = [None] if t_k is None else ["delay", "current_lag"]
            sse_wo = None
            for form in forms:
                tt = [terms[j] if j != t_k or form is None
                      else Term(cand=terms[j].cand, h=form, X=terms[j].X) for j in keep]
                try:
                    out = refine(model, sig, tt, dict(base), [betas[j] for j in keep], s2,
                                 names, iters=3, tolerance=tolerance)
                except ValueError:
                    continue
                cand_sse = block_sse(out[0])
                if sse_wo is None or cand_sse.sum() < sse_wo.sum():
                    sse_wo = cand_sse
            if sse_wo is None:
                continue
            dd = (sse_wo - sse_all) / s2  # > 0: the term helps
            # the held-out test chose it; here it is dropped only when the exact forms
            # leave it nothing to add (the EMPS ripple adds 91 units in 10 of 10 blocks,
            # t = 2.5: kept; the resonance beside a lag: -798)
            if dd.sum() < min_gain or np.sum(dd > 0) < 0.5 * dd.size:
                tstat = abs(dd.mean()) / (dd.std(ddof=1) / math.sqrt(dd.size) + 1e-300)
                weak.append((k, float(dd.sum()), float(tstat)))
        if weak:
            aug, base, betas, ctx, terms, alternatives = drop_terms(
                {k: (f"with the other terms in their exact forms it adds {gain:.0f} "
                     f"(t = {tstat:.1f} over the blocks)") for k, gain, tstat in weak},
                terms, betas, base, alternatives)

    # the readings' own noise: a term that smooths a reading (a compliant load the
    # acceleration) also takes up part of the noise the residual holds, in every block
    # alike. Its gain is read again with noise like the record's added (SIMEX) and
    # extrapolated back to noise-free readings: a clean 17 kg axis logged at 5 kHz with
    # a 0.1 um encoder had been given a damped 76 Hz resonance (gain 1376 in noise
    # units, of which noise like its own made about 1180). Only such terms: on others
    # the added noise acts through the friction's nonlinearity, not by correlation, and
    # the linear extrapolation does not hold (a friction bump seen through a 5 um
    # encoder at 1 kHz: 9887, of which the added noise "made" 4383)
    # A minor correction that smooths a reading is checked too: it is not named, but a
    # term accepted beside it may pass only with it (a clean 18 kg axis logged at 5 kHz:
    # a damped resonance, minor, then a 0.1 ms delay that gained nothing without it)
    named_k = [k for k, t in enumerate(terms) if t.cand.smooths_readings]
    noise_notes: list[str] = []
    if named_k:
        noisy = noise_made(sig, surrogates(rec, model, sig), model,
                           (aug, terms, betas, ctx), named_k, scorer.used_blocks, s2,
                           min_gain, alpha)
        gone = {terms[k].effect for k in noisy if terms[k].minor}
        beside: set[int] = set()
        if gone:
            # the named terms judged again as the search judged them, without it
            sel = [t for t in terms_sel if t.effect not in gone]
            ev_all = scorer.evaluate(sel)
            for k, t in enumerate(terms):
                j = next((i for i, u in enumerate(sel) if u.effect == t.effect), None)
                if t.minor or k in noisy or j is None:
                    continue
                evj = compare(scorer.evaluate(sel[:j] + sel[j + 1:]), ev_all, s2)
                if not accept(evj, alpha=alpha, min_gain=min_gain)[0]:
                    beside.add(k)
                    noisy[k] = (f"it passed the held-out test only beside a minor "
                                f"{' and '.join(sorted(gone)).replace('_', ' ')} that the "
                                "readings' own noise makes (without it: gain "
                                f"{evj['gain']:.0f}, {evj['positive']} of {evj['blocks']} "
                                "blocks)")
        if noisy:
            noise_notes = [
                (f"A {terms[k].effect.replace('_', ' ')} kept as a minor correction is "
                 f"dropped: {why}." if terms[k].minor else
                 f"A {terms[k].effect.replace('_', ' ')} is not named: {why}." if k in beside
                 else
                 f"A {terms[k].effect.replace('_', ' ')} passed the held-out test but is "
                 f"not named: {why}. A finer position reading or a lower band "
                 "(--cutoff-hz) would show whether physics is left under it.")
                for k, why in noisy.items()]
            for k in noisy:
                if terms[k].minor:
                    minor_log = next((g for g in log if g["effect"] == terms[k].effect
                                      and g.get("minor")), None)
                    if minor_log is not None:
                        minor_log["why"] += "; dropped: " + noisy[k]
            aug, base, betas, ctx, terms, alternatives = drop_terms(
                noisy, terms, betas, base, alternatives)

    # a mass refused for reading differently speeding up and braking was a look-alike of
    # what the findings, in their exact forms, now explain when adding it no longer
    # helps (a 64 Hz current lag's attenuation read as +0.3 kg speeding up, +2 kg
    # braking while the selection's timing column was a pure delay)
    if mass_ways is not None:
        mc = next(c for c in E.candidates() if c.effect == "mass")
        mt = make_term(mc, None, ctx)
        try:
            out = refine(model, sig, terms + [mt], dict(base),
                         betas + [np.zeros(mt.X.shape[1])], s2, names, iters=3,
                         tolerance=tolerance)
            dd = (block_sse(aug) - block_sse(out[0])) / s2  # > 0: a mass still helps
            still, _ = told_apart(dd, min_gain)
            if not (still and dd.sum() > 0):
                mass_ways = None
        except ValueError:
            pass

    # the model's own effects questioned again with the findings in: one the record
    # contradicts now (or one a finding of its kind only cancels) goes, and the record
    # is diagnosed again without it
    r1 = R.residual(aug, sig)
    if _question and model.effects:
        later = contradicted_beside(aug, len(model.effects), sig, r1, blocks=blocks,
                                    alpha=alpha, min_gain=min_gain, step=step,
                                    tolerance=tolerance)
        if later:
            return _diagnose(
                rec, _without(model, {k for k, _ in later}), holdout=holdout,
                cutoff_hz=cutoff_hz, blocks=blocks, alpha=alpha, min_gain=min_gain,
                closed_loop=closed_loop, candidates=candidates, screw_lead=screw_lead,
                free_mass=free_mass, tolerance=tolerance, backend=backend,
                _given=(model_given, removed + [e for _, e in later]))

    # 5. evidence and report
    noise_after = R.noise_floor(r1, sig)
    tot0 = float(np.sum(r0[sig.mask] ** 2))
    # most of the mismatch left over: the accepted terms are partial look-alikes of
    # physics outside the vocabulary, reported as what the rest resembles, not named.
    # The share is of what the base refit alone leaves: re-estimated friction levels
    # can absorb most of a mismatch they do not explain (a viscous coefficient that
    # falls as the axis warms up), and the terms must explain most of the rest.
    resembles: list[dict[str, Any]] = []
    r_base = scorer.evaluate([]).resid
    share = 1.0 - float(np.sum(r1[sig.mask] ** 2)) / max(
        min(float(np.sum(r_base[sig.mask] ** 2)), tot0), 1e-300)
    if (any(not t.minor for t in terms) and share < 0.9
            and _rms(r1, sig.mask) > PARTIAL_REST * noise_after["rms"]):
        for k, t in enumerate(terms):
            if t.minor:
                continue
            e0 = t.cand.to_effects(t.h, betas[k], ctx)[0]
            resembles.append({"effect": e0["effect"],
                              "parameters": {a: v for a, v in e0.items() if a != "effect"}})
        for lg in log:
            if lg["accepted"]:
                lg["accepted"] = False
                lg["why"] += "; not named: most of the mismatch stays unexplained with it"
        alternatives = {}
        aug, base, betas, ctx, terms = refine(
            model, sig, [], {n: B.get_base(model, n) for n, _ in B.BASE_PARAMS}, [], s2,
            names, iters=2, tolerance=tolerance)
        r1 = R.residual(aug, sig)
        noise_after = R.noise_floor(r1, sig)
    findings: list[Finding] = []
    accepted = [lg for lg in log if lg["accepted"]]
    data_effects: list[dict[str, Any]] = []
    minor: list[dict[str, Any]] = []
    for k, t in enumerate(terms):
        X = t.cand.columns(t.h, ctx)
        contrib = X @ betas[k]
        if t.minor:  # too small to name: kept in the model, listed apart
            for e in t.cand.to_effects(t.h, betas[k], ctx):
                minor.append({"effect": e["effect"], "rms_force": _rms(contrib, sig.mask),
                              "parameters": {a: v for a, v in e.items() if a != "effect"}})
            continue
        rem = r1 + contrib  # the final model without this term
        gain_e = np.sum(rem[sig.mask] ** 2) - np.sum(r1[sig.mask] ** 2)
        expl = float(np.clip(gain_e / tot0, 0.0, 1.0))
        effs = t.cand.to_effects(t.h, betas[k], ctx)
        e0 = effs[0]
        lg = next((g for g in accepted if g["effect"] == t.effect),
                  accepted[min(k, len(accepted) - 1)] if accepted else {})
        extra = t.cand.describe(t.h, betas[k], ctx)
        unc: dict[str, Any] = t.cand.uncertainty(t, betas[k], ctx, sig, s2)
        jack = [n for n, sd in intervals.get(t.effect, {}).items()
                if n not in unc and isinstance(effs[0].get(n), (int, float))]
        for name in jack:
            v, sd = float(effs[0][name]), intervals[t.effect][name]
            unc[name] = [v - 1.96 * sd, v + 1.96 * sd]
        if jack:
            unc["interval"] = (f"{', '.join(jack)}: 95 %, jackknife over the held-out blocks "
                               "(noise only, not model error)")
        if t.effect == "drift":
            unc, extra = V.drift_identifiability(t, float(sig.t[sig.mask][-1]), thr=min_gain)
        if t.effect in lookalike:
            alternatives.setdefault(k, []).append(lookalike[t.effect])
        if t.effect == "mass":
            alt_m = V.mass_alternative(float(e0["delta"]), float(model.mass), ctx,
                                       scorer.mask)
            if alt_m is not None:
                alternatives.setdefault(k, []).append(alt_m)
        if t.effect == "offset":
            alt_off, extra = V.offset_alternative(scorer, terms, ev_sel, names, tol, model,
                                                  sig, min_gain)
            if alt_off is not None:
                alternatives.setdefault(k, []).append(alt_off)
        params = {a: v for a, v in e0.items() if a != "effect"}
        if t.effect == "delay":
            from .timing import timing_parameters

            params = timing_parameters(e0, alternatives.get(k, []))
        findings.append(Finding(
            effect=e0["effect"], parameters=params,
            where=t.cand.where(t.h, betas[k], ctx), explained=expl,
            evidence=V.evidence(t, lg, blocks, extra) + _beside_given(model, e0),
            alternatives=alternatives.get(k, []),
            uncertainty=unc))
        data_effects.append({"effect": e0["effect"], **t.cand.figure(rem, contrib, ctx)})
        for e in effs[1:]:  # e.g. a spring whose x0 cannot be placed: offset beside it
            findings.append(Finding(effect=e["effect"],
                                    parameters={a: v for a, v in e.items() if a != "effect"},
                                    where={"position": None, "time": None, "velocity": None},
                                    explained=0.0, evidence="Part of the spring term above."))
    # shares that add up: each finding's share scaled so that together they make what
    # the refit explains (dropping one term alone, the base does not re-adjust)
    total = max(0.0, 1.0 - float(np.sum(r1[sig.mask] ** 2)) / tot0)
    summed = sum(f.explained for f in findings)
    if summed > total > 0.0 or (summed > 0.0 and total == 0.0):
        for f in findings:
            f.explained *= total / summed
    order = np.argsort([-f.explained for f in findings], kind="stable")
    findings = [findings[j] for j in order]

    base_rep = V.base_report(model, base, names, presliding)
    notes = V.base_notes(base_rep, findings) + noise_notes
    notes += _origin_notes(removed, findings)
    if held_kinds:
        kinds = sorted({"timing" if k == "delay" else k.replace("_", " ")
                        for k in held_kinds})
        notes.append(f"The model already holds its {' and '.join(kinds)} (one of a kind): "
                     "kept as given, not searched again.")
    fit: dict[str, Any] = {"before": _metrics(r0_given, sig.fm_f, sig.mask),
                           "after": _metrics(r1, sig.fm_f, sig.mask),
                           "holdout_before": {}, "holdout_after": {}}
    if holdout is not None:
        # the same band as the diagnosis, so that the two records are compared alike
        hb = evaluate(holdout, model_given, cutoff_hz=sig.cutoff_hz, backend=backend)
        ha = evaluate(holdout, aug, cutoff_hz=sig.cutoff_hz, backend=backend)
        fit["holdout_before"] = {k: hb[k] for k in ("rms_force", "nrmse_force")}
        fit["holdout_after"] = {k: ha[k] for k in ("rms_force", "nrmse_force")}
    fit["held_out_blocks"] = {
        "base_refit": float(np.sqrt(ev_held.sse_b.sum() / n_used)),
        "with_findings": float(np.sqrt(ev.sse_b.sum() / n_used)),
    }
    if closed_loop:
        cl = _closed_loop(rec, model_given, aug, sig.backend.simulate)
        if cl is not None and "error" not in cl:
            fit["closed_loop"] = cl

    located = {"before": locate(r0_given, sig, noise["rms"]),
               "after": locate(r1, sig, noise["rms"])}
    # a floor far above what the current's noise and the encoder explain holds
    # mismatch spread over the band: "nothing found" would hide it
    expected = R.expected_floor(sig, aug)
    excess = None
    if noise_after["rms"] > EXCESS_FLOOR * expected["rms"] > 0:
        excess = {"floor": noise_after["rms"], "expected": expected["rms"]}
    # the rest is measured against the floor after the findings when they lowered it
    # (a mismatch spread over the band, such as a lag's, raised the base refit's floor)
    unexplained = V.unexplained(r1, sig, min(noise["rms"], noise_after["rms"]),
                                located["after"], fit["after"], lag_rev, mass_ways, excess)
    if unexplained is not None and resembles:
        unexplained["resembles"] = resembles
        unexplained["message"] = unexplained["message"].replace(
            "After the findings the residual", "With the friction levels refitted the residual")
        unexplained["message"] += (
            " Part of it resembles " + ", ".join(r["effect"] for r in resembles)
            + " (consistent on held-out stretches), but with it the rest stays over "
            f"{PARTIAL_REST:g} times the noise floor and less than 90 % is explained: "
            "physics outside the vocabulary is likelier than that name.")
    kept = {t.effect for t in terms}
    hidden = V.could_not_reveal(scorer, ctx,
                                [c for c in E.candidates() if c.effect not in held_kinds],
                                [t.effect for t in terms if not t.minor],
                                min_gain, terms=[t for t in terms_sel if t.effect in kept],
                                alpha=alpha, noise_rms=noise["rms"], min_force=min_force)
    ks0, pk0 = position_spectrum(r0_given, sig)
    _, pk = position_spectrum(r1, sig)
    data = {"t": sig.t, "x": sig.x, "v": sig.vf, "force": sig.fm_f, "before": r0_given,
            "after": r1,
            "mask": sig.mask, "spectrum_k": ks0, "spectrum_before": pk0, "spectrum_after": pk,
            "model_before": sig.fm_f - r0_given, "model_after": sig.fm_f - r1,
            "effects": data_effects}
    dg = Diagnosis(findings=findings, fit=fit, model=model_given, augmented=aug, base=base_rep,
                   noise={**noise, "cutoff_hz": float(sig.cutoff_hz),
                          "rms_before_refit": R.noise_floor(r0, sig)["rms"],
                          "rms_after": noise_after["rms"],
                          "expected_rms": expected["rms"],
                          "expected_current": expected["current"],
                          "expected_encoder": expected["encoder"]},
                   located=located, unexplained=unexplained, notes=notes, trials=log,
                   data=data)
    dg.could_not_reveal = hidden
    dg.removed = removed
    dg.minor = minor
    dg.base_moves = V.base_moves(base_rep)
    dg.verdict = V.verdict(dg)
    return dg


def _without(model: Model, drop: set[int]) -> Model:
    d = model.to_dict()
    d["effects"] = [e for j, e in enumerate(d["effects"]) if j not in drop]
    return Model.from_dict(d)


def _variance_unit(r: np.ndarray, J: np.ndarray, tol: np.ndarray, sig: R.Signals,
                   blocks: int, step: int) -> tuple[dict[str, float], float]:
    """The noise floor of the base refit's residual and the scores' variance unit
    ``s2`` (its rms squared over the effective number of samples, in every sample)."""
    n_used = int(sig.mask.sum())
    noise = R.noise_floor(r, sig)
    s2 = noise["rms"] ** 2 * n_used / noise["n_eff"]
    ev = Scorer(r, J, tol, sig.mask, s2, blocks, step=step).evaluate([])
    noise = R.noise_floor(ev.resid, sig)
    return noise, noise["rms"] ** 2 * n_used / noise["n_eff"]


Removal = tuple[dict[str, Any], dict[str, Any], Model | None, np.ndarray]


def _removals(model: Model, sig: R.Signals, r: np.ndarray, sets: list[set[int]], *,
              blocks: int, step: int, tolerance: float,
              others: list[np.ndarray] | None = None) -> list[Removal | None]:
    """Held-out evidence of taking each set of ``model``'s effects out: per set, the
    gain of removing it and the gain of keeping it (:func:`compare`, the friction levels
    refitted in both), the model without it and its residual; ``None`` where no valid
    model is left. ``r`` is ``model``'s residual; ``others``: residuals of other models,
    judged the same way (after the sets, without a model)."""
    J, _, _, tol = B.base_jacobian(model, sig, names=B.LEVELS)
    tol = tol * float(tolerance)
    _, s2 = _variance_unit(r, J, tol, sig, blocks, step)
    sc = Scorer(r, J, tol, sig.mask, s2, blocks, step=step)
    ev = sc.evaluate([])

    def judged(m_o: Model | None, r_o: np.ndarray) -> Removal | None:
        if not np.all(np.isfinite(r_o[sig.mask])):
            return None
        ev_o = sc.like(r=r_o).evaluate([])
        return compare(ev, ev_o, s2), compare(ev_o, ev, s2), m_o, r_o

    out: list[Removal | None] = []
    for drop in sets:
        try:
            m_s = _without(model, drop)
            out.append(judged(m_s, R.residual(m_s, sig)))
        except ValueError:  # no valid model without them (they hold the others up)
            out.append(None)
    return out + [judged(None, r_o) for r_o in others or []]


#: A parameter of a one-of-a-kind effect found that differs from the model's by more
#: than this share has moved (less is a refinement)
MOVED_SHARE = 0.05


def _far(a: float, b: float) -> bool:
    return abs(a - b) > MOVED_SHARE * max(abs(a), abs(b))


def _differs(old: dict[str, Any], new: dict[str, Any]) -> bool:
    """Whether an effect found differs from the model's of its kind by more than
    :data:`MOVED_SHARE` in a parameter they share, or (a timing term of the other form)
    in its effective delay."""
    shared = [k for k, v in new.items()
              if isinstance(v, (int, float)) and isinstance(old.get(k), (int, float))]
    if old.get("effect") == "current_lag" and "seconds" not in old:
        shared = []  # a lag given by its bandwidth: compared by its mean delay below
    if shared:
        return any(_far(new[k], old[k]) for k in shared)
    sec_old = old.get("seconds")
    if sec_old is None and old.get("bandwidth"):
        sec_old = 1.0 / (2.0 * math.pi * float(old["bandwidth"]))
    sec_new = new.get("seconds")
    if isinstance(sec_old, (int, float)) and isinstance(sec_new, (int, float)):
        return _far(sec_new, sec_old)
    return True


def _moved(old: dict[str, Any], new: dict[str, Any]) -> str:
    """What moved between two effects of a kind, in words ("damping_ratio 0.18 -> 0.3;
    frequency, load_fraction within 5 %")."""
    moved, same = [], []
    for k, v in new.items():
        w = old.get(k)
        if not isinstance(v, (int, float)) or not isinstance(w, (int, float)):
            continue
        if _far(v, w):
            moved.append(f"{k} {w:.3g} -> {v:.3g}")
        else:
            same.append(k)
    return "; ".join(moved) + (f"; {', '.join(same)} within 5 %" if moved and same else "")


def _removed_entry(e: dict[str, Any], pt: dict[str, Any], why: str, *,
                   beside: str = "", instead: str = "", moved: str = "") -> dict[str, Any]:
    e = dict(e)
    name = str(e.pop("effect"))
    words = V.effect_words(name, e)
    how = ("consistently" if why.startswith("consistent") else
           "by far, where the mismatch lies")
    said = (f"The model's {name.replace('_', ' ')}{' (' + words + ')' if words else ''} "
            "does not match this record: ")
    if instead:
        said += (f"searched again without it, this record holds {instead}, which predicts "
                 f"the held-out stretches better {how} (in {pt['positive']} of "
                 f"{pt['blocks']}, by {pt['gain']:.0f} in squared-error units of the noise; "
                 f"chance of this from noise alone: p = {pt['p']:.2g}). It is replaced: "
                 "the augmented model holds the one found."
                 + (f" What moved: {moved}." if moved else ""))
        return {"effect": name, "parameters": e, "evidence": said, "gain": pt["gain"],
                "p": pt["p"], "positive": pt["positive"], "blocks": pt["blocks"],
                "replaced": True}
    if beside:
        said += (f"the search found {beside} of the opposite sense beside it, and the two "
                 "together do not earn their place on the held-out stretches (kept: "
                 f"better in {pt['positive']} of {pt['blocks']}, by {pt['gain']:.0f} in "
                 f"squared-error units of the noise, p = {pt['p']:.2g}). ")
    else:
        said += ("without it, the friction levels refitted, the held-out stretches are "
                 f"predicted better {how} (in {pt['positive']} of {pt['blocks']}, by "
                 f"{pt['gain']:.0f} in squared-error units of the noise; chance of this "
                 f"from noise alone: p = {pt['p']:.2g}). ")
    said += "It is left out of the augmented model and the record searched without it."
    return {"effect": name, "parameters": e, "evidence": said, "gain": pt["gain"],
            "p": pt["p"], "positive": pt["positive"], "blocks": pt["blocks"]}


def question_effects(model: Model, sig: R.Signals, r0: np.ndarray, *, blocks: int,
                     alpha: float, min_gain: float, step: int, tolerance: float
                     ) -> tuple[Model, list[dict[str, Any]], np.ndarray]:
    """The model's own effects that the record contradicts, removed one at a time.

    Each effect the model holds is taken out in turn and the residual of the model
    without it is scored against the model's on the held-out blocks, the friction
    levels refitted in both, by the search's own acceptance test (:func:`accept`). The
    effect whose removal gains most and passes is removed; the rest are questioned
    again without it. An effect the record cannot see (removing it changes nothing) is
    kept: only one the record contradicts goes.

    Returns
    -------
    (Model, list of dict, numpy.ndarray)
        The model without the contradicted effects; per removed effect ``effect``,
        ``parameters``, ``evidence`` (in words) and the block test (``gain``, ``p``,
        ``positive``, ``blocks``); the residual of the model returned.
    """
    removed: list[dict[str, Any]] = []
    cur, r_cur = model, r0
    while cur.effects:
        sets = [{k} for k in range(len(cur.effects))]
        best: tuple[Any, ...] | None = None
        for k, res in enumerate(_removals(cur, sig, r_cur, sets, blocks=blocks, step=step,
                                          tolerance=tolerance)):
            if res is None:
                continue
            ok, why = accept(res[0], alpha=alpha, min_gain=min_gain)
            if ok and (best is None or res[0]["gain"] > best[1]["gain"]):
                best = (k, res[0], res[2], res[3], why)
        if best is None:
            break
        k, pt, m_k, r_k, why = best
        removed.append(_removed_entry(cur.effects[k], pt, why))
        cur, r_cur = m_k, r_k
    return cur, removed, r_cur


def replace_one_of_a_kind(rec: Recording, model: Model, sig: R.Signals, r: np.ndarray, *,
                          cutoff_hz: float | None, screw_lead: float | None, backend: str,
                          blocks: int, alpha: float, min_gain: float, step: int,
                          tolerance: float
                          ) -> tuple[Model, list[dict[str, Any]], np.ndarray]:
    """One of a kind (a timing term, a resonance, a Stribeck shape) is not searched
    beside the model's own: the record is diagnosed for that kind again without it, and
    the one found replaces the model's when, put in its place with all else as given,
    it predicts the held-out blocks better (:func:`accept`) and differs from it by more
    than 5 % in a parameter (a delay given from another session; a resonance moved).
    ``r`` is ``model``'s residual; returns the model, the replaced effects' entries (as
    :func:`question_effects`) and the model's residual."""
    replaced: list[dict[str, Any]] = []
    for k, e in reversed(list(enumerate(model.effects))):
        kind = _kind(e["effect"])
        if kind not in ONE_OF_A_KIND:
            continue
        m_k = _without(model, {k})
        try:
            sub = _diagnose(rec, m_k, cutoff_hz=cutoff_hz, blocks=blocks, alpha=alpha,
                            min_gain=min_gain, closed_loop=False, candidates=[kind],
                            screw_lead=screw_lead, tolerance=tolerance, backend=backend,
                            _question=False)
        except ValueError:
            continue
        again = [f for f in sub.findings if _kind(f.effect) == kind]
        # a refinement is no contradiction (a lightly damped 23.7 Hz resonance
        # preferred at 23.6 Hz on a hold-out record stays as given)
        if not again or not _differs(e, again[0].parameters):
            continue
        # the one found in place of the model's, all else as given: the two alone are
        # compared (the search's refit of the friction levels is no part of it)
        d_sub = m_k.to_dict()
        d_sub["effects"] = list(d_sub["effects"]) + [
            x for x in sub.augmented.effects[len(m_k.effects):]
            if _kind(x["effect"]) == kind][:1]
        try:
            r_sub = R.residual(Model.from_dict(d_sub), sig)
        except ValueError:
            continue
        (res,) = _removals(model, sig, r, [], blocks=blocks, step=step,
                           tolerance=tolerance, others=[r_sub])
        if res is None:
            continue
        ok, why = accept(res[0], alpha=alpha, min_gain=min_gain)
        if not ok:
            continue
        f = again[0]
        replaced.append(_removed_entry(
            e, res[0], why,
            instead=f"{f.effect.replace('_', ' ')} ({V.effect_words(f.effect, f.parameters)})",
            moved=_moved(e, f.parameters) if f.effect == e["effect"] else ""))
        model, r = m_k, R.residual(m_k, sig)
    return model, replaced, r


def contradicted_beside(aug: Model, n_given: int, sig: R.Signals, r: np.ndarray, *,
                        blocks: int, alpha: float, min_gain: float, step: int,
                        tolerance: float) -> list[tuple[int, dict[str, Any]]]:
    """The model's own effects (the first ``n_given`` of ``aug``) that the record
    contradicts once the findings are in: taking one out improves the held-out
    stretches, or the search found the same kind of effect beside it and the two
    together do not earn their place (a drift of 5 % given, -4.8 % found). ``r`` is
    ``aug``'s residual. Returns ``(index, removed entry)`` pairs."""
    effs = aug.effects
    sets: list[set[int]] = []
    pairs: list[bool] = []
    for k in range(n_given):
        sets.append({k})
        pairs.append(False)
        same = {j for j in range(n_given, len(effs))
                if _kind(effs[j]["effect"]) == _kind(effs[k]["effect"])}
        if same:
            sets.append({k} | same)
            pairs.append(True)
    out: dict[int, dict[str, Any]] = {}
    for drop, pair, res in zip(sets, pairs, _removals(aug, sig, r, sets, blocks=blocks,
                                                      step=step, tolerance=tolerance)):
        if res is None:
            continue
        k = min(drop)
        if k in out:
            continue
        if pair:
            kept, why = accept(res[1], alpha=alpha, min_gain=min_gain)
            if not kept:
                found = " and ".join(sorted({effs[j]["effect"].replace("_", " ")
                                             for j in drop if j != k}))
                out[k] = _removed_entry(effs[k], res[1], why, beside=f"a {found}")
        else:
            ok, why = accept(res[0], alpha=alpha, min_gain=min_gain)
            if ok:
                out[k] = _removed_entry(effs[k], res[0], why)
    return sorted(out.items())


#: Effects whose one parameter adds up when two of them act: a finding of such a kind
#: beside the model's own is a correction of it
_ADDITIVE = {"mass": "delta", "offset": "force", "drag": "coefficient"}


def _beside_given(model: Model, e: dict[str, Any]) -> str:
    """A finding of a kind the model holds, in words, as the correction of the model's."""
    key = _ADDITIVE.get(str(e["effect"]))
    own = [g for g in model.effects if g["effect"] == e["effect"]]
    if key is None or not own:
        return ""
    unit = {"delta": " kg", "force": " N", "coefficient": " N s^2/m^2"}[key]
    have = sum(float(g[key]) for g in own)
    return (f" The model already holds a {e['effect']} ({key} {have:+.3g}{unit}); this "
            f"corrects it: together {key} {have + float(e[key]):+.3g}{unit}.")


def _origin_notes(removed: list[dict[str, Any]], findings: list[Finding]) -> list[str]:
    """A cogging removed and found again at its pitch but another phase: the record's
    position origin differs from the one the model was made on (the EMPS pulses record
    against its laps: 0.7 mm)."""
    out = []
    for r in removed:
        if r["effect"] != "cogging":
            continue
        p_old = float(r["parameters"]["pitch"])
        for f in findings:
            if f.effect != "cogging" or abs(f.parameters["pitch"] / p_old - 1) > 0.01:
                continue
            dphi = math.remainder(float(f.parameters["phase"])
                                  - float(r["parameters"].get("phase", 0.0)), 2 * math.pi)
            dx = dphi / (2 * math.pi) * p_old
            ratio = float(f.parameters["amplitude"]) / float(r["parameters"]["amplitude"])
            out.append(
                f"The cogging found has the pitch of the model's ({p_old * 1e3:.4g} mm) and "
                f"{ratio:.2g} times its amplitude, at a position shift of "
                f"{dx * 1e3:+.2g} mm ({dphi:+.2f} rad; modulo the pitch): this record's "
                "position origin likely differs from the one the model was made on "
                "(homing, an encoder offset). Home the axis alike for both, or use the "
                "phase found here for this setup.")
    return out


#: Kinds a model holds once at most (the timing candidate is ``delay``, for both forms).
ONE_OF_A_KIND = ("delay", "resonance", "stribeck_shape")


def _kind(effect: str) -> str:
    """An effect's kind: its name, but ``delay`` for both timing forms."""
    return "delay" if effect in ("delay", "current_lag") else str(effect)


def _held_kinds(model: Model) -> set[str]:
    """Candidates the model leaves no room for: effects it may hold once and already
    holds."""
    return {_kind(e["effect"]) for e in model.effects} & set(ONE_OF_A_KIND)


def _rms(y: np.ndarray, mask: np.ndarray) -> float:
    return float(np.sqrt(np.mean(y[mask] ** 2)))


def _jackknife_intervals(terms: list[Any], ev: Any, q: int, ctx: E.Context
                         ) -> dict[str, dict[str, float]]:
    """Standard deviations of each effect's parameters from the leave-one-block-out fits.

    The jackknife over the contiguous held-out blocks carries the coloured noise and the
    base moves: ``sd^2 = (K-1)/K * sum((p_k - mean)^2)``; intervals are ``p +- 1.96*sd``
    around the refitted value. Parameters chosen on a grid (a pitch) get none here.
    """
    out: dict[str, dict[str, float]] = {}
    if ev.jack is None:
        return out
    K = ev.jack.shape[0]
    j = q
    for t in terms:
        p = t.X.shape[1]
        try:
            full = t.cand.to_effects(t.h, ev.beta[j:j + p], ctx)[0]
            reps = [t.cand.to_effects(t.h, ev.jack[k, j:j + p], ctx)[0] for k in range(K)]
        except (ValueError, ArithmeticError):  # pragma: no cover - degenerate replicate
            j += p
            continue
        iv: dict[str, float] = {}
        for name, val in full.items():
            if name in ("effect", "phase") or not isinstance(val, (int, float)):
                continue  # (a phase is an angle: the amplitude's spread says it)
            vals = np.array([float(r[name]) for r in reps])
            sd = math.sqrt((K - 1) / K * float(np.sum((vals - vals.mean()) ** 2)))
            if sd > 0:
                iv[name] = sd
        if iv:
            out[t.effect] = iv
        j += p
    return out
