"""The main job on bundled data: the seed paper's axis, simulated.

Two experiments of the seed paper (m = 25 kg, K_F = 25 N/A, LuGre parameters of its
Tables 1 and 2):

1. stick-slip: a slow position ramp pulled through a soft position loop;
2. speed tracking of ``v_d = sin(2*pi*t)`` m/s under a PI speed loop (gains 1200 and
   12000 at 10 kHz, the choice stated in ``../shared/paper/NOTES.md``), without and
   with LuGre friction feed-forward.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from ._native import simulate
from .model import Model
from .plots import figure, label_axes, legend_above, save_png

__all__ = ["DemoResult", "run_demo"]


@dataclass
class DemoResult:
    """What the demo measured and wrote."""

    stick_stops: int
    """Number of times the axis stuck during the ramp (after the first second)."""
    max_speed_error: float
    """Maximum speed tracking error in the second second without compensation [m/s]."""
    max_speed_error_ff: float
    """The same with LuGre feed-forward [m/s]."""
    files: list[str]
    """PNG files written."""


def stick_slip_model() -> Model:
    """The paper's axis under a soft P position loop (kp = 1e4 N/m, 10 kHz)."""
    d = Model.paper().to_dict()
    d["controller"] = {"type": "pid", "kp": 1e4, "ki": 0.0, "kd": 0.0, "rate_hz": 1e4}
    return Model.from_dict(d)


def speed_loop_model(feedforward: str | None = None) -> Model:
    """The paper's axis under a PI speed loop, optionally with friction feed-forward."""
    d = Model.paper().to_dict()
    d["controller"] = {"type": "pi_speed", "kp": 1200.0, "ki": 12000.0, "rate_hz": 1e4}
    if feedforward:
        d["controller"]["feedforward"] = {"type": feedforward}
    return Model.from_dict(d)


def run_demo(out_dir: str | os.PathLike[str], verbose: bool = True) -> DemoResult:
    """Run both experiments, write ``stick_slip.png`` and ``speed_tracking.png``.

    Parameters
    ----------
    out_dir : path
        Directory for the figures (created if missing).
    verbose : bool
        Print what is done and measured.
    """
    os.makedirs(out_dir, exist_ok=True)
    say = print if verbose else (lambda *a, **k: None)

    # 1. stick-slip
    t = np.arange(0.0, 4.0, 1e-4)
    ramp = 0.01  # m/s
    x_ref = ramp * t
    r = simulate(stick_slip_model(), t, x_ref)
    late = t >= 1.0
    moving = r.v[late] > 0.1 * ramp
    stops = int(np.count_nonzero(moving[:-1] & ~moving[1:]))
    fig, ax = figure(3, 1, figsize=(9, 7))
    ax = ax[:, 0]
    ax[0].plot(t, 1e3 * x_ref, "k--", lw=1, label="reference")
    ax[0].plot(t, 1e3 * r.x, lw=1.2, label="position")
    legend_above(ax[0])
    ax[1].plot(t, 1e3 * r.v, lw=1)
    ax[2].plot(t, r.friction, lw=1, label="LuGre friction")
    ax[2].plot(t, 25.0 * r.i, lw=0.8, alpha=0.7, label="motor force")
    legend_above(ax[2])
    label_axes(ax, ["x [mm]", "v [mm/s]", "force [N]"], "t [s]")
    ax[0].set_title("Stick-slip: 10 mm/s ramp pulled through a soft position loop", pad=20)
    f1 = save_png(fig, os.path.join(out_dir, "stick_slip.png"))
    say(f"stick-slip: the speed fell below 1 mm/s {stops} times after t = 1 s, peak slip speed "
        f"{1e3 * r.v[late].max():.1f} mm/s (ramp 10 mm/s) -> {f1}")

    # 2. speed tracking with and without feed-forward
    t = np.arange(0.0, 2.0, 1e-4)
    v_ref = np.sin(2 * np.pi * t)
    plain = simulate(speed_loop_model(), t, v_ref=v_ref)
    comp = simulate(speed_loop_model("lugre"), t, v_ref=v_ref)
    e0, e1 = v_ref - plain.v, v_ref - comp.v
    second = t >= 1.0
    m0, m1 = float(np.abs(e0[second]).max()), float(np.abs(e1[second]).max())
    fig, ax = figure(2, 1, figsize=(9, 5.5))
    ax = ax[:, 0]
    # one unit per quantity across the figures: speeds in mm/s
    ax[0].plot(t, 1e3 * v_ref, "k--", lw=1, label="reference")
    ax[0].plot(t, 1e3 * plain.v, lw=1, label="no compensation")
    ax[0].plot(t, 1e3 * comp.v, lw=1, label="LuGre feed-forward")
    legend_above(ax[0])
    ax[1].plot(t, 1e3 * e0, lw=1, label=f"no compensation (max {1e3 * m0:.0f} mm/s)")
    ax[1].plot(t, 1e3 * e1, lw=1, label=f"LuGre feed-forward (max {1e3 * m1:.0f} mm/s)")
    legend_above(ax[1], ncol=2)
    label_axes(ax, ["v [mm/s]", "speed error [mm/s]"], "t [s]")
    ax[0].set_title("Speed tracking of sin(2 pi t) m/s, PI speed loop (1200, 12000) at 10 kHz",
                    pad=20)
    f2 = save_png(fig, os.path.join(out_dir, "speed_tracking.png"))
    say(f"speed tracking: max error {100 * m0:.1f} cm/s without compensation, "
        f"{100 * m1:.1f} cm/s with LuGre feed-forward (paper: about 18, then below 10) -> {f2}")
    return DemoResult(stops, m0, m1, [f1, f2])
