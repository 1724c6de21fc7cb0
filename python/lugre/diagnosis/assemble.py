"""Stage 6: the report. The findings with the base moves, the fit before and after (on
this record, the held-out one and in closed loop), where the mismatch lies, what stays
unexplained and what the record could not have revealed."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..io import Recording
from ..model import Model
from ..vocabulary import TIMING
from . import candidates as E
from . import evidence as V
from . import residual as R
from .evaluation import evaluate, metrics
from .findings import Evidence, origin_notes
from .locate import locate, position_spectrum
from .options import EXCESS_FLOOR, PARTIAL_REST, Options
from .prepare import Prepared
from .question import Questioned
from .report import Diagnosis
from .select import Selection
from .weigh import Weighing

__all__ = ["assemble", "closed_loop"]


def closed_loop(rec: Recording, before: Model, after: Model,
                simulate_batch: Any) -> dict[str, Any] | None:
    """Closed-loop simulations of both models under the recorded reference, against the
    record (PID controllers only; None without one or without ``x_ref``); the two run
    side by side (``simulate_batch`` of a backend)."""
    c = before.controller
    if c is None or rec.x_ref is None or c.get("type", "pid") != "pid":
        return None
    try:
        sims = simulate_batch([before, after], rec.t, rec.x_ref, x0=float(rec.x[0]))
    except (ValueError, ArithmeticError) as e:  # pragma: no cover - diverging
        return {"error": str(e)}
    out = {}
    for key, m, s in (("before", before, sims[0]), ("after", after, sims[1])):
        meas_i = rec.i if rec.i is not None else rec.F / m.force_constant
        out[key] = {"rms_position": float(np.sqrt(np.mean((s.x - rec.x) ** 2))),
                    "rms_current": float(np.sqrt(np.mean((s.i - meas_i) ** 2)))}
    return out


def _notes(q: Questioned, w: Weighing, sel: Selection, ev: Evidence,
           base_rep: dict[str, Any]) -> list[str]:
    notes = V.base_notes(base_rep, ev.findings) + ev.joint.noise_notes
    notes += origin_notes(list(q.removed), ev.findings)
    if sel.held_kinds:
        kinds = sorted({"timing" if k == TIMING else k.replace("_", " ")
                        for k in sel.held_kinds})
        notes.append(f"The model already holds its {' and '.join(kinds)} (one of a kind): "
                     "kept as given, not searched again.")
    return notes


def _fit(prep: Prepared, w: Weighing, sel: Selection, ev: Evidence, opts: Options
         ) -> dict[str, Any]:
    sig, aug = prep.sig, ev.joint.aug
    fit: dict[str, Any] = {"before": metrics(prep.r0_given, sig.fm_f, sig.mask),
                           "after": metrics(ev.r1, sig.fm_f, sig.mask),
                           "holdout_before": {}, "holdout_after": {}}
    if opts.holdout is not None:
        # the same band as the diagnosis, so that the two records are compared alike
        hb = evaluate(opts.holdout, prep.model_given, cutoff_hz=sig.cutoff_hz,
                      backend=opts.backend)
        ha = evaluate(opts.holdout, aug, cutoff_hz=sig.cutoff_hz, backend=opts.backend)
        fit["holdout_before"] = {k: hb[k] for k in ("rms_force", "nrmse_force")}
        fit["holdout_after"] = {k: ha[k] for k in ("rms_force", "nrmse_force")}
    fit["held_out_blocks"] = {
        "base_refit": float(np.sqrt(w.ev_held.sse_b.sum() / prep.n_used)),
        "with_findings": float(np.sqrt(sel.ev.sse_b.sum() / prep.n_used)),
    }
    if opts.closed_loop:
        cl = closed_loop(prep.rec, prep.model_given, aug, sig.backend.simulate_batch)
        if cl is not None and "error" not in cl:
            fit["closed_loop"] = cl
    return fit


def _unexplained(prep: Prepared, w: Weighing, sel: Selection, ev: Evidence,
                 located: dict[str, Any], fit: dict[str, Any], expected: dict[str, float]
                 ) -> dict[str, Any] | None:
    """The rest, measured against the floor after the findings when they lowered it (a
    mismatch spread over the band, such as a lag's, raised the base refit's floor); a
    floor far above what the current's noise and the encoder explain holds mismatch
    spread over the band: "nothing found" would hide it. ``expected``: the floor the
    current's noise and the encoder explain (:func:`lugre.diagnosis.residual.expected_floor`)."""
    sig, noise_after = prep.sig, ev.noise_after
    excess = None
    if noise_after["rms"] > EXCESS_FLOOR * expected["rms"] > 0:
        excess = {"floor": noise_after["rms"], "expected": expected["rms"]}
    un = V.unexplained(ev.r1, sig, min(w.noise["rms"], noise_after["rms"]),
                       located["after"], fit["after"], sel.own_check(TIMING),
                       ev.joint.mass_ways, excess)
    if un is not None and ev.resembles:
        un["resembles"] = ev.resembles
        un["message"] = un["message"].replace(
            "After the findings the residual", "With the friction levels refitted the residual")
        un["message"] += (
            " Part of it resembles " + ", ".join(r["effect"] for r in ev.resembles)
            + " (consistent on held-out stretches), but with it the rest stays over "
            f"{PARTIAL_REST:g} times the noise floor and less than 90 % is explained: "
            "physics outside the vocabulary is likelier than that name.")
    return un


def _hidden(w: Weighing, sel: Selection, ev: Evidence, opts: Options) -> Any:
    """What the record could not have revealed."""
    terms = ev.joint.terms
    kept = {t.effect for t in terms}
    return V.could_not_reveal(sel.base.scorer, ev.joint.ctx,
                              [c for c in E.candidates(w.model.kind)
                               if c.effect not in sel.held_kinds],
                              [t.effect for t in terms if not t.minor], opts.min_gain,
                              terms=[t for t in sel.terms if t.effect in kept],
                              alpha=opts.alpha, noise_rms=w.noise["rms"],
                              min_force=w.min_force)


def _data(prep: Prepared, ev: Evidence) -> dict[str, Any]:
    sig, r0, r1 = prep.sig, prep.r0_given, ev.r1
    ks0, pk0 = position_spectrum(r0, sig)
    _, pk = position_spectrum(r1, sig)
    return {"t": sig.t, "x": sig.x, "v": sig.vf, "force": sig.fm_f, "before": r0,
            "after": r1, "mask": sig.mask, "spectrum_k": ks0, "spectrum_before": pk0,
            "spectrum_after": pk, "model_before": sig.fm_f - r0, "model_after": sig.fm_f - r1,
            "effects": ev.figures}


def assemble(prep: Prepared, q: Questioned, w: Weighing, sel: Selection, ev: Evidence,
             opts: Options) -> Diagnosis:
    """The report stage (see the module's text)."""
    sig, j = prep.sig, ev.joint
    base_rep = V.base_report(w.model, j.base, sel.base.names, sel.presliding)
    fit = _fit(prep, w, sel, ev, opts)
    located = {"before": locate(prep.r0_given, sig, w.noise["rms"]),
               "after": locate(ev.r1, sig, w.noise["rms"])}
    expected = R.expected_floor(sig, j.aug)
    dg = Diagnosis(findings=ev.findings, fit=fit, model=prep.model_given, augmented=j.aug,
                   base=base_rep,
                   noise={**w.noise, "cutoff_hz": float(sig.cutoff_hz),
                          "rms_before_refit": R.noise_floor(w.r0, sig)["rms"],
                          "rms_after": ev.noise_after["rms"],
                          "expected_rms": expected["rms"],
                          "expected_current": expected["current"],
                          "expected_encoder": expected["encoder"]},
                   located=located,
                   unexplained=_unexplained(prep, w, sel, ev, located, fit, expected),
                   notes=_notes(q, w, sel, ev, base_rep), trials=sel.log, data=_data(prep, ev))
    dg.could_not_reveal = _hidden(w, sel, ev, opts)
    dg.removed = list(q.removed)
    dg.minor = ev.minor
    dg.base_moves = V.base_moves(base_rep)
    dg.verdict = V.verdict(dg)
    return dg
