"""``lugre fleet report``: the alarms, the axes ranked by change, the fleet page and the
Parquet export, from the history."""

from __future__ import annotations

import json as _json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .alarms import Alarm, assess
from .store import open_store
from .trends import AxisHistory, histories

__all__ = ["Ranked", "assess_fleet", "report"]


@dataclass
class Ranked:
    """An axis with its alarms and change score, in the fleet's order."""

    history: AxisHistory
    alarms: list[Alarm] = field(default_factory=list)
    score: float = 0.0


def assess_fleet(store: Any) -> tuple[list[Ranked], list[dict[str, Any]]]:
    """The axes ranked by change (those with an alarm first, then by score) and the
    recordings that could not be read or diagnosed."""
    ranked = []
    for h in histories(store):
        alarms, score = assess(h)
        ranked.append(Ranked(h, alarms, score))
    ranked.sort(key=lambda r: (-int(bool(r.alarms)), -r.score, r.history.axis))
    errors = store.rows("SELECT axis, recording, error FROM recordings WHERE status <> 'ok' "
                        "ORDER BY axis, recording")
    return ranked, errors


def alarms_document(ranked: list[Ranked], errors: list[dict[str, Any]]) -> dict[str, Any]:
    """ALARMS.json (CONTRACT, "Fleet")."""
    return {"alarms": [a.to_dict() for r in ranked for a in r.alarms],
            "errors": [{"axis": e["axis"], "recording": e["recording"], "error": e["error"]}
                       for e in errors]}


def report(db: str | os.PathLike[str], *, html: str | os.PathLike[str] | None = None,
           json: str | os.PathLike[str] | None = None,
           parquet: str | os.PathLike[str] | None = None) -> dict[str, Any]:
    """Read the history ``db``; write the fleet page (``html``), ALARMS.json (``json``)
    and one Parquet file per table into the folder ``parquet`` (created when missing,
    its parent must exist). Each file is written whole or not at all.

    Returns
    -------
    dict
        The ALARMS.json document, plus ``"ranking"``: the axes in order with their
        score and alarm kinds (not written to ALARMS.json).
    """
    from .._atomic import atomic_write

    with open_store(db, read_only=True) as store:
        ranked, errors = assess_fleet(store)
        doc = alarms_document(ranked, errors)
        page = None
        if html is not None:
            from .page import fleet_page

            page = fleet_page(ranked, errors, source=os.fspath(db))
        if parquet is not None:
            out = Path(parquet)
            out.mkdir(exist_ok=True)
            store.export_parquet(out)
    if json is not None:
        atomic_write(json, (_json.dumps(doc, indent=2) + "\n").encode())
    if page is not None and html is not None:
        atomic_write(html, page.encode("utf-8"))
    return {**doc, "ranking": [{"axis": r.history.axis, "score": r.score,
                                "alarms": [a.kind for a in r.alarms],
                                "recordings": len(r.history), "errors": r.history.errors}
                               for r in ranked]}
