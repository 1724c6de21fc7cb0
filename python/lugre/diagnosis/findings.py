"""Stage 5: the evidence. Each term kept becomes a finding with its parameters, where it
acts, the share it explains, its intervals and the alternatives beside it; accepted
terms that leave most of the mismatch unexplained are reported as what the rest
resembles, not named."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .. import units as U
from ..model import Model
from ..vocabulary import EFFECTS
from . import base as B
from . import candidates as E
from . import evidence as V
from . import residual as R
from .candidates import Term
from .joint import Joint, _Refitter
from .options import PARTIAL_REST, Options
from .prepare import Prepared
from .report import Finding
from .select import Selection
from .weigh import Weighing, rms

__all__ = ["Evidence", "gather"]


@dataclass(frozen=True)
class Evidence:
    """The findings (largest share first), the minor corrections kept in the model, what
    the accepted terms resemble when they leave most unexplained (``resembles``), the
    joint refit they stand on (``joint``), its residual ``r1`` and noise floor, and the
    figures' data of each finding."""

    findings: list[Finding]
    minor: list[dict[str, Any]]
    resembles: list[dict[str, Any]]
    joint: Joint
    r1: np.ndarray
    noise_after: dict[str, float]
    figures: list[dict[str, Any]]


def _partial(prep: Prepared, w: Weighing, sel: Selection, j: Joint, r1: np.ndarray,
             tot0: float, opts: Options) -> tuple[list[dict[str, Any]], Joint, np.ndarray]:
    """Most of the mismatch left over: the accepted terms are partial look-alikes of
    physics outside the vocabulary, reported as what the rest resembles, not named. The
    share is of what the base refit alone leaves: re-estimated friction levels can absorb
    most of a mismatch they do not explain (a viscous coefficient that falls as the axis
    warms up), and the terms must explain most of the rest. ``tot0``: the squared
    residual of the model diagnosed."""
    sig = prep.sig
    noise_after = R.noise_floor(r1, sig)
    r_base = sel.base.scorer.evaluate([]).resid
    share = 1.0 - float(np.sum(r1[sig.mask] ** 2)) / max(
        min(float(np.sum(r_base[sig.mask] ** 2)), tot0), 1e-300)
    if not (any(not t.minor for t in j.terms) and share < 0.9
            and rms(r1, sig.mask) > PARTIAL_REST * noise_after["rms"]):
        return [], j, r1
    resembles = []
    for k, t in enumerate(j.terms):
        if t.minor:
            continue
        e0 = t.cand.to_effects(t.h, j.betas[k], j.ctx)[0]
        resembles.append({"effect": e0["effect"],
                          "parameters": {a: v for a, v in e0.items() if a != "effect"}})
    for lg in sel.log:
        if lg["accepted"]:
            lg["accepted"] = False
            lg["why"] += "; not named: most of the mismatch stays unexplained with it"
    rf = _Refitter(model=w.model, sig=sig, w=w, names=sel.base.names, opts=opts, log=sel.log)
    aug, base, betas, ctx, terms = rf.refine(
        [], {n: B.get_base(w.model, n) for n, _ in B.BASE_PARAMS}, [], 2)
    j = replace(j, aug=aug, base=base, betas=betas, ctx=ctx, terms=terms, alternatives={})
    return resembles, j, R.residual(aug, sig)


def _minor(t: Term, beta: np.ndarray, j: Joint, mask: np.ndarray) -> list[dict[str, Any]]:
    contrib = t.cand.columns(t.h, j.ctx) @ beta
    return [{"effect": e["effect"], "rms_force": rms(contrib, mask),
             "parameters": {a: v for a, v in e.items() if a != "effect"}}
            for e in t.cand.to_effects(t.h, beta, j.ctx)]


def _uncertainty(t: Term, beta: np.ndarray, effs: list[dict[str, Any]], sel: Selection,
                 j: Joint, sig: R.Signals, s2: float) -> dict[str, Any]:
    """The candidate's own intervals, and jackknife ones over the held-out blocks for
    the parameters it gives none."""
    unc: dict[str, Any] = t.cand.uncertainty(t, beta, j.ctx, sig, s2)
    jack = [n for n in sel.intervals.get(t.effect, {})
            if n not in unc and isinstance(effs[0].get(n), (int, float))]
    for name in jack:
        v, sd = float(effs[0][name]), sel.intervals[t.effect][name]
        unc[name] = [v - 1.96 * sd, v + 1.96 * sd]
    if jack:
        unc["interval"] = (f"{', '.join(jack)}: 95 %, jackknife over the held-out blocks "
                           "(noise only, not model error)")
    return unc


def _finding(k: int, prep: Prepared, w: Weighing, sel: Selection, j: Joint,
             r1: np.ndarray, tot0: float, opts: Options, accepted: list[dict[str, Any]],
             alternatives: dict[int, list[dict[str, Any]]]
             ) -> tuple[list[Finding], dict[str, Any]]:
    """The findings of term ``k`` (a spring whose x0 cannot be placed gives an offset
    beside it) and its figure's data."""
    sig, t, beta, ctx = prep.sig, j.terms[k], j.betas[k], j.ctx
    contrib = t.cand.columns(t.h, ctx) @ beta
    rem = r1 + contrib  # the final model without this term
    gain_e = np.sum(rem[sig.mask] ** 2) - np.sum(r1[sig.mask] ** 2)
    expl = float(np.clip(gain_e / tot0, 0.0, 1.0))
    effs = t.cand.to_effects(t.h, beta, ctx)
    e0 = effs[0]
    lg = next((g for g in accepted if g["effect"] == t.effect),
              accepted[min(k, len(accepted) - 1)] if accepted else {})
    extra = t.cand.describe(t.h, beta, ctx)
    unc = _uncertainty(t, beta, effs, sel, j, sig, w.s2)
    if t.effect in sel.lookalike:
        alternatives.setdefault(k, []).append(sel.lookalike[t.effect])
    view = E.FindingView(sig=sig, model=w.model, scorer=sel.base.scorer, ev=sel.ev,
                         names=sel.base.names, tol=sel.base.tol, terms=j.terms,
                         min_gain=opts.min_gain, alternatives=alternatives.get(k, []))
    said = t.cand.finding(t, beta, e0, view)
    if said.uncertainty is not None:
        unc = said.uncertainty
    if said.evidence is not None:
        extra = said.evidence
    if said.alternatives:
        alternatives.setdefault(k, []).extend(said.alternatives)
    params = (said.parameters if said.parameters is not None
              else {a: v for a, v in e0.items() if a != "effect"})
    out = [Finding(effect=e0["effect"], parameters=params,
                   where=t.cand.where(t.h, beta, ctx), explained=expl,
                   evidence=V.evidence(t, lg, opts.blocks, extra) + _beside_given(w.model, e0),
                   alternatives=alternatives.get(k, []), uncertainty=unc)]
    for e in effs[1:]:  # e.g. a spring whose x0 cannot be placed: offset beside it
        out.append(Finding(effect=e["effect"],
                           parameters={a: v for a, v in e.items() if a != "effect"},
                           where={"position": None, "time": None, "velocity": None},
                           explained=0.0, evidence="Part of the spring term above."))
    return out, {"effect": e0["effect"], **t.cand.figure(rem, contrib, ctx)}


def gather(prep: Prepared, w: Weighing, sel: Selection, j: Joint, opts: Options) -> Evidence:
    """The evidence stage (see the module's text)."""
    sig = prep.sig
    r1 = R.residual(j.aug, sig)
    tot0 = float(np.sum(w.r0[sig.mask] ** 2))
    resembles, j, r1 = _partial(prep, w, sel, j, r1, tot0, opts)
    findings: list[Finding] = []
    figures: list[dict[str, Any]] = []
    minor: list[dict[str, Any]] = []
    accepted = [lg for lg in sel.log if lg["accepted"]]
    alternatives = {k: list(v) for k, v in j.alternatives.items()}
    for k, t in enumerate(j.terms):
        if t.minor:  # too small to name: kept in the model, listed apart
            minor += _minor(t, j.betas[k], j, sig.mask)
            continue
        fk, fig = _finding(k, prep, w, sel, j, r1, tot0, opts, accepted, alternatives)
        findings += fk
        figures.append(fig)
    # shares that add up: each finding's share scaled so that together they make what
    # the refit explains (dropping one term alone, the base does not re-adjust)
    total = max(0.0, 1.0 - float(np.sum(r1[sig.mask] ** 2)) / tot0)
    summed = sum(f.explained for f in findings)
    if summed > total > 0.0 or (summed > 0.0 and total == 0.0):
        for f in findings:
            f.explained *= total / summed
    order = np.argsort([-f.explained for f in findings], kind="stable")
    return Evidence(findings=[findings[i] for i in order], minor=minor, resembles=resembles,
                    joint=replace(j, alternatives=alternatives), r1=r1,
                    noise_after=R.noise_floor(r1, sig), figures=figures)


def _beside_given(model: Model, e: dict[str, Any]) -> str:
    """A finding of a kind the model holds, in words, as the correction of the model's."""
    spec = EFFECTS.get(str(e["effect"]))
    key = spec.additive if spec is not None else None
    own = [g for g in model.effects if g["effect"] == e["effect"]]
    if key is None or spec is None or not own:
        return ""
    unit = " " + U.si(spec.units[key])
    have = sum(float(g[key]) for g in own)
    return (f" The model already holds a {e['effect']} ({key} {have:+.3g}{unit}); this "
            f"corrects it: together {key} {have + float(e[key]):+.3g}{unit}.")


def origin_notes(removed: list[dict[str, Any]], findings: list[Finding]) -> list[str]:
    """A cogging removed and found again at its pitch but another phase: the record's
    position origin differs from the one the model was made on (the EMPS pulses record
    against its laps: 0.7 mm)."""
    out = []
    for r in removed:
        if r["effect"] != E.Cogging.effect:
            continue
        p_old = float(r["parameters"]["pitch"])
        for f in findings:
            if f.effect != E.Cogging.effect or abs(f.parameters["pitch"] / p_old - 1) > 0.01:
                continue
            dphi = math.remainder(float(f.parameters["phase"])
                                  - float(r["parameters"].get("phase", 0.0)), 2 * math.pi)
            dx = dphi / (2 * math.pi) * p_old
            ratio = float(f.parameters["amplitude"]) / float(r["parameters"]["amplitude"])
            u, k = U.position_unit()
            phase = f"{'phase ' if U.is_rotary() else ''}{dphi:+.2f} rad"
            out.append(
                f"The cogging found has the pitch of the model's ({p_old * k:.4g} {u}) and "
                f"{ratio:.2g} times its amplitude, at a position shift of "
                f"{dx * k:+.2g} {u} ({phase}; modulo the pitch): this record's "
                "position origin likely differs from the one the model was made on "
                "(homing, an encoder offset). Home the axis alike for both, or use the "
                "phase found here for this setup.")
    return out
