"""Figures for the HTML pages, rendered to PNG data URIs (nothing fetched from elsewhere;
PNG keeps pages with thousands of points small, at twice the screen resolution).

Quantities carry one unit each across the figures (:mod:`lugre.units`): position in mm,
speed in mm/s, time in s, force in N (rad, rad/s and N m on a rotary axis). Legends sit
above the axes, off the data.
"""

from __future__ import annotations

import base64
import io
from typing import Any

import numpy as np

from . import units as U
from .plots import figure

__all__ = ["data_uri", "effect_figure", "residual_figure"]

#: Most points drawn per trace (an SVG path per point beyond that only adds bytes).
MAX_POINTS = 2500

#: The quantity of each abscissa name.
_QUANTITY = {"t": "time", "time": "time", "x": "position", "position": "position",
             "v": "velocity", "velocity": "velocity"}


def abscissa(key: str) -> tuple[str, float]:
    """Axis label and factor from SI of an abscissa (``t``, ``x``, ``v`` or the
    quantity's name), in the units of the axis spoken now: ``("position [mm]", 1e3)``."""
    word = _QUANTITY[key]
    unit, k = U.where_unit(word)
    return f"{word} [{unit}]", k


def _force_label(what: str = "") -> str:
    """``"force residual [N]"``, ``"torque residual [N m]"`` on a rotary axis."""
    return f"{U.force_words()}{' ' + what if what else ''} [{U.si('N')}]"


def data_uri(fig: Any, dpi: int = 130) -> str:
    """The figure as a ``data:image/png;base64,...`` URI."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def _thin(n: int) -> np.ndarray:
    if n <= MAX_POINTS:
        return np.arange(n)
    return np.linspace(0, n - 1, MAX_POINTS).astype(int)


def _legend_above(ax: Any, ncol: int) -> None:
    ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.01), ncol=ncol, frameon=False,
              fontsize=8, borderaxespad=0.0)


def axis_label(xlabel: str | None, key: str | None = None) -> tuple[str, float]:
    """Label and factor for an abscissa given by name (``x``) or by label (``position
    [m]``): SI labels become display units."""
    if key in _QUANTITY:
        return abscissa(key)
    if xlabel:
        low = xlabel.lower()
        for word in ("position", "velocity", "time"):
            if low.startswith(word):
                return abscissa(word)
        return xlabel, 1.0
    return "", 1.0


def effect_figure(x: Any, residual: Any, effect: Any, xlabel: str, name: str) -> str:
    """The fitted effect drawn over the residual it explains, against its abscissa."""
    x = np.asarray(x, float)
    residual = np.asarray(residual, float)
    effect = np.asarray(effect, float)
    label, k = axis_label(xlabel)
    order = np.argsort(x, kind="stable")
    idx = order[_thin(order.size)]
    fig, axes = figure(1, 1, figsize=(7.5, 3.0))
    ax = axes[0, 0]
    ax.plot(k * x[idx], residual[idx], ".", ms=2, color="0.55",
            label="residual before the effect")
    ax.plot(k * x[idx], effect[idx], "-", lw=1.6, color="tab:red", label=f"fitted {name}")
    ax.set_xlabel(label)
    ax.set_ylabel(_force_label())
    ax.grid(alpha=0.3)
    _legend_above(ax, 2)
    return data_uri(fig)


def residual_figure(x: Any, before: Any, after: Any, key: str, floor: float | None = None,
                    mask: Any = None) -> str:
    """The force residual before and after the diagnosis, against ``t``, ``x`` or ``v``."""
    x = np.asarray(x, float)
    before = np.asarray(before, float)
    after = np.asarray(after, float)
    if mask is not None:
        m = np.asarray(mask, bool)
        x, before, after = x[m], before[m], after[m]
    label, k = abscissa(key)
    idx = _thin(x.size) if key == "t" else np.argsort(x, kind="stable")[_thin(x.size)]
    fig, axes = figure(1, 1, figsize=(7.5, 3.0))
    ax = axes[0, 0]
    style: dict[str, Any] = {"lw": 0.7} if key == "t" else {"ls": "none", "marker": ".",
                                                            "ms": 2}
    ax.plot(k * x[idx], before[idx], color="tab:red", alpha=0.7, label="residual before",
            **style)
    ax.plot(k * x[idx], after[idx], color="tab:blue", alpha=0.8, label="residual after",
            **style)
    if floor:
        for s in (-2 * floor, 2 * floor):
            ax.axhline(s, color="k", ls="--", lw=0.8)
        ax.plot([], [], "k--", lw=0.8, label="±2× noise floor")
    ax.set_xlabel(label)
    ax.set_ylabel(_force_label("residual"))
    ax.grid(alpha=0.3)
    _legend_above(ax, 3)
    return data_uri(fig)


def curve_figure(series: list[tuple[Any, Any, str, str]], xlabel: str, ylabel: str,
                 xscale: str = "linear") -> str:
    """Lines or points: ``series`` of ``(x, y, style, label)``."""
    fig, axes = figure(1, 1, figsize=(7.5, 3.2))
    ax = axes[0, 0]
    for x, y, style, label in series:
        ax.plot(x, y, style, ms=3, lw=1.2, label=label)
    ax.set_xscale(xscale)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3, which="both")
    _legend_above(ax, min(len(series), 3))
    return data_uri(fig)
