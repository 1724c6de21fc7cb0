"""Self-contained HTML pages: the diagnosis report, the fits and the paper's tables.

Each page is one file: styles inline, figures embedded as SVG data URIs, nothing fetched
from elsewhere; it reads on a laptop and on a phone. The diagnosis page renders from
:meth:`lugre.diagnosis.Diagnosis.to_dict` and the diagnosis's ``data`` arrays, and uses
the optional keys when present (``verdict``, per finding ``uncertainty``,
``could_not_reveal``, ``base_moves``, ``unexplained``, ``notes``, ``data["effects"]``).
"""

from __future__ import annotations

import datetime as _dt
import math
import re
from html import escape
from typing import Any

from . import units as U

__all__ = ["EXPERIMENTS", "diagnosis_page", "fit_page", "paper_page", "static_fit_page"]

#: The experiment that determines each effect (or base parameter) a record left open.
EXPERIMENTS: dict[str, str] = {
    "cogging": "a slow constant-speed move over at least three pitches in each direction",
    "spring": "slow moves across the whole stroke in both directions",
    "offset": "constant-speed moves in both directions at the same speed",
    "position_friction": "slow constant-speed moves over the whole stroke in both "
                         "directions",
    "drift": "a recording from a cold start lasting several time constants",
    "mass": "fast back-and-forth moves (large accelerations)",
    "delay": "fast reversals or a current chirp up to a few hundred Hz",
    "current_lag": "fast reversals or a current chirp up to a few hundred Hz",
    "resonance": "a chirp of the position reference through the suspected frequency band",
    "deadband": "very slow moves that cross zero current",
    "drag": "constant-speed moves at several high speeds",
    "stribeck_shape": "slow feeds at speeds from a tenth to ten times the Stribeck velocity",
    "sigma0": "short reversals with a stroke below a millimetre (presliding)",
    "sigma1": "short reversals with a stroke below a millimetre (presliding)",
    "fc": "constant-speed moves at several speeds in both directions",
    "fs": "slow feeds starting from standstill in both directions",
    "sigma2": "constant-speed moves at several speeds in both directions",
    "vs": "slow feeds at speeds around the Stribeck velocity",
    "force_constant": "a move with a known payload or a force sensor",
}

_NATURAL_ABSCISSA = {
    "cogging": "x", "spring": "x", "position_friction": "x", "drift": "t", "offset": "v",
    "drag": "v", "stribeck_shape": "v", "deadband": "v", "mass": "t", "delay": "t",
    "current_lag": "t", "resonance": "t",
}

_CSS = """
:root{--fg:#1d2329;--muted:#5b6670;--line:#d5dbe0;--ok:#1f7a3d;--warn:#9a5b00;--bad:#a3222b;
--bg:#fff;--card:#f6f8fa}
*{box-sizing:border-box}
body{font:16px/1.5 system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;color:var(--fg);
background:var(--bg);margin:0;padding:1rem}
main{max-width:56rem;margin:0 auto}
h1{font-size:1.5rem;margin:.2rem 0 .6rem}
h2{font-size:1.2rem;margin:2rem 0 .5rem;border-bottom:1px solid var(--line);padding-bottom:.2rem}
h3{font-size:1.05rem;margin:1.4rem 0 .4rem}
.verdict{background:var(--card);border-left:.35rem solid var(--warn);padding:.8rem 1rem;
border-radius:.3rem;font-size:1.05rem}
.verdict.ok{border-left-color:var(--ok)}
.meta{color:var(--muted);font-size:.85rem}
.scroll{overflow-x:auto}
table{border-collapse:collapse;margin:.4rem 0;font-size:.95rem}
th,td{border-bottom:1px solid var(--line);padding:.3rem .6rem;text-align:left;vertical-align:top}
th{background:var(--card);font-weight:600}
td.n{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
figure{margin:.6rem 0}
figure img{width:100%;height:auto;border:1px solid var(--line);border-radius:.2rem}
figcaption{color:var(--muted);font-size:.85rem}
.bar{display:flex;height:1.4rem;border-radius:.2rem;overflow:hidden;margin:.4rem 0}
.bar span{display:block;height:100%}
.legend span.sw{display:inline-block;width:.8rem;height:.8rem;margin-right:.3rem;
vertical-align:middle;border-radius:.15rem}
.finding{border:1px solid var(--line);border-radius:.4rem;padding:.2rem 1rem .8rem;margin:1rem 0}
ul{padding-left:1.3rem}
@media (max-width:40rem){body{font-size:15px;padding:.6rem}th,td{padding:.25rem .35rem}}
"""

_COLOURS = ["#c0392b", "#2471a3", "#d68910", "#7d3c98", "#138d75", "#a04000", "#566573"]


# --------------------------------------------------------------------------------------
# Page frame
# --------------------------------------------------------------------------------------


def _page(title: str, body: str, subtitle: str = "") -> str:
    from ._version import __version__

    stamp = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return (
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
        "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
        f"<title>{escape(title)}</title>\n<style>{_CSS}</style>\n</head>\n<body>\n<main>\n"
        f"<h1>{escape(title)}</h1>\n"
        + (f"<p class=\"meta\">{subtitle}</p>\n" if subtitle else "")
        + body
        + f"\n<p class=\"meta\">Written by lugre {escape(__version__)} on {stamp}.</p>\n"
        "</main>\n</body>\n</html>\n"
    )


def _table(head: list[str], rows: list[list[str]], numeric: set[int] | None = None) -> str:
    """A table; cells are HTML already (escape text before)."""
    numeric = numeric or set()
    h = "".join(f"<th>{c}</th>" for c in head)
    body = "".join(
        "<tr>" + "".join(f"<td class=\"n\">{c}</td>" if j in numeric else f"<td>{c}</td>"
                         for j, c in enumerate(r)) + "</tr>"
        for r in rows
    )
    return f"<div class=\"scroll\"><table><thead><tr>{h}</tr></thead><tbody>{body}</tbody></table></div>"


def _figure(uri: str | None, caption: str) -> str:
    if not uri:
        return ""
    return (f"<figure><img src=\"{uri}\" alt=\"{escape(caption)}\">"
            f"<figcaption>{escape(caption)}</figcaption></figure>")


def _p(text: str) -> str:
    return f"<p>{escape(text)}</p>"


def _safe_figure(make: Any, *args: Any, **kw: Any) -> str | None:
    """A figure, or ``None`` when its data are unusable (the page is written anyway)."""
    try:
        return str(make(*args, **kw))
    except (ValueError, KeyError, TypeError, IndexError):
        return None


# --------------------------------------------------------------------------------------
# Diagnosis
# --------------------------------------------------------------------------------------


_SCORE = re.compile(
    r"(?:it )?lowers the held-out score by [-+0-9.e]+\s*(?:\([^)]*\))?,?\s*")
_BLOCKS = re.compile(r"gains in (\d+) of (\d+) held-out blocks \(p = ([^)]+)\)")
_JARGON = re.compile(r"\s*\([^)]*(?:chi-square|noise scale|score)[^)]*\)")


def plain_text(text: str) -> str:
    """Evidence in words a control engineer acts on: no statistics' internal scores.

    ``"... it lowers the held-out score by 73442 (chi-square on the coloured noise
    scale), gains in 10 of 10 held-out blocks (p = 1e-12)"`` becomes ``"... it improves
    the fit in 10 of 10 stretches of the record it was not fitted on (chance of that by
    luck: 1e-12)"``.
    """
    out = _SCORE.sub("it improves the fit: it ", text)
    out = _BLOCKS.sub(lambda m: f"gains in {m.group(1)} of {m.group(2)} stretches of the "
                      f"record it was not fitted on (chance of that by luck: {m.group(3)})",
                      out)
    out = _JARGON.sub("", out)
    return out.replace("it improves the fit: it gains", "it improves the fit in").replace(
        "improves the fit in in", "improves the fit in")


def _effect_title(effect: str) -> str:
    return effect.replace("_", " ")


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
                 f"{U.fmt(pos[k], U.EFFECT_UNITS['position_friction']['positions'])}")
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
                            + EXPERIMENTS.get(effect, "a longer record"))
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
_TIMING_LABELS = {("delay", "seconds"): "effective delay",
                  ("delay", "bandwidth"): "or, as a current lag, its bandwidth",
                  ("current_lag", "seconds"): "effective delay"}


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
    return ", ".join(f"{w} {v:.3g} N rms" for w, v in vals)


def _where_text(where: dict[str, Any] | None) -> str:
    if not isinstance(where, dict) or not where:
        return "everywhere in the record (not confined)"
    parts = []
    for key in ("position", "time", "velocity"):
        txt = _ranges_text(where.get(key), U.WHERE_UNITS[key])
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
            + _table(["share of the force residual's variance (model as given)", ""], rows, {1})
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
            f"{100 * float(after.get('nrmse_force', math.nan)):.2f} % of the motor force")


def _verdict(report: dict[str, Any]) -> tuple[str, bool]:
    """The verdict paragraph (the report's own when it has one) and whether all is well."""
    findings = report.get("findings") or []
    fit = report.get("fit") or {}
    ok = (not findings and not report.get("unexplained") and not report.get("removed")
          and not report.get("rebased"))
    if report.get("verdict"):
        return str(report["verdict"]), ok
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
        from .figures import effect_figure

        uri = _safe_figure(effect_figure, fig["x"], fig["residual"], fig["effect"],
                           str(fig.get("xlabel", "")), _effect_title(effect))
        caption = f"The fitted {_effect_title(effect)} over the residual it explains."
    elif data and all(key in data for key in ("before", "after")):
        from .figures import residual_figure

        key = _NATURAL_ABSCISSA.get(effect, "t")
        if key in data:
            uri = _safe_figure(residual_figure, data[key], data["before"], data["after"], key,
                               floor, data.get("mask"))
        caption = (f"Force residual before and after, against "
                   f"{ {'t': 'time', 'x': 'position', 'v': 'velocity'}[key] }.")
    if uri:
        out.append(_figure(uri, caption))
    for alt in f.get("alternatives") or []:
        ps = ", ".join(f"{n.replace('_', ' ')} {U.fmt(v, U.unit_of(str(alt.get('effect')), n))}"
                       for n, v in (alt.get("parameters") or {}).items()
                       if isinstance(v, (int, float)))
        out.append(f"<p><b>Fits as well:</b> {escape(_effect_title(str(alt.get('effect'))))}"
                   f"{' (' + escape(ps) + ')' if ps else ''}. <b>To tell them apart:</b> "
                   f"{escape(str(alt.get('experiment') or EXPERIMENTS.get(str(alt.get('effect')), 'a second record')))}</p>")
    out.append("</section>")
    return "\n".join(out)


_PARAM_WORD = re.compile(r"\b(sigma0|sigma1|sigma2|mass|force_constant|fc|fs|vs)\b")


def _with_experiment(note: str) -> str:
    """A note that says a parameter is not (or poorly) determined, with the experiment that
    would determine it."""
    if "determined" not in note.lower() and "tolerance" not in note.lower():
        return note
    names = list(dict.fromkeys(_PARAM_WORD.findall(note)))
    if not names:
        return note
    exps = list(dict.fromkeys(EXPERIMENTS[n] for n in names))
    return (note.rstrip() + (" " if note.rstrip().endswith(".") else ". ")
            + f"To determine {', '.join(names)}: " + "; ".join(exps) + ".")


def _base_moves(report: dict[str, Any]) -> list[list[str]]:
    rows = []
    moves = report.get("base_moves")
    if moves:
        for m in moves:
            unit = U.display(m.get("unit")) if m.get("unit") else U.unit_of(None, str(m.get("parameter")))
            rows.append([escape(str(m.get("parameter"))), escape(U.fmt(m.get("before"), unit)),
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
                         f"{EXPERIMENTS.get(base, 'a longer record')})")
        rows.append([escape(name.replace("_", " ")), escape(U.fmt(b.get("before"), unit)),
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
        exp = c.get("experiment") or EXPERIMENTS.get(str(c.get("effect")), "a longer record")
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
    body.append(_table(["", "force residual (rms)", "of the motor force (rms)"], rows, {1, 2}))
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
        rows = [[escape(str(m.get("name"))), escape(f"{float(m.get('given', 0)):.4g}"),
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
                       f"never saw, the force residual goes {hg}."))
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
        body.append(_p("Consistent on the held-out stretches, but each under 0.3 % of the "
                       "motor force: kept in the augmented model so that they do not bend "
                       "the findings, too small to name as missing physics."))
        rows = [[escape(_effect_title(str(m.get("effect")))),
                 escape(", ".join(f"{k} {v:.4g}" if isinstance(v, (int, float)) else f"{k} {v}"
                                  for k, v in (m.get("parameters") or {}).items()
                                  if not isinstance(v, list))),
                 escape(U.fmt(m.get("rms_force"), ("N", 1.0)))]
                for m in minor if isinstance(m, dict)]
        body.append(_table(["effect", "parameters", "rms force"], rows, {2}))

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
        from .figures import residual_figure

        body.append("<h2>Residual before and after</h2>")
        for key, name in (("t", "time"), ("x", "position"), ("v", "velocity")):
            if key in data:
                uri = _safe_figure(residual_figure, data[key], data["before"], data["after"],
                                   key, floor, data.get("mask"))
                body.append(_figure(uri, f"Force residual against {name}; dashed: twice the "
                                         "noise floor."))

    notes = [_with_experiment(str(n)) for n in report.get("notes") or []]
    if notes:
        body.append("<h2>Notes</h2><ul>" + "".join(f"<li>{escape(n)}</li>" for n in notes)
                    + "</ul>")
    files = [f"recording {source}" if source else None, f"model {model}" if model else None,
             f"second run {holdout}" if holdout else None]
    subtitle = escape(", ".join(x for x in files if x))
    return _page(title or "Model mismatch diagnosis", "\n".join(body), subtitle)


# --------------------------------------------------------------------------------------
# Fits
# --------------------------------------------------------------------------------------


def _model_rows(doc: dict[str, Any]) -> list[list[str]]:
    rows = []
    axis = doc.get("axis") or {}
    fr = doc.get("friction") or {}
    for name in ("mass", "force_constant"):
        if name in axis:
            rows.append([name.replace("_", " "), escape(U.fmt(axis[name], U.BASE_UNITS[name]))])
    for name in ("sigma0", "sigma1"):
        if name in fr:
            rows.append([name, escape(U.fmt(fr[name], U.BASE_UNITS[name]))])
    for d in ("positive", "negative"):
        for name, val in (fr.get(d) or {}).items():
            rows.append([f"{name} ({'v ≥ 0' if d == 'positive' else 'v < 0'})",
                         escape(U.fmt(val, U.BASE_UNITS.get(name, ('', 1.0))))])
    return rows


def _stribeck_uri(doc: dict[str, Any], v: Any = None, F: Any = None,
                  rejected: Any = None) -> str | None:
    import numpy as np

    from ._native import stribeck
    from .figures import curve_figure
    from .model import Model

    try:
        m = Model.from_dict(doc)
        vmax = float(np.max(np.abs(v))) if v is not None and len(v) else 20 * max(
            m.positive["vs"], m.negative["vs"])
        grid = np.linspace(-vmax, vmax, 801)
        series = [(1e3 * grid, stribeck(grid, m), "-", "fitted steady-state friction")]
        if v is not None and F is not None:
            va, Fa = np.asarray(v, float), np.asarray(F, float)
            bad = np.zeros(va.size, bool)
            if rejected is not None and len(rejected):
                bad[np.asarray(rejected, int)] = True
            series.insert(0, (1e3 * va[~bad], Fa[~bad], "o", "steady-state points"))
            if bad.any():
                series.insert(1, (1e3 * va[bad], Fa[bad], "x",
                                  "rejected as gross errors"))
        return curve_figure(series, "velocity [mm/s]", "friction force [N]")
    except (ValueError, KeyError, TypeError):
        return None


def static_fit_page(fit: Any, v: Any, F: Any, model: dict[str, Any], *,
                    source: str | None = None, assumed: list[str] | None = None) -> str:
    """``lugre fit-static``: the Stribeck parameters with their 95 % intervals, the
    rejected points and the curve over the points."""
    body = []
    rows = []
    for d, label in (("positive", "v ≥ 0"), ("negative", "v < 0")):
        df = getattr(fit, d)
        for name, val in df.params.items():
            unit = U.BASE_UNITS.get(name, ("", 1.0))
            lo, hi = df.ci95.get(name, (None, None))
            rows.append([escape(f"{name} ({label})"), escape(U.fmt(val, unit)),
                         escape(U.fmt_range(lo, hi, unit)) if lo is not None else "–"])
    n_rej = len(fit.rejected)
    body.append(f"<div class=\"verdict ok\"><b>Result.</b> {escape(str(len(v)))} steady-state "
                f"points, {n_rej} rejected as gross errors ({escape(fit.weighting)} weights).</div>")
    body.append("<h2>Stribeck parameters</h2>")
    body.append(_table(["parameter", "estimate", "95 % interval"], rows, {1}))
    body.append(_figure(_stribeck_uri(model, v, F, fit.rejected), "Steady-state points, "
                        "those rejected as gross errors, and the fitted friction curve."))
    if assumed:
        body.append("<h2>Placeholders in the model</h2>")
        body.append(_p("Steady-state points do not determine " + ", ".join(assumed) + "; the "
                       "model holds the seed paper's values for them. Give a base model "
                       "(--model), --mass and --force-constant, and run lugre fit-dynamic for "
                       "sigma0 and sigma1."))
    body.append("<h2>Model written</h2>")
    body.append(_table(["parameter", "value"], _model_rows(model), {1}))
    return _page("Static friction fit", "\n".join(body), escape(f"points {source}") if source else "")


def _ident_rows(params: dict[str, Any]) -> list[list[str]]:
    from .diagnosis.fitreport import label

    rows = []
    for name, p in params.items():
        unit = str(p.get("unit", ""))
        lo, hi = (p.get("ci95") or [None, None])
        ends = [("open" if x is None else f"{float(x):.4g}") for x in (lo, hi)]
        rows.append([escape(label(name)), escape(f"{float(p['value']):.4g} {unit}"),
                     escape(f"{ends[0]} to {ends[1]} {unit}"),
                     "yes" if p.get("determined") else "<b>no</b>"])
    return rows


def fit_page(model: dict[str, Any], rec: Any = None, *, source: str | None = None,
             nrmse: dict[str, float | None] | None = None,
             first: dict[str, Any] | None = None) -> str:
    """``lugre fit``: the identified model, how well it explains the record, its friction
    curve."""
    body = []
    ident = model.get("identification") or {}
    if ident.get("summary"):
        far = bool(ident.get("far_from_floor"))
        head = "Check first." if far else "Result."
        body.append(f"<div class=\"verdict{'' if far else ' ok'}\"><b>{head}</b> The identified "
                    f"model explains the motor force to {100 * float(ident['nrmse_force']):.2f} "
                    f"% rms; {escape(str(ident['summary']))}.</div>")
    elif nrmse:
        best = min(v for v in nrmse.values() if v is not None)
        body.append(f"<div class=\"verdict ok\"><b>Result.</b> The identified model explains the "
                    f"motor force to {100 * best:.2f} % rms (force residual over motor force). "
                    "Next: check it on a second run with lugre evaluate, or look for missing "
                    "physics with lugre diagnose.</div>")
    if nrmse:
        rows = [[escape(k), f"{100 * float(v):.2f} %"] for k, v in nrmse.items() if v is not None]
        body.append("<h2>Force residual</h2>")
        body.append(_table(["step", "of the motor force (rms)"], rows, {1}))
    if ident.get("parameters"):
        body.append("<h2>What the record determines</h2>")
        body.append(_table(["parameter", "value", "95 % interval", "determined"],
                           _ident_rows(ident["parameters"]), {1, 2}))
    body.append("<h2>Identified model</h2>")
    body.append(_table(["parameter", "value"], _model_rows(model), {1}))
    v = None
    if rec is not None:
        try:
            import numpy as np

            v = np.gradient(rec.x, rec.t)
        except (AttributeError, ValueError):
            v = None
    body.append(_figure(_stribeck_uri(model, v), "Steady-state friction of the identified "
                        "model over the recorded speed range."))
    return _page("Friction identification", "\n".join(body),
                 escape(f"recording {source}") if source else "")


# --------------------------------------------------------------------------------------
# Paper
# --------------------------------------------------------------------------------------


def paper_document(result: dict[str, Any]) -> dict[str, Any]:
    """The CONTRACT's ``paper.json`` structure from what :func:`lugre.paper.run_paper`
    returns (or the structure itself, unchanged)."""
    t1 = result.get("table1") or {}
    if "positive" in t1 or "negative" in t1:
        return result
    table1: dict[str, dict[str, Any]] = {"positive": {}, "negative": {}}
    for key, row in t1.items():
        name, _, d = str(key).rpartition("_")
        if d in table1 and isinstance(row, dict):
            table1[d][name] = {"truth": row.get("truth"), "paper": row.get("paper"),
                               "estimate": row.get("estimate", row.get("igg")),
                               "ci95": list(row.get("ci95") or [None, None])}
    table2 = {}
    for key, row in (result.get("table2") or {}).items():
        if isinstance(row, dict):
            table2[key] = {"truth": row.get("truth"), "paper": row.get("paper"),
                           "estimate": row.get("estimate", row.get("ours")),
                           "ci95": list(row.get("ci95") or [None, None])}
    return {**result, "table1": table1, "table2": table2}


def _paper_rows(rows: dict[str, Any], label: str = "") -> list[list[str]]:
    out = []
    for name, r in rows.items():
        if not isinstance(r, dict):
            continue
        unit = U.BASE_UNITS.get(name, ("", 1.0))
        ci = r.get("ci95") or [None, None]
        truth = r.get("truth")
        est = r.get("estimate")
        err = (f"{100 * (float(est) - float(truth)) / float(truth):+.2f} %"
               if isinstance(est, (int, float)) and isinstance(truth, (int, float)) and truth
               else "–")
        covered = ("yes" if None not in ci and isinstance(truth, (int, float))
                   and float(ci[0]) <= float(truth) <= float(ci[1]) else "no")
        out.append([escape(name + label), escape(U.fmt(truth, unit)),
                    escape(U.fmt(r.get("paper"), unit)), escape(U.fmt(est, unit)), err,
                    escape(U.fmt_range(ci[0], ci[1], unit)) if None not in ci else "–",
                    covered])
    return out


def paper_page(result: dict[str, Any]) -> str:
    """``lugre paper``: Tables 1 and 2 beside the paper's numbers (``paper.json``)."""
    doc = paper_document(result)
    head = ["parameter", "truth", "paper", "this rerun", "error", "95 % interval",
            "truth inside"]
    body = [_p("The seed paper's experiments rerun on synthetic data with known parameters: "
               "each estimate beside the truth and the paper's own estimate.")]
    body.append("<h2>Table 1: static friction parameters</h2>")
    rows = []
    for d, label in (("positive", " (v ≥ 0)"), ("negative", " (v < 0)")):
        rows += _paper_rows((doc.get("table1") or {}).get(d) or {}, label)
    body.append(_table(head, rows, {1, 2, 3, 4, 5}))
    body.append("<h2>Table 2: dynamic parameters</h2>")
    body.append(_table(head, _paper_rows(doc.get("table2") or {}), {1, 2, 3, 4, 5}))
    tr = doc.get("tracking")
    if isinstance(tr, dict) and "with" in tr and "without" in tr:
        body.append("<h2>Speed tracking</h2>")
        body.append(_table(["", "largest speed error"], [
            ["without friction compensation", escape(U.fmt(tr["without"], "m/s"))],
            ["with the identified LuGre feed-forward", escape(U.fmt(tr["with"], "m/s"))]],
            {1}))
    return _page("The seed paper's experiments, rerun", "\n".join(body))
