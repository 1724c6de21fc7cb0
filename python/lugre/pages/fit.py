"""The pages of the fits: the model identified from a recording, the static fit."""

from __future__ import annotations

from html import escape
from typing import Any

from .. import units as U
from .frame import _figure, _p, _page, _table

__all__ = ["fit_page", "static_fit_page"]


# --------------------------------------------------------------------------------------
# Fits
# --------------------------------------------------------------------------------------


#: The axis's parameters (a linear or a rotary axis's) and the base parameter each is.
_AXIS_ROWS = (("mass", "mass"), ("inertia", "mass"), ("force_constant", "force_constant"),
              ("torque_constant", "force_constant"))


def _model_rows(doc: dict[str, Any]) -> list[list[str]]:
    rows = []
    axis = doc.get("axis") or {}
    fr = doc.get("friction") or {}
    for name, base in _AXIS_ROWS:
        if name in axis:
            rows.append([name.replace("_", " "), escape(U.fmt(axis[name], U.base_unit(base)))])
    for name in ("sigma0", "sigma1"):
        if name in fr:
            rows.append([name, escape(U.fmt(fr[name], U.base_unit(name)))])
    for d in ("positive", "negative"):
        for name, val in (fr.get(d) or {}).items():
            rows.append([f"{name} ({'v ≥ 0' if d == 'positive' else 'v < 0'})",
                         escape(U.fmt(val, U.base_unit(name)))])
    for e in doc.get("effects") or []:  # (those asked for)
        rows.append([escape(str(e.get("effect"))), escape(_effect_values(e))])
    for e in _set_aside(doc):
        rows.append([escape(f"{e.get('effect')} (set aside)"),
                     escape(_effect_values(e) + ": not in the model; lugre diagnose names it")])
    return rows


def _effect_values(e: dict[str, Any]) -> str:
    name = str(e.get("effect"))
    return ", ".join(f"{k} {U.fmt(v, U.unit_of(name, k))}" for k, v in e.items()
                     if k != "effect" and isinstance(v, (int, float)))


def _aside_words(aside: list[dict[str, Any]]) -> str:
    if not aside:
        return ""
    names = " and ".join(escape(str(e.get("effect"))) for e in aside)
    return (f" The fit found a {names} beside the base (the fit's residual is with it) and "
            "left it out of this model: run lugre diagnose on this record with this model, "
            "which names it with its evidence; its augmented model holds it.")


def _set_aside(doc: dict[str, Any]) -> list[dict[str, Any]]:
    """Effects the fit found beside the base and left out of the model."""
    return [e for e in (doc.get("identification") or {}).get("set_aside") or []
            if isinstance(e, dict)]


def _stribeck_uri(doc: dict[str, Any], v: Any = None, F: Any = None,
                  rejected: Any = None) -> str | None:
    import numpy as np

    from .._native import stribeck
    from ..figures import curve_figure
    from ..model import Model

    try:
        m = Model.from_dict(doc)
        vmax = float(np.max(np.abs(v))) if v is not None and len(v) else 20 * max(
            m.positive["vs"], m.negative["vs"])
        grid = np.linspace(-vmax, vmax, 801)
        vu, k = U.display("m/s")
        series = [(k * grid, stribeck(grid, m), "-", "fitted steady-state friction")]
        if v is not None and F is not None:
            va, Fa = np.asarray(v, float), np.asarray(F, float)
            bad = np.zeros(va.size, bool)
            if rejected is not None and len(rejected):
                bad[np.asarray(rejected, int)] = True
            series.insert(0, (k * va[~bad], Fa[~bad], "o", "steady-state points"))
            if bad.any():
                series.insert(1, (k * va[bad], Fa[bad], "x",
                                  "rejected as gross errors"))
        return curve_figure(series, f"velocity [{vu}]",
                            f"friction {U.force_words()} [{U.si('N')}]")
    except (ValueError, KeyError, TypeError):
        return None


def static_fit_page(fit: Any, v: Any, F: Any, model: dict[str, Any], *,
                    source: str | None = None, assumed: list[str] | None = None) -> str:
    """``lugre fit-static``: the Stribeck parameters with their 95 % intervals, the
    rejected points and the curve over the points (in the units of the model's axis)."""
    with U.axis(str((model.get("axis") or {}).get("kind", "linear"))):
        return _static_fit_page(fit, v, F, model, source=source, assumed=assumed)


def _static_fit_page(fit: Any, v: Any, F: Any, model: dict[str, Any], *,
                     source: str | None, assumed: list[str] | None) -> str:
    body = []
    rows = []
    for d, label in (("positive", "v ≥ 0"), ("negative", "v < 0")):
        df = getattr(fit, d)
        for name, val in df.params.items():
            unit = U.base_unit(name)
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
    from ..diagnosis.fitreport import label

    rows = []
    for name, p in params.items():
        unit = U.si(str(p.get("unit", "")))
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
    curve, in the units of the model's axis."""
    rotary = (model.get("axis") or {}).get("kind") == "rotary"
    with U.axis("rotary" if rotary else "linear"):
        return _fit_page(model, rec, source=source, nrmse=nrmse, first=first)


def _fit_page(model: dict[str, Any], rec: Any, *, source: str | None,
              nrmse: dict[str, float | None] | None, first: dict[str, Any] | None) -> str:
    body = []
    ident = model.get("identification") or {}
    if ident.get("summary"):
        aside = _set_aside(model)
        far = bool(ident.get("far_from_floor")) or bool(aside)
        head = "Check first." if far else "Result."
        body.append(f"<div class=\"verdict{'' if far else ' ok'}\"><b>{head}</b> The identified "
                    f"model explains the motor {U.force_words()} to "
                    f"{100 * float(ident['nrmse_force']):.2f} % rms; "
                    f"{escape(str(ident['summary']))}.{_aside_words(aside)}</div>")
    elif nrmse:
        best = min(v for v in nrmse.values() if v is not None)
        body.append("<div class=\"verdict ok\"><b>Result.</b> The identified model "
                    + U.words(f"explains the motor force to {100 * best:.2f} % rms (force "
                              "residual over motor force). ")
                    + "Next: check it on a second run with lugre evaluate, or look for "
                    "missing physics with lugre diagnose.</div>")
    if nrmse:
        rows = [[escape(k), f"{100 * float(v):.2f} %"] for k, v in nrmse.items() if v is not None]
        body.append(f"<h2>{U.force_words().capitalize()} residual</h2>")
        body.append(_table(["step", f"of the motor {U.force_words()} (rms)"], rows, {1}))
    if ident.get("parameters"):
        body.append("<h2>What the record determines</h2>")
        body.append(_table(["parameter", "value", "95 % interval", "determined"],
                           _ident_rows(ident["parameters"]), {1, 2}))
        body.append("<p>The intervals are the record's noise's: a model error that the "
                    "noise does not show (physics the model leaves out, a sampling that "
                    "differs from the model's) is not in them. The further the fit is "
                    "from the noise floor, the less they hold.</p>")
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
