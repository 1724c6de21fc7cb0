"""The start values of the static step (``starts.rs``): a Huber grid over ``ln vs`` and
least-trimmed-squares fits of elemental subsets (FAST-LTS on a fixed-seed subsample),
with their high-breakdown scales."""

from __future__ import annotations

import math
from collections.abc import Sequence

from .nm import NmOptions
from .robust import Weighting, median
from .static_vp import P4, _fill_phi, _ln, _Normal, _Sep, _vp_minimize

__all__: list[str] = []

_exp = math.exp
_MASK = 0xFFFF_FFFF_FFFF_FFFF
GRID_NODES = 17
LTS_CANDIDATES = 4
SEEDS_PER_NODE = 36
LTS_REWEIGHT_CUT = 2.5


# ---- starts (starts.rs) ------------------------------------------------------------------


def _grid_nodes(a: list[float], count: int) -> list[float]:
    amin, amax = min(a), max([0.0, *a])
    lo, hi = math.log(amin * 0.5), math.log(amax * 2.0)
    return [_exp(lo + (hi - lo) * k / (count - 1)) for k in range(count)]


def _start_values_huber(sep: _Sep) -> P4 | None:
    """At each ``ln vs`` node a few Huber IRLS steps of the linear fit, scored by the
    median absolute residual."""
    n = len(sep.a)
    huber = Weighting.huber()
    best: tuple[float, P4] | None = None
    fscale = sep.fc_min * 1e9
    for vs in _grid_nodes(sep.a, GRID_NODES):
        _fill_phi(sep.a, vs, sep.phi)
        w = [1.0] * n
        score = math.inf
        p = [math.nan] * 4
        for it in range(4):
            p = sep.params(sep.normal(w).solve_nonneg(), vs)
            d = p[1] - p[0]
            e = [y - (p[0] + d * phi + p[2] * a)
                 for phi, a, y in zip(sep.phi, sep.a, sep.y)]
            med = median(e)
            s = max(1.4826 * median([abs(x - med) for x in e]), 1e-12 * fscale)
            if it == 3:
                score = median([abs(x) for x in e])
                break
            w = [huber.weight(x / s) for x in e]
        if math.isfinite(score) and (best is None or score < best[0]):
            best = (score, p)
    return None if best is None else best[1]


def _elemental_seeds(a: list[float], count: int) -> list[list[int]]:
    """Three-point subsets, one from each third of the speed range, from the core's
    fixed-seed SplitMix64."""
    n = len(a)
    by_speed = _by_speed(a)
    rng = _SplitMix64(0x2545_F491_4F6C_DD1D)
    t1, t2 = n // 3, (2 * n) // 3
    out: list[list[int]] = []
    if t1 == 0 or t2 == t1:
        return out
    while len(out) < count:
        i = by_speed[rng.below(t1)]
        j = by_speed[t1 + rng.below(t2 - t1)]
        k = by_speed[t2 + rng.below(n - t2)]
        out.append([i, j, k])
    return out


def _by_speed(a: list[float]) -> list[int]:
    """Indices in order of speed (stable: equal speeds in input order)."""
    return sorted(range(len(a)), key=lambda i: a[i])


class _SplitMix64:
    """The core's fixed-seed SplitMix64."""

    def __init__(self, state: int) -> None:
        self.state = state

    def below(self, m: int) -> int:
        self.state = (self.state + 0x9E37_79B9_7F4A_7C15) & _MASK
        z = self.state
        z = ((z ^ (z >> 30)) * 0xBF58_476D_1CE4_E5B9) & _MASK
        z = ((z ^ (z >> 27)) * 0x94D0_49BB_1331_11EB) & _MASK
        return (z ^ (z >> 31)) % max(m, 1)


def _subsample(a: list[float], m: int) -> list[int]:
    """``m`` of the points spread over the speeds (``subsample``): the points in order of
    speed cut into ``m`` runs, one drawn from each by the fixed-seed generator; in input
    order."""
    n = len(a)
    if m >= n:
        return list(range(n))
    by_speed = _by_speed(a)
    rng = _SplitMix64(0x5DEE_CE66_D1CE_5EED)
    out = []
    for j in range(m):
        lo, hi = j * n // m, (j + 1) * n // m
        out.append(by_speed[lo + rng.below(hi - lo)])
    out.sort()
    return out


class _Lts:
    """Least-trimmed-squares work at one ``ln vs`` node (the node's ``phi`` in ``sep``)."""

    def __init__(self, n: int, h: int) -> None:
        self.h = h
        self.order = list(range(n))

    @staticmethod
    def fit(sep: _Sep, sub: Sequence[int], vs: float) -> P4:
        ne = _Normal()
        for i in sub:
            ne.add(sep.phi[i], sep.a[i], sep.y[i] - sep.fc_min, 1.0)
        return sep.params(ne.solve_nonneg(), vs)

    def cstep(self, sep: _Sep, p: P4) -> tuple[float, P4]:
        """The trimmed sum of ``p`` and the fit on its ``h`` best points."""
        d = p[1] - p[0]
        r2 = []
        for phi, a, y in zip(sep.phi, sep.a, sep.y):
            e = y - (p[0] + d * phi + p[2] * a)
            r2.append(e * e)
        h = self.h
        # the core selects the h smallest (select_nth_unstable): the same set, the
        # sum taken in another order
        self.order = sorted(range(len(r2)), key=lambda i: r2[i])
        total = 0.0
        for i in self.order[:h]:
            total += r2[i]
        return total, _Lts.fit(sep, self.order[:h], p[3])

    def concentrate(self, sep: _Sep, p: P4, max_steps: int) -> tuple[float, P4]:
        obj, nxt = self.cstep(sep, p)
        cur = p
        for _ in range(1, max_steps):
            o, nx = self.cstep(sep, nxt)
            if math.isnan(o) or o >= obj * (1.0 - 1e-12):
                if o <= obj:
                    return o, nxt
                self.cstep(sep, cur)
                return obj, cur
            cur = nxt
            obj = o
            nxt = nx
        return obj, cur


def _start_values_lts(sep: _Sep, h: int) -> list[P4]:
    """Least-trimmed-squares candidates over the ``ln vs`` grid, best first."""
    n = len(sep.a)
    nodes = _grid_nodes(sep.a, GRID_NODES)
    seeds = _elemental_seeds(sep.a, SEEDS_PER_NODE * len(nodes))
    lts = _Lts(n, h)
    every = list(range(n))
    prev: list[int] | None = None
    glob: tuple[float, P4, list[int]] | None = None
    node_subsets: list[list[int] | None] = [None] * len(nodes)
    found_at = 0
    candidates: list[tuple[float, P4, list[int]]] = []
    for k, vs in enumerate(nodes):
        _fill_phi(sep.a, vs, sep.phi)
        starts = [_Lts.fit(sep, every, vs)]
        if prev is not None:
            starts.append(_Lts.fit(sep, prev, vs))
        if glob is not None and prev != glob[2]:
            starts.append(_Lts.fit(sep, glob[2], vs))
        for sd in seeds[k * SEEDS_PER_NODE:(k + 1) * SEEDS_PER_NODE]:
            starts.append(_Lts.fit(sep, sd, vs))
        node_best: tuple[float, P4] | None = None
        for p0 in starts:
            obj, p = lts.concentrate(sep, p0, 2)
            if math.isfinite(obj) and (node_best is None or obj < node_best[0]):
                node_best = (obj, p)
        if node_best is None:
            continue
        obj, p = lts.concentrate(sep, node_best[1], 8)
        sub = sorted(lts.order[:h])
        node_subsets[k] = sub
        prev = sub
        if math.isfinite(obj):
            candidates.append((obj, p, sub))
        if glob is None or obj < glob[0]:
            glob = (obj, p, sub)
            found_at = k
    if glob is None:
        return []
    best_sub = glob[2]
    for k, vs in enumerate(nodes[:found_at]):
        if node_subsets[k] == best_sub:
            continue
        _fill_phi(sep.a, vs, sep.phi)
        obj, p = lts.concentrate(sep, _Lts.fit(sep, best_sub, vs), 8)
        if math.isfinite(obj):
            candidates.append((obj, p, best_sub))
    candidates.sort(key=lambda c: c[0])
    out: list[P4] = []
    seen: list[list[int]] = []
    for _, p, sub in candidates:
        if sub not in seen:
            seen.append(sub)
            out.append(p)
            if len(out) == LTS_CANDIDATES:
                break
    return out


def _refine_lts(sep: _Sep, p0: P4, h: int, nm: NmOptions, floor: float) -> tuple[float, P4]:
    """Concentration steps with ``vs`` free, until the subset settles."""
    n = len(sep.a)
    p = p0
    order = list(range(n))
    best: tuple[float, P4] = (math.inf, p0)
    for _ in range(12):
        e = sep.residuals(p)
        order.sort(key=lambda i: abs(e[i]))
        obj = 0.0
        for i in order[:h]:
            obj += e[i] * e[i]
        if math.isnan(obj) or obj >= best[0] * (1.0 - 1e-10):
            break
        best = (obj, p)
        w = [0.0] * n
        for i in order[:h]:
            w[i] = 1.0
        pn, _ = _vp_minimize(sep, w, _ln(p[3]), 0.05, nm, floor)
        if not all(math.isfinite(v) for v in pn):
            break
        p = pn
    return best


def _lts_sizes(n: int) -> list[int]:
    def clamp(h: int) -> int:
        return min(max(h, 5), n)

    return [clamp((n + 4) // 2), clamp(-(-3 * n // 4)), clamp(-(-2 * n // 5))]


def _truncated_variance(k: float) -> float:
    """Variance of a standard Gaussian truncated to ``|z| <= k``."""
    phi = _exp(-0.5 * k * k) / math.sqrt(2.0 * math.pi)
    return 1.0 - 2.0 * k * phi / math.erf(k / math.sqrt(2.0))


def _lts_scale(e: list[float], h: int) -> float:
    """High-breakdown scale of a trimmed fit (``lts_scale``): the ``h`` smallest squared
    residuals on ``h - 4`` degrees of freedom, consistent for the central fraction
    ``h/n``, then twice the points within 2.5 scales on ``kept - 4``."""
    n = len(e)
    h = min(max(h, 1), max(n, 1))
    r2 = [x * x for x in e]
    r2 = [x for x in r2 if not math.isnan(x)]
    if len(r2) < h:
        return math.nan
    r2.sort()
    frac = h / n
    lo, hi = 0.0, 10.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if math.erf(mid / math.sqrt(2.0)) < frac:
            lo = mid
        else:
            hi = mid
    dof = max(h - 4.0, 1.0)
    total = 0.0
    for x in r2[:h]:
        total += x
    s = math.sqrt(total / dof / _truncated_variance(0.5 * (lo + hi)))
    return _reweight_scale(r2, s)


def _reweight_scale(r2: list[float], s: float) -> float:
    """Twice, the points within 2.5 scales give the scale on ``kept - 4`` (``r2``
    sorted)."""
    if s == 0.0:
        return s
    for _ in range(2):
        c = LTS_REWEIGHT_CUT * s
        cut2 = c * c
        kept = []
        for x in r2:
            if not x <= cut2:
                break
            kept.append(x)
        if len(kept) <= 4:
            break
        total = 0.0
        for x in kept:
            total += x
        s = math.sqrt(total / (len(kept) - 4) / _truncated_variance(LTS_REWEIGHT_CUT))
    return s


def _rescale(e: list[float], s: float) -> float:
    """The scale of all points' residuals at a subsample's fit, reweighted from the
    path's own scale ``s`` (``rescale``)."""
    r2 = [x * x for x in e]
    r2 = [x for x in r2 if not math.isnan(x)]
    r2.sort()
    return _reweight_scale(r2, s)


def _fmax(a: float, b: float) -> float:
    """``f64::max``: the other operand when one is NaN."""
    if math.isnan(a):
        return b
    if math.isnan(b):
        return a
    return max(a, b)


def _clamp_start(p: P4 | None, a: list[float], fscale: float) -> P4:
    amin, amax = min(a), max([0.0, *a])
    if p is None or not all(math.isfinite(v) for v in p):
        p = [fscale, 1.5 * fscale, 0.0, amax]
    p = list(p)
    p[0] = max(p[0], 1e-3 * fscale)
    p[1] = max(p[1], p[0] * 1.01 + 1e-6 * fscale)
    p[2] = max(p[2], 1e-6 * fscale / max(amax, 1e-300))
    p[3] = min(max(p[3], amin * 0.5), amax * 2.0)
    return p
