"""The residual of a recording against a model, and how far the friction on it sits
from the model's: :func:`evaluate`."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .. import units as U
from ..exceptions import InputError
from ..io import Recording
from ..model import Model, _as_model
from . import residual as R

__all__ = ["as_recording", "evaluate", "level_shift", "level_shift_text", "metrics"]


def metrics(r: np.ndarray, f: np.ndarray, mask: np.ndarray) -> dict[str, float]:
    """The rms residual [N] and its share of the rms motor force."""
    rr = r[mask]
    ff = f[mask]
    rms = float(np.sqrt(np.mean(rr * rr)))
    rf = float(np.sqrt(np.mean(ff * ff)))
    return {"rms_force": rms, "nrmse_force": rms / rf if rf > 0 else math.nan}


def as_recording(recording: Any) -> Recording:
    """A :class:`~lugre.Recording` from a recording or a path."""
    if isinstance(recording, Recording):
        return recording
    from ..io import read_recording

    if isinstance(recording, (str, bytes)) or hasattr(recording, "__fspath__"):
        return read_recording(recording)
    raise InputError.at("recording", "give a lugre.Recording or the path of a recording")


#: A friction level shift on an evaluated record is reported when it exceeds this share
#: of the model's Coulomb level and three standard errors (over ten time blocks).
LEVEL_SHIFT_SHARE = 0.03


def level_shift(r: np.ndarray, sig: R.Signals, model: Model) -> dict[str, Any] | None:
    """How far the friction on this record sits from the model's, per direction.

    The mean residual while the axis moves forward, and minus it while it moves back:
    the friction magnitude the model misses (> 0: the record's friction is higher).
    Standard errors from ten consecutive time blocks of each direction (the residual is
    coloured). Both shifts with one sign are a change of friction since the model's
    record (temperature, lubrication, another session); opposite signs are a constant
    force. None when a direction has under 200 samples.
    """
    out: dict[str, Any] = {}
    for d, sgn in (("positive", 1.0), ("negative", -1.0)):
        sel = np.flatnonzero(sig.mask & (sgn * sig.vf > 0))
        if len(sel) < 200:
            return None
        vals = sgn * r[sel]
        blocks = [b.mean() for b in np.array_split(vals, 10)]
        fc = float(model.friction[d]["fc"])
        out[d] = {"shift": float(vals.mean()), "se": float(np.std(blocks, ddof=1) / np.sqrt(10)),
                  "share_of_fc": float(vals.mean() / fc) if fc > 0 else math.nan}
    sig_d = [abs(out[d]["shift"]) > 3.0 * out[d]["se"]
             and abs(out[d]["share_of_fc"]) > LEVEL_SHIFT_SHARE for d in ("positive", "negative")]
    same = out["positive"]["shift"] * out["negative"]["shift"] > 0
    out["significant"] = bool(any(sig_d))
    out["kind"] = ("friction level" if same else "constant force") if any(sig_d) else None
    return out


def level_shift_text(ls: dict[str, Any] | None) -> str | None:
    """One sentence on a significant :func:`level_shift`, or None."""
    if not ls or not ls["significant"]:
        return None
    p, n = ls["positive"], ls["negative"]
    u = U.si("N")
    figs = (f"{p['shift']:+.3g} {u} ({100 * p['share_of_fc']:+.1f} % of fc) moving forward, "
            f"{n['shift']:+.3g} {u} ({100 * n['share_of_fc']:+.1f} %) moving back")
    if ls["kind"] == "friction level":
        return (f"the friction on this record differs from the model's by {figs}: friction "
                "has changed since the model's record (temperature, lubrication, wear); "
                "compare records taken warm, at the same temperature, or refit the levels "
                "on this one (lugre diagnose refits them)")
    return U.words(f"the force on this record differs from the model's by {figs}, opposite "
                   "ways: a constant force (an offset: gravity, a cable) the model does not "
                   "hold")


def evaluate(recording: Any, model: Any, *, cutoff_hz: float | None = None,
             backend: Any = "core") -> dict[str, Any]:
    """Inverse-dynamics force residual of a recording against a model.

    ``r = K_F*i - m*a - F_friction - sum(F_effect)`` with every term low-passed by the
    same zero-phase filter, ``a`` from the filtered position and the bristle state
    driven by the measured velocity.

    Parameters
    ----------
    recording : Recording or path
        The recording.
    model : Model, dict or path
        The model (its effects included).
    cutoff_hz : float, optional
        Low-pass cut-off (default ``fs/25``).
    backend : "core" or module, default "core"
        The kernels: the compiled core, or a kernels module such as
        :mod:`lugre.reference.kernels` (the NumPy twin; slower, for checking).

    Returns
    -------
    dict
        ``rms_force`` [N], ``nrmse_force`` (rms residual over rms motor force),
        ``noise_floor`` [N], ``samples``, ``cutoff_hz``, and ``level_shift``: the
        friction the model misses per direction (see :func:`level_shift`; None when a
        direction has too few samples).
    """
    rec = as_recording(recording)
    m = _as_model(model)
    with U.axis(m.kind):
        return _evaluate(rec, m, cutoff_hz, backend)


def _evaluate(rec: Any, m: Model, cutoff_hz: float | None, backend: Any) -> dict[str, Any]:
    R.check_recording(rec, m)
    sig = R.prepare(rec, m, cutoff_hz=cutoff_hz, backend=backend)
    R.check_units(sig, m)
    r = R.residual(m, sig)
    out: dict[str, Any] = metrics(r, sig.fm_f, sig.mask)
    out["noise_floor"] = R.noise_floor(r, sig)["rms"]
    out["samples"] = len(sig)
    out["cutoff_hz"] = sig.cutoff_hz
    out["level_shift"] = level_shift(r, sig, m)
    return out
