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

import functools
import math
import warnings
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from .. import units as U
from ..exceptions import DataError, InputError, UnitsWarning
from ..io import Recording
from ..model import Model, _as_model
from . import dsp

__all__ = [
    "Signals",
    "base_friction",
    "check_recording",
    "deadband",
    "lowpass",
    "model_force",
    "noise_floor",
    "position_sums",
    "prepare",
    "residual",
]

#: Fewest samples a diagnosis accepts.
MIN_SAMPLES = 400

#: Odd-extension length of the zero-phase low-pass at each end [samples].
_PADLEN = 3 * 24


def lowpass(y: np.ndarray, cutoff_hz: float, fs: float, order: int = 4, *,
            backend: Any = "core") -> np.ndarray:
    """Zero-phase Butterworth low-pass (SciPy's ``sosfiltfilt``, in the kernels of
    ``backend``: :func:`kernels`) along the first axis.

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
    backend : "core" or module, default "core"
        The kernels that run the filter (:func:`kernels`).

    Returns
    -------
    numpy.ndarray
    """
    wn = cutoff_hz / (0.5 * fs)
    if wn >= 0.99:
        return np.array(y, dtype=float, copy=True)
    y = np.asarray(y, dtype=float)
    sos, padlen = _butter(order, wn), min(_PADLEN, len(y) - 1)
    run = kernels(backend).filtfilt
    if y.ndim == 1:
        return run(y, sos, padlen)
    out = np.empty(y.shape)
    for j in np.ndindex(y.shape[1:]):
        out[(slice(None), *j)] = run(np.ascontiguousarray(y[(slice(None), *j)]), sos, padlen)
    return out


@functools.lru_cache(maxsize=16)
def _butter(order: int, wn: float) -> np.ndarray:
    sos = dsp.butter_sos(order, wn)
    sos.setflags(write=False)  # (shared by the cache)
    return sos


def hampel(y: np.ndarray, half_window: int = 5, k: float = 5.0, *, backend: Any = "core"
           ) -> tuple[np.ndarray, np.ndarray]:
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
    backend : "core" or module, default "core"
        The kernels that take the moving median (:func:`kernels`).

    Returns
    -------
    cleaned : numpy.ndarray
    spikes : numpy.ndarray of bool
        Where a sample was replaced.
    """
    med = kernels(backend).moving_median(np.asarray(y, dtype=float), 2 * half_window + 1)
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


@dataclass(frozen=True)
class Signals:
    """A recording prepared for inverse dynamics (all arrays of one length: the
    recording's, or a step-th of it for a record sampled far faster than its band,
    ``info["decimation"]``).

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
    kernel : InverseRecord of the kernels
        The inverse-dynamics kernel over these signals (residual, model force,
        sensitivities, the parallel low-pass).
    backend : module
        The kernels the signals were prepared with (:func:`kernels`): where the
        diagnosis takes its other numerics (simulation, periodogram, robust fits) from.
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
    kernel: Any = None
    backend: Any = None

    @property
    def rows_step(self) -> int:
        """Every how many samples the held-out scores read the filtered signals.

        Everything they score is low-passed at ``cutoff_hz``, so a product of two
        columns has no content above ``2*cutoff_hz``; read at ``fs/step >= 5*cutoff_hz``,
        the sums of products over every ``step``-th sample are ``1/step`` of the full
        sums to well under a part in a thousand (what the filter passes at 2.5 times its
        cut-off), at a ``step``-th of the work and memory.
        """
        return max(1, int(self.fs / (5.0 * self.cutoff_hz)))

    def filt(self, y: np.ndarray) -> np.ndarray:
        """Apply the parallel low-pass to a signal or to the columns of a matrix."""
        y = np.asarray(y, dtype=float)
        if y.ndim == 1:
            return self.kernel.filt(y)
        return self.kernel.filt_columns(y)

    def __len__(self) -> int:
        return int(self.t.size)

    def with_drive(self, v: np.ndarray) -> Signals:
        """A copy whose bristles are driven by the velocity ``v``."""
        return self._rebuilt(v=np.ascontiguousarray(v, dtype=float))

    def with_force(self, f: np.ndarray) -> Signals:
        """A copy whose motor force is ``f`` (taken as low-passed already), the rest of
        the record as it is."""
        f = np.ascontiguousarray(f, dtype=float)
        return self._rebuilt(fm=f, fm_f=f)

    def _rebuilt(self, **arrays: np.ndarray) -> Signals:
        """A copy with ``arrays`` replaced and its kernel rebuilt (the signals are
        frozen, the kernel holds its own copy of them)."""
        new = replace(self, **arrays)
        sos, padlen = self.info["filter"]
        kernel = type(self.kernel)(new.t, new.x, new.info["x_drive"], new.v, new.a, new.fm,
                                   new.fm_f, new.dt, sos, padlen)
        return replace(new, kernel=kernel)


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
    from ..checks import require_plausible

    # gaps in the sampling, positions in the wrong unit (radians on a rotary axis)
    require_plausible(rec, "rotary" if U.is_rotary() else None)
    med = float(np.median(np.diff(rec.t)))
    span = float(np.ptp(rec.x))
    steps = np.abs(np.diff(rec.x))
    q = float(np.min(steps[steps > 0])) if np.any(steps > 0) else 0.0
    if span <= 0.0 or span < 20 * max(q, 1e-12):
        raise DataError(
            "the recording shows no motion (position range "
            f"{span:.3g} {U.si('m')}): a diagnosis needs the axis moving, ideally in both "
            "directions"
        )
    v = np.diff(rec.x) / med
    vmax = float(np.max(np.abs(v)))
    if model is not None:
        vs = min(model.positive["vs"], model.negative["vs"])
        if np.percentile(np.abs(v), 90) > 1000 * vs and vmax > 5.0:
            v_u = U.si("m/s")
            warnings.warn(
                f"speeds reach {vmax:.4g} {v_u}, over a thousand times the model's Stribeck "
                f"velocity {vs:g} {v_u}: are the positions in "
                f"{'radians' if U.is_rotary() else 'millimetres'}?",
                UnitsWarning,
                stacklevel=3,
            )
    _require_both_directions(rec, med)


#: Least share of the moving samples, and least count, that each direction must have.
MIN_DIRECTION_SHARE = 0.02
MIN_DIRECTION_SAMPLES = 50


def _require_both_directions(rec: Recording, dt: float) -> None:
    """Refuse a record that slides in one direction only (or nearly): friction is
    identified per direction, and a direction seen in a few jittery samples gives
    levels of any size. Sliding is read on the position's change over ten samples,
    beyond a twentieth of the largest speed."""
    k = min(10, max(1, len(rec) // 100))
    v = (rec.x[k:] - rec.x[:-k]) / (k * dt)
    moving = np.abs(v) > 0.05 * float(np.max(np.abs(v)))
    pos, neg = int(np.sum(moving & (v > 0))), int(np.sum(moving & (v < 0)))
    few = min(pos, neg)
    if few >= max(MIN_DIRECTION_SAMPLES, MIN_DIRECTION_SHARE * (pos + neg)):
        return
    side, other = ("negative", "positive") if neg < pos else ("positive", "negative")
    raise DataError(
        f"the recording moves in one direction only: {few} of its {pos + neg} moving "
        f"samples go the {side} way (at least {MIN_DIRECTION_SAMPLES} and "
        f"{100 * MIN_DIRECTION_SHARE:.0f} % are needed). Friction is identified per "
        f"direction, so the {side} direction's levels cannot be read from it: record a "
        f"move back as well (a reversal at the same speeds), or fit the {other} "
        "direction from a record that holds both"
    )


def command_hold(model: Model, dt: float | None = None) -> float:
    """Mean delay [s] of the force behind a logged current command that the model's
    controller holds between its updates (zero-order hold).

    The simulation holds each command until the next update, so the force follows a
    command logged at the update instants by half a controller period; the diagnosis
    reads the record the same way (:func:`prepare`), so that a ``delay`` it finds is
    what the drive adds beyond the hold, as the simulation needs it. A record logged at
    a rate that is not a whole fraction of the controller's catches the commands at
    ``q`` phases of the period (the log interval over the controller's, ``p/q`` in
    lowest terms), some of them late, and the mean hold is ``period/(2*q)``: a quarter
    period for a 5 kHz controller logged at 2 kHz. Zero without a controller (nothing
    known of a hold: a timing finding then includes it) or with a current loop (the
    logged current is then the measured one).

    Parameters
    ----------
    model : Model
        The model (its controller's rate).
    dt : float, optional
        The record's sample interval [s]; default: logged at the update instants.
    """
    c = model.controller
    if c is None or model.to_dict()["axis"].get("current_loop") is not None:
        return 0.0
    period = 1.0 / float(c["rate_hz"])
    q = 1
    if dt is not None and dt > 0:
        from fractions import Fraction

        q = Fraction(float(dt) / period).limit_denominator(1000).denominator
    return 0.5 * period / q


def prepare(
    rec: Recording,
    model: Model,
    *,
    cutoff_hz: float | None = None,
    drive_cutoff_hz: float | None = None,
    t0: float | None = None,
    backend: Any = "core",
) -> Signals:
    """Filter a recording and take its derivatives for inverse dynamics.

    Parameters
    ----------
    rec : Recording
        The recording (``x`` and ``i`` or ``F``).
    model : Model
        Supplies ``K_F`` when the recording holds the current.
    cutoff_hz : float, optional
        Parallel low-pass cut-off; default ``fs/25`` (40 Hz at 1 kHz), lowered to
        where the position reading's noise would dominate (:func:`reading_band`; not
        under 10 Hz).
    drive_cutoff_hz : float, optional
        Low-pass of the velocity that drives the bristles; default ``fs/6``.
    t0 : float, optional
        Time origin for time-dependent effects (drift); default the first sample.
    backend : "core" or module, default "core"
        The kernels (:func:`kernels`): ``"core"`` for the compiled ones of
        :mod:`lugre._native`, or a module offering the same names, such as the NumPy
        twins of :mod:`lugre.reference.kernels` (same results, for checking).

    Returns
    -------
    Signals
    """
    dt = rec.dt
    fs = 1.0 / dt
    force_raw = rec.force(model)
    fm, spikes = hampel(force_raw, backend=backend)
    # the noise levels are read from the force as logged: the interpolation that
    # moves it by the controller's hold would smooth its noise near Nyquist
    limit = reading_band(rec.x, fm, fs, float(model.mass))
    fm_logged = fm
    hold = command_hold(model, dt)
    if hold > 0.0:  # the force the held commands give, at the sample instants
        fm = np.interp(rec.t - hold, rec.t, fm)
    if cutoff_hz is not None:
        fc = float(cutoff_hz)
    else:
        fc = fs / 25.0 if limit is None else min(fs / 25.0, max(limit, 10.0))
    # a record sampled far faster than its band is read at about 25 cut-offs (the rate
    # the diagnosis is built for): the force averaged over each window, the position
    # sampled at its centre. Nothing in the band is lost; the work is a step-th.
    xr, tr, step = rec.x, rec.t, decimation(fs, fc)
    q = _quantum(rec.x)
    if step > 1:
        m = len(rec) // step  # whole windows only
        centre = np.arange(m) * step + step // 2
        def window_mean(y: np.ndarray) -> np.ndarray:
            c = np.cumsum(np.concatenate([[0.0], np.asarray(y, float)]))
            return (c[centre + step // 2] - c[centre - step // 2]) / step

        # (the position averaged too: sampled, its reading noise would fold into the
        # band; averaged, the motion in the band changes by (pi*f*step*dt)^2/6, 2e-3
        # at 62 Hz and 10 kHz)
        fm, xr = window_mean(fm), window_mean(rec.x)
        fm_logged = window_mean(fm_logged) if hold > 0.0 else fm
        spikes = np.add.reduceat(spikes.astype(int), centre - step // 2)[:m] > 0
        force_raw = force_raw[centre]
        tr = rec.t[centre] - 0.5 * rec.dt  # the windows' centres
        dt, fs = dt * step, fs / step
    n = xr.size
    fd = float(drive_cutoff_hz) if drive_cutoff_hz is not None else fs / 6.0
    mod = kernels(backend)
    x = lowpass(xr, fc, fs, backend=mod)
    vf = np.gradient(x, dt)
    a = np.gradient(vf, dt)
    xd = lowpass(xr, fd, fs, backend=mod)
    v = np.gradient(xd, dt)
    # quantised encoders give velocity chatter at rest: zero what is below one count per
    # filter time constant, so that the bristles do not creep at standstill
    v = np.where(np.abs(v) < 0.5 * q * fd, 0.0, v)
    fm_f = lowpass(fm, fc, fs, backend=mod)
    dfm = np.gradient(fm_f, dt)
    edge = max(round(3.0 * fs / fc), 5)
    mask = np.ones(n, dtype=bool)
    mask[:edge] = False
    mask[-edge:] = False
    tt = tr - (rec.t[0] if t0 is None else t0)
    wn = fc / (0.5 * fs)
    sos = _butter(4, wn) if wn < 0.99 else None
    x, xd, v, a, fm, fm_f = (np.ascontiguousarray(u, dtype=float) for u in (x, xd, v, a, fm, fm_f))
    tt = np.ascontiguousarray(tt, dtype=float)
    padlen = min(_PADLEN, n - 1)
    kernel = mod.InverseRecord(tt, x, xd, v, a, fm, fm_f, dt, sos, padlen)
    return Signals(t=tt, dt=dt, fs=fs, cutoff_hz=fc, x=x, v=v, vf=vf, a=a, fm=fm,
                   fm_f=fm_f, dfm=dfm, spikes=spikes, mask=mask, x_raw=np.array(xr, float),
                   force_raw=force_raw, recording=rec,
                   info={"drive_cutoff_hz": fd, "quantum": q, "edge": edge, "x_drive": xd,
                         "filter": (sos, padlen), "reading_band_hz": limit,
                         "decimation": step, "dt_logged": rec.dt, "hold_s": hold,
                         "fm_logged": np.asarray(fm_logged, float),
                         "cutoff_default": cutoff_hz is None},
                   kernel=kernel, backend=mod)


# --------------------------------------------------------------------------------------
# Model force: the inverse-dynamics kernel (``_core.InverseRecord``, or its NumPy twin
# ``lugre.reference.InverseRecord``) built once per prepared recording
# --------------------------------------------------------------------------------------


def base_friction(model: Model, sig: Signals) -> np.ndarray:
    """Unfiltered LuGre force at the sample instants (with position/drift scales and the
    Stribeck exponent when the model has them).

    The bristles are advanced over each sample interval with the velocity at its middle
    (the mean of the two samples), so that ``z[k]`` is the state at ``t_k``: advanced
    with ``v[k-1]`` held it would trail the samples by half an interval, a force error
    of ``sigma0*v*dt/2`` in presliding that reads as extra damping.
    """
    return sig.kernel.base_friction(model)


def deadband(f: np.ndarray, band: float) -> np.ndarray:
    """``sign(f)*max(|f| - band, 0)`` (a dead-band in force units)."""
    return np.sign(f) * np.maximum(np.abs(f) - band, 0.0)


def model_force(model: Model, sig: Signals) -> np.ndarray:
    """Filtered force the model needs besides the motor: ``m*a + F_friction + F_effects``.

    With a ``resonance`` the encoder sees the motor, ``(1 - r)*m``, and the load ``r*m``
    carries the friction and the effect forces behind a spring-damper: the motor gives
    ``(1 - r)*m*a + F_s``, ``F_s`` the force the coupling passes to the load, simulated
    along the measured motor motion (``lugre.load_coupling``, twice its automatic substeps).
    """
    return sig.kernel.model_force(model)


def residual(model: Model, sig: Signals) -> np.ndarray:
    """Force residual ``filt(F_m') - m*a - filt(F_friction + F_effects)`` [N], ``F_m'``
    the motor force after the model's ``delay``, ``deadband`` and ``current_lag``."""
    return sig.kernel.residual(model)


# --------------------------------------------------------------------------------------
# Noise floor
# --------------------------------------------------------------------------------------


def noise_floor(r: np.ndarray, sig: Signals) -> dict[str, float]:
    """Estimate the noise part of a residual from its spectrum.

    Trajectory-locked mismatch lives at the low frequencies of the motion, measurement
    noise (current noise, quantisation) is broadband. The noise density is a low
    quantile (30 %) of the Welch periodogram over 0.25 to 0.9 of the cut-off, corrected
    for the quantile of the chi-square spread of the periodogram, assumed flat below and
    shaped by the filter: narrow peaks of position-locked forces (a screw's ripple
    crossed at the record's speeds) and harmonics of repeated laps do not raise it, as
    they would a median or a mean. This gives the noise variance and the equivalent
    number of independent samples ``n_eff`` (coloured, not white).

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
    f, p = dsp.welch(y, sig.fs, nper)
    fc = sig.cutoff_hz
    sos = _butter(4, fc / (0.5 * sig.fs))
    h = dsp.sosfreqz(sos, f, sig.fs)
    h2 = np.abs(h) ** 4  # filtfilt: squared magnitude, squared again for power
    sel = (f >= 0.25 * fc) & (f <= 0.9 * fc)
    if np.sum(sel) < 4:  # pragma: no cover - tiny records
        sel = f > 0
    # the noise's shape: the force reading's white noise plus the position reading's,
    # twice differentiated (density growing as f^4), equal at f_eq
    # (taken where the band was set by the reading's noise; below that band the
    # flat density is kept: the acceptance thresholds were calibrated with it on the
    # clean records, and a shaped floor there is a 5 % lower variance unit)
    band = sig.info.get("reading_band_hz")
    f_eq = _equal_noise_hz(band) if band is not None and fc >= 0.99 * band else None
    shape = np.ones_like(f) if f_eq is None else 1.0 + (f / f_eq) ** 4
    g = h2 * shape
    segs = max(1, 2 * n // nper - 1)  # Hann, half overlap
    dof = 2.0 * segs * 0.9
    q = 0.3
    level = float(np.quantile(p[sel] / np.maximum(g[sel], 1e-12), q)
                  / (dsp.chi2_ppf(q, dof) / dof))
    df = f[1] - f[0]
    b_eq = float(np.sum(h2) * df)  # one-sided equivalent noise bandwidth [Hz]
    var = level * float(np.sum(g) * df)
    if f_eq is not None:  # a coloured noise has fewer independent samples: the band
        # (sum g)^2/sum g^2, relative to the same for the filter alone
        b_eq *= (float(np.sum(g)) ** 2 / float(np.sum(g * g))) / (
            float(np.sum(h2)) ** 2 / float(np.sum(h2 * h2)))
    n_eff = max(min(n * 2.0 * b_eq / sig.fs, float(n)), 10.0)
    return {"rms": math.sqrt(max(var, 1e-30)), "n_eff": n_eff, "bandwidth_hz": b_eq}


#: The position reading's noise, twice differentiated and times the mass, may reach
#: this multiple of the force reading's noise within the residual's band. Equal, not
#: twice: a quantised reading's error is white only while the axis moves fast; near
#: the reversals it sweeps through the band as a chirp (one count per v/q), more than
#: its level above the band foretells. At twice, the exact truth model of a clean
#: 6.7 kg axis logged at 2.5 and 5 kHz (1 um encoder) was given a damped 38 Hz
#: resonance: a compliant load smooths the acceleration, and with it that noise.
READING_NOISE_RATIO = 1.0


def reading_band(x: np.ndarray, fm: np.ndarray, fs: float, mass: float) -> float | None:
    """Highest cut-off [Hz] at which the position reading still does not dominate the
    residual's noise, or None when the record does not tell.

    The inverse dynamics takes the acceleration from the position twice differentiated:
    a reading noise of density ``sx`` (quantisation ``q^2/12`` or more, see
    :func:`expected_floor`) gives a force noise of density ``m^2 (2 pi f)^4 sx``, whose
    power up to ``fc`` grows as ``fc^5`` while the force reading's white noise (density
    ``sf``) grows as ``fc``. They are equal at ``fc = (5 sf/(m^2 sx))^(1/4)/(2 pi)``;
    the band ends where the first is :data:`READING_NOISE_RATIO` times the second. This
    does not depend on the sample rate: at 1 kHz the usual ``fs/25`` is within it; at
    10 kHz ``fs/25`` (400 Hz) would put a hundred times the acceleration noise into the
    residual, which any term that smooths the acceleration (a compliant load) then
    "explains".
    """
    x = np.asarray(x, float)
    fm = np.asarray(fm, float)
    if x.size < 258:
        return None
    level, _q, sq, read = reading_noises(x, fm, fs)
    sx = max(sq, read or 0.0)
    if level is None or not level > 0 or not sx > 0 or not mass > 0:
        return None
    if level * 0.5 * fs < (1e-6 * float(np.std(fm))) ** 2:
        return None  # a force without noise (a simulation): nothing to balance against
    ratio2 = READING_NOISE_RATIO ** 2
    return float((5.0 * ratio2 * level / (mass * mass * sx)) ** 0.25 / (2.0 * np.pi))


def reading_noises(x: np.ndarray, fm: np.ndarray, fs: float
                   ) -> tuple[float | None, float, float, float | None]:
    """The readings' white noise levels as the band and the checks read them: the
    force's one-sided density above the motion's band (:func:`hf_level`), the position's
    resolution ``q`` (smallest step), the density ``q^2/12/(fs/2)`` of its quantisation,
    and the density its second difference shows above the band (None where a level
    cannot be read: under 256 samples)."""
    x = np.asarray(x, float)
    level = hf_level(np.asarray(fm, float), fs)
    q = _quantum(x)
    sq = q * q / 12.0 / (0.5 * fs)
    read = hf_level(np.diff(x, 2), fs, lambda f: (2.0 - 2.0 * np.cos(2.0 * np.pi * f / fs)) ** 2)
    return level, q, sq, read


def decimation(fs: float, cutoff_hz: float) -> int:
    """Samples averaged into one for a record sampled at ``fs`` with the residual's band
    ``cutoff_hz``: even, so that the window is centred on its sample, and leaving at
    least 25 samples per cut-off period (1 at 1 kHz with the default 40 Hz)."""
    return max(1, 2 * int(fs / (50.0 * cutoff_hz)))


def _quantum(x: np.ndarray) -> float:
    """Smallest position step of a reading [m] (its resolution), 0 if it never moves."""
    steps = np.abs(np.diff(np.asarray(x, float)))
    return float(np.min(steps[steps > 0])) if np.any(steps > 0) else 0.0


def _equal_noise_hz(band_hz: float | None) -> float | None:
    """Frequency where the reading's differentiated noise density equals the force
    reading's (from :func:`reading_band`'s cut-off)."""
    if band_hz is None:
        return None
    return band_hz / (5.0 * READING_NOISE_RATIO ** 2) ** 0.25


def hf_level(y: np.ndarray, fs: float, gain: Any = None) -> float | None:
    """One-sided density of the white noise in ``y`` (divided by ``gain(f)``, the power
    gain it went through, when given), from the median of its Welch spectrum between
    0.5 and 0.9 of the Nyquist frequency, above the motion's band, corrected for the
    chi-square spread of the estimate; None for under 256 samples or too few bins."""
    if y.size < 256:
        return None
    nper = int(min(1024, y.size))
    f, p = dsp.welch(y - np.mean(y), fs, nper)
    band = (f > 0.25 * fs) & (f < 0.45 * fs)
    if np.sum(band) < 3:
        return None
    dof = 2.0 * max(1, 2 * y.size // nper - 1) * 0.9
    pb = p[band] if gain is None else p[band] / gain(f[band])
    return float(np.median(pb) / (dsp.chi2_ppf(0.5, dof) / dof))


def force_noise_power(sig: Signals, weight: Any) -> float:
    """Mean square per sample [N^2] of the recorded force's measurement noise after the
    residual's low-pass and a further power gain ``weight(f)``: the white level above
    the motion's band (:func:`hf_level`) through both; 0 when the level cannot be
    read."""
    level = hf_level(sig.info.get("fm_logged", sig.fm)[sig.mask], sig.fs)
    if level is None:
        return 0.0
    ff, f2 = filter_power(sig)
    w = f2 * weight(ff)
    return float(level * np.sum(0.5 * (w[1:] + w[:-1])) * (ff[1] - ff[0]))


def filter_power(sig: Signals) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies 0 to Nyquist (4001 points) and the power gain of the residual's
    zero-phase low-pass there (``|H|^4``: squared magnitude, applied twice)."""
    ff = np.linspace(0.0, 0.5 * sig.fs, 4001)
    h = dsp.sosfreqz(_butter(4, sig.cutoff_hz / (0.5 * sig.fs)), ff, sig.fs)
    return ff, np.abs(h) ** 4


def expected_floor(sig: Signals, model: Model) -> dict[str, float]:
    """The noise floor the measurements alone would give: the recorded current's noise
    and the encoder's resolution, through the residual's filter.

    The current's noise is taken white at the level of the motor force's spectrum
    between 0.5 and 0.9 of the Nyquist frequency (median over the band, corrected for
    the chi-square spread of the Welch estimate); the position reading's noise white at
    the larger of its quantisation (``q^2/12``) and the level of its second difference's
    spectrum in the same band (a reading noisier than its resolution), twice
    differentiated and times the mass. On clean records this matches
    :func:`noise_floor` to 10 %; a floor several times larger holds mismatch spread
    over the band (EMPS: the reading's noise is 1.16 times its quantisation, the floor
    26 times the expected).

    Returns
    -------
    dict
        ``rms`` [N], and its parts ``current`` and ``encoder`` [N].
    """
    ff, f2 = filter_power(sig)
    df = ff[1] - ff[0]
    level = hf_level(sig.info.get("fm_logged", sig.fm)[sig.mask], sig.fs)
    vi = 0.0 if level is None else level * float(np.sum(f2)) * df
    q = float(sig.info.get("quantum", 0.0))
    # one-sided density of the reading's noise (at the logged rate: a record read at a
    # step-th of it averages its windows, which keeps the density in the band)
    sx = q * q / 12.0 / (0.5 / float(sig.info.get("dt_logged", sig.dt)))
    xr = np.asarray(sig.x_raw, float)[sig.mask]
    if xr.size >= 258:
        # the second difference of white noise of density sx: (2 - 2 cos w)^2 * sx
        read = hf_level(np.diff(xr, 2), sig.fs,
                        lambda f: (2.0 - 2.0 * np.cos(2.0 * np.pi * f / sig.fs)) ** 2)
        sx = sx if read is None else max(sx, read)
    pa = (2.0 * np.pi * ff) ** 4 * sx
    va = float(model.mass) ** 2 * float(np.sum(pa * f2)) * df
    return {"rms": math.sqrt(vi + va), "current": math.sqrt(vi), "encoder": math.sqrt(va)}


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
            f"the model needs {sp:.3g} {U.si('N')} rms where the motor gives {sf:.3g} "
            f"{U.si('N')}: the positions look like "
            + ("degrees against a model in radians; convert x to radians (--x-unit deg)"
               if U.is_rotary() else "millimetres against a model in metres; convert x to "
               "metres (divide by 1000)"),
            UnitsWarning,
            stacklevel=3,
        )


def as_model(m: Any) -> Model:
    """A :class:`~lugre.Model` from a model, dict or path."""
    return _as_model(m)


def position_sums(sig: Signals, x: np.ndarray, r: np.ndarray, k0: float, dk: float, n: int,
                  squares: bool = False) -> tuple[np.ndarray, ...]:
    """Sums of ``r`` against ``sin`` and ``cos`` of ``2*pi*k_j*x``, ``k_j = k0 + j*dk``
    (``j < n``), on the kernels of ``sig`` (:func:`lugre._native.position_sums` or its
    NumPy twin): ``(S, C)``, with ``squares`` ``(S, C, SS, CC, SC)``."""
    return tuple(kernels(sig.backend).position_sums(x, r, k0, dk, n, squares=squares))


def kernels(backend: Any = "core") -> Any:
    """The numeric kernels the diagnosis calls: ``"core"`` (or ``None``) for
    :mod:`lugre._native`, the compiled core; any other object is taken as the kernels
    themselves, a module or object offering ``InverseRecord``, ``simulate``,
    ``position_sums`` and ``irls_linear_grid`` with :mod:`lugre._native`'s signatures
    (the NumPy twins: :mod:`lugre.reference.kernels`)."""
    if backend is None or (isinstance(backend, str) and backend == "core"):
        from .. import _native

        return _native
    if isinstance(backend, str) or not hasattr(backend, "InverseRecord"):
        raise InputError.at("backend", f"unknown backend {backend!r}: use \"core\" or give "
                            "the kernels (a module such as lugre.reference.kernels)")
    return backend
