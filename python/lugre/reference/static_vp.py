"""The separable Stribeck model of the static step (``varpro.rs``): for a fixed ``vs`` the
curve ``fc + (fs - fc)*phi + sigma2*a`` is linear, its linear part from the weighted
normal equations; a weighted problem is a search over ``ln vs``."""

from __future__ import annotations

import math
from collections.abc import Sequence

from .nm import NmOptions, minimize

__all__: list[str] = []

_exp = math.exp
P4 = list  # [fc, fs, sigma2, vs]


# ---- variable projection (varpro.rs) ----------------------------------------------------


def _ln(x: float) -> float:
    """``f64::ln``: -inf at 0, NaN below (``math.log`` raises there)."""
    if x > 0.0 or math.isnan(x):
        return math.log(x)
    return -math.inf if x == 0.0 else math.nan


def _div(a: float, b: float) -> float:
    """``a / b`` with IEEE results at ``b == 0`` (inf or NaN, as in Rust)."""
    if b != 0.0:
        return a / b
    if a == 0.0 or math.isnan(a):
        return math.nan
    return math.copysign(math.inf, a) * math.copysign(1.0, b)


def _curve(p: Sequence[float], a: float) -> float:
    r = a / p[3]
    return p[0] + (p[1] - p[0]) * _exp(-(r * r)) + p[2] * a


def _fill_phi(a: list[float], vs: float, phi: list[float]) -> None:
    iv = 1.0 / vs
    for k, ai in enumerate(a):
        r = ai * iv
        phi[k] = _exp(-(r * r)) if r * r < 40.0 else 0.0


def _inv_sqrt(v: float) -> float | None:
    return 1.0 / math.sqrt(v) if v > 0.0 and math.isfinite(v) else None


class _Normal:
    """Weighted normal equations of ``(fc - fc_min, fs - fc, sigma2)``."""

    __slots__ = ("b", "m")

    def __init__(self) -> None:
        self.m = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
        self.b = [0.0, 0.0, 0.0]

    def add(self, phi: float, a: float, y: float, w: float) -> None:
        wp, wa = w * phi, w * a
        m, b = self.m, self.b
        m[0][0] += w
        m[0][1] += wp
        m[0][2] += wa
        m[1][1] += wp * phi
        m[1][2] += wp * a
        m[2][2] += wa * a
        b[0] += w * y
        b[1] += wp * y
        b[2] += wa * y

    def solve_free(self, free: int) -> list[float] | None:
        pivot = 1e-13
        m = self.m
        x = [0.0, 0.0, 0.0]
        if free == 0b111:
            d0, d1, d2 = _inv_sqrt(m[0][0]), _inv_sqrt(m[1][1]), _inv_sqrt(m[2][2])
            if d0 is None or d1 is None or d2 is None:
                return None
            a, b, c = m[0][1] * d0 * d1, m[0][2] * d0 * d2, m[1][2] * d1 * d2
            p1 = 1.0 - a * a
            if math.isnan(p1) or p1 <= pivot:
                return None
            l11 = math.sqrt(p1)
            l21 = (c - a * b) / l11
            p2 = 1.0 - b * b - l21 * l21
            if math.isnan(p2) or p2 <= pivot:
                return None
            l22 = math.sqrt(p2)
            z0 = self.b[0] * d0
            z1 = (self.b[1] * d1 - a * z0) / l11
            z2 = (self.b[2] * d2 - b * z0 - l21 * z1) / l22
            u2 = z2 / l22
            u1 = (z1 - l21 * u2) / l11
            u0 = z0 - a * u1 - b * u2
            x = [u0 * d0, u1 * d1, u2 * d2]
        elif free in (0b011, 0b101, 0b110):
            i, j = {0b011: (0, 1), 0b101: (0, 2), 0b110: (1, 2)}[free]
            di, dj = _inv_sqrt(m[i][i]), _inv_sqrt(m[j][j])
            if di is None or dj is None:
                return None
            a = m[i][j] * di * dj
            det = 1.0 - a * a
            if math.isnan(det) or det <= pivot:
                return None
            bi, bj = self.b[i] * di, self.b[j] * dj
            x[i] = (bi - a * bj) / det * di
            x[j] = (bj - a * bi) / det * dj
        elif free in (0b001, 0b010, 0b100):
            i = {0b001: 0, 0b010: 1, 0b100: 2}[free]
            mii = m[i][i]
            if not (mii > 0.0 and math.isfinite(mii)):
                return None
            x[i] = self.b[i] / mii
        return x if all(math.isfinite(v) for v in x) else None

    def quad(self, x: list[float]) -> float:
        m = self.m
        mx = [m[0][0] * x[0] + m[0][1] * x[1] + m[0][2] * x[2],
              m[0][1] * x[0] + m[1][1] * x[1] + m[1][2] * x[2],
              m[0][2] * x[0] + m[1][2] * x[1] + m[2][2] * x[2]]
        q = 0.0
        for k in range(3):
            q += x[k] * (mx[k] - 2.0 * self.b[k])
        return q

    def solve_nonneg(self) -> list[float]:
        x = self.solve_free(0b111)
        if x is not None and all(v >= 0.0 for v in x):
            return x
        best, best_q = [0.0, 0.0, 0.0], 0.0
        for free in (0b011, 0b101, 0b110, 0b001, 0b010, 0b100):
            x = self.solve_free(free)
            if x is not None and all(v >= 0.0 for v in x):
                q = self.quad(x)
                if q < best_q:
                    best, best_q = x, q
        return best


class _Sep:
    """One direction's points and the separable problem (``Sep`` in varpro.rs)."""

    def __init__(self, a: list[float], y: list[float], fscale: float) -> None:
        amin = min(a)
        amax = max([0.0, *a])
        self.a, self.y = a, y
        self.fc_min = 1e-9 * fscale
        self.ln_lo = math.log(amin) - 7.0
        self.ln_hi = math.log(amax) + 7.0
        self.phi = [0.0] * len(a)

    def normal(self, w: Sequence[float]) -> _Normal:
        ne = _Normal()
        fm = self.fc_min
        for phi, a, y, wi in zip(self.phi, self.a, self.y, w):
            if wi != 0.0:
                ne.add(phi, a, y - fm, wi)
        return ne

    def params(self, x: list[float], vs: float) -> P4:
        fc = self.fc_min + x[0]
        return [fc, fc + x[1], x[2], vs]

    def profile(self, w: Sequence[float], ln_vs: float) -> tuple[float, P4]:
        if not (self.ln_lo <= ln_vs <= self.ln_hi):
            return math.inf, [math.nan] * 4
        vs = _exp(ln_vs)
        _fill_phi(self.a, vs, self.phi)
        p = self.params(self.normal(w).solve_nonneg(), vs)
        d = p[1] - p[0]
        ss = 0.0
        for phi, a, y, wi in zip(self.phi, self.a, self.y, w):
            e = y - (p[0] + d * phi + p[2] * a)
            ss += wi * e * e
        return ss, p

    def residuals(self, p: Sequence[float]) -> list[float]:
        return [y - _curve(p, a) for a, y in zip(self.a, self.y)]


def _vp_minimize(sep: _Sep, w: Sequence[float], ln_vs0: float, step: float,
                 nm: NmOptions, floor: float) -> tuple[P4, int]:
    """Minimum of the weighted profile over ``ln vs``: a bracket walked downhill, then
    Nelder-Mead from the vertex of its parabola."""

    def f(x: float) -> float:
        return sep.profile(w, x)[0] + floor

    xa, xb, xc = ln_vs0 - step, ln_vs0, ln_vs0 + step
    fa, fb, fc = f(xa), f(xb), f(xc)
    evals = 3
    h = step
    while evals < 40:
        if fa < fb and fa <= fc:
            h *= 2.0
            xc, fc, xb, fb = xb, fb, xa, fa
            xa = xb - h
            fa = f(xa)
        elif fc < fb:
            h *= 2.0
            xa, fa, xb, fb = xb, fb, xc, fc
            xc = xb + h
            fc = f(xc)
        else:
            break
        evals += 1
    da, dc = xb - xa, xb - xc
    den = da * (fb - fc) - dc * (fb - fa)
    x0 = xb
    if den != 0.0 and math.isfinite(den):
        xp = xb - 0.5 * (da * da * (fb - fc) - dc * dc * (fb - fa)) / den
        if xa < xp < xc:
            fp = f(xp)
            evals += 1
            if fp < fb:
                x0 = xp
    simplex = max(1e-3 * h, 1e-7)
    r = minimize(lambda x: f(x[0]), [x0], [simplex], nm)
    _, p = sep.profile(w, r.x[0])
    return p, evals + r.evals + 1
