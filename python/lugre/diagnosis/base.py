"""Base parameters of the model (mass, LuGre levels, presliding) as regressors.

The diagnosis re-estimates the friction levels of the model alongside every effect
(their tolerance is a Gaussian prior: how far the parameters of a model that is "about
right" may move). The mass is not among them: a changed mass is the ``mass`` effect
(a payload), tested like any other. The presliding parameters ``sigma0`` and ``sigma1``
are freed only when a record shows them (held-out profile test); otherwise they are held
and reported as not determined by the record.
"""

from __future__ import annotations

import numpy as np

from ..model import Model
from .residual import Signals

__all__ = ["BASE_PARAMS", "LEVELS", "PRESLIDING", "apply_base", "base_jacobian", "get_base",
           "unit"]

#: Every base parameter, and their tolerance (relative std of the
#: prior: how far a parameter of a model that is "about right" may move).
BASE_PARAMS: tuple[tuple[str, float], ...] = (
    ("mass", 0.03),
    ("positive.fc", 0.03),
    ("positive.fs", 0.03),
    ("positive.sigma2", 0.03),
    ("positive.vs", 0.1),
    ("negative.fc", 0.03),
    ("negative.fs", 0.03),
    ("negative.sigma2", 0.03),
    ("negative.vs", 0.1),
    ("sigma0", 0.3),
    ("sigma1", 0.3),
)

#: Friction levels re-estimated alongside every effect.
LEVELS: tuple[str, ...] = tuple(n for n, _ in BASE_PARAMS if "." in n)

#: Presliding parameters, freed only when the record shows them.
PRESLIDING: tuple[str, ...] = ("sigma0", "sigma1")


def unit(name: str) -> str:
    """SI unit of a base parameter."""
    key = name.split(".")[-1]
    return {"mass": "kg", "fc": "N", "fs": "N", "sigma2": "N s/m", "vs": "m/s",
            "sigma0": "N/m", "sigma1": "N s/m"}[key]


def get_base(model: Model, name: str) -> float:
    """Value of a base parameter by its path (``mass``, ``positive.fc``, ``sigma0``)."""
    if name == "mass":
        return float(model.mass)
    f = model._data["friction"]  # (as validated: no copy of the document)
    if "." in name:
        d, k = name.split(".")
        return float(f[d][k])
    return float(f[name])


def apply_base(model: Model, values: dict[str, float]) -> Model:
    """A copy of ``model`` with base parameters set (kept valid: ``fs >= fc`` etc.).

    Parameters
    ----------
    model : Model
        The model.
    values : dict
        New values by path.

    Returns
    -------
    Model
    """
    if "mass" in values:
        model = model.with_axis(mass=max(float(values["mass"]), 1e-6))
    d = model.to_dict()
    f = d["friction"]
    for name, val in values.items():
        val = float(val)
        if name == "mass":
            continue
        elif "." in name:
            a, k = name.split(".")
            f[a][k] = val
        else:
            f[name] = val
    for side in ("positive", "negative"):
        s = f[side]
        s["fc"] = max(float(s["fc"]), 1e-9)
        s["fs"] = max(float(s["fs"]), float(s["fc"]))
        s["vs"] = max(float(s["vs"]), 1e-6)
        s["sigma2"] = max(float(s["sigma2"]), 0.0)
    f["sigma0"] = max(float(f["sigma0"]), 1.0)
    f["sigma1"] = max(float(f["sigma1"]), 0.0)
    return Model(d)


def base_jacobian(model: Model, sig: Signals,
                  names: tuple[str, ...] | list[str] | None = None
                  ) -> tuple[np.ndarray, list[str], np.ndarray, np.ndarray]:
    """Jacobian of the filtered model force with respect to the base parameters.

    The friction columns are the exact sensitivities of the LuGre force, propagated
    through the bristle update by the inverse-dynamics kernel
    (``InverseRecord.base_sensitivities``); the mass column is the acceleration.

    Parameters
    ----------
    model : Model
        The model at which to linearise (its effects included).
    sig : Signals
        The prepared recording.
    names : sequence of str, optional
        The parameters to linearise in (default :data:`LEVELS`).

    Returns
    -------
    J : numpy.ndarray
        ``(n, q)``, filtered.
    names : list of str
        Parameter paths (identifiable ones only).
    theta : numpy.ndarray
        Current values.
    tol : numpy.ndarray
        Prior standard deviations (absolute).
    """
    wanted = set(LEVELS if names is None else names)
    fr = model.friction
    order: list[str] = []
    for name, _ in BASE_PARAMS:
        if name not in wanted:
            continue
        if name.endswith(".vs"):
            side = name.split(".")[0]
            if abs(fr[side]["fs"] - fr[side]["fc"]) < 1e-3 * fr[side]["fc"]:
                continue  # no Stribeck hump: vs does nothing
        order.append(name)
    friction = [n for n in order if n != "mass"]
    _, jac, nonzero = sig.kernel.base_sensitivities(model, friction)
    col_of = {n: j for j, n in enumerate(friction)}
    picks: list[int] = []  # per column of J: its column of jac, or -1 for the mass
    out: list[str] = []
    theta: list[float] = []
    tol: list[float] = []
    rel_of = dict(BASE_PARAMS)
    for name in order:
        j = -1 if name == "mass" else col_of[name]
        if j >= 0 and not nonzero[j]:
            continue
        picks.append(j)
        th = get_base(model, name)
        out.append(name)
        theta.append(th)
        tol.append(rel_of[name] * max(abs(th), 1e-12))
    return _columns(np.asarray(jac), picks, sig), out, np.array(theta), np.array(tol)


def _columns(jac: np.ndarray, picks: list[int], sig: Signals) -> np.ndarray:
    """The columns ``picks`` of ``jac`` (-1: the acceleration, the mass's column) as
    one C-ordered ``(n, q)`` array, the kernel's own when it holds them all in order (a
    million samples' columns stacked one by one cost a fifth of a second a call)."""
    if not picks:
        return np.zeros((len(sig), 0))
    fric = [k for k, j in enumerate(picks) if j >= 0]
    if len(fric) == len(picks):
        if picks == list(range(jac.shape[1])) and jac.flags.c_contiguous:
            return jac
        return np.ascontiguousarray(jac[:, picks])
    J = np.empty((len(sig), len(picks)))
    if fric:
        J[:, fric] = jac[:, [picks[k] for k in fric]]
    for k, j in enumerate(picks):
        if j < 0:
            J[:, k] = sig.a
    return J
