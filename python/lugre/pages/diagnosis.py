"""The diagnosis page: the verdict, each finding with its evidence and figure, the base
moves, what stays unexplained and what the record could not have revealed."""

from __future__ import annotations

import math
import re
from html import escape
from typing import Any

from .. import units as U
from .._words import plain_text
from ..vocabulary import CURRENT_LAG, DELAY, EFFECTS
from .frame import _COLOURS, _figure, _p, _page, _safe_figure, _table

__all__ = ["EXPERIMENTS", "diagnosis_page"]

#: The experiment that determines each effect (or base parameter) a record left open.
EXPERIMENTS: dict[str, str] = {
    **{name: spec.experiment for name, spec in EFFECTS.items()},
    "sigma0": "short reversals with a stroke below a millimetre (presliding)",
    "sigma1": "short reversals with a stroke below a millimetre (presliding)",
    "fc": "constant-speed moves at several speeds in both directions",
    "fs": "slow feeds starting from standstill in both directions",
    "sigma2": "constant-speed moves at several speeds in both directions",
    "vs": "slow feeds at speeds around the Stribeck velocity",
    "force_constant": "a move with a known payload or a force sensor",
}

#: What each effect's figure is drawn against.
_NATURAL_ABSCISSA = {name: spec.abscissa for name, spec in EFFECTS.items()}


def _experiment(name: str, default: str) -> str:
    """The experiment that determines ``name``, in the words of the axis."""
    return U.words(EXPERIMENTS.get(name, default))


def _effect_title(effect: str) -> str:
    return U.words(effect.replace("_", " "))


def _list_summary(name: str, vals: list[float], unit: tuple[str, float],
                  params: dict[str, Any]) -> str:
    """A long list parameter in one line: its span, and for a scale profile the largest
    change and where it is."""
    lo, hi = min(vals), max(vals)
    text = f"{len(vals)} values, {U.fmt_range(lo, hi, unit)}"
    pos = params.get("positions")
    if name == "scale" and isinstance(pos, (list, tuple)) and len(pos) == len(vals):
        k = max(range(len(vals)), key=lambda j: abs(vals[j] - 1.0))
        text += (f"; largest change ×{U.num(vals[k])} at "
                 f"{U.fmt(pos[k], U.position_unit())}")
    return text


def _param_rows(effect: str, params: dict[str, Any], unc: dict[str, Any]) -> list[list[str]]:
    rows = []
    for name, val in params.items():
        unit = U.unit_of(effect, name)
        iv = unc.get(name) if isinstance(unc, dict) else None
        if isinstance(iv, (list, tuple)) and len(iv) == 2 and not isinstance(iv[0], (list, dict)):
            lo, hi = iv
            if lo is None or hi is None or not all(math.isfinite(float(v)) for v in (lo, hi)):
                interval = ("not determined by this record: determine it with "
                            + _experiment(effect, "a longer record"))
            else:
                interval = U.fmt_range(lo, hi, unit)
        elif iv is None:
            interval = "–"
        else:
            interval = escape(U.fmt(iv, unit) if isinstance(iv, (int, float, list)) else str(iv))
        if isinstance(val, (list, tuple)) and len(val) > 4 and all(
                isinstance(v, (int, float)) for v in val):
            value = _list_summary(name, list(val), unit, params)
        else:
            value = U.fmt(val, unit) if isinstance(val, (int, float, list, tuple)) else str(val)
        label = _TIMING_LABELS.get((effect, name), name.replace("_", " "))
        rows.append([escape(label), escape(value), escape(interval)])
    return rows


# a timing finding carries both of its readings (lugre.diagnosis.timing.timing_parameters)
_TIMING_LABELS = {(DELAY, "seconds"): "effective delay",
                  (DELAY, "bandwidth"): "or, as a current lag, its bandwidth",
                  (CURRENT_LAG, "seconds"): "effective delay"}


def _is_num(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _ranges_text(r: Any, unit: tuple[str, float]) -> str | None:
    """A ``[lo, hi]`` range, or a list of them (several stretches), in words."""
    if isinstance(r, (list, tuple)) and len(r) == 2 and all(
            x is None or _is_num(x) for x in r):
        return U.fmt_range(r[0], r[1], unit)
    if isinstance(r, (list, tuple)) and r and all(
            isinstance(x, (list, tuple)) and len(x) == 2 and all(_is_num(y) for y in x)
            for x in r):
        parts = [U.fmt_range(a, b, unit) for a, b in r]
        if len(parts) > 4:
            return (f"{len(parts)} stretches between "
                    f"{U.fmt_range(r[0][0], r[-1][1], unit)}")
        return ", ".join(parts)
    return None


def _direction_text(d: dict[str, Any]) -> str | None:
    """Where the rest is largest among moving forward, back and at rest (force rms)."""
    words = {"positive": "moving forward", "negative": "moving back", "rest": "at rest"}
    vals = [(words[k], float(v)) for k, v in d.items() if k in words and _is_num(v)]
    if not vals:
        return None
    return ", ".join(f"{w} {v:.3g} {U.si('N')} rms" for w, v in vals)


def _where_text(where: dict[str, Any] | None) -> str:
    if not isinstance(where, dict) or not where:
        return "everywhere in the record (not confined)"
    parts = []
    for key in ("position", "time", "velocity"):
        txt = _ranges_text(where.get(key), U.where_unit(key))
        if txt:
            parts.append(f"{key} {txt}")
    d = where.get("direction")
    if isinstance(d, dict):
        txt = _direction_text(d)
        if txt:
            parts.append(f"residual {txt}")
    return "; ".join(parts) if parts else "everywhere in the record (not confined)"


def _shares(report: dict[str, Any]) -> list[tuple[str, float]]:
    """Shares of the residual variance of the model as given: each finding, the base
    re-estimation and interplay, and what is left; they add up to one."""
    fit = report.get("fit") or {}
    findings = report.get("findings") or []
    try:
        left = (float(fit["after"]["rms_force"]) / float(fit["before"]["rms_force"])) ** 2
    except (KeyError, TypeError, ZeroDivisionError, ValueError):
        left = max(0.0, 1.0 - sum(float(f.get("explained") or 0.0) for f in findings))
    left = min(max(left, 0.0), 1.0)
    found = [(f"{k}. {_effect_title(str(f.get('effect')))}", max(0.0, float(f.get("explained") or 0.0)))
             for k, f in enumerate(findings, 1)]
    total = sum(s for _, s in found)
    room = 1.0 - left
    if total > room > 0 and total > 0:
        found = [(n, s * room / total) for n, s in found]
        total = room
    out = list(found)
    rest = room - total
    if rest > 0.005:
        out.append(("base parameters re-estimated, and interplay", rest))
    out.append(("left unexplained (noise and the rest)", left))
    return out


def _share_block(report: dict[str, Any]) -> str:
    shares = _shares(report)
    pct = U.shares_that_add_up([s for _, s in shares])
    bar = "".join(
        f"<span style=\"width:{p}%;background:{_COLOURS[j % len(_COLOURS)] if j < len(shares) - 1 else '#ccd1d6'}\" "
        f"title=\"{escape(n)}: {p} %\"></span>"
        for j, ((n, _), p) in enumerate(zip(shares, pct)) if p > 0
    )
    rows = [[f"<span class=\"sw\" style=\"background:{_COLOURS[j % len(_COLOURS)] if j < len(shares) - 1 else '#ccd1d6'}\"></span>"
             + escape(n), f"{p} %"] for j, ((n, _), p) in enumerate(zip(shares, pct))]
    return (f"<div class=\"bar\">{bar}</div><div class=\"legend\">"
            + _table([U.words("share of the force residual's variance (model as given)"), ""],
                     rows, {1})
            + "</div>")


def _gain(before: dict[str, Any] | None, after: dict[str, Any] | None) -> str | None:
    if not before or not after:
        return None
    try:
        b, a = float(before["rms_force"]), float(after["rms_force"])
    except (KeyError, TypeError, ValueError):
        return None
    change = (a - b) / b if b else 0.0
    return (f"{U.fmt(b, 'N')} → {U.fmt(a, 'N')} rms ({100 * change:+.0f} %), "
            f"normalised {100 * float(before.get('nrmse_force', math.nan)):.2f} % → "
            f"{100 * float(after.get('nrmse_force', math.nan)):.2f} % of the motor "
            f"{U.force_words()}")


def _verdict(report: dict[str, Any]) -> tuple[str, bool]:
    """The verdict paragraph (the report's own when it has one) and whether all is well."""
    findings = report.get("findings") or []
    fit = report.get("fit") or {}
    ok = (not findings and not report.get("unexplained") and not report.get("removed")
          and not report.get("rebased"))
    if report.get("verdict"):
        return str(report["verdict"]), ok
    text, fine = _own_verdict(report, findings, fit, ok)
    return U.words(text), fine


def _own_verdict(report: dict[str, Any], findings: list[Any], fit: dict[str, Any],
                 ok: bool) -> tuple[str, bool]:
    """The verdict of a report that has none (in a linear axis's words)."""
    hold = fit.get("holdout_before") and fit.get("holdout_after")
    if not findings:
        if report.get("unexplained"):
            u = report["unexplained"]
            msg = ("The model misses something the effects vocabulary does not name: "
                   f"{u.get('message', '')} Look at where it lives (below) and record "
                   "that range again with a slower, longer move.")
            return msg, False
        msg = ("No missing physics: beyond the noise floor, no effect of the vocabulary "
               "explains the residual. ")
        g = _gain(fit.get("before"), fit.get("after"))
        try:
            moved = float(fit["after"]["rms_force"]) < 0.8 * float(fit["before"]["rms_force"])
        except (KeyError, TypeError, ValueError):
            moved = False
        if moved and g:
            msg += (f"Re-estimating the base parameters on this record alone takes the "
                    f"residual {g}: use the re-estimated model (--out-model), and check "
                    "the parameters flagged below as poorly determined before trusting them.")
        else:
            msg += ("Keep the model; check again with a record that moves over the whole "
                    "stroke at several speeds.")
        return msg, True
    names = ", ".join(_effect_title(str(f.get("effect"))) for f in findings)
    first = findings[0]
    g = _gain(fit.get("before"), fit.get("after"))
    text = (f"The model leaves out {names}. The largest, {_effect_title(str(first.get('effect')))}, "
            f"accounts for {U.percent(float(first.get('explained') or 0.0))} of the force "
            f"residual; with the findings added the residual goes {g}. ")
    if hold:
        hg = _gain(fit["holdout_before"], fit["holdout_after"])
        text += f"How sure: confirmed on the second run, where the residual goes {hg}. "
    else:
        text += ("How sure: checked on held-out stretches of this record only; give a "
                 "second run with --holdout to confirm. ")
    alts = [a for f in findings for a in (f.get("alternatives") or [])]
    if alts:
        text += (f"{len(alts)} other explanation(s) fit as well (see the findings). ")
    text += ("Next: use the augmented model (--out-model) in the controller's feed-forward "
             "and re-run the diagnosis on a new record.")
    return text, ok


def _finding_section(k: int, f: dict[str, Any], data: dict[str, Any] | None,
                     floor: float | None) -> str:
    effect = str(f.get("effect"))
    share = float(f.get("explained") or 0.0)
    out = [(f"<section class=\"finding\"><h3>{k}. {escape(_effect_title(effect))}: "
           f"{U.percent(share)} of the residual</h3>")]
    if f.get("evidence"):
        out.append(_p(plain_text(str(f["evidence"]))))
    unc = f.get("uncertainty") or {}
    out.append(_table(["parameter", "estimate", "95 % interval"],
                      _param_rows(effect, f.get("parameters") or {}, unc), {1}))
    out.append(f"<p><b>Where it lives:</b> {escape(_where_text(f.get('where')))}</p>")
    uri = None
    effects = (data or {}).get("effects")
    fig = None
    if isinstance(effects, (list, tuple)) and k - 1 < len(effects):
        fig = effects[k - 1]
    elif isinstance(effects, dict):
        fig = effects.get(k - 1, effects.get(str(k - 1), effects.get(effect)))
    if isinstance(fig, dict) and all(key in fig for key in ("x", "residual", "effect")):
        from ..figures import effect_figure

        uri = _safe_figure(effect_figure, fig["x"], fig["residual"], fig["effect"],
                           str(fig.get("xlabel", "")), _effect_title(effect))
        caption = f"The fitted {_effect_title(effect)} over the residual it explains."
    elif data and all(key in data for key in ("before", "after")):
        from ..figures import residual_figure

        key = _NATURAL_ABSCISSA.get(effect, "t")
        if key in data:
            uri = _safe_figure(residual_figure, data[key], data["before"], data["after"], key,
                               floor, data.get("mask"))
        caption = (f"{U.force_words().capitalize()} residual before and after, against "
                   f"{ {'t': 'time', 'x': 'position', 'v': 'velocity'}[key] }.")
    if uri:
        out.append(_figure(uri, caption))
    for alt in f.get("alternatives") or []:
        ps = ", ".join(f"{n.replace('_', ' ')} {U.fmt(v, U.unit_of(str(alt.get('effect')), n))}"
                       for n, v in (alt.get("parameters") or {}).items()
                       if isinstance(v, (int, float)))
        out.append(f"<p><b>Fits as well:</b> {escape(_effect_title(str(alt.get('effect'))))}"
                   f"{' (' + escape(ps) + ')' if ps else ''}. <b>To tell them apart:</b> "
                   f"{escape(_alt_experiment(alt))}</p>")
    out.append("</section>")
    return "\n".join(out)


def _alt_experiment(alt: dict[str, Any]) -> str:
    """The experiment that tells a look-alike from the finding, in the axis's words."""
    exp = alt.get("experiment") or _experiment(str(alt.get("effect")), "a second record")
    return U.words(str(exp))


_PARAM_WORD = re.compile(r"\b(sigma0|sigma1|sigma2|mass|force_constant|fc|fs|vs)\b")


def _with_experiment(note: str) -> str:
    """A note that says a parameter is not (or poorly) determined, with the experiment that
    would determine it."""
    if "determined" not in note.lower() and "tolerance" not in note.lower():
        return note
    names = list(dict.fromkeys(_PARAM_WORD.findall(note)))
    if not names:
        return note
    exps = list(dict.fromkeys(_experiment(n, "") for n in names))
    return (note.rstrip() + (" " if note.rstrip().endswith(".") else ". ")
            + f"To determine {', '.join(names)}: " + "; ".join(exps) + ".")


def _base_moves(report: dict[str, Any]) -> list[list[str]]:
    rows = []
    moves = report.get("base_moves")
    if moves:
        for m in moves:
            unit = U.display(m.get("unit")) if m.get("unit") else U.unit_of(None, str(m.get("parameter")))
            rows.append([escape(U.words(str(m.get("parameter")))),
                         escape(U.fmt(m.get("before"), unit)),
                         escape(U.fmt(m.get("after"), unit)), escape(str(m.get("text") or ""))])
        return rows
    for name, b in (report.get("base") or {}).items():
        try:
            change = float(b.get("change") or 0.0)
        except (TypeError, ValueError):
            continue
        if abs(change) <= 0.005:
            continue
        unit = U.unit_of(None, name)
        tol = b.get("tolerance")
        text = f"{100 * change:+.1f} %"
        if isinstance(tol, (int, float)) and tol:
            if abs(change) <= tol:
                text += " (within what the record determines)"
            else:
                base = name.rsplit(".", 1)[-1]
                text += (f" (beyond the ±{100 * float(tol):.1f} % the record determines: "
                         f"poorly determined here; to pin it down, "
                         f"{_experiment(base, 'a longer record')})")
        rows.append([escape(U.words(name.replace("_", " "))), escape(U.fmt(b.get("before"), unit)),
                     escape(U.fmt(b.get("after"), unit)), escape(text)])
    return rows


def _could_not_reveal(report: dict[str, Any]) -> str:
    items = report.get("could_not_reveal")
    if not items:
        return _p("This diagnosis does not list which effects the record was too short or "
                  "too narrow to reveal. A record that covers the whole stroke at several "
                  "speeds in both directions reveals the most.")
    rows = []
    for c in items:
        unit = U.display(c.get("unit")) if c.get("unit") else ("", 1.0)
        smallest = U.fmt(c.get("smallest"), unit) if c.get("smallest") is not None else "–"
        rng = c.get("range")
        rng_s = (U.fmt_range(rng[0], rng[1], unit) if isinstance(rng, (list, tuple))
                 and len(rng) == 2 else escape(str(rng or "–")))
        exp = c.get("experiment") or _experiment(str(c.get("effect")), "a longer record")
        rows.append([escape(_effect_title(str(c.get("effect")))), escape(smallest),
                     escape(rng_s), escape(str(c.get("text") or "")), escape(str(exp))])
    return _table(["effect", "smallest it would have seen", "range", "why", ("experiment "
                   "that would reveal it")], rows, {1})


def diagnosis_page(report: dict[str, Any], data: dict[str, Any] | None = None, *,
                   source: str | None = None, model: str | None = None,
                   holdout: str | None = None, resampled: str | None = None,
                   title: str | None = None) -> str:
    """The diagnosis as one self-contained HTML page.

    Parameters
    ----------
    report : dict
        :meth:`Diagnosis.to_dict` (REPORT.json), with the optional keys when present.
    data : dict, optional
        :attr:`Diagnosis.data`: arrays for the figures (``t``, ``x``, ``v``, ``before``,
        ``after``, ``mask``, and ``effects``: per finding ``x``, ``residual``, ``effect``,
        ``xlabel``). Without it the page has no figures.
    source, model, holdout : str, optional
        The files, named on the page.
    resampled : str, optional
        How the recording was resampled, said on the page.
    """
    kind = (report.get("axis") or {}).get("kind", "linear")
    with U.axis(kind if isinstance(kind, str) else "linear"):
        return _diagnosis_page(report, data, source=source, model=model, holdout=holdout,
                               resampled=resampled, title=title)


def _diagnosis_page(report: dict[str, Any], data: dict[str, Any] | None, *,
                    source: str | None, model: str | None, holdout: str | None,
                    resampled: str | None, title: str | None) -> str:
    findings = report.get("findings") or []
    fit = report.get("fit") or {}
    noise = report.get("noise") or {}
    floor = noise.get("rms") if isinstance(noise.get("rms"), (int, float)) else None
    verdict, ok = _verdict(report)
    body = [f"<div class=\"verdict{' ok' if ok else ''}\"><b>Verdict.</b> {escape(verdict)}</div>"]
    if resampled:
        body.append(_p(f"The recording was resampled: {resampled}."))

    body.append("<h2>How much the model misses</h2>")
    rows = []
    for key, label in (("before", "this record, model as given"),
                       ("after", "this record, after the refit"),
                       ("holdout_before", "second run, model as given"),
                       ("holdout_after", "second run, after the refit")):
        m = fit.get(key)
        if m:
            rows.append([escape(label), escape(U.fmt(m.get("rms_force"), "N")),
                         f"{100 * float(m.get('nrmse_force') or 0.0):.2f} %"])
    if floor is not None:
        rows.append(["noise floor", escape(U.fmt(floor, "N")), "–"])
    body.append(_table(["", U.words("force residual (rms)"),
                        U.words("of the motor force (rms)")], rows, {1, 2}))
    if findings or fit.get("after"):
        body.append(_share_block(report))

    body.append("<h2>Findings</h2>")
    if not findings:
        body.append(_p("No effect beyond noise was found."))
    for k, f in enumerate(findings, 1):
        body.append(_finding_section(k, f, data, floor))

    rebased = report.get("rebased")
    if isinstance(rebased, dict) and rebased.get("moves"):
        body.append("<h2>Base refitted first</h2>")
        body.append(_p("The base of the model as given is far from what this record "
                       "supports; the search ran from the refitted base, so that no finding "
                       "stands in for a base parameter."))
        rows = [[escape(U.words(str(m.get("name")))), escape(f"{float(m.get('given', 0)):.4g}"),
                 escape(f"{float(m.get('refit', 0)):.4g}"),
                 escape(f"{100 * float(m.get('change', 0)):+.0f} %")]
                for m in rebased["moves"] if isinstance(m, dict)]
        body.append(_table(["parameter", "as given", "refitted", "change"], rows, {1, 2, 3}))

    removed = [r for r in (report.get("removed") or []) if isinstance(r, dict)]
    if removed:
        body.append("<h2>Removed from the model</h2>")
        body.append(_p("Effects of the model as given that this record contradicts: the "
                       "augmented model leaves them out."))
        rows = [[escape(_effect_title(str(r.get("effect")))),
                 escape(", ".join(f"{k} {v:.4g}" if isinstance(v, (int, float)) else f"{k} {v}"
                                  for k, v in (r.get("parameters") or {}).items()
                                  if not isinstance(v, list))),
                 escape(str(r.get("evidence", "")))]
                for r in removed]
        body.append(_table(["effect", "parameters as given", "why"], rows))

    body.append("<h2>Held-out gain</h2>")
    hg = _gain(fit.get("holdout_before"), fit.get("holdout_after"))
    if hg:
        body.append(_p(f"On the second run ({holdout or 'hold-out record'}), which the fit "
                       f"never saw, the {U.force_words()} residual goes {hg}."))
    else:
        body.append(_p("No second run was given: the findings were checked on held-out "
                       "stretches of this record only. Record the same motion again and "
                       "pass it with --holdout to confirm them on data the fit never saw."))
    ho = fit.get("held_out")
    if isinstance(ho, dict) and ho.get("before") and ho.get("after"):
        g = _gain(ho["before"], ho["after"])
        if g:
            body.append(_p(f"On held-out stretches of this record: {g}."))

    body.append("<h2>Base parameters that moved</h2>")
    moves = _base_moves(report)
    if moves:
        body.append(_table(["parameter", "before", "after", "change"], moves, {1, 2}))
    else:
        body.append(_p("None moved by more than 0.5 %."))

    minor = report.get("minor")
    if isinstance(minor, list) and minor:
        body.append("<h2>Minor corrections</h2>")
        body.append(_p(f"Consistent on the held-out stretches, but each under 0.3 % of the "
                       f"motor {U.force_words()}: kept in the augmented model so that they do "
                       "not bend "
                       "the findings, too small to name as missing physics."))
        rows = [[escape(_effect_title(str(m.get("effect")))),
                 escape(", ".join(f"{k} {v:.4g}" if isinstance(v, (int, float)) else f"{k} {v}"
                                  for k, v in (m.get("parameters") or {}).items()
                                  if not isinstance(v, list))),
                 escape(U.fmt(m.get("rms_force"), "N"))]
                for m in minor if isinstance(m, dict)]
        body.append(_table(["effect", "parameters", f"rms {U.force_words()}"], rows, {2}))

    body.append("<h2>What this record could not have revealed</h2>")
    body.append(_could_not_reveal(report))

    body.append("<h2>Unexplained rest</h2>")
    u = report.get("unexplained")
    if u:
        msg = u.get("message") if isinstance(u, dict) else str(u)
        body.append(_p(str(msg)))
        if isinstance(u, dict) and u.get("where"):
            body.append(f"<p><b>Where:</b> {escape(_where_text(u['where']))}</p>")
    else:
        body.append(_p("What is left after the findings is at the level of the noise floor"
                       + (f" ({U.fmt(floor, 'N')} rms)." if floor is not None else ".")))

    if data and all(k in data for k in ("t", "before", "after")):
        from ..figures import residual_figure

        body.append("<h2>Residual before and after</h2>")
        for key, name in (("t", "time"), ("x", "position"), ("v", "velocity")):
            if key in data:
                uri = _safe_figure(residual_figure, data[key], data["before"], data["after"],
                                   key, floor, data.get("mask"))
                body.append(_figure(uri, f"{U.force_words().capitalize()} residual against "
                                         f"{name}; dashed: twice the noise floor."))

    notes = [U.words(_with_experiment(str(n))) for n in report.get("notes") or []]
    if notes:
        body.append("<h2>Notes</h2><ul>" + "".join(f"<li>{escape(n)}</li>" for n in notes)
                    + "</ul>")
    files = [f"recording {source}" if source else None, f"model {model}" if model else None,
             f"second run {holdout}" if holdout else None]
    subtitle = escape(", ".join(x for x in files if x))
    return _page(title or "Model mismatch diagnosis", "\n".join(body), subtitle)
