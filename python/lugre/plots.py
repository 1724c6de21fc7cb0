"""Matplotlib figures written as PNG (Agg backend, no display needed)."""

from __future__ import annotations

import io
import os
from collections.abc import Sequence
from typing import Any

from ._atomic import _atomic_write

__all__ = ["figure", "legend_above", "save_png"]


def figure(nrows: int = 1, ncols: int = 1, **kw: Any) -> tuple[Any, Any]:
    """A new figure on the Agg backend, whatever the user's default backend is.

    Parameters
    ----------
    nrows, ncols : int
        Subplot grid.
    **kw
        Passed to :class:`matplotlib.figure.Figure` (``figsize``, ...).

    Returns
    -------
    (Figure, axes)
    """
    from matplotlib.figure import Figure

    kw.setdefault("figsize", (9, 2.6 * nrows))
    kw.setdefault("layout", "constrained")
    fig = Figure(**kw)
    axes = fig.subplots(nrows, ncols, squeeze=False)
    return fig, axes


def save_png(fig: Any, path: str | os.PathLike[str], dpi: int = 110) -> str:
    """Render ``fig`` and write it to ``path`` whole (temporary file, then rename).

    Returns
    -------
    str
        The path written.
    """
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    _atomic_write(path, buf.getvalue())
    return os.fspath(path)


def legend_above(ax: Any, ncol: int = 3, fontsize: int = 8) -> None:
    """The legend in a row above the axes, off the data."""
    ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=ncol, frameon=False,
              fontsize=fontsize, borderaxespad=0.2)


def label_axes(axes: Sequence[Any], ylabels: Sequence[str], xlabel: str) -> None:
    """Y labels on each axis, the X label on the last, light grids."""
    for ax, yl in zip(axes, ylabels):
        ax.set_ylabel(yl)
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel(xlabel)


def static_fit_figure(v: Any, F: Any, fit: Any, path: str | os.PathLike[str]) -> str:
    """Steady-state points, rejected points and the fitted Stribeck curves, per direction.

    Returns
    -------
    str
        The path written.
    """
    import numpy as np

    from .model import Model

    v, F = np.asarray(v, float), np.asarray(F, float)
    fig, axes = figure(1, 2, figsize=(10, 4))
    rejected = np.zeros(len(v), bool)
    rejected[fit.rejected] = True
    for ax, sign, d, name in ((axes[0, 0], 1, fit.positive, "v > 0"),
                              (axes[0, 1], -1, fit.negative, "v < 0")):
        sel = np.sign(v) == sign
        a = np.abs(v[sel])
        ax.semilogx(1e3 * a, sign * F[sel], "o", ms=4, label="points")
        ax.semilogx(1e3 * np.abs(v[sel & rejected]), sign * F[sel & rejected], "x", ms=9,
                    mew=2, color="C3", label="rejected (gross error)")
        grid = np.geomspace(max(a.min(), 1e-6), a.max(), 300)
        m = Model.paper().with_friction(positive=d.params, negative=d.params)
        curve = np.abs(_stribeck(sign * grid, m))
        ax.semilogx(1e3 * grid, curve, "k-", lw=1, label="fit")
        p = d.params
        ax.set_title(f"{name}: fc {p['fc']:.2f} N, fs {p['fs']:.2f} N, "
                     f"sigma2 {p['sigma2']:.1f} N s/m, vs {1e3 * p['vs']:.2f} mm/s", fontsize=9,
                     pad=20)
        ax.set_xlabel("|v| [mm/s]")
        ax.set_ylabel("|F| [N]")
        ax.grid(alpha=0.3, which="both")
        legend_above(ax)
    return save_png(fig, path)


def _stribeck(v: Any, m: Any) -> Any:
    from ._native import stribeck

    return stribeck(v, m)
