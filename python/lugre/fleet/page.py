"""The fleet page: one self-contained HTML file, the axes ranked by change, each with its
alarms and trend figures (friction levels per direction, each effect's size over time
with its intervals), and the recordings that could not be read or diagnosed."""

from __future__ import annotations

from html import escape
from typing import Any

from .. import units as U
from ..pages.frame import _COLOURS, _figure, _p, _page, _safe_figure, _table
from .alarms import BASELINE, LEVEL_SHARE
from .trends import SIZE, AxisHistory, size_of

__all__ = ["FIGURES_FOR", "fleet_page"]

#: Axes (the first in rank) drawn with their figures; the rest are in the table only.
FIGURES_FOR = 60

_WAY = {"positive": "moving forward", "negative": "moving back"}


def _levels_panel(ax: Any, h: AxisHistory) -> None:
    import statistics

    unit = U.base_unit("fc")[0]
    for j, d in enumerate(("positive", "negative")):
        pts = [(t, v) for t, v in zip(h.times, h.levels.get(d, [])) if v is not None]
        if not pts:
            continue
        ts, vs = zip(*pts)
        ax.plot(ts, vs, "o-", ms=3, lw=1.0, color=_COLOURS[j], label=_WAY[d])
        base = [v for v in h.levels[d][:BASELINE] if v is not None]
        if len(base) >= 3:
            med = statistics.median(base)
            ax.axhspan(med * (1 - LEVEL_SHARE), med * (1 + LEVEL_SHARE), color=_COLOURS[j],
                       alpha=0.08, lw=0)
    ax.set_ylabel(f"Coulomb level [{unit}]")
    ax.grid(alpha=0.3)
    ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.01), ncol=2, frameon=False,
              fontsize=8, borderaxespad=0.0)


def _effects_panel(ax: Any, h: AxisHistory) -> None:
    for j, (effect, series) in enumerate(sorted(h.effects.items())):
        ts, vs, err_lo, err_hi = [], [], [], []
        for t, s in zip(h.times, series):
            if s is None:
                continue
            z, lo, hi = size_of(effect, s.parameters, s.intervals)
            if z is None or z == 0:
                continue
            ts.append(t)
            vs.append(1.0)
            err_lo.append(0.0 if lo is None else max(0.0, 1 - lo / z))
            err_hi.append(0.0 if hi is None else max(0.0, hi / z - 1))
            vs[-1] = z
            err_lo[-1] *= z
            err_hi[-1] *= z
        if not ts:
            continue
        name = SIZE[effect]
        unit, k = U.unit_of(effect, name)
        ax.errorbar(ts, [k * v for v in vs], yerr=[[k * e for e in err_lo],
                    [k * e for e in err_hi]], fmt="s-", ms=3, lw=1.0, capsize=2,
                    color=_COLOURS[(j + 2) % len(_COLOURS)],
                    label=f"{effect} {name} [{unit}]" if unit else f"{effect} {name}")
    ax.set_ylabel("effect size")
    ax.grid(alpha=0.3)
    ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.01), ncol=2, frameon=False,
              fontsize=8, borderaxespad=0.0)


def trend_figure(h: AxisHistory) -> str:
    """The axis's levels (and its effects' sizes, when any were found) over time."""
    from ..figures import data_uri
    from ..plots import figure

    rows = 2 if h.effects else 1
    fig, axes = figure(rows, 1, figsize=(7.5, 2.4 * rows))
    _levels_panel(axes[0, 0], h)
    if rows == 2:
        axes[1, 0].sharex(axes[0, 0])
        _effects_panel(axes[1, 0], h)
    axes[-1, 0].tick_params(axis="x", labelrotation=30, labelsize=8)
    return data_uri(fig, dpi=100)


def _section(r: Any, k: int) -> str:
    h = r.history
    with U.axis(h.kind):
        parts = [f"<h2 id=\"axis-{escape(h.axis)}\">{k}. {escape(h.axis)}</h2>"]
        if r.alarms:
            items = "".join(f"<li><b>{escape(a.kind)}</b>"
                            f"{' (' + escape(a.effect) + ')' if a.effect else ''} since "
                            f"{a.since:%Y-%m-%d %H:%M}: {escape(a.evidence)}</li>"
                            for a in r.alarms)
            parts.append(f"<div class=\"verdict\"><ul>{items}</ul></div>")
        else:
            parts.append("<div class=\"verdict ok\">No change beyond the night-to-night "
                         "scatter.</div>")
        if len(h) == 0:
            parts.append(_p("No recording of this axis could be diagnosed."))
        elif k <= FIGURES_FOR:
            uri = _safe_figure(trend_figure, h)
            parts.append(_figure(uri, f"{h.axis}: Coulomb level per direction (band: the "
                                 f"baseline's median ±{100 * LEVEL_SHARE:.0f} %)"
                                 + (" and each effect's size with its 95 % interval"
                                    if h.effects else "") + " over time"))
    return "\n".join(parts)


def fleet_page(ranked: list[Any], errors: list[dict[str, Any]], *, source: str = "") -> str:
    """The page (HTML text) from :func:`lugre.fleet.report.assess_fleet`'s results."""
    n_alarm = sum(1 for r in ranked if r.alarms)
    n_rec = sum(len(r.history) for r in ranked)
    head = ["rank", "axis", "alarms", "change", "recordings", "errors", "latest"]
    rows = [[str(k), f"<a href=\"#axis-{escape(r.history.axis)}\">{escape(r.history.axis)}</a>",
             escape(", ".join(a.kind + (f" ({a.effect})" if a.effect else "")
                              for a in r.alarms) or "none"),
             f"{r.score:.2f}", str(len(r.history)), str(r.history.errors),
             f"{r.history.times[-1]:%Y-%m-%d %H:%M}" if len(r.history) else "–"]
            for k, r in enumerate(ranked, 1)]
    body = [_p(f"{len(ranked)} axes, {n_rec} recordings diagnosed, {len(errors)} that could "
               f"not be; {n_alarm} axes with an alarm. Axes with an alarm come first, then "
               "by their change (1 is an alarm's threshold)."),
            _table(head, rows, numeric={0, 3, 4, 5})]
    if len(ranked) > FIGURES_FOR:
        body.append(_p(f"Figures for the first {FIGURES_FOR} axes; the others are in the "
                       "table and in the history."))
    body += [_section(r, k) for k, r in enumerate(ranked, 1)]
    if errors:
        body.append("<h2 id=\"errors\">Recordings not diagnosed</h2>")
        body.append(_table(["axis", "recording", "error"],
                           [[escape(e["axis"]), escape(e["recording"]),
                             escape(e["error"] or "")] for e in errors]))
    subtitle = escape(f"from {source}") if source else ""
    return _page("Fleet: which axes changed, how and since when", "\n".join(body), subtitle)
