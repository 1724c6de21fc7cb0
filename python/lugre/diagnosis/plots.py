"""PNG plots of a diagnosis (matplotlib, Agg backend)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .. import units as U
from .report import Diagnosis

__all__ = ["PLOT_FILES", "write_plots"]

#: The files :func:`write_plots` writes into its directory.
PLOT_FILES = ("residual_time.png", "residual_position.png", "residual_velocity.png",
              "residual_spectrum.png", "overlay.png")


def write_plots(diagnosis: Diagnosis, out_dir: str | os.PathLike[str]) -> list[Path]:
    """Write the diagnosis plots as PNG files.

    Files: ``residual_time.png``, ``residual_position.png``, ``residual_velocity.png``
    (residual before and after, with the noise floor), ``residual_spectrum.png``
    (spectrum of the residual over position), ``overlay.png`` (the force residual
    before and after, over time). Positions in mm, speeds in mm/s (on a rotary axis rad,
    rad/s and N m); legends above the axes.

    Parameters
    ----------
    diagnosis : Diagnosis
        The result of :func:`lugre.diagnosis.diagnose`.
    out_dir : str or os.PathLike
        Directory (created if needed).

    Returns
    -------
    list of Path
        The files written.
    """
    with U.axis(diagnosis.model.kind):
        return _write_plots(diagnosis, out_dir)


def _write_plots(diagnosis: Diagnosis, out_dir: str | os.PathLike[str]) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        from ..exceptions import InputError

        raise InputError.at("out_dir", f"{out} exists and is not a directory: give a "
                            "directory for the figures")
    out.mkdir(parents=True, exist_ok=True)
    d = diagnosis.data
    m = d["mask"]
    floor = diagnosis.noise["rms"]
    files: list[Path] = []

    def save(fig: plt.Figure, name: str) -> None:
        # whole or nothing, like every other output (a device or FIFO written through)
        import io

        from .._atomic import atomic_write

        p = out / name
        fig.tight_layout()
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=110)
        plt.close(fig)
        atomic_write(p, buf.getvalue())
        files.append(p)

    # one unit per quantity across the figures: position in mm, speed in mm/s
    f_label = f"{U.force_words()} residual [{U.si('N')}]"
    for key, label in (("t", "time"), ("x", "position"), ("v", "velocity")):
        unit, scale = U.where_unit(label)
        fig, ax = plt.subplots(figsize=(8, 4))
        style = "-" if key == "t" else "."
        kw = {"lw": 0.6} if key == "t" else {"ms": 1}
        ax.plot(scale * d[key][m], d["before"][m], style, color="tab:red", alpha=0.6,
                label="residual before", **kw)
        ax.plot(scale * d[key][m], d["after"][m], style, color="tab:blue", alpha=0.7,
                label="residual after", **kw)
        for s in (-2 * floor, 2 * floor):
            ax.axhline(s, color="k", ls="--", lw=0.8)
        ax.set_xlabel(f"{label} [{unit}]")
        ax.set_ylabel(f_label)
        ax.set_title(f"Residual against {label} (dashed: 2x noise floor)", loc="left",
                     pad=22)
        _legend_above(ax)
        save(fig, f"residual_{label}.png")

    fig, ax = plt.subplots(figsize=(8, 4))
    k = d["spectrum_k"]
    p_unit, p_scale = U.position_unit()
    with np.errstate(divide="ignore"):
        ax.semilogy(1.0 / k * p_scale, d["spectrum_before"], color="tab:red",
                    label="residual before")
        ax.semilogy(1.0 / k * p_scale, d["spectrum_after"], color="tab:blue",
                    label="residual after")
    ax.set_xscale("log")
    ax.set_xlabel(f"pitch [{p_unit}]")
    ax.set_ylabel(f"amplitude [{U.si('N')}]")
    ax.set_title("Spectrum of the residual over position", loc="left", pad=22)
    _legend_above(ax)
    save(fig, "residual_spectrum.png")

    # the models' forces lie on top of the measured force at this scale: show what they
    # leave, the residual before and after
    fig, ax = plt.subplots(figsize=(9, 4))
    t = d["t"]
    ax.plot(t[m], d["before"][m], color="tab:red", lw=0.6, label="residual before")
    ax.plot(t[m], d["after"][m], color="tab:blue", lw=0.6, label="residual after")
    fb, fa = diagnosis.fit["before"], diagnosis.fit["after"]
    n = U.si("N")
    ax.set_title(f"{U.force_words().capitalize()} residual {fb['rms_force']:.3g} {n} -> "
                 f"{fa['rms_force']:.3g} {n} rms", loc="left", pad=22)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(f_label)
    _legend_above(ax)
    save(fig, "overlay.png")
    return files


def _legend_above(ax: object) -> None:
    """The legend above the axes, off the data."""
    ax.legend(loc="lower right", bbox_to_anchor=(1.0, 1.0), ncol=3, frameon=False,  # type: ignore[attr-defined]
              fontsize=8, borderaxespad=0.2)
