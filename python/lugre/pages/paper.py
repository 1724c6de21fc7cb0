"""The page of the paper's experiments: its tables beside ours."""

from __future__ import annotations

from html import escape
from typing import Any

from .. import units as U
from .frame import _p, _page, _table

__all__ = ["paper_document", "paper_page"]


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
        unit = U.base_unit(name)
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
