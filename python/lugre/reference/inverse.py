"""NumPy twin of the inverse-dynamics kernel (``src/inverse``): :class:`InverseRecord`.

The same steps as the core, in the same order (``docs/DESIGN.md``, "Inverse
dynamics"): the zero-phase low-pass by second-order sections with odd extension, the
friction scales, the bristles advanced with the mid-interval velocity, the effect forces,
the load behind a ``resonance``, the motor force after delay, dead-band, current limit,
current lag and force ripple (and the friction levels it raises under a
``load_friction``), and the exact sensitivities of the LuGre force to its parameters. Exported as
``lugre.reference.InverseRecord``; the diagnosis runs on either.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._args import as_array as _array
from .._args import frequency_count
from ..exceptions import InputError, ParameterError, _fmt_f64
from ..model import ModelLike, _as_model
from ..vocabulary import (
    COGGING,
    CURRENT_LAG,
    CURRENT_LIMIT,
    DEADBAND,
    DELAY,
    DRAG,
    DRIFT,
    FORCE_RIPPLE,
    GRAVITY,
    LOAD_FRICTION,
    OFFSET,
    POSITION_FRICTION,
    RESONANCE,
    SPRING,
    STRIBECK_SHAPE,
)

__all__ = ["COUPLING_SUBSTEPS", "InverseRecord", "filtfilt", "moving_median",
           "parse_base_param",
           "position_sums"]

#: Substeps multiplier of the load simulation behind a ``resonance``
#: (``COUPLING_SUBSTEPS`` in src/inverse/mod.rs).
COUPLING_SUBSTEPS = 2

_SIDES = ("positive", "negative")
_KEYS = ("fc", "fs", "sigma2", "vs")


def parse_base_param(name: str) -> tuple[str, str]:
    """``(side, key)`` of a friction parameter path (side ``""`` for sigma0/sigma1)."""
    if name in ("sigma0", "sigma1"):
        return "", name
    side, _, key = name.partition(".")
    if side not in _SIDES or key not in _KEYS:
        raise InputError.at(
            "names",
            f"unknown friction parameter {name!r}: use sigma0, sigma1 or "
            "positive/negative.fc, .fs, .sigma2, .vs",
        )
    return side, key


def _vec(name: str, a: Any) -> np.ndarray:
    try:
        arr = np.array(a, dtype=float)
    except (TypeError, ValueError) as e:
        raise InputError.at(name, f"must be an array of numbers ({e})") from None
    if arr.ndim != 1:
        raise InputError.at(name, "must be a contiguous 1-D float64 array")
    return arr


def _interp(x: np.ndarray, xp: Any, fp: Any) -> np.ndarray:
    """``numpy.interp`` written out as the core does it (knots exact)."""
    xp = [float(u) for u in xp]
    fp = [float(u) for u in fp]
    m = len(xp)
    out = np.empty(x.size)
    for k, xv in enumerate(x.tolist()):
        if xv < xp[0]:
            out[k] = fp[0]
        elif xv >= xp[m - 1]:
            out[k] = fp[m - 1]
        else:
            lo, hi = 0, m
            while lo < hi:  # partition point of xp <= xv
                mid = (lo + hi) // 2
                if xp[mid] <= xv:
                    lo = mid + 1
                else:
                    hi = mid
            j = lo - 1
            if xp[j] == xv:
                out[k] = fp[j]
            else:
                slope = (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j])
                out[k] = slope * (xv - xp[j]) + fp[j]
    return out


def _midpoints(a: np.ndarray) -> np.ndarray:
    h = np.empty_like(a)
    h[:-1] = 0.5 * (a[:-1] + a[1:])
    h[-1] = a[-1]
    return h


#: Samples of a pass between two flushes of the sections' states, and the magnitude under
#: which a state is set to zero (src/inverse/filter.rs, FLUSH_EVERY and FLUSH).
_FLUSH_EVERY = 32
_FLUSH = 1e-270


class _Lowpass:
    """Second-order sections forward and backward, odd extension (SciPy's
    ``sosfiltfilt(padtype="odd")``)."""

    def __init__(self, sos: Any, padlen: int) -> None:
        self.sections: list[tuple[float, ...]] = []
        self.zi: list[tuple[float, float]] = []
        self.padlen = int(padlen)
        if sos is None:
            return
        s = np.asarray(sos, dtype=float)
        if s.ndim != 2 or s.shape[1] != 6:
            raise InputError.at("sos", f"has {s.shape[-1] if s.ndim else 0} columns: give one "
                                "row [b0, b1, b2, 1, a1, a2] per section")
        scale = 1.0
        for k, row in enumerate(s.tolist()):
            if not all(math.isfinite(c) for c in row):
                raise InputError.at("sos", f"section {k} has a non-finite coefficient")
            if row[3] != 1.0:
                raise InputError.at("sos", f"section {k} has a0 = {row[3]}: normalise the "
                                    "sections to a0 = 1")
            b0, b1, b2, _, a1, a2 = row
            den = 1.0 + a1 + a2
            if den == 0.0:
                raise InputError.at("sos", f"section {k} has a pole at z = 1: it is not a "
                                    "low-pass")
            c0, c1 = b1 - a1 * b0, b2 - a2 * b0
            z0 = (c0 + c1) / den
            z1 = c1 - a2 * z0
            self.zi.append((scale * z0, scale * z1))
            self.sections.append(tuple(row))
            scale *= (b0 + b1 + b2) / den

    def _run(self, y: list[float], x0: float) -> None:
        st = [[z0 * x0, z1 * x0] for z0, z1 in self.zi]
        secs = list(zip(self.sections, st))
        for k in range(len(y)):
            x = y[k]
            for c, s in secs:
                out = c[0] * x + s[0]
                s[0] = c[1] * x - c[4] * out + s[1]
                s[1] = c[2] * x - c[5] * out
                x = out
            y[k] = x
            if (k + 1) % _FLUSH_EVERY == 0:
                for s in st:  # states decaying towards the subnormal numbers: zero
                    s[:] = [0.0 if abs(v) < _FLUSH else v for v in s]

    def filtfilt(self, y: np.ndarray) -> np.ndarray:
        n = y.size
        if not self.sections or n == 0:
            return np.array(y, dtype=float)
        edge = min(self.padlen, n - 1)
        yl = y.tolist()
        first, last = yl[0], yl[-1]
        ext = ([2.0 * first - yl[k] for k in range(edge, 0, -1)] + yl
               + [2.0 * last - yl[n - 1 - k] for k in range(1, edge + 1)])
        self._run(ext, ext[0])
        ext.reverse()
        self._run(ext, ext[0])
        ext.reverse()
        return np.array(ext[edge:edge + n])


def filtfilt(y: Any, sos: Any, padlen: int) -> np.ndarray:
    """``y`` through the sections ``sos`` forward and backward, odd extension of
    ``min(padlen, len(y) - 1)`` samples (the low-pass of :meth:`InverseRecord.filt`):
    the twin of :func:`lugre._native.filtfilt`."""
    yy = _vec("y", y)
    s = np.asarray(sos, dtype=float)
    if s.ndim != 2:
        raise InputError.at("sos", "must be a matrix with one row [b0, b1, b2, 1, a1, a2] "
                            "per section")
    return _Lowpass(s, int(padlen)).filtfilt(yy)


def moving_median(y: Any, size: int) -> np.ndarray:
    """The moving median of ``y`` over ``size`` samples centred on each (the element of
    rank ``size // 2`` of the window), the ends extended by their edge values: the twin
    of :func:`lugre._native.moving_median`."""
    yy = _vec("y", y)
    size = int(size)
    if yy.size == 0 or size <= 1:
        return yy.copy()
    half = size // 2
    ext = np.concatenate((np.full(half, yy[0]), yy, np.full(size - 1 - half, yy[-1])))
    win = np.lib.stride_tricks.sliding_window_view(ext, size)
    return np.partition(win, half, axis=-1)[:, half].copy()


class InverseRecord:
    """A recording prepared for inverse dynamics (NumPy twin of ``_core.InverseRecord``).

    Parameters
    ----------
    t, x, x_drive, v, a, fm, fm_f : array_like
        Time from the origin of time-dependent effects [s], low-passed position [m],
        lightly filtered position and the velocity that drives the bristles, the
        acceleration of ``x``, the motor force [N] and its low-passed copy.
    dt : float
        Sample interval [s].
    sos : array_like, optional
        Sections ``[b0, b1, b2, 1, a1, a2]`` of the parallel low-pass (None: no filter).
    padlen : int, default 0
        Odd-extension length at each end (capped at ``len - 1``).
    """

    def __init__(self, t: Any, x: Any, x_drive: Any, v: Any, a: Any, fm: Any, fm_f: Any,
                 dt: float, sos: Any = None, padlen: int = 0) -> None:
        self._filter = _Lowpass(sos, padlen)
        arrays = {"t": t, "x": x, "x_drive": x_drive, "v": v, "a": a, "fm": fm, "fm_f": fm_f}
        vals = {k: _vec(k, a_) for k, a_ in arrays.items()}
        n = vals["t"].size
        if n < 2:
            raise InputError.at("t", "needs at least two samples")
        for k, arr in vals.items():
            if arr.size != n:
                raise InputError.at(k, f"has {arr.size} samples but t has {n}: give arrays "
                                    "of the same length")
            bad = np.flatnonzero(~np.isfinite(arr))
            if bad.size:
                raise InputError.at(k, f"element {bad[0]} is {arr[bad[0]]} : remove or "
                                    "interpolate non-finite samples")
        dt = float(dt)
        if not (math.isfinite(dt) and dt > 0.0):
            raise ParameterError.invalid("dt", dt, "must be a finite sample interval "
                                         "greater than zero [s]")
        self.dt = dt
        self.t, self.x, self.x_drive = vals["t"], vals["x"], vals["x_drive"]
        self.v, self.a, self.fm, self.fm_f = vals["v"], vals["a"], vals["fm"], vals["fm_f"]

    def __len__(self) -> int:
        return int(self.t.size)

    def filt(self, y: Any) -> np.ndarray:
        """The parallel low-pass of a signal of the record's length."""
        ys = _vec("y", y)
        if ys.size != len(self):
            raise InputError.at("y", f"has {ys.size} samples but the record has {len(self)}: "
                                "give arrays of the same length")
        return self._filter.filtfilt(ys)

    def filt_columns(self, y: Any) -> np.ndarray:
        """The parallel low-pass of each column of an ``(n, m)`` matrix."""
        try:
            arr = np.array(y, dtype=float)
        except (TypeError, ValueError) as e:
            raise InputError.at("y", f"must be an array of numbers ({e})") from None
        if arr.ndim != 2:
            raise InputError.at("y", "must be a 2-D float64 array")
        if arr.shape[0] != len(self):
            raise InputError.at("y", f"has {arr.shape[0]} rows but the record has "
                                f"{len(self)} samples: give one row per sample")
        out = np.empty_like(arr)
        for j in range(arr.shape[1]):
            out[:, j] = self._filter.filtfilt(arr[:, j])
        return out

    def friction_scale(self, model: ModelLike) -> np.ndarray | None:
        """Product of the ``position_friction`` and ``drift`` scales, or None."""
        m = _as_model(model)
        s = None
        for e in m.effects:
            k = e["effect"]
            if k == POSITION_FRICTION:
                f = _interp(self.x, e["positions"], e["scale"])
            elif k == DRIFT:
                f = 1.0 - e["gain"] * (1.0 - np.exp(-self.t / e["time_constant"]))
            else:
                continue
            s = f.copy() if s is None else s * f
        return s

    @staticmethod
    def _exponent(m: Any) -> float | None:
        for e in m.effects:
            if e["effect"] == STRIBECK_SHAPE:
                ex = float(e["exponent"])
                return None if ex == 2.0 else ex
        return None

    @staticmethod
    def _g(fr: dict[str, Any], v: float, exponent: float | None,
           level: float | None = None) -> float:
        """``g(v)``, both levels raised by ``level`` when given (a ``load_friction``:
        ``(fc + level) + (fs - fc)*exp(-p)``)."""
        s = fr["positive"] if v >= 0.0 else fr["negative"]
        r = v / s["vs"]
        e = math.exp(-(r * r)) if exponent is None else math.exp(-(abs(r) ** exponent))
        if level is None:
            return s["fc"] + (s["fs"] - s["fc"]) * e
        return (s["fc"] + level) + (s["fs"] - s["fc"]) * e

    def _bristles(self, m: Any, exponent: float | None
                  ) -> tuple[list[float], Any, list[float] | None]:
        """The bristle state at the samples, the friction scale and the levels' rise."""
        s = self.friction_scale(m)
        lev = self._friction_level(m)
        vh = _midpoints(self.v).tolist()
        sh = None if s is None else _midpoints(s).tolist()
        lh = None if lev is None else _midpoints(lev).tolist()
        fr = m.friction
        s0 = float(fr["sigma0"])
        dt = self.dt
        z = 0.0
        zs = []
        for k, u in enumerate(vh):
            zs.append(z)
            if u == 0.0:
                continue
            g = ((1.0 if sh is None else sh[k])
                 * self._g(fr, u, exponent, None if lh is None else lh[k]))
            sign = 1.0 if u > 0.0 else -1.0
            zss = sign * g / s0
            z = zss + (z - zss) * math.exp(-(s0 * abs(u) * dt / g))
        return zs, s, None if lev is None else lev.tolist()

    def base_friction(self, model: ModelLike) -> np.ndarray:
        """Unfiltered LuGre force at the samples."""
        m = _as_model(model)
        ex = self._exponent(m)
        z, s, lev = self._bristles(m, ex)
        fr = m.friction
        s0, s1 = float(fr["sigma0"]), float(fr["sigma1"])
        out = np.empty(len(self))
        for k, v in enumerate(self.v.tolist()):
            g = ((1.0 if s is None else float(s[k]))
                 * self._g(fr, v, ex, None if lev is None else lev[k]))
            s2 = fr["positive"]["sigma2"] if v >= 0.0 else fr["negative"]["sigma2"]
            zdot = v - s0 * abs(v) * z[k] / g
            out[k] = s0 * z[k] + s1 * zdot + s2 * v
        return out

    def effect_force(self, model: ModelLike) -> np.ndarray:
        """Unfiltered sum of the effect forces (cogging, spring, offset, drag, gravity)."""
        m = _as_model(model)
        out = np.zeros(len(self))
        x, v = self.x, self.v
        for e in m.effects:
            k = e["effect"]
            if k == COGGING:
                w = 2.0 * math.pi / e["pitch"]
                out += e["amplitude"] * np.sin(w * x + e.get("phase", 0.0))
                for j, (amp, ph) in enumerate(e.get("harmonics", []) or []):
                    out += amp * np.sin(float(j + 2) * w * x + ph)
            elif k == SPRING:
                out += e["stiffness"] * (x - e.get("x0", 0.0))
            elif k == OFFSET:
                out += e["force"]
            elif k == DRAG:
                out += e["coefficient"] * np.abs(v) * v
            elif k == GRAVITY:
                out += e["torque"] * np.sin(x + e.get("phase", 0.0))
        return out

    def coupling_force(self, model: ModelLike) -> np.ndarray:
        """Unfiltered force the ``resonance`` coupling passes to the load."""
        from .coupling import _load_coupling

        m = _as_model(model)
        return _load_coupling(self.x_drive, self.v, self.dt, m, scale=self.friction_scale(m),
                              extra=self.effect_force(m), level=self._friction_level(m),
                              substeps=COUPLING_SUBSTEPS).force

    def model_force(self, model: ModelLike) -> np.ndarray:
        """Filtered force the model needs besides the motor."""
        m = _as_model(model)
        mass = m.total_mass
        res = next((e for e in m.effects if e["effect"] == RESONANCE), None)
        if res is None:
            f = self.base_friction(m) + self.effect_force(m)
            return mass * self.a + self.filt(f)
        r = float(res["load_fraction"])
        return (1.0 - r) * mass * self.a + self.filt(self.coupling_force(m))

    def motor_force(self, model: ModelLike) -> np.ndarray:
        """Filtered motor force after the actuator (:meth:`_actuator_force`)."""
        f = self._actuator_force(_as_model(model))
        return self.fm_f.copy() if f is None else self.filt(f)

    def _friction_level(self, m: Any) -> np.ndarray | None:
        """The rise ``coefficient*|F_m'|`` of the friction levels under a
        ``load_friction`` (``Record::friction_level``), or None."""
        c = None
        for e in m.effects:
            if e["effect"] == LOAD_FRICTION:
                c = float(e["coefficient"])
        if c is None:
            return None
        f = self._actuator_force(m)
        return c * np.abs(self.fm if f is None else f)

    def _actuator_force(self, m: Any) -> np.ndarray | None:
        """Unfiltered motor force after the ``delay``, ``deadband``, ``current_limit``,
        ``current_lag`` and ``force_ripple``, in this order (``Record::actuator_force``);
        None without them."""
        delay = db = limit = lag = None
        ripple = []
        for e in m.effects:
            k = e["effect"]
            if k == DELAY and e["seconds"] > 0:
                delay = float(e["seconds"])
            elif k == DEADBAND:
                db = float(e["current"])
            elif k == CURRENT_LIMIT:
                limit = float(e["current"]) * m.force_constant
            elif k == CURRENT_LAG:
                lag = float(e["bandwidth"])
            elif k == FORCE_RIPPLE:
                ripple.append((float(e["amplitude"]), 2.0 * math.pi / float(e["pitch"]),
                               float(e.get("phase", 0.0))))
        band = db * m.force_constant if db is not None and db > 0 else None
        if delay is None and band is None and limit is None and lag is None and not ripple:
            return None
        f = self.fm.copy()
        if delay is not None:
            f = _interp(self.t - delay, self.t, self.fm)
        if band is not None:
            f = np.sign(f) * np.maximum(np.abs(f) - band, 0.0)
        if limit is not None:
            f = np.clip(f, -limit, limit)
        if lag is not None:
            a = 2.0 * math.pi * lag * self.dt
            c = math.exp(-a)
            b1 = 1.0 - (1.0 - c) / a
            b2 = 1.0 - c - b1
            y = f.tolist()
            state = (1.0 - b1) * y[0]
            for k, x in enumerate(y):
                out = b1 * x + state
                state = b2 * x + c * out
                y[k] = out
            f = np.array(y)
        if ripple:
            r = np.ones(f.size)
            for a, w, ph in ripple:
                r = r + a * np.sin(w * self.x + ph)
            f = f * r
        return f

    def residual(self, model: ModelLike) -> np.ndarray:
        """Force residual ``filt(F_m') - m*a - filt(F_friction + F_effects)`` [N]."""
        m = _as_model(model)
        return self.motor_force(m) - self.model_force(m)

    def residuals(self, models: list[ModelLike]) -> np.ndarray:
        """Residuals of several models, one column each."""
        if not models:
            return np.zeros((len(self), 0))
        return np.column_stack([self.residual(m) for m in models])

    def fit_base(self, starts: list[ModelLike], mask: Any, names: list[str],
                 max_iter: int = 60, keep: int = 3, scouts: int = 12,
                 weighting: str = "huber", tol: float = 1e-6,
                 information: bool = True) -> dict[str, Any]:
        """The base parameters ``names`` fitted from ``starts`` (twin of the core's
        ``fit_base``; see ``lugre._reference_basefit``)."""
        import warnings

        from .basefit import fit_base

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return fit_base(self, starts, mask, names, max_iter=max_iter, keep=keep,
                            scouts=scouts, weighting=weighting, tol=tol,
                            information=information)

    def base_sensitivities(self, model: ModelLike, names: list[str]
                           ) -> tuple[np.ndarray, np.ndarray, list[bool]]:
        """``(force, J, nonzero)``: the LuGre force, its filtered derivatives with respect
        to the named parameters, and whether each unfiltered column is non-zero."""
        m = _as_model(model)
        params = [parse_base_param(n) for n in names]
        ex = self._exponent(m)
        exn = 2.0 if ex is None else ex
        fr = m.friction
        s0, s1 = float(fr["sigma0"]), float(fr["sigma1"])
        s = self.friction_scale(m)
        sl = None if s is None else s.tolist()
        sh = None if s is None else _midpoints(s).tolist()
        lev = self._friction_level(m)  # (the levels' rise depends on no parameter)
        ll = None if lev is None else lev.tolist()
        lh = None if lev is None else _midpoints(lev).tolist()
        vl = self.v.tolist()
        vh = _midpoints(self.v).tolist()
        n, q = len(vl), len(params)
        force = np.empty(n)
        cols = np.zeros((n, q))
        dz = [0.0] * q
        z = 0.0
        dt = self.dt

        def dg(side: str, key: str, v: float) -> tuple[float, float]:
            own = "positive" if v >= 0.0 else "negative"
            if side != own:
                return 0.0, 0.0
            st = fr[own]
            r = abs(v / st["vs"])
            p = r * r if exn == 2.0 else r ** exn
            e = math.exp(-p)
            if key == "fc":
                return 1.0 - e, 0.0
            if key == "fs":
                return e, 0.0
            if key == "vs":
                return (st["fs"] - st["fc"]) * e * exn * p / st["vs"], 0.0
            return 0.0, 1.0  # sigma2

        for k in range(n):
            v = vl[k]
            sc = 1.0 if sl is None else sl[k]
            g = sc * self._g(fr, v, ex, None if ll is None else ll[k])
            s2 = fr["positive"]["sigma2"] if v >= 0.0 else fr["negative"]["sigma2"]
            w = v - s0 * abs(v) * z / g
            force[k] = s0 * z + s1 * w + s2 * v
            for j, (side, key) in enumerate(params):
                dg0, ds2 = dg(side, key, v) if side else (0.0, 0.0)
                dgk = sc * dg0
                ds0 = 1.0 if key == "sigma0" else 0.0
                ds1 = 1.0 if key == "sigma1" else 0.0
                dw = -abs(v) * (ds0 * z / g + s0 * dz[j] / g - s0 * z * dgk / (g * g))
                cols[k, j] = ds0 * z + s0 * dz[j] + ds1 * w + s1 * dw + ds2 * v
            if k + 1 == n:
                break
            u = vh[k]
            if u == 0.0:
                continue
            su = 1.0 if sh is None else sh[k]
            gh = su * self._g(fr, u, ex, None if lh is None else lh[k])
            sign = 1.0 if u > 0.0 else -1.0
            zss = sign * gh / s0
            e = math.exp(-(s0 * abs(u) * dt / gh))
            for j, (side, key) in enumerate(params):
                dgh = su * (dg(side, key, u)[0] if side else 0.0)
                ds0 = 1.0 if key == "sigma0" else 0.0
                dzss = sign * (dgh / s0 - gh * ds0 / (s0 * s0))
                da = abs(u) * dt * (ds0 / gh - s0 * dgh / (gh * gh))
                dz[j] = dzss * (1.0 - e) + e * dz[j] - (z - zss) * e * da
            z = zss + (z - zss) * e
        nonzero = [bool(np.any(cols[:, j] != 0.0)) for j in range(q)]
        jac = np.column_stack([self.filt(cols[:, j]) for j in range(q)]) if q else np.zeros((n, 0))
        return force, jac, nonzero


def _number(name: str, value: Any) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        raise ParameterError.invalid(name, value, "must be a finite number") from None


def _finite_samples(name: str, a: np.ndarray) -> None:
    bad = np.flatnonzero(~np.isfinite(a))
    if bad.size:
        raise InputError.at(name, f"element {bad[0]} is {_fmt_f64(float(a[bad[0]]))} : remove "
                            "or interpolate non-finite samples")


def position_sums(x: Any, r: Any, k0: float, dk: float, n: int, *, squares: bool = False
                  ) -> tuple[np.ndarray, ...]:
    """Sums of ``r`` against ``sin`` and ``cos`` of ``2*pi*k_j*x`` over a uniform grid of
    spatial frequencies ``k_j = k0 + j*dk``, ``j < n`` (NumPy twin of
    ``_core.position_sums``: ``sin`` and ``cos`` of the outer product, evaluated
    directly in blocks of frequencies).

    Parameters
    ----------
    x, r : array_like
        Positions [m] and values, 1-D, same length, finite.
    k0 : float
        First spatial frequency [1/m], finite.
    dk : float
        Frequency step [1/m], finite and > 0.
    n : int
        Number of frequencies, 1 to :data:`MAX_FREQUENCIES`.
    squares : bool, default False
        Also return the sums of ``sin^2``, ``cos^2`` and ``sin*cos``.

    Returns
    -------
    tuple of numpy.ndarray
        ``(S, C)``, with ``squares`` ``(S, C, SS, CC, SC)``, each of length ``n``.

    Raises
    ------
    InputError
        ``x`` or ``r`` not 1-D or not finite, ``r`` of another length than ``x``.
    ParameterError
        ``k0`` not finite, ``dk`` not finite or <= 0, ``n`` out of range.
    """
    xa, ra = _array("x", x), _array("r", r)
    k0f, dkf = _number("k0", k0), _number("dk", dk)
    nn = frequency_count(n)
    # the core's checks in the core's order
    _finite_samples("x", xa)
    if ra.size != xa.size:
        raise InputError.at("r", f"has {ra.size} samples but x has {xa.size}: give arrays of "
                            "the same length")
    _finite_samples("r", ra)
    if not math.isfinite(k0f):
        raise ParameterError.invalid("k0", k0f, "must be a finite spatial frequency [1/m]")
    if not (math.isfinite(dkf) and dkf > 0.0):
        raise ParameterError.invalid("dk", dkf, "must be a finite frequency step greater "
                                     "than zero [1/m]")
    ks = k0f + np.arange(nn, dtype=float) * dkf
    out = [np.empty(nn) for _ in range(5 if squares else 2)]
    step = max(1, 2**20 // max(xa.size, 1))  # about 8 MB per block of angles
    for j0 in range(0, nn, step):
        ph = 2.0 * np.pi * np.outer(ks[j0:j0 + step], xa)
        s, c = np.sin(ph), np.cos(ph)
        out[0][j0:j0 + step] = s @ ra
        out[1][j0:j0 + step] = c @ ra
        if squares:
            out[2][j0:j0 + step] = (s * s).sum(1)
            out[3][j0:j0 + step] = (c * c).sum(1)
            out[4][j0:j0 + step] = (s * c).sum(1)
    return tuple(out)
