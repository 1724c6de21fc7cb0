"""Force residual by inverse dynamics: filtering, derivatives, model force, noise floor.

The residual of a recording against a model is

``r = filt(F_m) - m*a - filt(F_friction) - filt(sum F_effect)``

where ``F_m`` is the motor force (``K_F*i`` or ``F``) after removing isolated spikes,
``a`` the second derivative of the low-passed position, ``F_friction`` the LuGre force
with its bristle state driven by the measured velocity (lightly filtered, so that the
bristles see the motion as it happened), and ``filt`` the same zero-phase low-pass that
was applied to the position ("parallel filtering": every term carries the same filter,
so the residual holds no filter artefacts).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy import signal

from .._native import friction_force
from ..exceptions import DataError, InputError, UnitsWarning
from ..io import Recording
from ..model import Model, _as_model

__all__ = [
    "Signals",
    "check_recording",
    "lowpass",
    "model_force",
    "noise_floor",
    "prepare",
    "residual",
    "scaled_friction",
]

#: Fewest samples a diagnosis accepts.
MIN_SAMPLES = 400


def lowpass(y: np.ndarray, cutoff_hz: float, fs: float, order: int = 4) -> np.ndarray:
    """Zero-phase Butterworth low-pass (``sosfiltfilt``) along the first axis.

    Parameters
    ----------
    y : numpy.ndarray
        Signal, or matrix with one signal per column.
    cutoff_hz : float
        Cut-off frequency [Hz]; at or above Nyquist the signal is returned as is.
    fs : float
        Sample rate [Hz].
    order : int, default 4
        Filter order (applied twice).

    Returns
    -------
    numpy.ndarray
    """
    wn = cutoff_hz / (0.5 * fs)
    if wn >= 0.99:
        return np.array(y, dtype=float, copy=True)
    sos = signal.butter(order, wn, output="sos")
    return signal.sosfiltfilt(sos, y, axis=0, padtype="odd", padlen=min(3 * 24, len(y) - 1))


def hampel(y: np.ndarray, half_window: int = 5, k: float = 5.0) -> tuple[np.ndarray, np.ndarray]:
    """Replace isolated one-sample spikes by the local median (Hampel identifier).

    A sample is a spike when it deviates from the moving median by more than ``k``
    robust standard deviations **and** stands out from both its neighbours, in the
    direction of the deviation, by at least half of it. A step of the force and the
    controller's transient after it (a force pulse injected into the loop, a reversal)
    deviate from the median too but are not isolated: they are real forces that move
    the axis, so they stay in the signal, where the parallel filter treats them like the
    acceleration they cause. Removing them from the force alone would leave the
    acceleration unbalanced.

    Parameters
    ----------
    y : numpy.ndarray
        Signal.
    half_window : int, default 5
        Half width of the moving window [samples].
    k : float, default 5.0
        Threshold in robust standard deviations of the deviation from the local median.

    Returns
    -------
    cleaned : numpy.ndarray
    spikes : numpy.ndarray of bool
        Where a sample was replaced.
    """
    from scipy.ndimage import median_filter

    med = median_filter(y, size=2 * half_window + 1, mode="nearest")
    dev = y - med
    ad = np.abs(dev)
    ad = ad[ad > 0]
    s = 1.4826 * float(np.median(ad)) if ad.size else 0.0
    if not s > 0 or y.size < 3:
        return y.copy(), np.zeros(y.shape, dtype=bool)
    left = y - np.r_[y[0], y[:-1]]
    right = y - np.r_[y[1:], y[-1]]
    sd = np.sign(dev)
    isolated = ((np.sign(left) == sd) & (np.sign(right) == sd)
                & (np.minimum(np.abs(left), np.abs(right)) > 0.5 * np.abs(dev)))
    spikes = (np.abs(dev) > k * s) & isolated
    out = y.copy()
    out[spikes] = med[spikes]
    return out, spikes


@dataclass
class Signals:
    """A recording prepared for inverse dynamics (all arrays of the recording's length).

    Attributes
    ----------
    t : numpy.ndarray
        Time [s] from the start of the recording.
    dt, fs : float
        Sample interval [s] and rate [Hz].
    cutoff_hz : float
        Cut-off of the parallel low-pass.
    x : numpy.ndarray
        Low-passed position [m].
    v : numpy.ndarray
        Velocity driving the bristles (light filter) [m/s].
    vf, a : numpy.ndarray
        Velocity and acceleration of the low-passed position.
    fm : numpy.ndarray
        Motor force with spikes replaced (unfiltered) [N].
    fm_f : numpy.ndarray
        ``fm`` low-passed.
    dfm : numpy.ndarray
        Time derivative of ``fm_f`` [N/s].
    spikes : numpy.ndarray of bool
        Samples whose force was replaced.
    mask : numpy.ndarray of bool
        Samples used for fitting (filter edges excluded).
    x_raw : numpy.ndarray
        Measured position.
    force_raw : numpy.ndarray
        Motor force as recorded.
    """

    t: np.ndarray
    dt: float
    fs: float
    cutoff_hz: float
    x: np.ndarray
    v: np.ndarray
    vf: np.ndarray
    a: np.ndarray
    fm: np.ndarray
    fm_f: np.ndarray
    dfm: np.ndarray
    spikes: np.ndarray
    mask: np.ndarray
    x_raw: np.ndarray
    force_raw: np.ndarray
    recording: Recording | None = None
    info: dict[str, Any] = field(default_factory=dict)

    def filt(self, y: np.ndarray) -> np.ndarray:
        """Apply the parallel low-pass to a signal or to the columns of a matrix."""
        return lowpass(y, self.cutoff_hz, self.fs)

    def __len__(self) -> int:
        return int(self.t.size)


def check_recording(rec: Recording, model: Model | None = None) -> None:
    """Refuse recordings a diagnosis cannot use, and warn about suspicious units.

    Parameters
    ----------
    rec : Recording
        The recording.
    model : Model, optional
        The model, to compare the position scale against.

    Raises
    ------
    DataError
        Too short, no motion, or no motion in either direction.
    InputError
        No motor force: neither ``i`` nor ``F``.
    """
    if not isinstance(rec, Recording):
        raise InputError.at("recording", f"must be a lugre.Recording, got {type(rec).__name__}")
    n = len(rec)
    if n < MIN_SAMPLES:
        raise DataError(
            f"the recording has {n} samples; a diagnosis needs at least {MIN_SAMPLES} "
            "(a few seconds of motion at 1 kHz): record longer"
        )
    if rec.i is None and rec.F is None:  # pragma: no cover - Recording refuses it
        raise InputError.at("i", "the recording has neither the current i nor the force F")
    dts = np.diff(rec.t)
    if np.max(dts) > 1.5 * np.median(dts) * 1.0001 + 1e-12:
        warnings.warn(
            "the sample interval of the recording varies by more than 50 %; it is "
            "treated as uniform at the median interval",
            UnitsWarning,
            stacklevel=3,
        )
    span = float(np.ptp(rec.x))
    steps = np.abs(np.diff(rec.x))
    q = float(np.min(steps[steps > 0])) if np.any(steps > 0) else 0.0
    if span <= 0.0 or span < 20 * max(q, 1e-12):
        raise DataError(
            "the recording shows no motion (position range "
            f"{span:.3g} m): a diagnosis needs the axis moving, ideally in both directions"
        )
    v = np.diff(rec.x) / np.median(dts)
    vmax = float(np.max(np.abs(v)))
    if vmax > 20.0 or span > 20.0:
        warnings.warn(
            f"the positions span {span:.4g} and the speed reaches {vmax:.4g} per second: "
            "this looks like millimetres, but models are in metres. Convert x to metres "
            "(divide by 1000) before diagnosing.",
            UnitsWarning,
            stacklevel=3,
        )
    if model is not None:
        vs = min(model.positive["vs"], model.negative["vs"])
        if np.percentile(np.abs(v), 90) > 1000 * vs and vmax > 5.0:
            warnings.warn(
                f"speeds reach {vmax:.4g} m/s, over a thousand times the model's Stribeck "
                f"velocity {vs:g} m/s: are the positions in millimetres?",
                UnitsWarning,
                stacklevel=3,
            )
    if not (np.any(v > 0) and np.any(v < 0)):
        raise DataError(
            "the recording moves in one direction only: the diagnosis needs motion in "
            "both directions to separate friction from other forces"
        )


def prepare(
    rec: Recording,
    model: Model,
    *,
    cutoff_hz: float | None = None,
    drive_cutoff_hz: float | None = None,
    t0: float | None = None,
) -> Signals:
    """Filter a recording and take its derivatives for inverse dynamics.

    Parameters
    ----------
    rec : Recording
        The recording (``x`` and ``i`` or ``F``).
    model : Model
        Supplies ``K_F`` when the recording holds the current.
    cutoff_hz : float, optional
        Parallel low-pass cut-off; default ``fs/25`` (40 Hz at 1 kHz).
    drive_cutoff_hz : float, optional
        Low-pass of the velocity that drives the bristles; default ``fs/6``.
    t0 : float, optional
        Time origin for time-dependent effects (drift); default the first sample.

    Returns
    -------
    Signals
    """
    n = len(rec)
    dt = rec.dt
    fs = 1.0 / dt
    fc = float(cutoff_hz) if cutoff_hz is not None else fs / 25.0
    fd = float(drive_cutoff_hz) if drive_cutoff_hz is not None else fs / 6.0
    force_raw = rec.force(model)
    fm, spikes = hampel(force_raw)
    x = lowpass(rec.x, fc, fs)
    vf = np.gradient(x, dt)
    a = np.gradient(vf, dt)
    xd = lowpass(rec.x, fd, fs)
    v = np.gradient(xd, dt)
    # quantised encoders give velocity chatter at rest: zero what is below one count per
    # filter time constant, so that the bristles do not creep at standstill
    steps = np.abs(np.diff(rec.x))
    q = float(np.min(steps[steps > 0])) if np.any(steps > 0) else 0.0
    v = np.where(np.abs(v) < 0.5 * q * fd, 0.0, v)
    fm_f = lowpass(fm, fc, fs)
    dfm = np.gradient(fm_f, dt)
    edge = max(round(3.0 * fs / fc), 5)
    mask = np.ones(n, dtype=bool)
    mask[:edge] = False
    mask[-edge:] = False
    tt = rec.t - (rec.t[0] if t0 is None else t0)
    return Signals(t=tt, dt=dt, fs=fs, cutoff_hz=fc, x=x, v=v, vf=vf, a=a, fm=fm,
                   fm_f=fm_f, dfm=dfm, spikes=spikes, mask=mask, x_raw=rec.x.copy(),
                   force_raw=force_raw, recording=rec,
                   info={"drive_cutoff_hz": fd, "quantum": q, "edge": edge})


# --------------------------------------------------------------------------------------
# Model force
# --------------------------------------------------------------------------------------


def _interp_scale(positions: Any, scale: Any, x: np.ndarray) -> np.ndarray:
    return np.interp(x, np.asarray(positions, float), np.asarray(scale, float))


def friction_scale(model: Model, sig: Signals) -> np.ndarray | None:
    """The product of the ``position_friction`` and ``drift`` scales, or ``None``."""
    s = None
    for e in model.effects:
        k = e["effect"]
        if k == "position_friction":
            f = _interp_scale(e["positions"], e["scale"], sig.x)
        elif k == "drift":
            f = 1.0 - e["gain"] * (1.0 - np.exp(-sig.t / e["time_constant"]))
        else:
            continue
        s = f if s is None else s * f
    return s


def scaled_friction(v: np.ndarray, dt: float, model: Model, scale: np.ndarray) -> np.ndarray:
    """LuGre force with ``g`` multiplied by ``scale[k]`` at each sample (exact update).

    Parameters
    ----------
    v : numpy.ndarray
        Velocity driving the bristles [m/s].
    dt : float
        Sample interval [s].
    model : Model
        Friction parameters.
    scale : numpy.ndarray
        Scale of the Coulomb and static levels, one per sample.

    Returns
    -------
    numpy.ndarray
        Friction force [N].
    """
    f = model.friction
    s0, s1 = float(f["sigma0"]), float(f["sigma1"])
    pos, neg = f["positive"], f["negative"]
    n = v.size
    vp = np.maximum(v, 0.0)
    vn = np.minimum(v, 0.0)
    gp = pos["fc"] + (pos["fs"] - pos["fc"]) * np.exp(-(vp / pos["vs"]) ** 2)
    gn = neg["fc"] + (neg["fs"] - neg["fc"]) * np.exp(-(vn / neg["vs"]) ** 2)
    g = np.where(v >= 0, gp, gn) * scale
    s2 = np.where(v >= 0, pos["sigma2"], neg["sigma2"])
    av = np.abs(v)
    zss = np.sign(v) * g / s0
    dec = np.exp(-s0 * av * dt / g)
    zs = np.empty(n)
    z = 0.0
    zss_l = zss.tolist()
    dec_l = dec.tolist()
    for k in range(n):
        zs[k] = z
        z = zss_l[k] + (z - zss_l[k]) * dec_l[k]
    zdot = v - s0 * av * zs / g
    return s0 * zs + s1 * zdot + s2 * v


def base_friction(model: Model, sig: Signals) -> np.ndarray:
    """Unfiltered LuGre force (with position/drift scales when the model has them)."""
    s = friction_scale(model, sig)
    if s is None:
        return friction_force(sig.v, sig.dt, model)
    return scaled_friction(sig.v, sig.dt, model, s)


def motor_force_effective(model: Model, sig: Signals) -> np.ndarray:
    """The filtered motor force after the ``delay`` and ``current_lag`` effects."""
    f = sig.fm
    changed = False
    for e in model.effects:
        if e["effect"] == "delay" and e["seconds"] > 0:
            f = np.interp(sig.t - e["seconds"], sig.t, f)
            changed = True
        elif e["effect"] == "current_lag":
            c = math.exp(-2.0 * math.pi * e["bandwidth"] * sig.dt)
            f = signal.lfilter([1.0 - c], [1.0, -c], f, zi=[c * f[0]])[0]
            changed = True
    return sig.filt(f) if changed else sig.fm_f


def effect_force(model: Model, sig: Signals) -> np.ndarray:
    """Unfiltered sum of the position forces (cogging, spring, offset)."""
    out = np.zeros(len(sig))
    x = sig.x
    for e in model.effects:
        k = e["effect"]
        if k == "cogging":
            w = 2.0 * math.pi / e["pitch"]
            out += e["amplitude"] * np.sin(w * x + e.get("phase", 0.0))
            for j, (amp, ph) in enumerate(e.get("harmonics", []) or []):
                out += amp * np.sin((j + 2) * w * x + ph)
        elif k == "spring":
            out += e["stiffness"] * (x - e.get("x0", 0.0))
        elif k == "offset":
            out += e["force"]
    return out


def total_mass(model: Model) -> float:
    """Axis mass plus every ``mass`` effect."""
    return model.mass + sum(e["delta"] for e in model.effects if e["effect"] == "mass")


def model_force(model: Model, sig: Signals) -> np.ndarray:
    """Filtered force the model needs besides the motor: ``m*a + F_friction + F_effects``."""
    fr = base_friction(model, sig) + effect_force(model, sig)
    return total_mass(model) * sig.a + sig.filt(fr)


def residual(model: Model, sig: Signals) -> np.ndarray:
    """Force residual ``filt(F_m) - m*a - filt(F_friction + F_effects)`` [N]."""
    return motor_force_effective(model, sig) - model_force(model, sig)


# --------------------------------------------------------------------------------------
# Noise floor
# --------------------------------------------------------------------------------------


def noise_floor(r: np.ndarray, sig: Signals) -> dict[str, float]:
    """Estimate the noise part of a residual from its spectrum.

    Trajectory-locked mismatch lives at the low frequencies of the motion, measurement
    noise (current noise, quantisation) is broadband. The noise density is the median
    periodogram level in the upper part of the pass band (0.5 to 0.9 of the cut-off),
    assumed flat below and shaped by the filter. This gives the noise variance and
    the equivalent number of independent samples ``n_eff`` (coloured, not white).

    Parameters
    ----------
    r : numpy.ndarray
        Residual (filtered).
    sig : Signals
        The prepared recording.

    Returns
    -------
    dict
        ``rms`` [N] (noise floor), ``n_eff``, ``bandwidth_hz`` (equivalent noise band).
    """
    y = r[sig.mask] - np.mean(r[sig.mask])
    n = y.size
    nper = int(min(n, max(256, 2 ** int(np.log2(max(n // 8, 256))))))
    f, p = signal.welch(y, fs=sig.fs, nperseg=nper)
    fc = sig.cutoff_hz
    sos = signal.butter(4, fc / (0.5 * sig.fs), output="sos")
    _, h = signal.sosfreqz(sos, worN=f, fs=sig.fs)
    h2 = np.abs(h) ** 4  # filtfilt: squared magnitude, squared again for power
    band = (f >= 0.5 * fc) & (f <= 0.9 * fc)
    if not np.any(band):  # pragma: no cover - tiny records
        band = f > 0
    level = float(np.median(p[band] / np.maximum(h2[band], 1e-12)))
    df = f[1] - f[0]
    b_eq = float(np.sum(h2) * df)  # one-sided equivalent noise bandwidth [Hz]
    var = level * b_eq
    n_eff = max(min(n * 2.0 * b_eq / sig.fs, float(n)), 10.0)
    return {"rms": math.sqrt(max(var, 1e-30)), "n_eff": n_eff, "bandwidth_hz": b_eq}


def check_units(sig: Signals, model: Model) -> None:
    """Warn when the motion and the model's mass and friction disagree by ~1000x.

    Parameters
    ----------
    sig : Signals
        The prepared recording.
    model : Model
        The model.
    """
    fm = sig.fm_f[sig.mask]
    pred = model_force(model, sig)[sig.mask]
    sf, sp = float(np.std(fm)), float(np.std(pred))
    if sp > 0 and sf > 0 and (sp / sf > 30.0) and np.ptp(sig.x) > 1.0:
        warnings.warn(
            f"the model needs {sp:.3g} N rms where the motor gives {sf:.3g} N: the "
            "positions look like millimetres against a model in metres; convert x to "
            "metres (divide by 1000)",
            UnitsWarning,
            stacklevel=3,
        )


def as_model(m: Any) -> Model:
    """A :class:`~lugre.Model` from a model, dict or path."""
    return _as_model(m)
