"""Selection of effects: held-out criterion on contiguous blocks, with a significance test.

The residual is coloured (filters, bristle dynamics, slow mismatch), so neither the
sample count nor a white-noise information criterion measures the evidence. Instead:

* the data are cut into ``K`` contiguous blocks; every candidate model (base parameters
  plus a set of effects) is fitted on ``K-1`` blocks and scored on the one left out;
* squared errors are counted in units of ``sigma_eff**2 = noise**2 * n / n_eff``, the
  noise floor scaled by the effective number of independent samples of the filtered
  noise (:func:`lugre.diagnosis.residual.noise_floor`), so the score is a chi-square on
  the coloured scale;
* the base LuGre parameters are re-estimated in every fit, under a Gaussian prior of
  their tolerance (:data:`lugre.diagnosis.base.BASE_PARAMS`); the prior cost of how far
  they must move is added to the score. A constant force that would otherwise need four
  Coulomb/static levels moved by ten per cent is then the cheaper story;
* a term is accepted when it lowers the score by at least ``min_gain`` and its gain is
  consistent over the held-out blocks (one-sided t-test over the ``K`` per-block gains,
  ``p < alpha``), so that noise gives no finding.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import dsp
from .candidates import Term
from .candidates.base import rows_of

__all__ = ["OVERWHELMING", "Evaluation", "Scorer", "accept", "accept_many",
           "block_evidence", "block_gains", "compare", "rows_count", "rows_of",
           "told_apart"]

#: The confined route's gain, in multiples of ``min_gain``.
OVERWHELMING = 20.0


@dataclass
class Evaluation:
    """Scores of one candidate model (``fitted`` and ``resid`` computed when asked:
    the search scores hundreds of fits and looks at the residual of a few)."""

    score: float
    sse_b: np.ndarray
    prior: float
    beta: np.ndarray
    sse: float
    splits: list[slice] = field(default_factory=list)
    jack: np.ndarray | None = None
    r: np.ndarray | None = None
    J: np.ndarray | None = None
    X: list[np.ndarray] = field(default_factory=list)

    @property
    def fitted(self) -> np.ndarray:
        """The fitted change of the residual, ``J @ beta_base + X @ beta_effects`` [N]."""
        assert self.J is not None
        j = self.J.shape[1]
        out = self.J @ self.beta[:j]
        for x in self.X:
            out = out + x @ self.beta[j:j + x.shape[1]]
            j += x.shape[1]
        return out

    @property
    def resid(self) -> np.ndarray:
        """The residual left by the fit [N]."""
        assert self.r is not None
        return self.r - self.fitted


def rows_count(n: int, step: int) -> int:
    """Rows ``0, step, 2*step, ...`` of ``n`` samples."""
    return -(-n // step)


class Scorer:
    """Held-out scoring of joint fits (base Jacobian plus effect columns).

    Parameters
    ----------
    r : numpy.ndarray
        Residual of the current model (filtered) [N].
    J : numpy.ndarray
        Base Jacobian ``(n, q)``.
    tol : numpy.ndarray
        Prior standard deviation of each base parameter.
    mask : numpy.ndarray of bool
        Samples used.
    sigma_eff2 : float
        Variance unit of the score [N^2].
    blocks : int, default 10
        Number of contiguous held-out blocks.
    center : numpy.ndarray, optional
        Prior mean of the base changes (default 0: the model as given).
    step : int, default 1
        Read every ``step``-th sample only (:attr:`Signals.rows_step
        <lugre.diagnosis.residual.Signals.rows_step>`); sums count for every sample.
    """

    def __init__(self, r: np.ndarray, J: np.ndarray, tol: np.ndarray, mask: np.ndarray,
                 sigma_eff2: float, blocks: int = 10, center: np.ndarray | None = None,
                 step: int = 1) -> None:
        self.r = r
        self.J = J
        self.tol = tol
        self.mask = mask
        self.s2 = float(sigma_eff2)
        self.K = int(blocks)
        self.step = int(step)
        self.n = int(mask.size)
        # the samples read: every step-th of the record (a fixed grid, so that columns
        # kept at those rows only serve every scorer) among those used
        keep = mask.copy()
        if self.step > 1:
            keep[np.arange(self.n) % self.step != 0] = False
        idx = np.flatnonzero(keep)
        nb = idx.size // self.K  # equal blocks (the last few samples are left out)
        idx = idx[:nb * self.K]
        self.idx = idx
        self._nb = nb
        # the samples read as one strided slice when they are evenly spaced (the usual
        # mask: the filter's edges left out): blocks of a column are then views
        self._span = None
        self._rows = None
        if idx.size and np.all(np.diff(idx) == self.step):
            self._span = slice(int(idx[0]), int(idx[-1]) + 1, self.step)
            if self.step > 1:  # and the same rows of columns kept at those rows only
                self._rows = slice(int(idx[0]) // self.step, int(idx[-1]) // self.step + 1)
        self._products: dict[int, tuple[Any, tuple[np.ndarray, ...]]] = {}
        self._cross: dict[tuple[int, int], tuple[Any, Any, np.ndarray]] = {}
        edges = np.arange(self.K + 1) * nb
        self.blocks = [slice(edges[k], edges[k + 1]) for k in range(self.K)]
        self.center = np.zeros(J.shape[1]) if center is None else np.asarray(center, float)
        # per-block products of the base columns and the residual, once: an evaluation
        # adds only its own columns' products (the search runs hundreds of them)
        self._Jm = self._blocks_of(J)
        self._rm = self._blocks_of(r[:, None])
        self._GJJ = self._gram(self._Jm, self._Jm)
        self._hJ = self._gram(self._Jm, self._rm)[:, :, 0]
        self._rr = self._gram(self._rm, self._rm)[:, 0, 0]

    @property
    def block_samples(self) -> int:
        """Samples of the record in one held-out block (rows read times ``step``)."""
        return self._nb * self.step

    @property
    def used_blocks(self) -> list[slice]:
        """The held-out blocks as slices of the used samples (``r[mask]``), every
        sample of each stretch, not only those read."""
        used = np.flatnonzero(self.mask)
        starts = [int(np.searchsorted(used, self.idx[b.start])) for b in self.blocks]
        end = int(np.searchsorted(used, self.idx[-1] + self.step)) if self.idx.size else 0
        return [slice(a, b) for a, b in zip(starts, starts[1:] + [end])]

    def like(self, **changes: Any) -> Scorer:
        """A scorer of the same residual, base and rows with some arguments changed
        (``J``, ``tol``, ``mask``, ``blocks``, ``center``)."""
        kw: dict[str, Any] = {"r": self.r, "J": self.J, "tol": self.tol, "mask": self.mask,
                              "sigma_eff2": self.s2, "blocks": self.K, "center": self.center,
                              "step": self.step}
        kw.update(changes)
        return Scorer(**kw)

    def _stack(self, a: np.ndarray) -> np.ndarray:
        """``(n, c)`` samples as ``(K, n/K, c)`` blocks."""
        return a.reshape(self.K, self._nb, a.shape[1])

    def _blocks_of(self, X: np.ndarray) -> np.ndarray:
        """The samples read of the columns ``X`` as ``(K, n/K, p)`` blocks.

        ``X`` holds every sample of the record, or (with ``step > 1``) only every
        ``step``-th, as :func:`rows_of` keeps them.
        """
        if self.step > 1 and X.shape[0] == rows_count(self.n, self.step):
            if self._rows is not None and X.flags.c_contiguous:  # a view: no copy
                return self._stack(X[self._rows])
            return self._stack(X[self.idx // self.step])
        if X.shape[0] != self.n:
            raise ValueError(f"columns of {X.shape[0]} rows for a record of {self.n}")
        if self._span is not None:
            return self._stack(np.ascontiguousarray(X[self._span]))
        return self._stack(X[self.idx])

    def _term_products(self, X: np.ndarray) -> tuple[np.ndarray, ...]:
        """Per-block products of a term's columns with the base columns, themselves and
        the residual, computed once per column array (the search scores the same
        columns again at every step of the selection)."""
        hit = self._products.get(id(X))
        if hit is not None and hit[0]() is X:
            return hit[1]
        Xm = self._blocks_of(X)
        out = (self._gram(Xm, self._Jm), self._gram(Xm, Xm), self._gram(Xm, self._rm)[:, :, 0])
        self._products[id(X)] = (weakref.ref(X), out)  # (a weak key: X may be dropped)
        return out

    def _cross_products(self, X1: np.ndarray, X2: np.ndarray) -> np.ndarray:
        """Per-block ``X1.T @ X2`` of two terms' columns (kept for the pair)."""
        key = (id(X1), id(X2))
        hit = self._cross.get(key)
        if hit is not None and hit[0]() is X1 and hit[1]() is X2:
            return hit[2]
        g = self._gram(self._blocks_of(X1), self._blocks_of(X2))
        self._cross[key] = (weakref.ref(X1), weakref.ref(X2), g)
        return g

    def _gram(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Per-block ``a.T @ b``, in units of every sample (times ``step``)."""
        g = np.matmul(a.transpose(0, 2, 1), b)
        return g * self.step if self.step > 1 else g

    def _assemble(self, terms: list[Term]) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                    np.ndarray]:
        """Per-block Gram matrices ``(K, q+p, q+p)`` and products with the residual
        ``(K, q+p)`` of base plus ``terms``, raw; the prior standard deviations and prior
        means of all coefficients (in their own units)."""
        q = self.J.shape[1]
        Xs = [t.X for t in terms]
        tols = [self.tol]
        for t in terms:  # effect priors (absolute, in coefficient units); None: flat
            tols.append(np.full(t.X.shape[1], np.inf) if t.prior is None else t.prior)
        ptol = np.concatenate(tols)
        p = sum(x.shape[1] for x in Xs)
        G_b = np.empty((self.K, q + p, q + p))
        G_b[:, :q, :q] = self._GJJ
        h_b = np.empty((self.K, q + p))
        h_b[:, :q] = self._hJ
        offs = []
        o = q
        for i, x in enumerate(Xs):
            pi = x.shape[1]
            GXJ, GXX, GXr = self._term_products(x)
            G_b[:, o:o + pi, :q] = GXJ
            G_b[:, :q, o:o + pi] = GXJ.transpose(0, 2, 1)
            G_b[:, o:o + pi, o:o + pi] = GXX
            h_b[:, o:o + pi] = GXr
            for j in range(i):
                oj, pj = offs[j], Xs[j].shape[1]
                C = self._cross_products(Xs[j], x)
                G_b[:, oj:oj + pj, o:o + pi] = C
                G_b[:, o:o + pi, oj:oj + pj] = C.transpose(0, 2, 1)
            offs.append(o)
            o += pi
        cen = np.zeros(q + p)
        cen[:q] = self.center
        j = q
        for t in terms:
            pt = t.X.shape[1]
            if t.center is not None:
                cen[j:j + pt] = np.asarray(t.center, float)
            j += pt
        return G_b, h_b, ptol, cen

    def _fit(self, G_b: np.ndarray, h_b: np.ndarray, ptol: np.ndarray, center: np.ndarray
             ) -> dict[str, np.ndarray]:
        """The joint fit on all blocks and the ``K`` leave-one-block-out fits of one or
        several column sets at once: every argument with the same leading axes (none,
        or one per set), then the block axis, then the coefficients. Each set's numbers
        are those of a fit of that set alone (elementwise operations and solves stacked
        along the leading axes)."""
        rr_b = self._rr
        diag = np.einsum("...kii->...i", G_b)
        sc = np.sqrt(diag / (self.idx.size * self.step))
        sc[sc == 0] = 1.0
        # scaled by the columns' rms
        G_b = G_b / (sc[..., :, None] * sc[..., None, :])[..., None, :, :]
        h_b = h_b / sc[..., None, :]
        prec = np.where(np.isfinite(ptol), 1.0 / (sc * ptol) ** 2, 0.0)
        cen = center * sc
        G, h, rr = G_b.sum(-3), h_b.sum(-2), rr_b.sum()
        lam = self.s2 * prec
        eps = 1e-10 * np.trace(G, axis1=-2, axis2=-1) / G.shape[-1]
        d = G.shape[-1]
        A = np.zeros(G.shape)
        A.reshape(G.shape[:-2] + (d * d,))[..., ::d + 1] = lam + eps[..., None]
        rhs = lam * cen

        def solve(Gm: np.ndarray, hm: np.ndarray, Am: np.ndarray, rm: np.ndarray
                  ) -> np.ndarray:
            """``(Gm + Am) b = hm + rm``: one system or a stack of them."""
            try:
                return np.linalg.solve(Gm + Am, (hm + rm)[..., None])[..., 0]
            except np.linalg.LinAlgError:
                if Gm.ndim > 2:  # one singular fit of the stack: each alone
                    Am = np.broadcast_to(Am, Gm.shape)
                    rm = np.broadcast_to(rm, hm.shape)
                    return np.array([solve(g, v, a, r) for g, v, a, r in zip(Gm, hm, Am, rm)])
                return np.linalg.lstsq(Gm + Am, hm + rm, rcond=None)[0]

        b = solve(G, h, A, rhs)
        prior = np.sum(prec * (b - cen) ** 2, axis=-1)
        # the K leave-one-block-out fits as one stacked solve
        bk = solve(G[..., None, :, :] - G_b, h[..., None, :] - h_b, A[..., None, :, :],
                   rhs[..., None, :])
        sse_b = (rr_b - 2 * np.einsum("...ki,...ki->...k", bk, h_b)
                 + np.einsum("...ki,...ki->...k", np.matmul(G_b, bk[..., None])[..., 0], bk))
        score = sse_b.sum(-1) / self.s2 + prior
        return {"score": score, "sse_b": sse_b, "prior": prior, "b": b, "sc": sc, "G": G,
                "h": h, "rr": rr, "bk": bk}

    def evaluate(self, terms: list[Term]) -> Evaluation:
        """Fit base plus ``terms`` on all blocks and on each leave-one-block-out set.

        Parameters
        ----------
        terms : list of Term
            Effect terms.

        Returns
        -------
        Evaluation
        """
        f = self._fit(*self._assemble(terms))
        b, G, h, sc = f["b"], f["G"], f["h"], f["sc"]
        sse = float(f["rr"] - 2 * b @ h + b @ G @ b)
        return Evaluation(score=float(f["score"]), sse_b=f["sse_b"], prior=float(f["prior"]),
                          beta=b / sc, sse=sse, splits=self.blocks, jack=f["bk"] / sc,
                          r=self.r, J=self.J, X=[t.X for t in terms])

    def evaluate_many(self, kept: list[Term], news: list[Term]
                      ) -> tuple[np.ndarray, np.ndarray]:
        """Scores and coefficients of ``kept + [new]`` for each of ``news`` (terms of one
        width: the grid points of a candidate), as :meth:`evaluate` of each, in one
        stacked fit.

        Returns
        -------
        score : numpy.ndarray
            ``(len(news),)``.
        beta : numpy.ndarray
            ``(len(news), q + p)``: the coefficients of each fit, the new term's last.
        """
        G0, h0, tol0, cen0 = self._assemble(kept)
        m = len(news)
        d0 = G0.shape[-1]
        pn = news[0].X.shape[1] if m else 0
        d = d0 + pn
        G_b = np.empty((m, self.K, d, d))
        G_b[:, :, :d0, :d0] = G0
        h_b = np.empty((m, self.K, d))
        h_b[:, :, :d0] = h0
        ptol = np.empty((m, d))
        ptol[:, :d0] = tol0
        cen = np.zeros((m, d))
        cen[:, :d0] = cen0
        q = self.J.shape[1]
        offs = np.cumsum([q] + [t.X.shape[1] for t in kept])
        for i, t in enumerate(news):
            x = t.X
            if x.shape[1] != pn:
                raise ValueError("terms of one width only")
            GXJ, GXX, GXr = self._term_products(x)
            Gi = G_b[i]
            Gi[:, d0:, :q] = GXJ
            Gi[:, :q, d0:] = GXJ.transpose(0, 2, 1)
            Gi[:, d0:, d0:] = GXX
            h_b[i, :, d0:] = GXr
            for j, tk in enumerate(kept):
                o, pj = offs[j], tk.X.shape[1]
                C = self._cross_products(tk.X, x)
                Gi[:, o:o + pj, d0:] = C
                Gi[:, d0:, o:o + pj] = C.transpose(0, 2, 1)
            ptol[i, d0:] = np.inf if t.prior is None else t.prior
            if t.center is not None:
                cen[i, d0:] = np.asarray(t.center, float)
        f = self._fit(G_b, h_b, ptol, cen)
        return f["score"], f["b"] / f["sc"]


_ONE_BLOCK = 0.8


def _one_block(scorer: Scorer, contrib: np.ndarray) -> int | None:
    """The block holding over :data:`_ONE_BLOCK` of a contribution's energy once the
    base columns are projected out, or None."""
    Q = scorer.__dict__.get("_Q")
    if Q is None:
        J = scorer.J[scorer.idx]
        Q = scorer.__dict__["_Q"] = (np.linalg.qr(J)[0] if J.shape[1]
                                     else np.zeros((J.shape[0], 0)))
    c = contrib[scorer.idx]
    cp = c - Q @ (Q.T @ c)
    e = np.array([float(cp[b] @ cp[b]) for b in scorer.blocks])
    tot = float(e.sum())
    if not tot > 0:
        return None
    k = int(np.argmax(e))
    return k if e[k] > _ONE_BLOCK * tot else None


def compare(cur: Evaluation, new: Evaluation, s2: float) -> dict[str, float]:
    """Held-out evidence of ``new`` against ``cur``.

    The per-block gain is the held-out squared error saved in that block (in units of
    ``s2``) plus an equal share of the change of the prior cost.

    Returns
    -------
    dict
        ``gain`` (score gain), ``t`` and ``p`` (one-sided t-test over the blocks),
        ``positive`` (blocks with a gain), ``blocks``, ``ratio`` (sum of positive over sum of
        negative block gains), ``d`` (the per-block gains).
    """
    d = block_gains(cur, new, s2)
    out = block_evidence(d)
    out["d"] = d
    out["gain"] = float(cur.score - new.score)
    fit_gain = float((cur.sse_b.sum() - new.sse_b.sum()) / s2)
    prior_gain = float(cur.prior - new.prior)
    return {**out, "fit_gain": fit_gain, "prior_gain": prior_gain,
            "p_prior": dsp.chi2_sf1(max(prior_gain, 0.0))}  # stats.chi2.sf


def block_gains(cur: Evaluation, new: Evaluation, s2: float) -> np.ndarray:
    """Per-block gains of ``new`` over ``cur`` as :func:`compare` reads them."""
    K = cur.sse_b.size
    return (cur.sse_b - new.sse_b) / s2 + (cur.prior - new.prior) / K


def block_evidence(d: np.ndarray) -> dict[str, Any]:
    """:func:`compare`'s evidence from per-block gains ``d``: ``gain`` (their sum),
    ``t`` and ``p``, ``positive``, ``blocks``, ``ratio``."""
    K = d.size
    sd = float(np.std(d, ddof=1))
    if sd <= 0:
        t = float("inf") if d.mean() > 0 else 0.0
        p = 0.0 if d.mean() > 0 else 1.0
    else:
        t = float(d.mean() / (sd / np.sqrt(K)))
        p = float(dsp.t_cdf(K - 1, -t))  # stats.t.sf(t, K - 1)
    pos = float(d[d > 0].sum())
    neg = float(-d[d < 0].sum())
    return {"gain": float(d.sum()), "t": t, "p": p, "positive": int(np.sum(d > 0)),
            "blocks": int(d.size), "ratio": pos / neg if neg > 0 else float("inf")}


def told_apart(dd: np.ndarray, min_gain: float) -> tuple[bool, float]:
    """Whether block differences of squared error (noise units) tell two fits apart, as
    a term is accepted: consistently (t >= 3), or confined and overwhelming (over
    ``20*min_gain``, in at least three blocks, ten times what the others lose); and t."""
    tstat = abs(dd.mean()) / (dd.std(ddof=1) / math.sqrt(dd.size) + 1e-300)
    sd = np.sign(dd.sum()) * dd
    lose = float(-sd[sd < 0].sum())
    apart = abs(dd.sum()) >= min_gain and (
        tstat >= 3.0 or (abs(dd.sum()) > OVERWHELMING * min_gain and int(np.sum(sd > 0)) >= 3
                         and float(sd[sd > 0].sum()) > 10 * lose))
    return bool(apart), float(tstat)


def accept(ev: dict[str, float], *, alpha: float, min_gain: float) -> tuple[bool, str]:
    """Decide on a term from :func:`compare`'s evidence.

    A term passes when its held-out score gain exceeds ``min_gain`` and its gains hold
    up on the held-out blocks: either they are consistent (one-sided t-test,
    ``p < alpha``), or the mismatch is confined to part of the record and the gain is
    overwhelming there (over ``20*min_gain``, positive in at least three blocks and at
    least ten times what the other blocks lose). Parsimony alone (sparing base moves)
    buys nothing: a term whose held-out blocks do not improve is no finding.
    """
    if ev["gain"] <= min_gain:
        return False, "gain below threshold"
    if ev["p"] < alpha:
        return True, "consistent over blocks"
    if _overwhelming(ev["gain"], ev["positive"], ev["ratio"], min_gain):
        return True, "confined but overwhelming"
    return False, (f"not consistent over held-out blocks (gains in {ev['positive']} "
                   f"blocks, p = {ev['p']:.2g})")


def _overwhelming(gain: Any, positive: Any, ratio: Any, min_gain: float) -> Any:
    """:func:`accept`'s route for a confined mismatch (scalars or arrays alike)."""
    return (gain > OVERWHELMING * min_gain) & (positive >= 3) & (ratio > 10)


def accept_many(d: np.ndarray, gain: np.ndarray, *, alpha: float,
                min_gain: float) -> np.ndarray:
    """:func:`accept`'s decision for many sets of per-block gains at once: ``d``
    ``(m, K)``, their score gains ``gain`` ``(m,)``; a boolean ``(m,)``. The block
    statistics are :func:`block_evidence`'s, along the last axis."""
    d = np.atleast_2d(d)
    K = d.shape[-1]
    sd = np.std(d, axis=-1, ddof=1)
    mean = d.mean(-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(sd > 0, mean / (sd / np.sqrt(K)), np.where(mean > 0, np.inf, 0.0))
    p = np.where(sd > 0, dsp.t_cdf(K - 1, -np.where(np.isfinite(t), t, 0.0)),
                 np.where(mean > 0, 0.0, 1.0))
    pos = np.where(d > 0, d, 0.0).sum(-1)
    neg = -np.where(d < 0, d, 0.0).sum(-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(neg > 0, pos / neg, np.inf)
    npos = np.sum(d > 0, axis=-1)
    return (gain > min_gain) & ((p < alpha) | _overwhelming(gain, npos, ratio, min_gain))
