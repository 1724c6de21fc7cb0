"""The base fit in words and in the model file: each parameter with its interval, what
the record does not determine and what would."""

from __future__ import annotations

import math
from typing import Any

from .. import units as U
from ..model import Model
from .base import unit
from .basefit import BaseFitResult

__all__ = ["fit_unit", "identification", "label", "undetermined_notes"]


#: What would determine a parameter the record leaves open.
_WOULD = {
    "mass": "faster changes of speed (accelerations well above the friction's noise)",
    "fc": "sliding at steady speeds in this direction",
    "hump": "slow motion through the Stribeck range, with reversals and break-away",
    "vs": "motion at speeds around the Stribeck speed (slow sweeps, reversals)",
    "sigma2": "sliding over a wider range of speeds",
    "sigma0": "the presliding regime: an open-loop force sweep at standstill below "
              "break-away (lugre.presliding), or a record sampled fast enough to resolve "
              "the bristles' spring",
    "sigma1": "the presliding regime (as sigma0), or a closed-loop stick-slip record with "
              "the static sets from constant-velocity runs (lugre fit-static, then "
              "lugre fit-dynamic)",
}


def _key(name: str) -> str:
    return name.split(".")[-1]


def fit_unit(name: str) -> str:
    """SI unit of a fitted parameter (``positive.hump`` is in the unit of ``fs``), on the
    axis spoken now (``N m`` for ``N`` on a rotary axis)."""
    return U.si(unit(name.replace(".hump", ".fs")))


def label(name: str) -> str:
    """``positive.hump`` -> ``fs - fc (v >= 0)``; ``mass`` is ``inertia`` on a rotary
    axis."""
    side, _, key = name.rpartition(".")
    text = "fs - fc" if key == "hump" else U.mass_words() if key == "mass" else key
    return f"{text} ({'v >= 0' if side == 'positive' else 'v < 0'})" if side else text


def _num(x: Any) -> float | None:
    return None if x is None or not math.isfinite(float(x)) else float(x)


def identification(fit: BaseFitResult, model: Model, nrmse: float) -> dict[str, Any]:
    """The ``identification`` section of a fitted model file: the fit against the
    record's noise floor and every fitted parameter with its 95 % interval (units and
    words of the model's axis)."""
    with U.axis(model.kind):
        return _identification(fit, nrmse)


def _identification(fit: BaseFitResult, nrmse: float) -> dict[str, Any]:
    params = {}
    for name, p in fit.profiles.items():
        ci = p.get("ci95") or [None, None]
        params[name] = {"value": float(p["value"]), "unit": fit_unit(name),
                        "ci95": [_num(ci[0]), _num(ci[1])],
                        "determined": bool(p["determined"]), "how": p["how"]}
        if p.get("passivity_bound") is not None:
            params[name]["passivity_bound"] = float(p["passivity_bound"])
    words, far = fit.floor_words()
    out = {"nrmse_force": float(nrmse), "rms_force": fit.rms, "noise_floor": fit.noise,
           "floor_ratio": fit.floor_ratio, "far_from_floor": far, "summary": words,
           "parameters": params}
    if fit.set_aside:  # (fitted beside the base, left out for the diagnosis to name)
        out["set_aside"] = [dict(e) for e in fit.set_aside]
    return out


def undetermined_notes(fit: BaseFitResult) -> list[str]:
    """One sentence per parameter the record does not determine (in the words of the
    fitted model's axis)."""
    with U.axis(fit.model.kind):
        return [U.words(n) for n in _undetermined(fit)]


def _undetermined(fit: BaseFitResult) -> list[str]:
    out = []
    for name, p in fit.profiles.items():
        if p.get("passivity_bound") is not None:
            lo, hi = p["ci95"]
            out.append(f"{label(name)} = {p['value']:.4g} {fit_unit(name)} lies beyond the "
                       f"passivity bound 4*sigma2*fc/(fs - fc) = {p['passivity_bound']:.4g} "
                       f"{fit_unit(name)} of the friction, and the record puts it there (95 % "
                       f"interval {lo:.4g} to {hi:.4g}): kept. The bound is sufficient for "
                       "passivity, not necessary; a simulation with this model may feed "
                       "energy into the axis near the reversals, so check it against a "
                       "record before a compensator relies on it")
        if p["determined"]:
            continue
        key = _key(name)
        val = f"{p['value']:.4g} {fit_unit(name)}"
        if p["how"] == "held (simplest)":
            what = ("set to zero (fs = fc)" if key == "hump" else "held within the passivity "
                    "bound" if key == "sigma1" else "held: without a hump it does nothing")
            out.append(f"{label(name)} = {val} is NOT determined by this record and is "
                       f"{what}: the fit is as good within the noise. Would determine it: "
                       f"{_WOULD[key]}")
            continue
        if p["how"] == "passivity bound":
            out.append(f"{label(name)} = {val} is held at the passivity bound "
                       "4*sigma2*fc/(fs - fc) of the friction: the fit gave "
                       f"{p['fitted']:.4g} {fit_unit(name)}, beyond which the friction map "
                       "is not passive (it could feed energy into the axis). Would "
                       f"determine it: {_WOULD[key]}")
            continue
        if p["how"] == "no hump":
            out.append(f"{label(name)} = {val} is NOT determined: the fit found no Stribeck "
                       "hump in this direction (fs = fc), so vs does nothing. Would show a "
                       f"hump: {_WOULD['hump']}")
            continue
        lo, hi = (p.get("ci95") or [None, None])
        side = ("either way" if lo is None and hi is None else
                "upwards" if hi is None else "downwards")
        out.append(f"{label(name)} = {val} is NOT determined by this record: moved "
                   f"{side} by up to a factor of ten (the others refitted) the fit stays "
                   f"within the noise. Would determine it: {_WOULD[key]}")
    return out
