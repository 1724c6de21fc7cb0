"""NumPy twin of the base fit (``src/inverse/fit.rs``): robust Levenberg-Marquardt on
the inverse-dynamics residual of :class:`~lugre.reference.InverseRecord`, the same
steps in the same order (scales of the parameters, scouting starts, the loss that ranks
them). Reached as ``InverseRecord.fit_base`` of the twin."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..exceptions import DataError, InputError
from ..model import Model, _as_model
from ..vocabulary import MASS
from .robust import Weighting, robust_scale

__all__ = ["fit_base"]

_SIDES = ("positive", "negative")
_LOG = ("mass", "fc", "vs", "sigma0")


def _parse(name: str) -> tuple[str | None, str]:
    if name in ("mass", "sigma0", "sigma1"):
        return None, name
    side, _, key = name.partition(".")
    if side not in _SIDES or key not in ("fc", "hump", "sigma2", "vs"):
        raise InputError.at("names", f"unknown base parameter {name!r}: use mass, sigma0, "
                            "sigma1 or positive/negative.fc, .hump, .sigma2, .vs")
    return side, key


def _get(doc: dict[str, Any], p: tuple[str | None, str]) -> float:
    side, key = p
    f = doc["friction"]
    if key == "mass":
        return float(doc["axis"]["mass"])
    if side is None:
        return float(f[key])
    s = f[side]
    return float(s["fs"] - s["fc"]) if key == "hump" else float(s[key])


def _set(doc: dict[str, Any], p: tuple[str | None, str], value: float) -> None:
    side, key = p
    f = doc["friction"]
    if key == "mass":
        doc["axis"]["mass"] = value
    elif side is None:
        f[key] = value
    elif key == "fc":
        hump = f[side]["fs"] - f[side]["fc"]
        f[side]["fc"], f[side]["fs"] = value, value + hump
    elif key == "hump":
        f[side]["fs"] = f[side]["fc"] + value
    else:
        f[side][key] = value


def _scale_of(p: tuple[str | None, str], doc: dict[str, Any], vmax: float) -> float | None:
    f = doc["friction"]
    fc = max(f["positive"]["fc"], f["negative"]["fc"], 1e-9)
    key = p[1]
    if key == "hump":
        return fc
    if key == "sigma2":
        return fc / max(vmax, 1e-9)
    if key == "sigma1":
        return math.sqrt(f["sigma0"] * max(_total_mass(doc), 1e-9))
    return None


def _total_mass(doc: dict[str, Any]) -> float:
    return float(doc["axis"]["mass"]) + sum(float(e.get("delta", 0.0)) for e in doc["effects"]
                                           if e.get("effect") == MASS)


def _loss(w: Weighting, u: np.ndarray) -> np.ndarray:
    a = np.abs(u)
    if w.kind == "huber":
        return np.where(a > w.c, w.c * a - 0.5 * w.c * w.c, 0.5 * a * a)
    a = np.minimum(a, 2.5)
    return 0.5 * a * a


class _Problem:
    def __init__(self, rec: Any, mask: np.ndarray, params: list[tuple[str | None, str]],
                 scales: list[float | None], weighting: Weighting) -> None:
        self.rec, self.mask, self.params, self.scales = rec, mask, params, scales
        self.weighting = weighting
        self.evaluations = 0

    def residual(self, doc: dict[str, Any]) -> np.ndarray | None:
        self.evaluations += 1
        r = np.where(self.mask, self.rec.residual(Model(doc)), 0.0)
        return r if np.all(np.isfinite(r)) else None

    def weights(self, r: np.ndarray) -> tuple[np.ndarray, float]:
        s = max(robust_scale(r[self.mask].tolist()), 1e-300)
        w = np.where(self.mask, self.weighting.weights(r.tolist(), s), 0.0)
        return w, s

    def encode(self, doc: dict[str, Any]) -> np.ndarray:
        return np.array([math.log(max(_get(doc, p), 1e-300)) if sc is None
                         else max(_get(doc, p), 0.0) / sc
                         for p, sc in zip(self.params, self.scales)])

    def decode(self, doc: dict[str, Any], u: np.ndarray) -> dict[str, Any]:
        out = {"axis": dict(doc["axis"]), "friction": {
            **doc["friction"], **{s: dict(doc["friction"][s]) for s in _SIDES}}}
        out = {**doc, **out}
        for p, sc, ui in zip(self.params, self.scales, u):
            _set(out, p, math.exp(ui) if sc is None else sc * max(ui, 0.0))
        return out

    def slope(self, sc: float | None, ui: float) -> float:
        return math.exp(ui) if sc is None else sc

    def advance(self, u: np.ndarray, step: np.ndarray) -> np.ndarray:
        out = np.empty_like(u)
        for k, (ui, s, sc) in enumerate(zip(u, step, self.scales)):
            if sc is None:
                out[k] = ui + min(max(s, -2.0), 2.0)
            else:
                lim = 2.0 * max(abs(ui), 1.0)
                out[k] = max(ui + min(max(s, -lim), lim), 0.0)
        return out

    def jacobian(self, doc: dict[str, Any], u: np.ndarray) -> np.ndarray:
        names = [f"{s}.{k}" for s in _SIDES for k in ("fc", "fs", "sigma2", "vs")]
        names += ["sigma0", "sigma1"]
        _, jac, _ = self.rec.base_sensitivities(Model(doc), names)
        col = {n: np.asarray(jac[:, j]) for j, n in enumerate(names)}
        cols = []
        for (side, key), sc, ui in zip(self.params, self.scales, u):
            if key == "mass":
                c = np.asarray(self.rec.a, dtype=float)
            elif key == "fc":
                c = col[f"{side}.fc"] + col[f"{side}.fs"]
            elif key == "hump":
                c = col[f"{side}.fs"]
            elif side is None:
                c = col[key]
            else:
                c = col[f"{side}.{key}"]
            cols.append(np.where(self.mask, c * self.slope(sc, ui), 0.0))
        return np.column_stack(cols)

    def run(self, start: dict[str, Any], max_iter: int, tol: float) -> dict[str, Any] | None:
        r = self.residual(start)
        if r is None:
            return None
        doc, u = start, self.encode(start)
        w, scale = self.weights(r)
        lam, iterations, small, converged = 1e-3, 0, 0, False
        for _ in range(max_iter):
            iterations += 1
            cost = float(np.sum(w * r * r))
            J = self.jacobian(doc, u)
            A = J.T @ (w[:, None] * J)
            b = J.T @ (w * r)
            trace = max(float(np.trace(A)), 1e-300)
            accepted = None
            for _ in range(12):
                M = A + np.diag(lam * np.diag(A) + 1e-12 * trace)
                try:
                    step = np.linalg.solve(M, b)
                except np.linalg.LinAlgError:
                    lam *= 10.0
                    continue
                u2 = self.advance(u, step)
                d2 = self.decode(doc, u2)
                r2 = self.residual(d2)
                if r2 is not None and float(np.sum(w * r2 * r2)) < cost:
                    accepted = (d2, u2, r2, float(np.sum(w * r2 * r2)))
                    break
                lam *= 5.0
            if accepted is None:
                break
            lam = max(lam / 3.0, 1e-9)
            rel = (cost - accepted[3]) / max(cost, 1e-300)
            moved = float(np.max(np.abs(accepted[1] - u))) if u.size else 0.0
            doc, u, r = accepted[0], accepted[1], accepted[2]
            w, scale = self.weights(r)
            small = small + 1 if (rel < tol or moved < 1e-5) else 0
            if small >= 2:
                converged = True
                break
        return {"doc": doc, "r": r, "w": w, "scale": scale, "iterations": iterations,
                "cost": float(np.sum(w * r * r)), "converged": converged}


def _information(pb: _Problem, run: dict[str, Any]) -> np.ndarray:
    """``J^T W J`` of a run's model in the parameters themselves (not their logs)."""
    u = pb.encode(run["doc"])
    J = pb.jacobian(run["doc"], u)
    J = J / np.array([pb.slope(sc, ui) for sc, ui in zip(pb.scales, u)])
    return J.T @ (run["w"][:, None] * J)


def fit_base(rec: Any, starts: list[Any], mask: Any, names: list[str], max_iter: int = 60,
             keep: int = 3, scouts: int = 12, weighting: str = "huber",
             scout_iter: int = 6, tol: float = 1e-6, information: bool = True
             ) -> dict[str, Any]:
    """Twin of ``_core.InverseRecord.fit_base`` (see ``lugre::inverse::fit_base``)."""
    if not (math.isfinite(tol) and tol >= 0.0):
        raise InputError.at("tol", f"must be a finite number >= 0, got {tol}")
    mask = np.asarray(mask, dtype=bool)
    if mask.size != len(rec):
        raise InputError.at("mask", f"has {mask.size} samples, the record {len(rec)}")
    if not starts:
        raise InputError.at("starts", "give at least one start model")
    params = [_parse(n) for n in names]
    docs = [_as_model(s).to_dict() for s in starts]
    vmax = float(np.max(np.abs(rec.v)))
    w8 = Weighting.from_name(weighting)
    pb = _Problem(rec, mask, params, [_scale_of(p, docs[0], vmax) for p in params], w8)
    first = rec.residuals([Model(d) for d in docs])
    pb.evaluations += len(docs)
    ranked = sorted((float(np.sum(first[mask, k] ** 2)), k) for k in range(len(docs))
                    if np.all(np.isfinite(first[:, k])))

    def rank(runs: list[tuple[int, dict[str, Any]]]) -> list[tuple[float, int, dict[str, Any]]]:
        smin = min((r["scale"] for _, r in runs), default=math.inf)
        out = [(float(np.sum(_loss(w8, r["r"][mask] / smin))), k, r) for k, r in runs]
        return sorted(out, key=lambda t: t[0])

    found = [(k, pb.run(docs[k], scout_iter, tol)) for _, k in ranked[:max(scouts, keep, 1)]]
    runs = []
    for _, k, sc in rank([(k, r) for k, r in found if r is not None])[:max(keep, 1)]:
        run = sc if sc["converged"] else pb.run(sc["doc"], max_iter, tol)
        if run is not None:
            if run is not sc:
                run["iterations"] += sc["iterations"]
            runs.append((k, run))
    best_all = rank(runs)
    if not best_all:
        raise DataError("the model's residual is not finite at any start: check the "
                        "recording's units and the force constant")
    criterion, start, best = best_all[0]
    doc = best["doc"]
    info = _information(pb, best) if information else None
    f = doc["friction"]
    values = {"mass": float(doc["axis"]["mass"])}
    for s in _SIDES:
        for k in ("fc", "fs", "sigma2", "vs"):
            values[f"{s}.{k}"] = float(f[s][k])
    values["sigma0"], values["sigma1"] = float(f["sigma0"]), float(f["sigma1"])
    return {"values": values, "cost": best["cost"], "scale": best["scale"],
            "criterion": criterion, "weights": best["w"], "information": info,
            "start": start, "iterations": best["iterations"], "evaluations": pb.evaluations}
