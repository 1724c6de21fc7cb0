"""Matplotlib figures written as PNG (Agg backend, no display needed)."""

from __future__ import annotations

import io
import os
from collections.abc import Sequence
from typing import Any

from .io import _atomic_write

__all__ = ["figure", "save_png"]


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


def label_axes(axes: Sequence[Any], ylabels: Sequence[str], xlabel: str) -> None:
    """Y labels on each axis, the X label on the last, light grids."""
    for ax, yl in zip(axes, ylabels):
        ax.set_ylabel(yl)
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel(xlabel)
