"""PNG plots of a diagnosis (matplotlib, Agg backend)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .report import Diagnosis

__all__ = ["write_plots"]


def write_plots(diagnosis: Diagnosis, out_dir: str | os.PathLike[str]) -> list[Path]:
    """Write the diagnosis plots as PNG files.

    Files: ``residual_time.png``, ``residual_position.png``, ``residual_velocity.png``
    (residual before and after, with the noise floor), ``residual_spectrum.png``
    (spectrum of the residual over position), ``overlay.png`` (measured motor force
    against the model before and after).

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
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    d = diagnosis.data
    m = d["mask"]
    floor = diagnosis.noise["rms"]
    files: list[Path] = []

    def save(fig: plt.Figure, name: str) -> None:
        p = out / name
        fig.tight_layout()
        fig.savefig(p, dpi=110)
        plt.close(fig)
        files.append(p)

    for key, label, unit in (("t", "time", "s"), ("x", "position", "m"), ("v", "velocity", "m/s")):
        fig, ax = plt.subplots(figsize=(8, 4))
        style = "-" if key == "t" else "."
        kw = {"lw": 0.6} if key == "t" else {"ms": 1}
        ax.plot(d[key][m], d["before"][m], style, color="tab:red", alpha=0.6,
                label="before", **kw)
        ax.plot(d[key][m], d["after"][m], style, color="tab:blue", alpha=0.7,
                label="after", **kw)
        for s in (-2 * floor, 2 * floor):
            ax.axhline(s, color="k", ls="--", lw=0.8)
        ax.set_xlabel(f"{label} [{unit}]")
        ax.set_ylabel("force residual [N]")
        ax.set_title(f"Residual against {label} (dashed: 2x noise floor)")
        ax.legend(loc="upper right")
        save(fig, f"residual_{label}.png")

    fig, ax = plt.subplots(figsize=(8, 4))
    k = d["spectrum_k"]
    with np.errstate(divide="ignore"):
        ax.semilogy(1.0 / k * 1e3, d["spectrum_before"], color="tab:red", label="before")
        ax.semilogy(1.0 / k * 1e3, d["spectrum_after"], color="tab:blue", label="after")
    ax.set_xscale("log")
    ax.set_xlabel("pitch [mm]")
    ax.set_ylabel("amplitude [N]")
    ax.set_title("Spectrum of the residual over position")
    ax.legend()
    save(fig, "residual_spectrum.png")

    fig, axs = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    t = d["t"]
    axs[0].plot(t[m], d["force"][m], color="k", lw=0.8, label="measured motor force")
    axs[0].plot(t[m], d["model_before"][m], color="tab:red", lw=0.6, label="model before")
    axs[0].plot(t[m], d["model_after"][m], color="tab:blue", lw=0.6, label="model after")
    axs[0].set_ylabel("force [N]")
    axs[0].legend(loc="upper right")
    fb, fa = diagnosis.fit["before"], diagnosis.fit["after"]
    axs[0].set_title(f"Before/after: rms residual {fb['rms_force']:.3g} N -> "
                     f"{fa['rms_force']:.3g} N")
    axs[1].plot(t[m], d["before"][m], color="tab:red", lw=0.6, label="residual before")
    axs[1].plot(t[m], d["after"][m], color="tab:blue", lw=0.6, label="residual after")
    axs[1].set_xlabel("time [s]")
    axs[1].set_ylabel("residual [N]")
    axs[1].legend(loc="upper right")
    save(fig, "overlay.png")
    return files
