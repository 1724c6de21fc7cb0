"""One recording diagnosed against its axis's model: the task a Dask worker runs.

:func:`diagnose_file` never raises for a problem with the recording: it returns the
result as a plain dict (what the history store writes), with ``status`` ``"ok"`` or
``"error"`` and, for an error, the sentence that says what is wrong and the fix.
"""

from __future__ import annotations

import datetime as _dt
import math
import time
from pathlib import Path
from typing import Any

from .discover import parse_time, time_from_name

__all__ = ["diagnose_file", "failed"]


def failed(axis: str, path: str, stamp: str, error: str, when: _dt.datetime | None = None
           ) -> dict[str, Any]:
    """The result of a recording that could not be read or diagnosed."""
    name = Path(path).name
    if when is None:
        when = time_from_name(name)
    return {"axis": axis, "recording": name, "path": path, "stamp": stamp,
            "time": when.isoformat() if when else None, "status": "error", "error": error,
            "levels": [], "findings": [], "limits": []}


def _finite(x: Any) -> float | None:
    try:
        f = float(x)
    except (TypeError, ValueError):
        return None
    return f if math.isfinite(f) else None


def diagnose_file(axis: str, path: str, model: dict[str, Any], stamp: str = ""
                  ) -> dict[str, Any]:
    """Read ``path``, diagnose it against ``model`` (the axis's, as a dict) and evaluate
    the friction levels per direction; the result as a plain dict."""
    from ..exceptions import LugreError

    start = time.perf_counter()
    name = Path(path).name
    try:
        out = _diagnose(axis, path, model, stamp)
    except (LugreError, OSError, ValueError, ArithmeticError) as e:
        text = " ".join(str(e).split()) or type(e).__name__
        if name not in text:
            text = f"{path}: {text}"
        return failed(axis, path, stamp, text)
    out["seconds"] = time.perf_counter() - start
    return out


def _recording_time(rec: Any, path: str) -> _dt.datetime:
    from ..exceptions import FileFormatError

    text = rec.meta.get("time")
    if text:
        return parse_time(str(text), path)
    when = time_from_name(Path(path).name)
    if when is None:
        raise FileFormatError(f"{path}: no time: give the recording a '# time: ISO-8601' line "
                              "(or time metadata) or a date in its file name, e.g. "
                              "2024-03-01T0200.csv", path=path)
    return when


def _diagnose(axis: str, path: str, model_dict: dict[str, Any], stamp: str
              ) -> dict[str, Any]:
    from ..diagnosis import diagnose, evaluate
    from ..io import read_recording, require_plausible
    from ..model import Model

    model = Model(model_dict)
    rec = read_recording(path, x_unit="rad" if model.kind == "rotary" else "m")
    when = _recording_time(rec, path)
    rec = require_plausible(rec, model.kind)
    d = diagnose(rec, model)
    report = d.to_dict()
    ev = evaluate(rec, model)
    fit = report.get("fit", {})
    unexplained = report.get("unexplained")
    return {
        "axis": axis, "recording": Path(path).name, "path": path, "stamp": stamp,
        "time": when.isoformat(), "status": "ok", "error": None,
        "nrmse_force": _finite(fit.get("before", {}).get("nrmse_force")),
        "nrmse_after": _finite(fit.get("after", {}).get("nrmse_force")),
        "rms_force": _finite(fit.get("before", {}).get("rms_force")),
        "samples": len(rec), "duration": float(rec.t[-1] - rec.t[0]),
        "verdict": report.get("verdict"),
        "unexplained": _unexplained_text(unexplained),
        "levels": _levels(ev, model, report, float(rec.t[-1] - rec.t[0])),
        "findings": _findings(report),
        "limits": _limits(report),
    }


def _unexplained_text(u: Any) -> str | None:
    if not u:
        return None
    if isinstance(u, dict):
        for key in ("text", "evidence", "summary"):
            if isinstance(u.get(key), str):
                return str(u[key])
    return str(u)


def _drift_factor(report: dict[str, Any], duration: float) -> float:
    """How much a drift the diagnosis found scales the friction levels at the record's end
    (1 without one): a level change inside the record is part of the level it ends on."""
    from ..vocabulary import DRIFT

    for f in report.get("findings", []):
        if f.get("effect") == DRIFT:
            p = f.get("parameters", {})
            g, tau = _finite(p.get("gain")), _finite(p.get("time_constant"))
            if g is not None and tau and tau > 0:
                return 1.0 - g * (1.0 - math.exp(-duration / tau))
    return 1.0


def _levels(ev: dict[str, Any], model: Any, report: dict[str, Any], duration: float
            ) -> list[dict[str, Any]]:
    """Friction level per direction: the diagnosis's refitted Coulomb level (times the
    change of a drift it found, at the record's end), and beside it the friction the
    model misses on the record (the evaluation's mean residual while moving that way,
    with its standard error)."""
    ls = ev.get("level_shift") or {}
    base = report.get("base", {})
    factor = _drift_factor(report, duration)
    out = []
    for d in ("positive", "negative"):
        fc = float(model.friction[d]["fc"])
        refit = _finite(base.get(f"{d}.fc", {}).get("after"))
        shift = ls.get(d, {})
        out.append({"direction": d, "level": None if refit is None else refit * factor,
                    "refit_fc": refit, "model_fc": fc, "shift": _finite(shift.get("shift")),
                    "se": _finite(shift.get("se"))})
    return out


def _findings(report: dict[str, Any]) -> list[dict[str, Any]]:
    """Each finding with its parameters, intervals and held-out evidence (the accepted
    trial of its effect: gain, p, held-out blocks that improved)."""
    trials = {t.get("effect"): t for t in report.get("trials", []) if t.get("accepted")}
    out = []
    for k, f in enumerate(report.get("findings", [])):
        unc = f.get("uncertainty") or {}
        intervals = {p: v for p, v in unc.items()
                     if isinstance(v, (list, tuple)) and len(v) == 2}
        trial = trials.get(f["effect"], {})
        out.append({"rank": k, "effect": f["effect"], "parameters": f.get("parameters", {}),
                    "intervals": intervals, "where": f.get("where"),
                    "explained": _finite(f.get("explained")),
                    "held_out_gain": _finite(trial.get("gain")),
                    "held_out_p": _finite(trial.get("p")),
                    "blocks_better": trial.get("positive"),
                    "evidence": f.get("evidence", "")})
    return out


def _limits(report: dict[str, Any]) -> list[dict[str, Any]]:
    """What the record could not have revealed: the smallest size of each effect."""
    return [{"effect": c.get("effect"), "smallest": _finite(c.get("smallest")),
             "unit": c.get("unit"), "text": c.get("text")}
            for c in report.get("could_not_reveal", []) or []]
