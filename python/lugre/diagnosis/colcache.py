"""The search's columns, kept on the context while the search lasts.

The forward selection scores the same candidates at every step, so their columns are
built once. On a long record the scorers read every ``rows_step``-th sample only
(:class:`lugre.diagnosis.scoring.Scorer`), and that is all a trial's fit needs; what
else the search reads of a trial is the rms of its contribution over every sample used,
``sqrt(beta' G beta / n)`` with the term's Gram matrix ``G`` over those samples (p x p).
So a trial's term keeps its columns at the rows read and that matrix
(:attr:`Term.gram <lugre.diagnosis.candidates.Term.gram>`), a fifth or less of the
columns; a term the search takes gets all its samples back (:func:`whole`), since the
residual it leaves is read whole.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from .candidates import Candidate, Context, Term
from .scoring import Evaluation, rows_of

__all__ = ["contribution_rms", "contribution_rows", "make_term", "prefetch", "reads_rows",
           "release_columns", "whole"]

#: Most column bytes built in one parallel batch (four grid points of a million
#: samples: the batch's residuals and the filter's buffers beside them add about
#: 50 MB to the search's peak; eight, twice that).
_BATCH_BYTES = 32 * 2**20

#: Rows of a column matrix multiplied at once for its Gram matrix.
_GRAM_ROWS = 65536


def make_term(c: Candidate, h: Any, ctx: Context, *, rows: bool = False,
              summed: bool = False) -> Term:
    """Build a :class:`Term` with its columns and prior.

    The columns depend on the candidate, its parameter and the context's base model only,
    so they are kept on the context: the forward selection profiles the same grids at
    every step. With ``rows``, the term holds only the rows the scorers read
    (``ctx.extra["rows_step"]``): what a profile over a grid needs, at a fraction of the
    memory; such a term is for scoring only. With ``summed`` (and rows read), it holds
    the same rows of its columns as built whole, and their Gram matrix over every sample
    used: enough for a trial (:func:`contribution_rms`).
    """
    step = int(ctx.extra.get("rows_step", 1))
    cache = ctx.extra.setdefault(("cache", id(ctx.model)), {})
    gram = None
    if summed and step > 1:
        key = _column_key(c, h, step) + ("summed",)
        hit = cache.get(key)
        if hit is None:
            full = c.columns(h, ctx)
            hit = cache[key] = (rows_of(full, step), _gram(full, ctx.sig.mask))
        X, gram = hit
    else:
        key = _column_key(c, h, step if rows else 1)
        X = cache.get(key)
        if X is None:
            X = c.columns(h, ctx)
            if rows:
                X = rows_of(X, step)
            cache[key] = X
    return Term(cand=c, h=h, X=X, prior=c.prior_tol(h, ctx), center=c.prior_center(h, ctx),
                gram=gram)


def reads_rows(scorer: Any, ctx: Context) -> bool:
    """Whether ``scorer`` reads the rows the columns are kept at (a long record)."""
    return int(ctx.extra.get("rows_step", 1)) == scorer.step > 1


def _gram(X: np.ndarray, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``X[mask].T @ X[mask]``, a slab of rows at a time; and the mask it is over."""
    G = np.zeros((X.shape[1], X.shape[1]))
    for a in range(0, X.shape[0], _GRAM_ROWS):
        xs = X[a:a + _GRAM_ROWS][mask[a:a + _GRAM_ROWS]]
        G += xs.T @ xs
    return G, mask


def contribution_rms(term: Term, beta: np.ndarray, mask: np.ndarray, ctx: Context
                     ) -> float:
    """Rms [N] over the samples ``mask`` of what ``term`` with coefficients ``beta``
    adds (rms, not std: a constant force is a contribution too)."""
    if term.gram is not None and term.gram[1] is mask:
        return float(np.sqrt(max(float(beta @ term.gram[0] @ beta), 0.0) / np.sum(mask)))
    X = term.X if term.gram is None else term.cand.columns(term.h, ctx)
    return float(np.sqrt(np.mean(np.einsum("ij,j->i", X, beta)[mask] ** 2)))


def contribution_rows(term: Term, beta: np.ndarray, ctx: Context) -> np.ndarray:
    """What ``term`` adds [N] at every sample, or, for a term kept at the rows read
    only, at those rows (zero between them: all the held-out blocks read)."""
    if term.gram is None:
        return term.X @ beta
    step = int(ctx.extra.get("rows_step", 1))
    out = np.zeros(ctx.sig.t.size)
    out[::step] = term.X @ beta
    return out


def whole(terms: list[Term], ev: Evaluation, ctx: Context) -> tuple[list[Term], Evaluation]:
    """The terms with all their samples (the columns of a term kept at the rows read
    built again, the same numbers), and ``ev`` holding them."""
    if all(t.gram is None for t in terms):
        return terms, ev
    out = [t if t.gram is None else replace(t, X=t.cand.columns(t.h, ctx), gram=None)
           for t in terms]
    return out, replace(ev, X=[t.X for t in out])


def release_columns(ctx: Context) -> None:
    """Drop the columns :func:`make_term` and :func:`prefetch` keep on ``ctx``, and
    what the candidates keep there to make them (a base residual, a record with another
    motor force: :data:`_MADE_WITH`).

    The search profiles the same grids at every step and in its later runs (a refusal,
    a look-alike), so the columns stay while it lasts; after it nothing reads them (the
    joint refit builds its own). The terms chosen keep their own columns."""
    for key in [k for k in ctx.extra if isinstance(k, tuple) and k[:1] in _MADE_WITH]:
        del ctx.extra[key]


#: Keys of ``ctx.extra`` that hold columns or what they are made from, by their first
#: element: the column cache, a secant's base residual, a record with the force the
#: model needs (:class:`~lugre.diagnosis.candidates.drive.LoadFriction`).
_MADE_WITH = (("cache",), ("r_base",), ("needed_force",))


def _column_key(c: Candidate, h: Any, step: int = 1) -> tuple[Any, ...]:
    return ("columns", c.effect, h if isinstance(h, (tuple, str)) or h is None else float(h),
            step)


def prefetch(c: Candidate, hs: Any, ctx: Context) -> None:
    """Build the missing columns of grid points ``hs`` in parallel batches, when the
    candidate can (``columns_many``, which returns the rows the scorers read only),
    into the cache :func:`make_term` reads."""
    many = getattr(c, "columns_many", None)
    if many is None:
        return
    step = int(ctx.extra.get("rows_step", 1))
    cache = ctx.extra.setdefault(("cache", id(ctx.model)), {})
    todo = [h if isinstance(h, tuple) else float(h) for h in hs]
    todo = [h for h in todo if _column_key(c, h, step) not in cache]
    per = max(1, _BATCH_BYTES // (8 * max(len(ctx.sig), 1)))
    for i in range(0, len(todo), per):
        chunk = todo[i:i + per]
        cols = many(chunk, ctx, step)
        if cols is None:
            return
        for h, X in zip(chunk, cols):
            cache[_column_key(c, h, step)] = X
