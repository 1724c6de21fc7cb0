"""The few signal-processing routines the diagnosis takes from SciPy, in NumPy alone.

``import scipy.signal`` costs about a second (it imports ``scipy.stats``,
``scipy.interpolate`` and most of SciPy with it), twice what a diagnosis of a 20 000-sample
record takes; the diagnosis needs a Butterworth design, Welch's periodogram and a
frequency response from it, a chi-square quantile and a moving median. These follow
SciPy 1.17's own steps (``scipy.signal.butter(..., output="sos")``, ``welch``,
``sosfreqz``, ``scipy.stats.chi2.ppf``, ``scipy.ndimage.median_filter(mode="nearest")``):
the design and the median give SciPy's numbers bit for bit, the spectra agree to the
rounding of the FFT (``tests/test_dsp.py``).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["butter_sos", "chi2_ppf", "chi2_sf1", "sosfreqz", "t_cdf", "welch"]


# --------------------------------------------------------------------------------------
# Butterworth low-pass as second-order sections (scipy.signal.butter, zpk2sos "nearest")
# --------------------------------------------------------------------------------------


def butter_sos(order: int, wn: float) -> np.ndarray:
    """Digital Butterworth low-pass of ``order`` with cut-off ``wn`` (a fraction of
    Nyquist, 0 < wn < 1) as second-order sections: ``scipy.signal.butter(order, wn,
    output="sos")``, step for step."""
    n = int(order)
    if n < 1 or not 0.0 < wn < 1.0:
        raise ValueError(f"a low-pass of order >= 1 with 0 < wn < 1, not {order}, {wn}")
    # analog prototype (buttap)
    z = np.asarray([], dtype=np.float64)
    m = np.arange(-n + 1, n, 2, dtype=np.float64)
    p = -np.exp(1j * np.pi * m / (2 * n))
    k = 1.0
    # pre-warped cut-off, fs = 2
    fs = 2.0
    wo = float(2 * fs * np.tan(np.pi * np.asarray(wn, dtype=np.float64) / fs))
    # lp2lp_zpk
    degree = p.shape[0] - z.shape[0]
    z, p, k = wo * z, wo * p, k * wo**degree
    # bilinear_zpk
    fs2 = 2.0 * fs
    z_z = (fs2 + z) / (fs2 - z)
    p_z = (fs2 + p) / (fs2 - p)
    z_z = np.concatenate((z_z, -np.ones(degree)))
    k_z = k * np.real(np.prod(fs2 - z) / np.prod(fs2 - p))
    return _zpk2sos(z_z, p_z, k_z)


def _poly(zeros: np.ndarray) -> np.ndarray:
    zeros = np.atleast_1d(np.asarray(zeros))
    if zeros.shape[0] == 0:
        return np.asarray(1.0, dtype=np.real(zeros).dtype)
    a = np.ones((1,), dtype=zeros.dtype)
    one = np.ones_like(zeros[0])
    for zero in zeros:
        a = np.convolve(a, np.stack((one, -zero)), mode="full")
    if np.iscomplexobj(a):
        roots = np.asarray(zeros, dtype=np.complex128)
        if np.all(np.sort(np.imag(roots)) == np.sort(np.imag(np.conj(roots)))):
            a = np.asarray(np.real(a), copy=True)
    return a


def _single_section(z: list[Any], p: list[Any]) -> np.ndarray:
    sos = np.zeros(6)
    zz, pp = np.asarray(z), np.asarray(p)
    k = np.asarray(1, dtype=np.result_type(np.real(zz), np.real(pp), 1))
    if np.issubdtype(k.dtype, np.integer):
        k = k.astype(np.float64)
    b = k * _poly(zz)
    a = np.atleast_1d(_poly(pp))
    b = np.atleast_1d(b)
    sos[3 - len(b):3] = b
    sos[6 - len(a):6] = a
    return sos


def _cplxreal(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    z = np.atleast_1d(z)
    if z.size == 0:
        return z, z
    tol = 100 * np.finfo((1.0 * z).dtype).eps
    z = z[np.lexsort((abs(z.imag), z.real))]
    real_indices = abs(z.imag) <= tol * abs(z)
    zr = z[real_indices].real
    if len(zr) == len(z):
        return np.array([]), zr
    z = z[~real_indices]
    zp = z[z.imag > 0]
    zn = z[z.imag < 0]
    if len(zp) != len(zn):  # pragma: no cover - a Butterworth's poles come in pairs
        raise ValueError("a complex value with no matching conjugate")
    same_real = np.diff(zp.real) <= tol * abs(zp[:-1])
    diffs = np.diff(np.concatenate(([0], same_real, [0])))
    run_starts = np.nonzero(diffs > 0)[0]
    run_stops = np.nonzero(diffs < 0)[0]
    for i in range(len(run_starts)):
        start = run_starts[i]
        stop = run_stops[i] + 1
        for chunk in (zp[start:stop], zn[start:stop]):
            chunk[...] = chunk[np.lexsort([abs(chunk.imag)])]
    zc = (zp + zn.conj()) / 2
    return zc, zr


def _nearest(fro: np.ndarray, to: Any, which: str) -> int:
    order = np.argsort(np.abs(fro - to))
    if which == "any":
        return int(order[0])
    mask = np.isreal(fro[order])
    if which == "complex":
        mask = ~mask
    return int(order[np.nonzero(mask)[0][0]])


def _zpk2sos(z: np.ndarray, p: np.ndarray, k: Any) -> np.ndarray:
    """``scipy.signal.zpk2sos(z, p, k)`` of a digital filter ("nearest" pairing)."""
    z, p, k = np.asarray(z), np.asarray(p), np.asarray(k)
    p = np.concatenate((p, np.zeros(max(len(z) - len(p), 0))))
    z = np.concatenate((z, np.zeros(max(len(p) - len(z), 0))))
    n_sections = (max(len(p), len(z)) + 1) // 2
    if len(p) % 2 == 1:
        p = np.concatenate((p, [0.0]))
        z = np.concatenate((z, [0.0]))
    z = np.concatenate(_cplxreal(z))
    p = np.concatenate(_cplxreal(p))
    k = k.real

    def idx_worst(p: np.ndarray) -> int:  # the closest to the unit circle
        return int(np.argmin(np.abs(1 - np.abs(p))))

    sos = np.zeros((n_sections, 6))
    for si in range(n_sections - 1, -1, -1):
        p1_idx = idx_worst(p)
        p1 = p[p1_idx]
        p = np.delete(p, p1_idx)
        if np.isreal(p1) and np.isreal(p).sum() == 0:
            z1_idx = _nearest(z, p1, "real")
            z1 = z[z1_idx]
            z = np.delete(z, z1_idx)
            sos[si] = _single_section([z1, 0], [p1, 0])
        elif (len(p) + 1 == len(z) and not np.isreal(p1) and np.isreal(p).sum() == 1
              and np.isreal(z).sum() == 1):
            z1_idx = _nearest(z, p1, "complex")
            z1 = z[z1_idx]
            z = np.delete(z, z1_idx)
            sos[si] = _single_section([z1, z1.conj()], [p1, p1.conj()])
        else:
            if np.isreal(p1):
                prealidx = np.flatnonzero(np.isreal(p))
                p2_idx = prealidx[idx_worst(p[prealidx])]
                p2 = p[p2_idx]
                p = np.delete(p, p2_idx)
            else:
                p2 = p1.conj()
            if len(z) > 0:
                z1_idx = _nearest(z, p1, "any")
                z1 = z[z1_idx]
                z = np.delete(z, z1_idx)
                if not np.isreal(z1):
                    sos[si] = _single_section([z1, z1.conj()], [p1, p2])
                elif len(z) > 0:
                    z2_idx = _nearest(z, p1, "real")
                    z2 = z[z2_idx]
                    z = np.delete(z, z2_idx)
                    sos[si] = _single_section([z1, z2], [p1, p2])
                else:
                    sos[si] = _single_section([z1], [p1, p2])
            else:
                sos[si] = _single_section([], [p1, p2])
    sos[0][:3] *= k
    return sos


# --------------------------------------------------------------------------------------
# Frequency response and spectra
# --------------------------------------------------------------------------------------


def sosfreqz(sos: np.ndarray, freqs: np.ndarray, fs: float) -> np.ndarray:
    """Complex response of the sections ``sos`` at the frequencies ``freqs`` [Hz] for
    the sample rate ``fs``: ``scipy.signal.sosfreqz(sos, worN=freqs, fs=fs)[1]``."""
    w = 2 * math.pi * np.atleast_1d(np.asarray(freqs, dtype=np.float64)) / float(fs)
    zm1 = np.exp(-1j * w)
    h: Any = 1.0
    for row in np.asarray(sos, dtype=np.float64):
        h = h * (_polyval(zm1, row[:3]) / _polyval(zm1, row[3:]))
    return np.asarray(h)


def _polyval(x: np.ndarray, c: np.ndarray) -> np.ndarray:
    c0 = np.broadcast_to(np.asarray(c[-1], dtype=np.result_type(c, x)), x.shape)
    for i in range(2, c.shape[0] + 1):
        c0 = c[-i] + c0 * x
    return c0


def welch(y: np.ndarray, fs: float, nperseg: int) -> tuple[np.ndarray, np.ndarray]:
    """One-sided power spectral density by Welch's method with SciPy's defaults (a
    periodic Hann window of ``nperseg`` samples, half overlap, each segment's mean
    removed, densities averaged): ``scipy.signal.welch(y, fs=fs, nperseg=nperseg)``,
    in SciPy 1.17's order of operations."""
    y = np.asarray(y, dtype=np.float64)
    nper = min(int(nperseg), y.size)  # (SciPy warns and takes the whole signal)
    hop = nper - nper // 2
    win = 0.5 + 0.5 * np.cos(np.linspace(-np.pi, np.pi, nper + 1))[:-1]
    win = win * (1 / np.sqrt(sum(win**2) / (1.0 / fs)))  # (Python's sum, as SciPy)
    nseg = (y.size - nper // 2) // hop
    segs = np.lib.stride_tricks.sliding_window_view(y, nper)[::hop][:nseg]
    pxx = np.empty((nper // 2 + 1, nseg))
    # a few segments at a time: the windowed copies of a million-sample record's
    # segments would double its memory
    per = max(1, (1 << 22) // nper)
    for s in range(0, nseg, per):
        block = segs[s:s + per]
        block = (block - np.mean(block, axis=-1, keepdims=True)) * win
        spec = np.fft.rfft(block, n=nper, axis=-1)
        pxx[:, s:s + per] = (spec.real**2 + spec.imag**2).T
    pxx[1:-1 if nper % 2 == 0 else None] *= 2
    return np.fft.rfftfreq(nper, 1.0 / fs), pxx.mean(axis=-1)


# --------------------------------------------------------------------------------------
# Chi-square quantile
# --------------------------------------------------------------------------------------


def chi2_ppf(q: float, dof: float) -> float:
    """The ``q`` quantile of the chi-square law with ``dof`` degrees of freedom
    (``scipy.stats.chi2.ppf``: twice the inverse of the regularised lower incomplete
    gamma function at ``dof/2``), to about 1e-14 relative."""
    return 2.0 * _gammaincinv(0.5 * float(dof), float(q))


def chi2_sf1(x: float) -> float:
    """Survival function of the chi-square law with one degree of freedom at ``x``
    (``scipy.special.chdtrc(1, x)``): ``erfc(sqrt(x/2))``."""
    return math.erfc(math.sqrt(max(float(x), 0.0) / 2.0))


def t_cdf(df: int, t: Any) -> Any:
    """Student's t distribution function with ``df`` degrees of freedom at ``t`` (an
    array or a number; ``scipy.special.stdtr(df, t)``, cephes' steps: the incomplete
    beta function below ``t = -2``, the finite series of an integer ``df`` above), to
    about 1e-14 relative, small tail probabilities included."""
    arr = np.asarray(t, dtype=float)
    out = np.array([_t_cdf(int(df), float(v)) for v in arr.ravel()]).reshape(arr.shape)
    return out if arr.ndim else float(out)


def _t_cdf(k: int, t: float) -> float:
    if k <= 0 or math.isnan(t):
        return math.nan
    if math.isinf(t):
        return 1.0 if t > 0 else 0.0
    if t == 0.0:
        return 0.5
    if t < -2.0:
        return 0.5 * _incbet(0.5 * k, 0.5, k / (k + t * t))
    x = abs(t)
    z = 1.0 + x * x / k
    eps = 1.11022302462515654042e-16
    if k & 1:
        xsqk = x / math.sqrt(k)
        p = math.atan(xsqk)
        if k > 1:
            f = tz = 1.0
            j = 3
            while j <= k - 2 and tz / f > eps:
                tz *= (j - 1) / (z * j)
                f += tz
                j += 2
            p += f * xsqk / z
        p *= 2.0 / math.pi
    else:
        f = tz = 1.0
        j = 2
        while j <= k - 2 and tz / f > eps:
            tz *= (j - 1) / (z * j)
            f += tz
            j += 2
        p = f * x / math.sqrt(z * k)
    if t < 0:
        p = -p
    return 0.5 + 0.5 * p


def _incbet(a: float, b: float, x: float) -> float:
    """Regularised incomplete beta function ``I_x(a, b)`` (continued fraction, modified
    Lentz; the symmetric form where it converges faster)."""
    if x <= 0.0:
        return 0.0
    if x >= 1.0:
        return 1.0
    front = math.exp(a * math.log(x) + b * math.log1p(-x)
                     + math.lgamma(a + b) - math.lgamma(a) - math.lgamma(b))
    if x > (a + 1.0) / (a + b + 2.0):
        return 1.0 - front * _betacf(b, a, 1.0 - x) / b
    return front * _betacf(a, b, x) / a


def _betacf(a: float, b: float, x: float) -> float:
    tiny = 1e-300
    qab, qap, qam = a + b, a + 1.0, a - 1.0
    c, d = 1.0, 1.0 - qab * x / qap
    d = 1.0 / (d if abs(d) > tiny else tiny)
    h = d
    for m in range(1, 1000):
        m2 = 2 * m
        aa = m * (b - m) * x / ((qam + m2) * (a + m2))
        d = 1.0 + aa * d
        d = 1.0 / (d if abs(d) > tiny else tiny)
        c = 1.0 + aa / c
        c = c if abs(c) > tiny else tiny
        h *= d * c
        aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2))
        d = 1.0 + aa * d
        d = 1.0 / (d if abs(d) > tiny else tiny)
        c = 1.0 + aa / c
        c = c if abs(c) > tiny else tiny
        delta = d * c
        h *= delta
        if abs(delta - 1.0) < 1e-16:
            break
    return h


def _gammainc(a: float, x: float) -> float:
    """Regularised lower incomplete gamma function ``P(a, x)``."""
    if x <= 0.0:
        return 0.0
    lead = a * math.log(x) - x - math.lgamma(a)
    if x < a + 1.0:  # series
        term = total = 1.0 / a
        ap = a
        for _ in range(10000):
            ap += 1.0
            term *= x / ap
            total += term
            if abs(term) < abs(total) * 1e-17:
                break
        return total * math.exp(lead)
    tiny = 1e-300  # continued fraction of Q(a, x), modified Lentz
    b = x + 1.0 - a
    c, d = 1.0 / tiny, 1.0 / b
    h = d
    for i in range(1, 10000):
        an = -i * (i - a)
        b += 2.0
        d = an * d + b
        d = 1.0 / (d if abs(d) > tiny else tiny)
        c = b + an / c
        c = c if abs(c) > tiny else tiny
        delta = d * c
        h *= delta
        if abs(delta - 1.0) < 1e-16:
            break
    return 1.0 - math.exp(lead) * h


def _gammaincinv(a: float, q: float) -> float:
    """``x`` with ``P(a, x) = q`` (Newton's method from the Wilson-Hilferty start)."""
    if not 0.0 < q < 1.0 or not a > 0.0:
        return 0.0 if q == 0.0 else math.inf if q == 1.0 else math.nan
    # start: the Wilson-Hilferty cube of a normal quantile (Acklam's approximation)
    zq = _normal_ppf(q)
    x = a * (1.0 - 1.0 / (9.0 * a) + zq / (3.0 * math.sqrt(a))) ** 3
    if not x > 0.0:
        x = (q * a * math.exp(math.lgamma(a))) ** (1.0 / a)  # small-x form of P
    lg = math.lgamma(a)
    for _ in range(100):
        f = _gammainc(a, x) - q
        dens = math.exp((a - 1.0) * math.log(x) - x - lg)
        if dens <= 0.0:
            break
        step = f / dens
        # Halley's correction (second derivative of P over its first: (a-1)/x - 1)
        step /= max(1.0 - 0.5 * step * ((a - 1.0) / x - 1.0), 0.1)
        nx = x - step
        x = nx if nx > 0.0 else 0.5 * x
        if abs(step) <= 1e-15 * x:
            break
    return x


def _normal_ppf(p: float) -> float:
    """Standard normal quantile (Acklam's rational approximation, 1e-9: a start)."""
    a = (-3.969683028665376e01, 2.209460984245205e02, -2.759285104469687e02,
         1.383577518672690e02, -3.066479806614716e01, 2.506628277459239e00)
    b = (-5.447609879822406e01, 1.615858368580409e02, -1.556989798598866e02,
         6.680131188771972e01, -1.328068155288572e01)
    c = (-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e00,
         -2.549732539343734e00, 4.374664141464968e00, 2.938163982698783e00)
    d = (7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e00,
         3.754408661907416e00)
    lo = 0.02425
    if p < lo:
        u = math.sqrt(-2.0 * math.log(p))
        return (((((c[0] * u + c[1]) * u + c[2]) * u + c[3]) * u + c[4]) * u + c[5]) / \
            ((((d[0] * u + d[1]) * u + d[2]) * u + d[3]) * u + 1.0)
    if p > 1.0 - lo:
        return -_normal_ppf(1.0 - p)
    u = p - 0.5
    r = u * u
    return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * u / \
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0)
